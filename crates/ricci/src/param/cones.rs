//! Automatic cone placement for conformal flattening by the greedy of Ben-Chen, Gotsman and
//! Bunin ("Conformal flattening by curvature prescription and metric scaling", 2008, §4) as
//! used by Boundary First Flattening (Sawhney–Crane 2017, §6.2).
//!
//! **Linearised flattening.** A conformal change `e^{2u}` of the input metric changes the
//! angle defects to first order by `K ≈ K⁰ + L u`, `L` the cotangent Laplacian (positive
//! semi-definite; `∂K_i/∂u_j` of vertex scaling at `u = 0`). Flattening everywhere except at
//! the cone set `C` (and at the boundary, where `u = 0`: the free boundary of least area
//! distortion) is the Dirichlet problem
//!
//! ```text
//! (L u)_i = −K⁰_i  (i ∉ C ∪ ∂M),     u_i = 0  (i ∈ C ∪ ∂M),
//! ```
//!
//! and the curvature left at the cones is `K̄_c = K⁰_c + (L u)_c`; Gauss–Bonnet holds
//! exactly because `Σ_i (L u)_i = 0`. `2u` is the log area distortion of the flattening.
//!
//! **Greedy.** Repeatedly put a cone where `|u|` is largest and solve again. On a closed
//! surface (submodule `closed`) the first cone is Boundary First Flattening's (the most negative
//! angle defect when `χ < 0`) or the extremum of the smooth solution with the total curvature
//! spread by area, whichever greedy ends with the smaller area-weighted `σ(2u)`; then the
//! cones are moved one at a time while `σ(2u)` drops. Every solve uses one factorization of
//! the Laplacian and the cones' Green's functions (submodule `green`). With a boundary, every
//! solve is the system `L + P` (`P` a large diagonal penalty holding `u = 0` on the boundary
//! and the cones), solved from one factorization of `L + P_boundary` and one column per cone
//! by the Woodbury identity (submodule `held`). With a count `N` the greedy stops after `N`
//! cones; with a bound `D` on the area distortion it stops at the first cone set whose
//! linearised `max |2u − mean(2u)| ≤ D` (at most `max_cones` cones).

mod closed;
mod green;
mod held;

use crate::analysis::forms::harmonic::cotan_weights;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::metric::IntrinsicMetric;
use crate::numeric::sparse::{LowerCsc, SymmetricSolver};
use green::GreenBasis;
use held::HeldBasis;
use std::f64::consts::PI;

/// How many cones the greedy places.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ConeBudget {
    /// Exactly this many.
    Count(usize),
    /// As few as needed for a linearised log area distortion `max |2u − mean| ≤ bound`, at
    /// most `max_cones`.
    AreaDistortion { bound: f64, max_cones: usize },
}

/// The cones chosen and the linearised distortion they leave.
#[derive(Debug, Clone)]
pub struct ConePlacement {
    /// `(vertex, target curvature K̄)`; the cone angle is `2π − K̄`.
    pub cones: Vec<(u32, f64)>,
    /// Linearised `max |2u − mean(2u)|` after each cone (index k: with k + 1 cones).
    pub distortion_history: Vec<f64>,
}

/// The cotangent Laplacian of `mesh` with `lengths` in lower-CSC form (diagonal first in each
/// column), and the vertex areas (a third of the incident face areas).
struct Laplacian {
    n: usize,
    col_ptr: Vec<u32>,
    row_idx: Vec<u32>,
    values: Vec<f64>,
    diag: Vec<usize>,
    area: Vec<f64>,
}

