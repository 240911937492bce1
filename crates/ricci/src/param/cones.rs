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
//! **Greedy.** Start from a closed surface's solution with the total curvature spread by area
//! (`L u = −(K⁰ − 2πχ a_i / A)`, one vertex pinned; the extremum of `u` is the first cone),
//! then repeatedly put a cone where `|u|` is largest and solve again. Each solve is one
//! numeric Cholesky factorization of `L + P` (`P` a large diagonal penalty holding `u_c = 0`,
//! same symbolic pattern every time). With a count `N` the greedy stops after `N` cones; with
//! a bound `D` on the area distortion it stops at the first cone set whose linearised
//! `max |2u − mean(2u)| ≤ D` (at most `max_cones` cones).

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::numeric::sparse::{LowerCsc, SymmetricSolver};
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

fn laplacian(mesh: &Mesh, lengths: &[f64]) -> Result<Laplacian> {
    let n = mesh.n_vertices();
    let mut w = vec![0.0; mesh.n_edges()];
    let mut area = vec![0.0; n];
    for f in 0..mesh.n_faces() as u32 {
        let t = mesh.face(f);
        let hs = mesh.face_halfedges(f);
        // Edge of half-edge 3f+i joins t[i], t[i+1]; opposite corner t[i+2].
        let l: Vec<f64> = hs
            .iter()
            .map(|&h| lengths[mesh.he_edge(h) as usize])
            .collect();
        let a = crate::numeric::vec3::heron([l[0], l[1], l[2]]);
        if a.is_nan() || a <= 0.0 {
            return Err(Error::numerical(format!(
                "face {f} has zero area in the input metric; cones cannot be placed"
            )));
        }
        for i in 0..3 {
            let (x, y, z) = (l[i], l[(i + 1) % 3], l[(i + 2) % 3]);
            // cot of the angle opposite x: (y² + z² − x²) / 4A.
            w[mesh.he_edge(hs[i]) as usize] += (y * y + z * z - x * x) / (8.0 * a);
            area[t[i] as usize] += a / 3.0;
        }
    }
    let mut cols: Vec<Vec<(u32, f64)>> = vec![Vec::new(); n];
    let mut d = vec![0.0; n];
    for (e, &we) in w.iter().enumerate() {
        let [a, b] = mesh.edge_vertices(e as u32);
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        cols[lo as usize].push((hi, -we));
        d[a as usize] += we;
        d[b as usize] += we;
    }
    let mut col_ptr = vec![0u32];
    let mut row_idx = Vec::new();
    let mut values = Vec::new();
    let mut diag = Vec::with_capacity(n);
    for (j, c) in cols.iter_mut().enumerate() {
        c.sort_by_key(|x| x.0);
        diag.push(row_idx.len());
        row_idx.push(j as u32);
        values.push(d[j]);
        for &(r, v) in c.iter() {
            row_idx.push(r);
            values.push(v);
        }
        col_ptr.push(row_idx.len() as u32);
    }
    Ok(Laplacian {
        n,
        col_ptr,
        row_idx,
        values,
        diag,
        area,
    })
}

