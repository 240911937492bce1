//! [`ManifoldSpace::new`], stage by stage (paper 000 §5; see the module docs of [`super`]):
//! the active faces, the vertex frames and their motions into each face, the knot clouds in
//! vertex frames, the basis of every active face in its home chart, and the candidate
//! triangles of every face.

use super::*;
use crate::spline::error::SplineError;

/// Knot placement in vertex frames (module docs).
struct Placement<'m> {
    mesh: &'m Mesh,
    n: usize,
    active: &'m [bool],
    /// Per corner `3f + i`: vertex frame of corner `i` → canonical development of `f`.
    corner_motion: &'m [RigidMotion],
}

impl Placement<'_> {
    /// Knot array of active face `f` (three clouds mapped into its canonical frame).
    fn face_knots(&self, knots: &[Point], f: u32, out: &mut Vec<Point>) {
        let n = self.n;
        out.clear();
        for (i, &w) in self.mesh.face(f).iter().enumerate() {
            let m = &self.corner_motion[3 * f as usize + i];
            for k in 0..=n {
                out.push(apply(m, knots[w as usize * (n + 1) + k]));
            }
        }
    }
    /// Worst knot triple involving `v`'s moving knots over `v`'s active faces.
    fn local_quality(&self, v: u32, knots: &[Point], floor: f64, arr: &mut Vec<Point>) -> f64 {
        let n = self.n;
        let mut q = f64::INFINITY;
        for h in self.mesh.vertex_corners(v) {
            let f = h / 3;
            if !self.active[f as usize] {
                continue;
            }
            let i = h as usize % 3;
            arr.clear();
            let m = &self.corner_motion[h as usize];
            for k in 1..=n {
                arr.push(apply(m, knots[v as usize * (n + 1) + k]));
            }
            for (mm, &w) in self.mesh.face(f).iter().enumerate() {
                let mw = &self.corner_motion[3 * f as usize + mm];
                if mm == i {
                    arr.push(apply(mw, knots[w as usize * (n + 1)]));
                } else {
                    for k in 0..=n {
                        arr.push(apply(mw, knots[w as usize * (n + 1) + k]));
                    }
                }
            }
            q = q.min(general_position_involving(arr, n, floor));
            if q <= floor {
                return q;
            }
        }
        q
    }
}

/// A face's basis in its home chart with the chart's relative residual on the face's stars.
type HomeBasis = Option<(ChartId, TriangleBasis, f64)>;

/// The candidates of one face: `(I, motion canon(g) → home(I), g's corners in home(I))`.
type Candidates = Vec<(u32, RigidMotion, [Point; 3])>;

