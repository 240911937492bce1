//! Holomorphic 1-forms of a surface with boundary through its double (paper 003 §2): a
//! connected surface `M` of genus `g` with `b ≥ 1` boundary loops is glued to its mirror copy
//! along the boundary ([`crate::mesh::double_cover`]); the double `D` is a closed surface of
//! genus `G = 2g + b − 1` with an antiholomorphic involution `σ` (the reflection) fixing `∂M`.
//! The doubled flat metric (each boundary vertex becomes a cone point of twice its boundary
//! angle) is conformal to the Schottky double of `M`, so [`super::holomorphic_forms`] on `D`
//! gives the basis `ω_1 … ω_G`, the period matrix `Ω` and the zeros (`2G − 2`).
//!
//! The reflection on homology: every loop `γ_l` of the canonical basis (a path on the cut's
//! refined mesh `R`, whose first vertices are `D`'s) is mapped by `σ` vertex by vertex
//! (consecutive input vertices joined by shortest paths of `R`), and the harmonic basis `ζ_k`
//! (`∫_{γ_l} ζ_k = δ_kl`) integrated along `σγ_l` gives the integer matrix `N` of `σ_*`
//! (`σ_* γ_l = Σ_k N_kl γ_k`). Checks: `N² = 1`; with `A_j = σ a_j`, `B_j = −σ b_j` (a
//! canonical basis: `σ` reverses intersections) the period matrix of `(A, B)` is `−Ω̄`
//! (`∫_{σγ} ω = conj ∫_γ conj(σ^*ω)` and `conj(σ^*ω)` is holomorphic).
//!
//! Even and odd forms: `σ^*` acts on harmonic coordinates (periods) by `Nᵀ`; it anticommutes
//! with the Hodge star, so the `2G`-dimensional harmonic space splits into `G` even and `G`
//! odd forms. An odd harmonic form `α` vanishes on the boundary's tangent (`σ` fixes it), so
//! its integral is constant along every boundary loop: `ω = α + i *α` is the holomorphic form
//! whose real part is orthogonal to the boundary (paper 003 §2); [`DoubleForms::orthogonal`]
//! is a basis of the `G` of them.
//!
//! An interior edge of `M` between two boundary vertices (a chord: the double would have two
//! edges between them) is split at its midpoint first (same flat metric). Before that, boundary
//! corners sharper than π/2 are widened by a vertex scaling (same discrete conformal class;
//! [`super::corners`]): their cones on the double are too sharp for the discrete forms' zeros.

use super::cochain;
use super::corners::{widen_sharp_corners, WidenedCorner};
use super::small::{self, Matrix};
use super::symmetric;
use super::working::working_surface;
use super::{
    holomorphic_forms_on, FormsOptions, FormsTriangulation, HolomorphicForm, HolomorphicForms,
};
use crate::error::{Error, Result};
use crate::mesh::double::double_edge_origin;
use crate::mesh::{double_cover, topology, Mesh, Surface};
use crate::metric::refine::Refined;
use crate::metric::{Geometry, IntrinsicMetric};
use crate::progress::Progress;
use serde::Serialize;
use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

/// The reflection's action measured on the forms of the double (module docs).
#[derive(Debug, Clone, Serialize)]
pub struct Reflection {
    /// `σ_*` on the homology basis `a₁, b₁, …` (rounded; `N_kl` = coefficient of `γ_k` in
    /// `σ_* γ_l`).
    pub matrix: Vec<Vec<i64>>,
    /// `max |N − round(N)|` before rounding.
    pub integrality: f64,
    /// `max |N² − 1|`.
    pub involution_error: f64,
    /// Dimensions of the even and odd harmonic forms (`G` each).
    pub even: usize,
    pub odd: usize,
    /// The period matrix of the reflected basis `(σa, −σb)`, and `max |Ω_σ + Ω̄|`.
    pub reflected_re: Matrix,
    pub reflected_im: Matrix,
    pub reflected_error: f64,
    /// Whether the working triangulation is σ-symmetric; then the forms, `Ω` and `N` are
    /// computed on it ([`super::symmetric`]) and the reflection commutes with the
    /// discretization, otherwise `N` comes from the loops mapped by `σ`.
    pub symmetric: bool,
    /// Symmetric case: `max |σ^*ζ_k − Σ_m C_mk ζ_m| / max |ζ_k|` (rounding only).
    pub symmetry_residual: Option<f64>,
}