/// The cotangent Laplacian of `metric` ([`Laplacian`]), the angle defects
/// ([`angle_defects`]) and the symbolic analysis of the Laplacian's pattern (fill-reducing
/// ordering and supernodal structure) for the cone placement's one factorization. The
/// analysis needs only the pattern (the mesh's edges), so it runs beside the cotangent
/// weights, areas and defects on the second core (`rayon::join`); both halves are the same
/// computations as one after the other.
fn laplacian_system(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
) -> Result<(Laplacian, Vec<f64>, SymmetricSolver)> {
    let n = mesh.n_vertices();
    // Lower-CSC pattern: column `lo` holds the diagonal, then every edge (lo, hi), hi > lo,
    // by row (a counting pass by column, then each column's few entries sorted).
    let ne = mesh.n_edges();
    let mut col_ptr = vec![0u32; n + 1];
    for e in 0..ne as u32 {
        let [a, b] = mesh.edge_vertices(e);
        col_ptr[a.min(b) as usize + 1] += 1;
    }
    for j in 0..n {
        col_ptr[j + 1] += col_ptr[j] + 1;
    }
    let nnz = col_ptr[n] as usize;
    let mut row_idx = vec![0u32; nnz];
    // The edge of every off-diagonal entry (`NONE` on the diagonal).
    let mut entry_edge = vec![crate::mesh::NONE; nnz];
    let mut fill: Vec<u32> = col_ptr[..n].iter().map(|&p| p + 1).collect();
    let diag: Vec<usize> = (0..n).map(|j| col_ptr[j] as usize).collect();
    for (j, &d) in diag.iter().enumerate() {
        row_idx[d] = j as u32;
    }
    for e in 0..ne as u32 {
        let [a, b] = mesh.edge_vertices(e);
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        let at = fill[lo as usize] as usize;
        fill[lo as usize] += 1;
        row_idx[at] = hi;
        entry_edge[at] = e;
    }
    let mut column: Vec<(u32, u32)> = Vec::new();
    for j in 0..n {
        let range = diag[j] + 1..col_ptr[j + 1] as usize;
        column.clear();
        column.extend(range.clone().map(|p| (row_idx[p], entry_edge[p])));
        column.sort_unstable();
        for (p, &(r, e)) in range.zip(&column) {
            row_idx[p] = r;
            entry_edge[p] = e;
        }
    }
    let pattern = LowerCsc {
        n,
        col_ptr: &col_ptr,
        row_idx: &row_idx,
    };
    let (solver, values) = rayon::join(
        || SymmetricSolver::new(pattern),
        || -> Result<_> {
            let lengths = metric.lengths();
            // The edge weights (cot α + cot β)/2 of the analysis module (one definition in
            // the crate).
            let w = cotan_weights(mesh, lengths).map_err(|e| {
                Error::numerical(format!("{e} in the input metric; cones cannot be placed"))
            })?;
            let mut area = vec![0.0; n];
            for f in 0..mesh.n_faces() as u32 {
                let l = mesh
                    .face_halfedges(f)
                    .map(|h| lengths[mesh.he_edge(h) as usize]);
                let a = crate::numeric::vec3::heron(l);
                for v in mesh.face(f) {
                    area[v as usize] += a / 3.0;
                }
            }
            let mut d = vec![0.0; n];
            for (e, &we) in w.iter().enumerate() {
                let [a, b] = mesh.edge_vertices(e as u32);
                d[a as usize] += we;
                d[b as usize] += we;
            }
            let values: Vec<f64> = entry_edge
                .iter()
                .zip(&row_idx)
                .map(|(&e, &r)| match e {
                    crate::mesh::NONE => d[r as usize],
                    e => -w[e as usize],
                })
                .collect();
            Ok((values, area, angle_defects(mesh, metric)))
        },
    );
    let (values, area, k0) = values?;
    let lap = Laplacian {
        n,
        col_ptr,
        row_idx,
        values,
        diag,
        area,
    };
    Ok((lap, k0, solver?))
}

