//! The robust route from a closed genus-0 mesh to the sphere, used when spherical Newton does
//! not converge from the initial metric (paper 001 §V and paper 002 §7.1 treat the spherical
//! flow; this is the classical puncture-and-project construction, made exact for vertex
//! scaling):
//!
//! 1. remove the star of one vertex `v` (the largest Euclidean angle deficit among vertices of
//!    valence ≥ 5): a disk;
//! 2. flatten the disk by Euclidean vertex-scaling flow with the link of `v` held at
//!    `w_j = −2 log l_vj` and `K̄ = 0` inside. This is exact: stereographic projection from
//!    the north pole `N` scales chords by `|σ(x) − σ(y)| = 2|x − y| / (|x − N||y − N|)`, so the
//!    planar image of a vertex-scaled unit sphere with `v` at `N` is a vertex-scaled flat disk
//!    whose link values are `−2 log l_vj` up to a constant (the inversion of the star about
//!    `v`). (docs/DESIGN.md suggests a round boundary here; the Dirichlet condition is the one that
//!    reproduces the discrete conformal class exactly, and it is a convex problem.);
//! 3. lay the disk out in the plane (breadth-first placement by circle intersection) and move
//!    the least-squares circle through its boundary to the unit circle;
//! 4. stereographic projection to the unit sphere, `v` at the north pole;
//! 5. Möbius normalization: the centroid of the vertices moves to the origin (iterated
//!    `x ↦ T_a(x) = (1 − |a|²)(x − a)/|x − a|² − a` with `a` a damped centroid);
//! 6. spherical edge lengths from the embedded points, `d = 2 asin(|x_i − x_j|/2)`;
//! 7. the scheme's variables `u` fitted to these lengths (Gauss–Newton on `Σ (l_e(u) − d_e)²`;
//!    exact for vertex scaling when the embedding is valid), then spherical Newton from there:
//!    the start is close to the solution set with its Möbius freedom already centred.

//!
//! [`conformal_sphere`] is the sphere of the conformal scheme (discrete conformal equivalence
//! with intrinsic Delaunay flips, the default): the flat metric of the surface with one vertex
//! at infinity — link values `u_j = −λ_∞j`, every other vertex flat, the link kept convex
//! (the KKT conditions of the bound-constrained convex problem `u_w ≥ −λ_∞w` of
//! Gillespie–Springborn–Crane 2021 §4.3, derived in its doc comment) — then stereographic
//! projection and Möbius centring of the vertex areas, with the metric carried exactly by
//! vertex scaling (`λ = λ⁰ + u_i + u_j`, not recomputed from the points). Public API:
//! [`conformal_sphere`] → [`ConformalSphere`] (final triangulation with its flip log, points,
//! `u`, diagnostics), [`mobius_centre`].

use super::newton::{self, NewtonSettings, SolveOutcome};
use super::target::Target;
use super::FlowOptions;
use crate::error::{Error, Result};
use crate::mesh::{Mesh, NONE};
use crate::metric::{Evaluator, Geometry, HessianPattern, Scheme};
use crate::numeric::sparse::SymmetricSolver;
use crate::progress::Progress;
mod conformal_sphere;
pub use conformal_sphere::{conformal_sphere, mobius_centre, ConformalSphere};