/// The forms of a surface with boundary, computed on its double.
#[derive(Debug, Clone)]
pub struct DoubleForms {
    /// Genus and boundary loops of the surface; genus of the double.
    pub surface_genus: usize,
    pub boundary_loops: usize,
    pub genus: usize,
    /// Chords split before doubling, and the vertex count of the split surface (`D`'s
    /// vertices `0..surface_vertices` are the surface's, the rest their mirrors).
    pub chord_splits: usize,
    pub surface_vertices: usize,
    /// Boundary corners widened by a vertex scaling before doubling ([`super::corners`]).
    pub widened: Vec<WidenedCorner>,
    /// `σ` on the vertices of the double.
    pub sigma: Vec<u32>,
    /// The forms of the double.
    pub forms: HolomorphicForms,
    pub reflection: Reflection,
    /// Holomorphic forms `α + i *α` with `α` odd (real part orthogonal to the boundary).
    pub orthogonal: Vec<HolomorphicForm>,
    /// `max |α(e)| / max |α|` over the boundary edges of the surface that are edges of the
    /// refined mesh, for the forms of `orthogonal` (0 for the smooth forms).
    pub orthogonal_boundary_defect: f64,
}

impl DoubleForms {
    /// For every face of the refined mesh of the double, whether it lies on the surface: its
    /// working face has no mirror vertex (faces straddling the boundary after intrinsic flips
    /// count as mirror faces).
    pub fn surface_faces(&self) -> Vec<bool> {
        let w = &self.forms.working.mesh;
        let on: Vec<bool> = (0..w.n_faces() as u32)
            .map(|f| {
                w.face(f)
                    .iter()
                    .all(|&v| (v as usize) < self.surface_vertices)
            })
            .collect();
        self.forms
            .cut
            .refined
            .face_origin
            .iter()
            .map(|&f| on.get(f as usize).copied().unwrap_or(false))
            .collect()
    }
}