impl<'a, A: FlatCharts + Sync + ?Sized> ManifoldSpace<'a, A> {
    /// Place knots and build the basis of every active face in its home chart. Errors name the
    /// face or vertex at fault (a missing home chart, a chart inconsistent with a vertex star,
    /// knots that violate the DMS conditions).
    pub fn new(charts: &'a A, degree: usize, opts: &KnotOptions) -> Result<Self> {
        let mesh = charts.mesh();
        let lengths = charts.lengths();
        let n = degree;
        if !(2..=MAX_DEGREE).contains(&n) {
            return Err(SplineError::DegreeUnsupported {
                spline: "manifold",
                degree: n,
                min: 2,
                max: MAX_DEGREE,
            }
            .into());
        }
        if !(opts.spread > 0.0 && opts.spread <= 0.45) {
            return Err(SplineError::KnotSpread {
                spread: opts.spread,
            }
            .into());
        }
        check_metric(mesh, lengths)?;
        let nf = mesh.n_faces();
        let (is_sing, active) = active_faces(charts)?;
        let frames: Vec<Option<StarFrame>> = (0..mesh.n_vertices() as u32)
            .into_par_iter()
            .map(|v| {
                (!is_sing[v as usize] && !mesh.is_isolated(v)).then(|| star_frame(mesh, lengths, v))
            })
            .collect();
        let corner_motion = corner_motions(mesh, lengths, &frames, &active)?;
        let pl = Placement {
            mesh,
            n,
            active: &active,
            corner_motion: &corner_motion,
        };
        let knots = place_knots(&pl, &frames, opts)?;
        let built = home_bases(charts, n, &frames, &active, &knots)?;
        let mut home = vec![ChartId::MAX; nf];
        let mut bases = Vec::with_capacity(nf);
        let mut report = ManifoldReport {
            degree: n,
            active_faces: 0,
            control_points: 0,
            min_orientation: f64::INFINITY,
            min_omega_ratio: f64::INFINITY,
            min_general_position: f64::INFINITY,
            max_chart_residual: 0.0,
            max_candidates: 0,
        };
        for (f, b) in built.into_iter().enumerate() {
            match b {
                Some((h, basis, res)) => {
                    home[f] = h;
                    report.active_faces += 1;
                    report.min_orientation = report.min_orientation.min(basis.min_orientation());
                    report.min_omega_ratio = report.min_omega_ratio.min(basis.omega_ratio());
                    report.min_general_position =
                        report.min_general_position.min(basis.general_position());
                    report.max_chart_residual = report.max_chart_residual.max(res);
                    bases.push(Some(basis));
                }
                None => bases.push(None),
            }
        }
        report.control_points = report.active_faces * per_triangle(n);
        let (canon, canon_coords) = canonical_charts(charts, &active, &home)?;
        let cands = candidates(charts, &active, &home, &canon_coords)?;
        let mut cand_start = vec![0u32; nf + 1];
        let mut cand = Vec::new();
        for (g, c) in cands.into_iter().enumerate() {
            report.max_candidates = report.max_candidates.max(c.len());
            cand.extend(c);
            cand_start[g + 1] = cand.len() as u32;
        }
        Ok(ManifoldSpace {
            charts,
            degree: n,
            active,
            frames,
            knots,
            home,
            bases,
            canon,
            canon_coords,
            cand_start,
            cand,
            report,
        })
    }
}

/// The singular vertices (checked) and the active faces, those not incident to one.
fn active_faces<A: FlatCharts + Sync + ?Sized>(charts: &A) -> Result<(Vec<bool>, Vec<bool>)> {
    let mesh = charts.mesh();
    let nv = mesh.n_vertices();
    let mut is_sing = vec![false; nv];
    for &s in charts.singular_vertices() {
        if s as usize >= nv {
            let (vertex, n_vertices) = (s, nv);
            return Err(SplineError::SingularVertexMissing { vertex, n_vertices }.into());
        }
        is_sing[s as usize] = true;
    }
    let active: Vec<bool> = mesh
        .faces()
        .iter()
        .map(|t| t.iter().all(|&v| !is_sing[v as usize]))
        .collect();
    if !active.iter().any(|&a| a) {
        return Err(Error::input(
            "manifold spline: every face is incident to a singular vertex",
        ));
    }
    Ok((is_sing, active))
}

/// Per corner `3f + i` of an active face: the rigid motion from the vertex frame of corner
/// `i` to the canonical development of `f` ([`develop_face`]).
fn corner_motions(
    mesh: &Mesh,
    lengths: &[f64],
    frames: &[Option<StarFrame>],
    active: &[bool],
) -> Result<Vec<RigidMotion>> {
    let nf = mesh.n_faces();
    let canon_dev: Vec<[Point; 3]> = (0..nf as u32)
        .map(|f| develop_face(face_side_lengths(mesh, lengths, f)))
        .collect();
    let mut corner_motion = vec![RigidMotion::new(0.0, C::new(0.0, 0.0)); 3 * nf];
    for f in 0..nf as u32 {
        if !active[f as usize] {
            continue;
        }
        for (i, &v) in mesh.face(f).iter().enumerate() {
            let fr = frames[v as usize]
                .as_ref()
                .ok_or_else(|| Error::input(format!("manifold spline: vertex {v} has no star")))?;
            let c = fr.coords_of(f).ok_or_else(|| {
                Error::input(format!(
                    "manifold spline: face {f} missing in the star of {v}"
                ))
            })?;
            corner_motion[3 * f as usize + i] = fit_rigid(c, &canon_dev[f as usize]).0;
        }
    }
    Ok(corner_motion)
}