/// Angle defects of the input metric (`2π − Σθ` inside, `π − Σθ` on the boundary).
pub fn angle_defects(mesh: &Mesh, metric: &IntrinsicMetric) -> Vec<f64> {
    let lengths = metric.lengths();
    let n = mesh.n_vertices();
    let mut k: Vec<f64> = (0..n as u32)
        .map(|v| {
            if mesh.is_isolated(v) {
                0.0
            } else if mesh.is_boundary_vertex(v) {
                PI
            } else {
                2.0 * PI
            }
        })
        .collect();
    for f in 0..mesh.n_faces() as u32 {
        let t = mesh.face(f);
        let hs = mesh.face_halfedges(f);
        let l: Vec<f64> = hs
            .iter()
            .map(|&h| lengths[mesh.he_edge(h) as usize])
            .collect();
        for i in 0..3 {
            // Angle at t[i]: between edges l[i] (to t[i+1]) and l[i+2] (from t[i+2]); opposite
            // edge l[i+1].
            let (a, b, c) = (l[i], l[(i + 2) % 3], l[(i + 1) % 3]);
            let cos = ((a * a + b * b - c * c) / (2.0 * a * b)).clamp(-1.0, 1.0);
            k[t[i] as usize] -= cos.acos();
        }
    }
    k
}

/// The greedy placement (module docs) on a connected mesh with Euclidean `lengths`: closed
/// surfaces by `closed::place_cones`; with a boundary, boundary vertices are held at
/// `u = 0` and never become cones.
pub fn greedy_cones(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    budget: ConeBudget,
) -> Result<ConePlacement> {
    greedy_cones_with(mesh, metric, budget, ConeSearch::Greedy)
}

/// How widely the placement on a closed surface searches (see submodule `closed`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ConeSearch {
    /// The Dirichlet greedy from two first cones and its moves (the default).
    #[default]
    Greedy,
    /// Also the greedy on the least-squares energy with adjoint candidates, and moves over
    /// the same candidates (cone count only). Lower σ (session 10: horse 8 cones 1.02 →
    /// 0.72), more CPU, and stronger cones, on which the `--seamless` holonomy solve of
    /// `tests/param_seamless.rs` genus 2 does not converge — hence opt-in.
    Energy,
}

/// [`greedy_cones`] with a choice of search on closed surfaces.
pub fn greedy_cones_with(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    budget: ConeBudget,
    search: ConeSearch,
) -> Result<ConePlacement> {
    let (lap, k0, solver) = laplacian_system(mesh, metric)?;
    let n = lap.n;
    let used: Vec<bool> = (0..n as u32).map(|v| !mesh.is_isolated(v)).collect();
    let boundary: Vec<bool> = (0..n as u32).map(|v| mesh.is_boundary_vertex(v)).collect();
    if !boundary.iter().any(|&b| b) {
        let chi = crate::metric::euler_characteristic(mesh) as f64;
        let mut g = GreenBasis::new(&lap, &k0, chi, used.clone(), solver)?;
        let mut p = closed::place_cones(&mut g, &k0, &used, budget, search == ConeSearch::Energy)?;
        bound_cone_angles(&mut p.cones, 2.0 * PI * chi);
        return Ok(p);
    }
    HeldBasis::new(&lap, &k0, &boundary, &used, solver)?.greedy(budget)
}

/// How cones at given positions get their curvatures (see [`cone_curvatures_at`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CurvatureRule {
    /// `u = 0` at every cone (Ben-Chen–Gotsman–Bunin; BFF's cone angles).
    Dirichlet,
    /// Least area-weighted `‖u − ū‖²` (Soliman–Slepčev–Crane 2018 with positions fixed).
    LeastSquares,
}