/// The holomorphic 1-forms of a connected surface with boundary (module docs). `metric` is a
/// Euclidean metric on `mesh` (e.g. the input's lengths); positions are carried folded (a
/// mirror vertex at its original's position).
pub fn double_forms(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    positions: Option<&[[f64; 3]]>,
    options: &FormsOptions,
    progress: &mut dyn Progress,
) -> Result<DoubleForms> {
    if metric.geometry() != Geometry::Euclidean {
        return Err(Error::input(
            "the forms of the double need a Euclidean metric on the surface",
        ));
    }
    if metric.lengths().len() != mesh.n_edges() {
        return Err(Error::input(format!(
            "the metric has {} lengths for {} edges",
            metric.lengths().len(),
            mesh.n_edges()
        )));
    }
    let t = topology(mesh);
    let (g, b) = match t.components.as_slice() {
        [c] if c.boundary_loops > 0 => (c.genus.max(0) as usize, c.boundary_loops),
        _ => {
            return Err(Error::topology(format!(
                "the double needs one connected surface with boundary; this mesh has {} \
                 component(s) and {} boundary loop(s)",
                t.components.len(),
                t.boundary_loops()
            )))
        }
    };
    if 2 * g + b < 2 {
        return Err(Error::topology(
            "a disk's double is a sphere, which has no holomorphic 1-forms",
        ));
    }
    progress.report("forms", Some(0.0), "doubling the surface");
    let (widened_lengths, widened) = if options.keep_sharp_corners {
        (metric.lengths().to_vec(), Vec::new())
    } else {
        widen_sharp_corners(mesh, metric.lengths())
    };
    let (split, lengths, pos, chord_splits) = split_chords(mesh, &widened_lengths, positions)?;
    let (double, sigma) = double_cover(&split)?;
    let origin = double_edge_origin(&split, &double, &sigma)?;
    let dl: Vec<f64> = origin.iter().map(|&e| lengths[e as usize]).collect();
    let dpos: Option<Vec<[f64; 3]>> = pos.as_ref().map(|p| {
        (0..double.n_vertices())
            .map(|v| p[(v as u32).min(sigma[v]) as usize])
            .collect()
    });
    let metric_d = IntrinsicMetric::euclidean(dl);
    let mut working = working_surface(
        &double,
        &metric_d,
        dpos.as_deref(),
        options.triangulation,
        progress,
    )?;
    if options.triangulation == FormsTriangulation::Delaunay
        && symmetric::extend_symmetry(&working.mesh, &working.lengths, &sigma).is_none()
    {
        // The intrinsic Delaunay triangulation lost the symmetry (the vertices inserted to make
        // it simplicial, or ties): the double's own triangulation is symmetric by construction.
        progress.report(
            "forms",
            Some(0.0),
            "the Delaunay triangulation is not symmetric",
        );
        working = working_surface(
            &double,
            &metric_d,
            dpos.as_deref(),
            FormsTriangulation::Input,
            progress,
        )?;
    }
    let mut forms = holomorphic_forms_on(working, &options.cut, progress)?;
    // Not σ-symmetric, or the refinement not read (an error): the refined mesh's forms.
    let sym = symmetric::symmetrize(&mut forms, &sigma, progress).unwrap_or(None);
    let nv = split.n_vertices();
    let reflection = reflection(&forms, &sigma, sym)?;
    let (orthogonal, defect) = orthogonal_forms(&forms, &reflection, &split);
    Ok(DoubleForms {
        surface_genus: g,
        boundary_loops: b,
        genus: forms.genus,
        chord_splits,
        surface_vertices: nv,
        widened,
        sigma,
        forms,
        reflection,
        orthogonal,
        orthogonal_boundary_defect: defect,
    })
}

/// The double of a surface with boundary as a surface ([`split_chords`], then
/// [`double_cover`]), mirror vertices at their originals' positions (folded, so its edge
/// lengths from positions are the surface's): the closed surface, `σ` on its vertices and the
/// number of chords split.
pub fn folded_double(surface: &Surface) -> Result<(Surface, Vec<u32>, usize)> {
    let lengths = surface.edge_lengths();
    let (split, _, pos, chord_splits) =
        split_chords(&surface.mesh, &lengths, Some(&surface.positions))?;
    let pos = pos.unwrap_or_else(|| surface.positions.clone());
    let (mesh, sigma) = double_cover(&split)?;
    let positions: Vec<[f64; 3]> = (0..mesh.n_vertices())
        .map(|v| pos[(v as u32).min(sigma[v]) as usize])
        .collect();
    let s = Surface {
        mesh,
        positions,
        uvs: None,
    };
    Ok((s, sigma, chord_splits))
}

type Split = (Mesh, Vec<f64>, Option<Vec<[f64; 3]>>, usize);