/// Angle defects of the input metric (`2π − Σθ` inside, `π − Σθ` on the boundary).
pub fn angle_defects(mesh: &Mesh, lengths: &[f64]) -> Vec<f64> {
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

/// The greedy placement (module docs) on a connected mesh with Euclidean `lengths`. Boundary
/// vertices are held at `u = 0` and never become cones.
pub fn greedy_cones(mesh: &Mesh, lengths: &[f64], budget: ConeBudget) -> Result<ConePlacement> {
    let lap = laplacian(mesh, lengths)?;
    let n = lap.n;
    let k0 = angle_defects(mesh, lengths);
    let pattern = LowerCsc {
        n,
        col_ptr: &lap.col_ptr,
        row_idx: &lap.row_idx,
    };
    let mut solver = SymmetricSolver::new(pattern)?;
    let total_area: f64 = lap.area.iter().sum();
    let chi = crate::metric::euler_characteristic(mesh) as f64;
    let boundary: Vec<bool> = (0..n as u32).map(|v| mesh.is_boundary_vertex(v)).collect();
    let used: Vec<bool> = (0..n as u32).map(|v| !mesh.is_isolated(v)).collect();
    let has_boundary = boundary.iter().any(|&b| b);
    let scale = lap.diag.iter().map(|&i| lap.values[i]).fold(0.0, f64::max);
    let penalty = 1e10 * scale.max(1e-300);
    // Solve with u held at 0 on `held` (penalty); `rhs` per vertex.
    let mut solve = |held: &[bool], rhs: &[f64]| -> Result<Vec<f64>> {
        let mut vals = lap.values.clone();
        for v in 0..n {
            if held[v] || !used[v] {
                vals[lap.diag[v]] += penalty;
            }
        }
        if !solver.factor_llt(&vals) && !solver.factor_ldlt(&vals) {
            return Err(Error::numerical(
                "the cotangent Laplacian could not be factorized for cone placement",
            ));
        }
        let mut x: Vec<f64> = (0..n)
            .map(|v| if held[v] || !used[v] { 0.0 } else { rhs[v] })
            .collect();
        solver.solve(&mut x);
        Ok(x)
    };
    let spread = |u: &[f64]| -> f64 {
        let m: f64 = (0..n).map(|v| 2.0 * u[v] * lap.area[v]).sum::<f64>() / total_area;
        (0..n)
            .filter(|&v| used[v])
            .map(|v| (2.0 * u[v] - m).abs())
            .fold(0.0, f64::max)
    };
    let mut held = boundary.clone();
    let mut cones: Vec<u32> = Vec::new();
    let mut history = Vec::new();
    let (max_cones, bound) = match budget {
        ConeBudget::Count(c) => (c, -1.0),
        ConeBudget::AreaDistortion { bound, max_cones } => (max_cones, bound),
    };
    // Initial solution.
    let mut u = if has_boundary {
        let rhs: Vec<f64> = k0.iter().map(|&k| -k).collect();
        solve(&held, &rhs)?
    } else {
        let pin = (0..n).find(|&v| used[v]).unwrap_or(0);
        let mut h = held.clone();
        h[pin] = true;
        let rhs: Vec<f64> = (0..n)
            .map(|v| -(k0[v] - 2.0 * PI * chi * lap.area[v] / total_area))
            .collect();
        solve(&h, &rhs)?
    };
    let rhs: Vec<f64> = k0.iter().map(|&k| -k).collect();
    while cones.len() < max_cones {
        if bound >= 0.0 && !cones.is_empty() && spread(&u) <= bound {
            break;
        }
        let mean: f64 = if has_boundary || cones.is_empty() {
            (0..n).map(|v| u[v] * lap.area[v]).sum::<f64>() / total_area
        } else {
            0.0
        };
        let next = (0..n)
            .filter(|&v| used[v] && !held[v])
            .max_by(|&a, &b| (u[a] - mean).abs().total_cmp(&(u[b] - mean).abs()));
        let Some(c) = next else { break };
        cones.push(c as u32);
        held[c] = true;
        u = solve(&held, &rhs)?;
        history.push(spread(&u));
    }
    // Curvature left at the cones: K̄_c = K⁰_c + (L u)_c.
    let mut lu = vec![0.0; n];
    for j in 0..n {
        for p in lap.col_ptr[j] as usize..lap.col_ptr[j + 1] as usize {
            let i = lap.row_idx[p] as usize;
            let v = lap.values[p];
            lu[i] += v * u[j];
            if i != j {
                lu[j] += v * u[i];
            }
        }
    }
    let mut out: Vec<(u32, f64)> = cones
        .iter()
        .map(|&c| (c, k0[c as usize] + lu[c as usize]))
        .collect();
    if !has_boundary {
        // Exact Gauss–Bonnet (rounding) and cone angles kept positive: the excess of a cone
        // above 2π − 0.05 goes to the others in proportion to their curvature's magnitude.
        let limit = 2.0 * PI - 0.05;
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
            last.1 += 2.0 * PI * chi - sum;
        }
    }
    Ok(ConePlacement {
        cones: out,
        distortion_history: history,
    })
}