/// Curvatures `(vertex, K̄)` (`Σ K̄ = 2πχ`) of cones at `vertices` of a closed, connected
/// mesh by `rule`, and the linearised area-weighted `σ(2u)` they leave: the placement's
/// energy, so that positions from elsewhere (another tool's cones) can be compared with
/// [`greedy_cones`]' at equal footing.
pub fn cone_curvatures_at(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    vertices: &[u32],
    rule: CurvatureRule,
) -> Result<(Vec<(u32, f64)>, f64)> {
    let (lap, k0, solver) = laplacian_system(mesh, metric)?;
    let n = lap.n;
    if let Some(&v) = vertices.iter().find(|&&v| v as usize >= n) {
        return Err(Error::input(format!(
            "cone vertex {v} is not a vertex of the mesh ({n} vertices)"
        )));
    }
    if (0..n as u32).any(|v| mesh.is_boundary_vertex(v)) {
        return Err(Error::input(
            "cone curvatures at given positions need a closed surface",
        ));
    }
    let used: Vec<bool> = (0..n as u32).map(|v| !mesh.is_isolated(v)).collect();
    let chi = crate::metric::euler_characteristic(mesh) as f64;
    let mut g = GreenBasis::new(&lap, &k0, chi, used, solver)?;
    let (k, u) = match rule {
        CurvatureRule::Dirichlet => g.dirichlet(vertices)?,
        CurvatureRule::LeastSquares => g.least_squares(vertices)?,
    };
    Ok((k, g.sigma_2x(&u)))
}

/// Curvatures of cones at `cones` (interior vertices of a connected mesh **with boundary**,
/// `u = 0` held on the boundary) for the least area-weighted variance of the linearised log
/// scale factor `u` (Soliman–Slepčev–Crane 2018 with the positions fixed; the boundary's
/// turning is free, so the cones need not add up to anything): `u = u₀ + Σ_c K̄_c g_c`, `g_c`
/// the Dirichlet Green's function of cone `c`, `K̄` from the `k × k` normal equations. Cone
/// angles are kept positive (`K̄ ≤ 2π − 0.05`). Returns `(vertex, K̄)` and the linearised
/// area-weighted `σ(2u)`.
pub fn free_boundary_least_squares(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    cones: &[u32],
) -> Result<(Vec<(u32, f64)>, f64)> {
    let (lap, k0, solver) = laplacian_system(mesh, metric)?;
    let mut basis = held_basis(mesh, &lap, &k0, solver)?;
    basis.least_squares(cones, None)
}

/// The bound `β` of [`free_boundary_cones`]' least-squares curvatures on a surface with a
/// boundary: no cone's linearised log scale `u(c)` above `ū + β sd(u)`. The least-squares
/// rule weighs `u` by area, so it is free to give a cone whose small neighbourhood carries
/// little area a curvature far beyond the greedy's (camelhead, 8 cones: 2.86 where `u = 0`
/// gives 1.61, `u(c)` 7 sd above the mean); the map is then far from linear in the first
/// rings around it and those faces set the qc p95 (camelhead 1.1033, above Boundary First
/// Flattening's 1.0979). With `β = 3`: 1.0961, σ(log area) 0.371 → 0.391 (BFF 0.572);
/// bunny 1.0552 → 1.0549, σ 0.745 → 0.749; face and beetle unchanged (BENCHMARKS.md,
/// session 16 cq16). Not used on the disk of free seams, where it raised kitten's σ
/// (0.426 → 0.51, BFF 0.489) for little qc.
pub const CONE_SCALE_CEILING: f64 = 3.0;

/// The greedy with the boundary held ([`greedy_cones`] on a surface with boundary) and the
/// curvatures at its positions by `rule` (`Dirichlet`: the greedy's own, `u = 0` at the
/// cones; `LeastSquares`: [`free_boundary_least_squares`], with the cones' linearised `u`
/// held at most `ceiling` standard deviations above its mean when `ceiling` is given, see
/// [`CONE_SCALE_CEILING`]), from one factorization of the Laplacian (submodule `held`) —
/// what `--seams free` places on its disk and `--boundary …` inside a surface with boundary.
pub fn free_boundary_cones(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    budget: ConeBudget,
    rule: CurvatureRule,
    ceiling: Option<f64>,
) -> Result<ConePlacement> {
    let (lap, k0, solver) = laplacian_system(mesh, metric)?;
    let mut basis = held_basis(mesh, &lap, &k0, solver)?;
    let mut p = basis.greedy(budget)?;
    if rule == CurvatureRule::LeastSquares {
        let at: Vec<u32> = p.cones.iter().map(|c| c.0).collect();
        p.cones = basis.least_squares(&at, ceiling)?.0;
    }
    Ok(p)
}