/// Run the puncture route; `ev` and `target` belong to the spherical problem on `mesh`.
pub fn puncture_route(
    mesh: &Mesh,
    lengths: &[f64],
    ev: &mut Evaluator,
    target: &mut Target,
    settings: &NewtonSettings,
    options: &FlowOptions,
    progress: &mut dyn Progress,
) -> Result<SolveOutcome> {
    let n = mesh.n_vertices();
    // 1. The puncture vertex: the largest Euclidean angle deficit among vertices of valence
    //    ≥ 5 (a convex, well-connected star inverts to a well-shaped boundary).
    let k_in = crate::metric::curvature(mesh, Geometry::Euclidean, lengths);
    let v = (0..n as u32)
        .filter(|&v| !mesh.is_isolated(v))
        .max_by(|&a, &b| {
            let ka = (mesh.valence(a) >= 5, k_in[a as usize]);
            let kb = (mesh.valence(b) >= 5, k_in[b as usize]);
            ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1)).then(b.cmp(&a))
        })
        .ok_or_else(|| Error::topology("the mesh has no vertices"))?;
    let (disk, disk_lengths, new_id, old_id) = star_removed(mesh, lengths, v)?;
    // 2. Flat disk. Vertex scaling with the link fixed at w_j = −2 log l_vj is exact: it is
    //    the stereographic image of the discrete conformal (vertex-scaling) sphere with v at
    //    the north pole (|σ(x) − σ(y)| = 2|x − y| / (|x − N||y − N|)).
    let link: Vec<(u32, f64)> = mesh
        .outgoing(v)
        .map(|h| {
            (
                new_id[mesh.he_tip(h) as usize],
                lengths[mesh.he_edge(h) as usize],
            )
        })
        .collect();
    let mean_log = link.iter().map(|(_, l)| l.ln()).sum::<f64>() / link.len() as f64;
    let flat_structure = crate::metric::ConformalStructure::new(
        &disk,
        &disk_lengths,
        Geometry::Euclidean,
        Scheme::Yamabe,
        1.0,
    )?;
    let mut flat_ev = Evaluator::new(&disk, flat_structure);
    let mut flat_target = Target {
        curvature: vec![0.0; disk.n_vertices()],
        fixed: vec![false; disk.n_vertices()],
        round_loops: Vec::new(),
        description: "puncture disk".into(),
    };
    let mut w0 = vec![0.0; disk.n_vertices()];
    for &(j, l) in &link {
        flat_target.fixed[j as usize] = true;
        w0[j as usize] = -2.0 * (l.ln() - mean_log);
    }
    let flat_settings = NewtonSettings {
        tolerance: 1e-12,
        max_iterations: 60,
        line_search: newton::LineSearch::Energy,
        pinned: Vec::new(),
        indefinite: false,
    };
    let flat = {
        let mut sub = |stage: &str, f: Option<f64>, m: &str| {
            progress.report(&format!("puncture/{stage}"), f, m)
        };
        newton::newton(&mut flat_ev, &mut flat_target, w0, &flat_settings, &mut sub)?
    };
    if !flat_ev.evaluate(&flat.u) || flat.max_error > 1e-8 {
        return Err(Error::numerical(format!(
            "the puncture route could not flatten the punctured sphere (max |K| = {:.2e})",
            flat.max_error
        )));
    }
    let flat_lengths = flat_ev.ws.lengths.clone();
    let flat_scheme = Scheme::Yamabe;
    let _ = options;
    // 3. Planar layout and the boundary circle.
    let mut p = layout_plane(&disk, &flat_lengths)?;
    let loops = disk.boundary_loops();
    let ring = loops
        .first()
        .ok_or_else(|| Error::topology("the punctured mesh has no boundary"))?;
    let (c, r) = fit_circle(ring.iter().map(|&w| p[w as usize]));
    for q in p.iter_mut() {
        *q = [(q[0] - c[0]) / r, (q[1] - c[1]) / r];
    }
    // 4. Stereographic projection, v at the north pole.
    let mut x = vec![[0.0, 0.0, 1.0]; n];
    for (k, &w) in old_id.iter().enumerate() {
        let [a, b] = p[k];
        let d = a * a + b * b + 1.0;
        x[w as usize] = [2.0 * a / d, 2.0 * b / d, (a * a + b * b - 1.0) / d];
    }
    // 5. Möbius centring.
    centre_by_boosts(mesh, &mut x);
    // 6. Spherical lengths.
    let d: Vec<f64> = (0..mesh.n_edges() as u32)
        .map(|e| {
            let [a, b] = mesh.edge_vertices(e);
            let (xa, xb) = (x[a as usize], x[b as usize]);
            let ch = ((xa[0] - xb[0]).powi(2) + (xa[1] - xb[1]).powi(2) + (xa[2] - xb[2]).powi(2))
                .sqrt();
            2.0 * (0.5 * ch).min(1.0).asin()
        })
        .collect();
    if d.iter().any(|&l| l.is_nan() || l <= 0.0) {
        return Err(Error::numerical(
            "the puncture route produced coincident points on the sphere",
        ));
    }
    // 7. Fit u to the lengths, then spherical Newton.
    let u = fit_variables(ev, &d)?;
    let mut out = newton::newton(ev, target, u, settings, progress)?;
    out.notes.insert(
        0,
        format!(
            "puncture route: removed the star of vertex {v}, flattened the disk with the {} \
             scheme and the link fixed at w_j = −2 log l_vj ({} Newton steps, max |K| = {:.1e}), \
             projected stereographically, centred by Möbius maps, then spherical Newton",
            flat_scheme, flat.iterations, flat.max_error
        ),
    );
    Ok(out)
}