/// Split every interior edge between two boundary vertices at its midpoint (the lengths of
/// the new edges from the two triangles: half the edge, and the medians).
pub(crate) fn split_chords(
    mesh: &Mesh,
    lengths: &[f64],
    positions: Option<&[[f64; 3]]>,
) -> Result<Split> {
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut len: HashMap<(u32, u32), f64> = (0..mesh.n_edges() as u32)
        .map(|e| {
            let [a, b] = mesh.edge_vertices(e);
            (key(a, b), lengths[e as usize])
        })
        .collect();
    let mut pos = positions.map(|p| p.to_vec());
    let mut faces = mesh.faces().to_vec();
    let mut nv = mesh.n_vertices();
    let mut splits = 0;
    let mut cur = mesh.clone();
    loop {
        let chord = (0..cur.n_edges() as u32).find(|&e| {
            let [a, b] = cur.edge_vertices(e);
            !cur.is_boundary_edge(e) && cur.is_boundary_vertex(a) && cur.is_boundary_vertex(b)
        });
        let Some(e) = chord else { break };
        let h = cur.edge_halfedge(e);
        let t = cur.he_twin(h);
        let (a, bv) = (cur.he_origin(h), cur.he_tip(h));
        let c = cur.he_tip(cur.he_next(h));
        let d = cur.he_tip(cur.he_next(t));
        let m = nv as u32;
        nv += 1;
        let l = len[&key(a, bv)];
        let median = |x: u32| {
            let (p, q) = (len[&key(a, x)], len[&key(bv, x)]);
            (0.5 * (2.0 * p * p + 2.0 * q * q - l * l).max(0.0)).sqrt() / 2f64.sqrt()
        };
        let (mc, md) = (median(c), median(d));
        len.insert(key(a, m), 0.5 * l);
        len.insert(key(bv, m), 0.5 * l);
        len.insert(key(c, m), mc);
        len.insert(key(d, m), md);
        if let Some(p) = pos.as_mut() {
            let (pa, pb) = (p[a as usize], p[bv as usize]);
            p.push([
                0.5 * (pa[0] + pb[0]),
                0.5 * (pa[1] + pb[1]),
                0.5 * (pa[2] + pb[2]),
            ]);
        }
        let (fh, ft) = (cur.he_face(h) as usize, cur.he_face(t) as usize);
        faces[fh] = [a, m, c];
        faces.push([m, bv, c]);
        faces[ft] = [bv, m, d];
        faces.push([m, a, d]);
        cur = Mesh::from_triangles(nv, faces.clone())?;
        splits += 1;
    }
    let mut out = Vec::with_capacity(cur.n_edges());
    for e in 0..cur.n_edges() as u32 {
        let [a, b] = cur.edge_vertices(e);
        out.push(*len.get(&key(a, b)).ok_or_else(|| {
            Error::numerical(format!("split surface: edge {a}–{b} has no length"))
        })?);
    }
    Ok((cur, out, pos, splits))
}

/// A vertex of the double near vertex `v` of the refined mesh: the input vertex nearest along
/// its split edges, or — for a vertex the working triangulation inserted (ids `nd..`, to make
/// the intrinsic Delaunay triangulation simplicial) — the first double vertex found breadth
/// first from it.
fn input_vertex(r: &Refined, nd: usize, mut v: u32) -> u32 {
    let n = r.original_vertices;
    while (v as usize) >= n {
        let Some(s) = r.new_vertices.get(v as usize - n) else {
            break;
        };
        v = if s.t < 0.5 { s.a } else { s.b };
    }
    if (v as usize) < nd {
        return v;
    }
    let mut seen = std::collections::HashSet::from([v]);
    let mut queue = std::collections::VecDeque::from([v]);
    while let Some(x) = queue.pop_front() {
        for y in r.mesh.vertex_neighbors(x) {
            if (y as usize) < nd {
                return y;
            }
            if seen.insert(y) {
                queue.push_back(y);
            }
        }
    }
    v
}

/// The loop's vertex sequence mapped by `σ` onto the refined mesh: each vertex replaced by a
/// nearby vertex of the double ([`input_vertex`]) and mapped, consecutive images joined by
/// shortest paths (half-edges).
fn reflected_loop(refined: &Refined, sigma: &[u32], vertices: &[u32]) -> Result<Vec<u32>> {
    let mut keep: Vec<u32> = Vec::with_capacity(vertices.len() + 1);
    for &v in vertices {
        let o = input_vertex(refined, sigma.len(), v) as usize;
        if o < sigma.len() {
            let s = sigma[o];
            if keep.last() != Some(&s) {
                keep.push(s);
            }
        }
    }
    if let (Some(&first), Some(&last)) = (keep.first(), keep.last()) {
        if first != last {
            keep.push(first);
        }
    }
    let (r, lengths) = (&refined.mesh, &refined.lengths);
    let mut path = Vec::new();
    for w in keep.windows(2) {
        if w[0] != w[1] {
            path.extend(shortest_path(r, lengths, w[0], w[1])?);
        }
    }
    Ok(path)
}