/// [`HeldBasis`] of a mesh with boundary (boundary and isolated vertices held at `u = 0`).
fn held_basis<'a>(
    mesh: &Mesh,
    lap: &'a Laplacian,
    k0: &'a [f64],
    solver: SymmetricSolver,
) -> Result<HeldBasis<'a>> {
    let n = lap.n;
    let boundary: Vec<bool> = (0..n as u32).map(|v| mesh.is_boundary_vertex(v)).collect();
    if !boundary.iter().any(|&b| b) {
        return Err(Error::input(
            "free-boundary cone curvatures need a boundary",
        ));
    }
    let used: Vec<bool> = (0..n as u32).map(|v| !mesh.is_isolated(v)).collect();
    HeldBasis::new(lap, k0, &boundary, &used, solver)
}

/// One Newton-type correction of cone curvatures on the *nonlinear* flow towards the least
/// `L²` norm of the log scale factor (the energy of Soliman–Slepčev–Crane, "Optimal cone
/// singularities for conformal flattening", 2018, §4, here with the cone positions fixed).
/// `u` is the conformal factor the flow reached with curvatures `cones` (per vertex of the
/// closed, connected `mesh`); the change `δk` (with `Σ δk = 0`: Gauss–Bonnet kept)
/// minimises `‖u − ū + G δk‖²_M`, `G` the Green's functions of the input's cotangent
/// Laplacian (submodule `green`), i.e. the linear response of the flow's `u` to moving curvature
/// between the cones. `damping ∈ (0, 1]` scales the step. Returns the new `(vertex, K̄)`
/// list; cone angles are kept at least [`MIN_CONE_ANGLE`] and nothing else is clamped: a
/// strong negative cone is allowed, because a map whose input faces fold around it is written
/// on the common subdivision.
pub fn correct_cone_curvatures(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    cones: &[(u32, f64)],
    u: &[f64],
    damping: f64,
) -> Result<Vec<(u32, f64)>> {
    let (lap, k0, solver) = laplacian_system(mesh, metric)?;
    let total: f64 = cones.iter().map(|c| c.1).sum();
    let used: Vec<bool> = (0..lap.n as u32).map(|v| !mesh.is_isolated(v)).collect();
    let mut g = GreenBasis::new(&lap, &k0, total / (2.0 * PI), used, solver)?;
    let mean = g.mean(u);
    let r: Vec<f64> = u.iter().map(|x| x - mean).collect();
    let vertices: Vec<u32> = cones.iter().map(|c| c.0).collect();
    let dk = g.least_squares_with(&r, &vertices, 0.0)?;
    let mut out: Vec<(u32, f64)> = cones
        .iter()
        .zip(&dk)
        .map(|(&(c, k), &d)| (c, k + damping * d))
        .collect();
    bound_cone_angles(&mut out, total);
    Ok(out)
}

/// The smallest cone angle the placement on a closed surface gives (`K̄ ≤ 2π − π/8`). A cone
/// of angle `θ` shrinks its neighbourhood like `r^{2π/θ − 1}`, so a near-zero angle makes the
/// input faces around it fold in the flat map: horse with 8 cones had two hoof cones of 0.05
/// and 0.17 rad, 9 input faces folding, the map on the common subdivision (qc p95 1.1587, by
/// count, above Boundary First Flattening's 1.1448); with angles ≥ π/8 it is on the input faces,
/// qc p95 1.074, σ(log area) 1.02 → 1.09 (BFF 2.30). No other mesh of the benchmarks has a
/// cone below π/8 (BENCHMARKS.md, session 17 lead).
pub const MIN_CONE_ANGLE: f64 = PI / 8.0;