/// The mesh without the star of `v` (a disk), its edge lengths, and the vertex maps
/// `new_id` (mesh → disk, `NONE` for `v` and isolated vertices) and `old_id` (disk → mesh).
type StarRemoved = (Mesh, Vec<f64>, Vec<u32>, Vec<u32>);
fn star_removed(mesh: &Mesh, lengths: &[f64], v: u32) -> Result<StarRemoved> {
    let n = mesh.n_vertices();
    let mut new_id = vec![NONE; n];
    let mut old_id = Vec::with_capacity(n - 1);
    for w in 0..n as u32 {
        if w != v && !mesh.is_isolated(w) {
            new_id[w as usize] = old_id.len() as u32;
            old_id.push(w);
        }
    }
    let faces: Vec<[u32; 3]> = mesh
        .faces()
        .iter()
        .filter(|t| !t.contains(&v))
        .map(|t| t.map(|w| new_id[w as usize]))
        .collect();
    let disk = Mesh::from_triangles(old_id.len(), faces)?;
    let disk_lengths: Vec<f64> = (0..disk.n_edges() as u32)
        .map(|e| {
            let [a, b] = disk.edge_vertices(e);
            let h = mesh
                .halfedge_between(old_id[a as usize], old_id[b as usize])
                .expect("edge of the disk is an edge of the mesh");
            lengths[mesh.he_edge(h) as usize]
        })
        .collect();
    Ok((disk, disk_lengths, new_id, old_id))
}

/// Möbius normalization of the puncture route: the (unweighted) centroid of the used vertices
/// moves to the origin by damped boosts `x ↦ (1 − |a|²)(x − a)/|x − a|² − a` (budget 500).
fn centre_by_boosts(mesh: &Mesh, x: &mut [[f64; 3]]) {
    let used: Vec<usize> = (0..x.len())
        .filter(|&w| !mesh.is_isolated(w as u32))
        .collect();
    for _ in 0..500 {
        let mut cm = [0.0; 3];
        for &w in &used {
            for k in 0..3 {
                cm[k] += x[w][k];
            }
        }
        let cm = cm.map(|t| t / used.len() as f64);
        let norm = (cm[0] * cm[0] + cm[1] * cm[1] + cm[2] * cm[2]).sqrt();
        if norm < 1e-12 {
            break;
        }
        let a = cm.map(|t| t * 0.9_f64.min(0.5 / norm.max(0.5)));
        let a2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
        for &w in &used {
            let d = [x[w][0] - a[0], x[w][1] - a[1], x[w][2] - a[2]];
            let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let y = [
                (1.0 - a2) * d[0] / dd - a[0],
                (1.0 - a2) * d[1] / dd - a[1],
                (1.0 - a2) * d[2] / dd - a[2],
            ];
            let m = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2]).sqrt();
            x[w] = [y[0] / m, y[1] / m, y[2] / m];
        }
    }
}