/// One Newton-type correction of cone curvatures on the *nonlinear* flow towards the least
/// `L²` norm of the log scale factor (the energy of Soliman–Slepčev–Crane, "Optimal cone
/// singularities for conformal flattening", 2018, §4, here with the cone positions fixed).
/// `u` is the conformal factor the flow reached with curvatures `cones` (per vertex of the
/// closed, connected `mesh`); the change `δk` (with `Σ δk = 0`: Gauss–Bonnet kept)
/// minimises `‖u − ū + G δk‖²_M`, `G` the Green's functions of the input's cotangent
/// Laplacian (`L g_c = δ_c − a/A`, zero area mean), i.e. the linear response of the flow's
/// `u` to moving curvature between the cones (normal equations: the `(|C| + 1)²` system
/// `[GᵀMG 1; 1ᵀ 0] [δk; λ] = [−GᵀM(u − ū); 0]`). `damping ∈ (0, 1]` scales the step.
/// Returns the new `(vertex, K̄)` list, cone angles kept positive (`K̄ ≤ 2π − 0.05`).
pub fn correct_cone_curvatures(
    mesh: &Mesh,
    lengths: &[f64],
    cones: &[(u32, f64)],
    u: &[f64],
    damping: f64,
) -> Result<Vec<(u32, f64)>> {
    let lap = laplacian(mesh, lengths)?;
    let n = lap.n;
    let pattern = LowerCsc {
        n,
        col_ptr: &lap.col_ptr,
        row_idx: &lap.row_idx,
    };
    let mut solver = SymmetricSolver::new(pattern)?;
    let total_area: f64 = lap.area.iter().sum();
    let used: Vec<bool> = (0..n as u32).map(|v| !mesh.is_isolated(v)).collect();
    let scale = lap.diag.iter().map(|&i| lap.values[i]).fold(0.0, f64::max);
    let penalty = 1e10 * scale.max(1e-300);
    let pin = (0..n).find(|&v| used[v]).unwrap_or(0);
    let mut vals = lap.values.clone();
    for v in 0..n {
        if v == pin || !used[v] {
            vals[lap.diag[v]] += penalty;
        }
    }
    if !solver.factor_llt(&vals) && !solver.factor_ldlt(&vals) {
        return Err(Error::numerical(
            "the cotangent Laplacian could not be factorized for the cone correction",
        ));
    }
    let area = &lap.area;
    let mean_u: f64 = (0..n).map(|v| u[v] * area[v]).sum::<f64>() / total_area;
    let r: Vec<f64> = (0..n)
        .map(|v| if used[v] { u[v] - mean_u } else { 0.0 })
        .collect();
    let m = cones.len();
    let mut g: Vec<Vec<f64>> = Vec::with_capacity(m);
    for &(c, _) in cones {
        let mut x: Vec<f64> = (0..n)
            .map(|v| {
                if v == pin || !used[v] {
                    0.0
                } else {
                    (if v == c as usize { 1.0 } else { 0.0 }) - area[v] / total_area
                }
            })
            .collect();
        solver.solve(&mut x);
        let mx: f64 = (0..n).map(|v| x[v] * area[v]).sum::<f64>() / total_area;
        for v in 0..n {
            x[v] = if used[v] { x[v] - mx } else { 0.0 };
        }
        g.push(x);
    }
    let dot = |x: &[f64], y: &[f64]| -> f64 { (0..n).map(|v| x[v] * area[v] * y[v]).sum() };
    let mut a = vec![vec![0.0; m + 1]; m + 1];
    let mut rhs = vec![0.0; m + 1];
    for i in 0..m {
        for j in i..m {
            let d = dot(&g[i], &g[j]);
            a[i][j] = d;
            a[j][i] = d;
        }
        a[i][m] = 1.0;
        a[m][i] = 1.0;
        rhs[i] = -dot(&g[i], &r);
    }
    let x = crate::analysis::forms::small::solve(&a, &rhs);
    if x.iter().any(|v| !v.is_finite()) {
        return Err(Error::numerical(
            "the cone curvature correction is singular (two cones too close?)",
        ));
    }
    let total: f64 = cones.iter().map(|c| c.1).sum();
    let mut out: Vec<(u32, f64)> = cones
        .iter()
        .zip(&x)
        .map(|(&(c, k), &d)| (c, k + damping * d))
        .collect();
    // Curvatures kept in [K_lo, 2π − 0.05], K_lo the most negative given curvature (no cone
    // angle grows beyond the largest given one: a stronger cone makes the flow flip its whole
    // neighbourhood away, where the cut on kept input edges cannot reach it); what is cut off
    // goes to the cones inside the range, equally.
    let upper = 2.0 * PI - 0.05;
    let lower = cones
        .iter()
        .map(|c| c.1)
        .fold(f64::INFINITY, f64::min)
        .min(upper);
    for _ in 0..16 {
        let excess: f64 = out
            .iter()
            .map(|&(_, k)| (k - upper).max(0.0) - (lower - k).max(0.0))
            .sum();
        for x in out.iter_mut() {
            x.1 = x.1.clamp(lower, upper);
        }
        if excess.abs() <= 1e-15 {
            break;
        }
        let share: Vec<usize> = (0..out.len())
            .filter(|&i| {
                if excess > 0.0 {
                    out[i].1 < upper
                } else {
                    out[i].1 > lower
                }
            })
            .collect();
        if share.is_empty() {
            break;
        }
        for &i in &share {
            out[i].1 += excess / share.len() as f64;
        }
    }
    let sum: f64 = out.iter().map(|x| x.1).sum();
    if let Some(last) = out.last_mut() {
        last.1 += total - sum;
    }
    Ok(out)
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
        let k = angle_defects(&mesh, &l);
        for x in &k {
            assert!((x - 2.0 * PI / 3.0).abs() < 1e-12);
        }
        let p = greedy_cones(&mesh, &l, ConeBudget::Count(3)).unwrap();
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