/// Cone angles kept at least [`MIN_CONE_ANGLE`]: curvatures above `2π − MIN_CONE_ANGLE` are
/// cut there and the excess goes to the other cones equally; then the last cone takes the
/// rounding so that `Σ K̄ = total`.
fn bound_cone_angles(out: &mut [(u32, f64)], total: f64) {
    let limit = 2.0 * PI - MIN_CONE_ANGLE;
    for _ in 0..8 {
        let excess: f64 = out.iter().map(|&(_, k)| (k - limit).max(0.0)).sum();
        for x in out.iter_mut() {
            x.1 = x.1.min(limit);
        }
        if excess <= 0.0 {
            break;
        }
        let share: Vec<usize> = (0..out.len()).filter(|&i| out[i].1 < limit).collect();
        for &i in &share {
            out[i].1 += excess / share.len() as f64;
        }
    }
    let sum: f64 = out.iter().map(|x| x.1).sum();
    if let Some(last) = out.last_mut() {
        last.1 += total - sum;
    }
}

/// Round cone curvatures to multiples of `π/2` keeping their sum (a multiple of `π/2` when it
/// is `2πχ`): nearest multiples first, then the cones with the largest rounding error moved
/// by `±π/2` until the sum is right. Cones that round to 0 are dropped; cone angles stay
/// positive (`K̄ ≤ max_quarters · π/2`: 3 inside, 1 on a boundary).
pub fn round_to_quarter_turns(
    cones: &[(u32, f64)],
    total: f64,
    max_quarters: i64,
) -> Vec<(u32, f64)> {
    let q = PI / 2.0;
    let mut k: Vec<(u32, i64, f64)> = cones
        .iter()
        .map(|&(v, x)| {
            let m = ((x / q).round() as i64).min(max_quarters);
            (v, m, x / q - m as f64)
        })
        .collect();
    let want = (total / q).round() as i64;
    let mut guard = 0;
    loop {
        let have: i64 = k.iter().map(|x| x.1).sum();
        if have == want || guard > 4 * cones.len() + 8 {
            break;
        }
        guard += 1;
        let up = have < want;
        // The cone whose residual points most in the needed direction.
        let best = (0..k.len())
            .filter(|&i| !up || k[i].1 < max_quarters)
            .max_by(|&a, &b| {
                let ra = if up { k[a].2 } else { -k[a].2 };
                let rb = if up { k[b].2 } else { -k[b].2 };
                ra.total_cmp(&rb)
            });
        let Some(i) = best else { break };
        if up {
            k[i].1 += 1;
            k[i].2 -= 1.0;
        } else {
            k[i].1 -= 1;
            k[i].2 += 1.0;
        }
    }
    k.into_iter()
        .filter(|x| x.1 != 0)
        .map(|(v, m, _)| (v, m as f64 * q))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed octahedron's angle defects are 4π/6 each (Gauss–Bonnet: 4π); the greedy's
    /// cones carry 4π in total, and rounding to quarter turns keeps the sum.
    #[test]
    fn octahedron_cones_satisfy_gauss_bonnet() {
        let faces = vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ];
        let mesh = Mesh::from_triangles(6, faces).unwrap();
        let l = vec![1.0; mesh.n_edges()];
        let k = angle_defects(
            &mesh,
            &crate::metric::IntrinsicMetric::euclidean(l.to_vec()),
        );
        for x in &k {
            assert!((x - 2.0 * PI / 3.0).abs() < 1e-12);
        }
        let p = greedy_cones(
            &mesh,
            &crate::metric::IntrinsicMetric::euclidean(l.to_vec()),
            ConeBudget::Count(3),
        )
        .unwrap();
        assert_eq!(p.cones.len(), 3);
        let s: f64 = p.cones.iter().map(|c| c.1).sum();
        assert!((s - 4.0 * PI).abs() < 1e-9, "{s}");
        let r = round_to_quarter_turns(&p.cones, 4.0 * PI, 3);
        let s: f64 = r.iter().map(|c| c.1).sum();
        assert!((s - 4.0 * PI).abs() < 1e-12);
        for c in &r {
            assert!(c.1 <= 1.5 * PI + 1e-12);
            assert!(((c.1 / (PI / 2.0)).round() * PI / 2.0 - c.1).abs() < 1e-12);
        }
    }
}