/// Breadth-first planar layout of a disk with Euclidean `lengths` (by edge id).
pub fn layout_plane(mesh: &Mesh, lengths: &[f64]) -> Result<Vec<[f64; 2]>> {
    let n = mesh.n_vertices();
    let mut p = vec![[f64::NAN; 2]; n];
    let mut placed = vec![false; n];
    let mut done = vec![false; mesh.n_faces()];
    let len = |a: u32, b: u32| -> f64 {
        let h = mesh.halfedge_between(a, b).expect("edge exists");
        lengths[mesh.he_edge(h) as usize]
    };
    let f0 = 0u32;
    let t = mesh.face(f0);
    let (l01, l02, l12) = (len(t[0], t[1]), len(t[0], t[2]), len(t[1], t[2]));
    p[t[0] as usize] = [0.0, 0.0];
    p[t[1] as usize] = [l01, 0.0];
    let x = (l01 * l01 + l02 * l02 - l12 * l12) / (2.0 * l01);
    p[t[2] as usize] = [x, (l02 * l02 - x * x).max(0.0).sqrt()];
    for &w in &t {
        placed[w as usize] = true;
    }
    done[f0 as usize] = true;
    let mut queue = std::collections::VecDeque::from([f0]);
    while let Some(f) = queue.pop_front() {
        for h in mesh.face_halfedges(f) {
            let tw = mesh.he_twin(h);
            let g = mesh.he_face(tw);
            if g == NONE || done[g as usize] {
                continue;
            }
            done[g as usize] = true;
            // In g, the half-edge tw goes a → b; the third vertex c lies to its left.
            let a = mesh.he_origin(tw);
            let b = mesh.he_tip(tw);
            let c = mesh.he_origin(mesh.he_prev(tw));
            if !placed[c as usize] {
                let (pa, pb) = (p[a as usize], p[b as usize]);
                let e = [pb[0] - pa[0], pb[1] - pa[1]];
                let dd = (e[0] * e[0] + e[1] * e[1]).sqrt();
                let (lac, lbc) = (len(a, c), len(b, c));
                let xx = (lac * lac - lbc * lbc + dd * dd) / (2.0 * dd);
                let yy = (lac * lac - xx * xx).max(0.0).sqrt();
                let (ex, ey) = (e[0] / dd, e[1] / dd);
                p[c as usize] = [pa[0] + xx * ex - yy * ey, pa[1] + xx * ey + yy * ex];
                placed[c as usize] = true;
            }
            queue.push_back(g);
        }
    }
    if placed
        .iter()
        .enumerate()
        .any(|(w, &ok)| !ok && !mesh.is_isolated(w as u32))
    {
        return Err(Error::topology("the disk is not connected"));
    }
    Ok(p)
}

/// Least-squares circle through points (Kåsa fit): centre and radius.
pub fn fit_circle(points: impl Iterator<Item = [f64; 2]>) -> ([f64; 2], f64) {
    // Minimize Σ (x² + y² + D x + E y + F)².
    let mut m = [[0.0; 3]; 3];
    let mut rhs = [0.0; 3];
    for [x, y] in points {
        let row = [x, y, 1.0];
        let z = -(x * x + y * y);
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += row[i] * row[j];
            }
            rhs[i] += row[i] * z;
        }
    }
    let s = solve3(m, rhs);
    let c = [-0.5 * s[0], -0.5 * s[1]];
    let r = (c[0] * c[0] + c[1] * c[1] - s[2]).max(1e-300).sqrt();
    (c, r)
}

fn solve3(m: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(m);
    let mut x = [0.0; 3];
    for k in 0..3 {
        let mut mk = m;
        for i in 0..3 {
            mk[i][k] = b[i];
        }
        x[k] = det(mk) / d;
    }
    x
}