/// Dijkstra from `s` to `t` on the edges of `r`: the half-edges of a shortest path.
fn shortest_path(r: &Mesh, lengths: &[f64], s: u32, t: u32) -> Result<Vec<u32>> {
    let mut dist: HashMap<u32, (f64, u32)> = HashMap::new();
    let mut heap = BinaryHeap::new();
    dist.insert(s, (0.0, u32::MAX));
    heap.push(Reverse((0u64, s)));
    while let Some(Reverse((dk, v))) = heap.pop() {
        let d = f64::from_bits(dk);
        if d > dist[&v].0 {
            continue;
        }
        if v == t {
            let mut hs = Vec::new();
            let mut x = t;
            while x != s {
                let h = dist[&x].1;
                hs.push(h);
                x = r.he_origin(h);
            }
            hs.reverse();
            return Ok(hs);
        }
        for h in r.outgoing(v) {
            let w = r.he_tip(h);
            let nd = d + lengths[r.he_edge(h) as usize];
            if dist.get(&w).is_none_or(|&(old, _)| nd < old) {
                dist.insert(w, (nd, h));
                heap.push(Reverse((nd.to_bits(), w)));
            }
        }
    }
    Err(Error::topology(format!(
        "no path from vertex {s} to vertex {t} on the double"
    )))
}

/// `σ_*` on homology and the reflected period matrix (module docs).
fn reflection(
    h: &HolomorphicForms,
    sigma: &[u32],
    sym: Option<symmetric::Symmetric>,
) -> Result<Reflection> {
    let gg = h.genus;
    let n = 2 * gg;
    let r = &h.cut.refined;
    let (symmetric, symmetry_residual) = (sym.is_some(), sym.as_ref().map(|s| s.residual));
    let nm = match sym {
        Some(s) => s.n,
        None => {
            let mut nm = vec![vec![0.0; n]; n];
            for (l, lp) in h.cut.loops.iter().take(n).enumerate() {
                let path = reflected_loop(r, sigma, &lp.vertices)?;
                for (k, z) in h.harmonic.iter().enumerate() {
                    nm[k][l] = cochain::period(&r.mesh, z, &path);
                }
            }
            nm
        }
    };
    let integrality = nm
        .iter()
        .flatten()
        .map(|x| (x - x.round()).abs())
        .fold(0.0, f64::max);
    let ni: Matrix = nm
        .iter()
        .map(|row| row.iter().map(|x| x.round()).collect())
        .collect();
    let involution_error = small::max_diff(&small::mul(&ni, &ni), &small::identity(n));
    let trace: f64 = (0..n).map(|i| ni[i][i]).sum();
    let even = ((n as f64 + trace) / 2.0).round().max(0.0) as usize;
    // Periods of ω_i on γ_k: a-cycles δ, b-cycles Ω; on σγ_l: Σ_k N_kl (those).
    let pm = &h.period_matrix;
    let period = |i: usize, k: usize| -> (f64, f64) {
        let j = k / 2;
        if k.is_multiple_of(2) {
            (if i == j { 1.0 } else { 0.0 }, 0.0)
        } else {
            (pm.re[i][j], pm.im[i][j])
        }
    };
    let on_reflected = |i: usize, l: usize| -> (f64, f64) {
        (0..n).fold((0.0, 0.0), |(x, y), k| {
            let (p, q) = period(i, k);
            (x + ni[k][l] * p, y + ni[k][l] * q)
        })
    };
    // PA_ij = ∫_{σ a_j} ω_i, PB_ij = −∫_{σ b_j} ω_i; Ω_σ = PA⁻¹ PB (as a real 2G system).
    let mut block = vec![vec![0.0; n]; n];
    let mut pb = vec![vec![(0.0, 0.0); gg]; gg];
    for i in 0..gg {
        for j in 0..gg {
            let (x, y) = on_reflected(i, 2 * j);
            block[i][j] = x;
            block[i][j + gg] = -y;
            block[i + gg][j] = y;
            block[i + gg][j + gg] = x;
            let (u, v) = on_reflected(i, 2 * j + 1);
            pb[i][j] = (-u, -v);
        }
    }
    let inv = small::inverse(&block, "reflected a-periods")?;
    let mut re = vec![vec![0.0; gg]; gg];
    let mut im = vec![vec![0.0; gg]; gg];
    let mut err: f64 = 0.0;
    for i in 0..gg {
        for j in 0..gg {
            let (mut x, mut y) = (0.0, 0.0);
            for k in 0..gg {
                let (ur, ui) = (inv[i][k], inv[i + gg][k]);
                let (pr, pi) = pb[k][j];
                x += ur * pr - ui * pi;
                y += ur * pi + ui * pr;
            }
            re[i][j] = x;
            im[i][j] = y;
            err = err.max((x + pm.re[i][j]).abs().max((y - pm.im[i][j]).abs()));
        }
    }
    Ok(Reflection {
        matrix: ni
            .iter()
            .map(|row| row.iter().map(|&x| x as i64).collect())
            .collect(),
        integrality,
        involution_error,
        even,
        odd: n - even.min(n),
        reflected_re: re,
        reflected_im: im,
        reflected_error: err,
        symmetric,
        symmetry_residual,
    })
}