/// Where each vertex's cloud may go, in its vertex frame.
struct CloudShapes {
    /// `spread ×` the smallest altitude at the vertex.
    radius: Vec<f64>,
    /// `(centre direction, half angle)` of the wedge outside the spline domain's boundary
    /// (`(0, π)`: the full circle).
    wedge: Vec<(f64, f64)>,
    /// Whether the vertex belongs to an active face.
    used: Vec<bool>,
}

/// The radius and the wedge of every vertex's cloud (module docs).
fn cloud_shapes(
    mesh: &Mesh,
    frames: &[Option<StarFrame>],
    active: &[bool],
    opts: &KnotOptions,
) -> Result<CloudShapes> {
    let nv = mesh.n_vertices();
    let mut radius = vec![0.0f64; nv];
    let mut wedge = vec![(0.0, PI); nv];
    let mut used = vec![false; nv];
    for v in 0..nv as u32 {
        let Some(fr) = frames[v as usize].as_ref() else {
            continue;
        };
        let mut r = f64::INFINITY;
        for (_, c) in &fr.faces {
            let area2 = det3(c[0], c[1], c[2]);
            // altitude at v = 2A / opposite side; v is the corner at the origin
            let i = c
                .iter()
                .position(|p| p[0] == 0.0 && p[1] == 0.0)
                .unwrap_or(0);
            let (p, q) = (c[(i + 1) % 3], c[(i + 2) % 3]);
            let opp = (p[0] - q[0]).hypot(p[1] - q[1]);
            r = r.min(opts.spread * area2.abs() / opp);
        }
        radius[v as usize] = r;
        let k = fr.faces.len();
        let act: Vec<bool> = fr.faces.iter().map(|(f, _)| active[*f as usize]).collect();
        used[v as usize] = act.iter().any(|&a| a);
        let boundary = mesh.is_boundary_vertex(v);
        if act.iter().all(|&a| a) && !boundary {
            continue; // full circle
        }
        if !used[v as usize] {
            continue;
        }
        // Runs of active faces (cyclic for interior vertices).
        let starts: Vec<usize> = (0..k)
            .filter(|&j| {
                act[j]
                    && if j == 0 {
                        boundary || !act[k - 1]
                    } else {
                        !act[j - 1]
                    }
            })
            .collect();
        if starts.len() != 1 {
            return Err(Error::input(format!(
                "manifold spline: vertex {v} touches the boundary of the spline domain in {} separate places (e.g. next to two cones); not supported",
                starts.len()
            )));
        }
        let j0 = starts[0];
        let mut span = 0.0;
        let mut j = j0;
        while act[j] {
            span += fr.corner_angles[j];
            j = (j + 1) % k;
            if j == j0 || (boundary && j == 0) {
                break;
            }
        }
        let a0 = fr.start_angles[j0];
        let a1 = a0 + span;
        let half = 0.5 * span.min(2.0 * PI - span).max(0.0);
        if !(half > 1e-6) {
            return Err(SplineError::BoundaryFolds { vertex: v }.into());
        }
        wedge[v as usize] = (0.5 * (a0 + a1) + PI, half);
    }
    Ok(CloudShapes {
        radius,
        wedge,
        used,
    })
}

/// Candidate number `attempt` for the cloud of vertex `v` (`t_{v,0} = v` at the origin, the
/// others pseudo-random in the wedge at radii `0.6–1 ×` `r`), written into `out`.
fn candidate_cloud(
    wedge: (f64, f64),
    seed: u64,
    v: usize,
    r: f64,
    attempt: u64,
    out: &mut [Point],
) {
    let (center, half) = wedge;
    let n = out.len() - 1;
    let key = hash64(seed ^ hash64(v as u64) ^ attempt.wrapping_mul(0xA24B_AED4_963E_E407));
    out[0] = [0.0, 0.0];
    for k in 1..=n {
        let rr = r * (0.6 + 0.4 * unit(key.wrapping_add(2 * k as u64)));
        let t = unit(key.wrapping_add(2 * k as u64 + 1));
        let ang = if half >= PI {
            2.0 * PI * t
        } else {
            center + 0.75 * half * (2.0 * t - 1.0)
        };
        out[k] = [rr * ang.cos(), rr * ang.sin()];
    }
}