/// Variables `u` of the evaluator's scheme whose lengths best match `d` (Gauss–Newton with a
/// small Levenberg–Marquardt shift), starting from Thurston-like radii of `d`.
fn fit_variables(ev: &mut Evaluator, d: &[f64]) -> Result<Vec<f64>> {
    let data = ev.data.clone();
    let n = data.n_vertices();
    let mut u = vec![0.0; n];
    if ev.structure.scheme.is_circle_packing() {
        // γ_i = mean over faces of (d_ij + d_ik − d_jk)/2.
        let mut sum = vec![0.0; n];
        let mut cnt = vec![0.0; n];
        for (f, t) in data.faces.iter().enumerate() {
            let l = data.face_edges[f].map(|e| d[e as usize]);
            for i in 0..3 {
                sum[t[i] as usize] += 0.5 * (l[(i + 1) % 3] + l[(i + 2) % 3] - l[i]);
                cnt[t[i] as usize] += 1.0;
            }
        }
        for w in 0..n {
            if cnt[w] > 0.0 {
                let g: f64 = (sum[w] / cnt[w]).clamp(1e-9, 3.0);
                u[w] = (0.5 * g).tan().ln();
            }
        }
    } else {
        // sin(d/2) = e^{(ui+uj)/2} η: start from the mean log ratio per vertex.
        let mut sum = vec![0.0; n];
        let mut cnt = vec![0.0; n];
        for (e, &[a, b]) in data.edges.iter().enumerate() {
            let r = 2.0 * ((0.5 * d[e]).sin() / ev.structure.eta[e]).ln();
            for w in [a, b] {
                sum[w as usize] += 0.5 * r;
                cnt[w as usize] += 1.0;
            }
        }
        for w in 0..n {
            if cnt[w] > 0.0 {
                u[w] = sum[w] / cnt[w];
            }
        }
    }
    let fixed: Vec<bool> = data.isolated_vertex.clone();
    let pattern = HessianPattern::new(&data, &fixed);
    let mut solver = SymmetricSolver::new(&pattern)?;
    let mut vals = vec![0.0; pattern.nnz()];
    let mut g = vec![0.0; pattern.n()];
    let mut l = vec![0.0; data.n_edges()];
    let mut dl = vec![[0.0; 2]; data.n_edges()];
    let mut cost = f64::INFINITY;
    for _ in 0..20 {
        ev.structure.lengths_from_data(&data, &u, &mut l, &mut dl);
        let c: f64 = l.iter().zip(d).map(|(a, b)| (a - b) * (a - b)).sum();
        if !c.is_finite() || c > cost * (1.0 - 1e-6) {
            break;
        }
        cost = c;
        vals.fill(0.0);
        g.fill(0.0);
        for (e, &[a, b]) in data.edges.iter().enumerate() {
            let r = l[e] - d[e];
            let (ia, ib) = (
                pattern.free_index[a as usize],
                pattern.free_index[b as usize],
            );
            vals[pattern.diag_slot[a as usize] as usize] += dl[e][0] * dl[e][0];
            vals[pattern.diag_slot[b as usize] as usize] += dl[e][1] * dl[e][1];
            vals[pattern.edge_slot[e] as usize] += dl[e][0] * dl[e][1];
            g[ia as usize] -= dl[e][0] * r;
            g[ib as usize] -= dl[e][1] * r;
        }
        let dmax = vals.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        for &w in &pattern.free_vertex {
            vals[pattern.diag_slot[w as usize] as usize] += 1e-10 * dmax;
        }
        if !solver.factor_llt(&vals) {
            break;
        }
        solver.solve(&mut g);
        let mut trial = u.clone();
        for (k, &w) in pattern.free_vertex.iter().enumerate() {
            trial[w as usize] += g[k];
        }
        ev.structure
            .lengths_from_data(&data, &trial, &mut l, &mut dl);
        let ct: f64 = l.iter().zip(d).map(|(a, b)| (a - b) * (a - b)).sum();
        if ct.is_finite() && ct < cost {
            u = trial;
        } else {
            break;
        }
    }
    Ok(u)
}