/// A basis of the odd harmonic forms (columns of `(1 − Nᵀ)/2`, orthonormalized) made
/// holomorphic, `α + i *α`, and their largest relative value on the surface's boundary edges.
fn orthogonal_forms(
    h: &HolomorphicForms,
    refl: &Reflection,
    surface: &Mesh,
) -> (Vec<HolomorphicForm>, f64) {
    let n = 2 * h.genus;
    let mut basis: Vec<Vec<f64>> = Vec::new();
    for col in 0..n {
        let mut c: Vec<f64> = (0..n)
            .map(|k| {
                let id = if k == col { 1.0 } else { 0.0 };
                0.5 * (id - refl.matrix[col][k] as f64)
            })
            .collect();
        for q in &basis {
            let d: f64 = c.iter().zip(q).map(|(x, y)| x * y).sum();
            for (x, y) in c.iter_mut().zip(q) {
                *x -= d * y;
            }
        }
        let norm = c.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm > 1e-6 && basis.len() < refl.odd {
            basis.push(c.iter().map(|x| x / norm).collect());
        }
    }
    let j = &h.complex_structure;
    let rm = &h.cut.refined.mesh;
    let combine = |c: &[f64]| -> Vec<f64> {
        let mut z = vec![0.0; rm.n_edges()];
        for (k, zk) in h.harmonic.iter().enumerate() {
            for (a, b) in z.iter_mut().zip(zk) {
                *a += c[k] * b;
            }
        }
        z
    };
    let boundary: Vec<u32> = (0..surface.n_edges() as u32)
        .filter(|&e| surface.is_boundary_edge(e))
        .filter_map(|e| {
            let [a, b] = surface.edge_vertices(e);
            rm.halfedge_between(a, b).map(|hh| rm.he_edge(hh))
        })
        .collect();
    let mut defect: f64 = 0.0;
    let forms = basis
        .iter()
        .map(|c| {
            let jc: Vec<f64> = (0..n)
                .map(|r| (0..n).map(|k| j[r][k] * c[k]).sum())
                .collect();
            let re = combine(c);
            let scale = re.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
            for &e in &boundary {
                defect = defect.max(re[e as usize].abs() / scale);
            }
            HolomorphicForm {
                re,
                im: combine(&jc),
            }
        })
        .collect();
    (forms, defect)
}