/// The knots in vertex frames, `[v * (n+1) + k]`: per vertex the best of 32 candidate clouds
/// (worst knot triple over its faces), in rounds that shrink the clouds of faces whose `Δ_β`
/// come out too thin (at most 12 rounds).
fn place_knots(
    pl: &Placement<'_>,
    frames: &[Option<StarFrame>],
    opts: &KnotOptions,
) -> Result<Vec<Point>> {
    let (mesh, n, active) = (pl.mesh, pl.n, pl.active);
    let (nv, nf) = (mesh.n_vertices(), mesh.n_faces());
    let CloudShapes {
        mut radius,
        wedge,
        used,
    } = cloud_shapes(mesh, frames, active, opts)?;
    let candidate = |v: usize, r: f64, attempt: u64, out: &mut [Point]| {
        candidate_cloud(wedge[v], opts.seed, v, r, attempt, out)
    };
    let mut knots = vec![[0.0; 2]; nv * (n + 1)];
    for v in 0..nv {
        if used[v] {
            candidate(v, radius[v], 0, &mut knots[v * (n + 1)..(v + 1) * (n + 1)]);
        }
    }
    const CANDIDATES: u64 = 32;
    let mut trial = vec![[0.0; 2]; n + 1];
    let mut dirty = used.clone();
    let mut counter = 0u64;
    let mut arr = Vec::with_capacity(3 * (n + 1));
    for round in 0..12 {
        for sweep in 0..2 {
            for v in 0..nv {
                if !dirty[v] {
                    continue;
                }
                let range = v * (n + 1)..(v + 1) * (n + 1);
                let mut best_q = pl.local_quality(v as u32, &knots, 0.0, &mut arr);
                if sweep > 0 && best_q > 0.05 {
                    continue;
                }
                let mut best = knots[range.clone()].to_vec();
                for _ in 0..CANDIDATES {
                    counter += 1;
                    candidate(v, radius[v], counter, &mut trial);
                    knots[range.clone()].copy_from_slice(&trial);
                    let q = pl.local_quality(v as u32, &knots, best_q, &mut arr);
                    if q > best_q {
                        best_q = q;
                        best.copy_from_slice(&trial);
                    }
                }
                knots[range].copy_from_slice(&best);
            }
        }
        dirty.fill(false);
        let mut any = false;
        for f in 0..nf as u32 {
            if !active[f as usize] {
                continue;
            }
            pl.face_knots(&knots, f, &mut arr);
            if needs_shrink(n, &arr) {
                for &v in &mesh.face(f) {
                    dirty[v as usize] = true;
                }
                any = true;
            }
        }
        if !any || round == 11 {
            break;
        }
        for v in 0..nv {
            if dirty[v] {
                radius[v] *= 0.7;
                for k in 1..=n {
                    let t = &mut knots[v * (n + 1) + k];
                    *t = [0.7 * t[0], 0.7 * t[1]];
                }
            }
        }
    }
    Ok(knots)
}

/// The basis of every active face in its home chart, from the three clouds mapped there by
/// the rigid motion fitted from each vertex's star (checked to 1e-6 of the star's size).
fn home_bases<A: FlatCharts + Sync + ?Sized>(
    charts: &A,
    n: usize,
    frames: &[Option<StarFrame>],
    active: &[bool],
    knots: &[Point],
) -> Result<Vec<HomeBasis>> {
    let mesh = charts.mesh();
    (0..mesh.n_faces() as u32)
        .into_par_iter()
        .map(|f| -> Result<HomeBasis> {
            if !active[f as usize] {
                return Ok(None);
            }
            let h = charts.home_chart(f).ok_or_else(|| {
                Error::input(format!(
                    "manifold spline: the charts give no home chart for face {f}, which is not incident to a singular vertex"
                ))
            })?;
            let mut clouds: Vec<Vec<Point>> = Vec::with_capacity(3);
            let mut worst = 0.0f64;
            let own = charts.face_coords(h, f).ok_or_else(|| {
                Error::input(format!("manifold spline: face {f} is not in its home chart {h}"))
            })?;
            for (corner, v) in mesh.face(f).into_iter().enumerate() {
                let fr = frames[v as usize].as_ref().ok_or_else(|| {
                    Error::input(format!("manifold spline: vertex {v} has no star"))
                })?;
                let mut a = Vec::new();
                let mut b = Vec::new();
                let mut size = 0.0f64;
                for (g, c) in &fr.faces {
                    if !active[*g as usize] {
                        continue;
                    }
                    if let Some(x) = charts.face_coords(h, *g) {
                        a.extend_from_slice(c);
                        b.extend_from_slice(&x);
                        for p in c {
                            size = size.max(p[0].hypot(p[1]));
                        }
                    }
                }
                if a.is_empty() {
                    return Err(Error::input(format!(
                        "manifold spline: home chart {h} of face {f} contains none of the faces around vertex {v}"
                    )));
                }
                let (m, res) = fit_rigid(&a, &b);
                worst = worst.max(res / size.max(1e-300));
                if !(res <= 1e-6 * size) {
                    return Err(Error::input(format!(
                        "manifold spline: home chart {h} of face {f} is not a consistent development of the star of vertex {v} (residual {res:.2e} relative to {size:.2e})"
                    )));
                }
                // t_{v,0} = v exactly as the chart places it (the fitted motion is off by
                // the chart's rounding), so that points at vertices and on edges, which are
                // mapped through the same chart coordinates, land exactly on knot lines.
                let mut cl: Vec<Point> = knots[v as usize * (n + 1)..(v as usize + 1) * (n + 1)]
                    .iter()
                    .map(|&p| apply(&m, p))
                    .collect();
                cl[0] = own[corner];
                clouds.push(cl);
            }
            let basis = TriangleBasis::new(n, [&clouds[0], &clouds[1], &clouds[2]])
                .map_err(|e| Error::input(format!("manifold spline, face {f}: {e}")))?;
            Ok(Some((h, basis, worst)))
        })
        .collect::<Result<_>>()
}

/// The canonical chart of every face (its home chart, else the first chart containing it)
/// and the face's corners there.
#[allow(clippy::type_complexity)]
fn canonical_charts<A: FlatCharts + Sync + ?Sized>(
    charts: &A,
    active: &[bool],
    home: &[ChartId],
) -> Result<(Vec<ChartId>, Vec<[Point; 3]>)> {
    let nf = charts.mesh().n_faces();
    let mut canon = vec![0; nf];
    let mut canon_coords = vec![[[0.0; 2]; 3]; nf];
    for f in 0..nf as u32 {
        let c = if active[f as usize] {
            home[f as usize]
        } else {
            *charts
                .charts_of_face(f)
                .first()
                .ok_or_else(|| Error::input(format!("manifold spline: face {f} is in no chart")))?
        };
        canon[f as usize] = c;
        canon_coords[f as usize] = charts.face_coords(c, f).ok_or_else(|| {
            Error::input(format!(
                "manifold spline: chart {c} is listed for face {f} but has no coordinates for it"
            ))
        })?;
    }
    Ok((canon, canon_coords))
}

/// The candidates of every active face `g`: the active faces `I` sharing a vertex with `g`,
/// with the motion from `g`'s canonical chart to `I`'s home chart and `g`'s corners there.
fn candidates<A: FlatCharts + Sync + ?Sized>(
    charts: &A,
    active: &[bool],
    home: &[ChartId],
    canon_coords: &[[Point; 3]],
) -> Result<Vec<Candidates>> {
    let mesh = charts.mesh();
    (0..mesh.n_faces() as u32)
        .into_par_iter()
        .map(|g| -> Result<Candidates> {
            if !active[g as usize] {
                return Ok(Vec::new());
            }
            let mut set: Vec<u32> = Vec::new();
            for v in mesh.face(g) {
                for i in mesh.vertex_faces(v) {
                    if active[i as usize] {
                        set.push(i);
                    }
                }
            }
            set.sort_unstable();
            set.dedup();
            set.into_iter()
                .map(|i| {
                    let hc = home[i as usize];
                    let b = charts.face_coords(hc, g).ok_or_else(|| {
                        Error::input(format!(
                            "manifold spline: face {g} shares a vertex with face {i} but is not in its home chart {hc}"
                        ))
                    })?;
                    Ok((i, fit_rigid(&canon_coords[g as usize], &b).0, b))
                })
                .collect()
        })
        .collect::<Result<_>>()
}
