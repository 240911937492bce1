//! Boundary conditions of charts with boundary (`ricci param --boundary`), see the module
//! docs of [`super`]: the targets of `fixed-angles` — the boundary keeps its geodesic
//! curvature `κ_i = π − Σθ`, the interior curvature `2πχ − Σκ` (less what cones inside take)
//! moved to the boundary in proportion to the dual boundary lengths (Sawhney–Crane 2017 §4.2,
//! "prescribed curvature") — and the curvature budgets of cones inside a round or fixed-angles
//! boundary (Gauss–Bonnet: `Σ κ̄_boundary + Σ K̄_cones = 2πχ`).

use super::cones::round_to_quarter_turns;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::metric::IntrinsicMetric;
use std::f64::consts::PI;

/// Per-vertex targets and the cones `(vertex, K̄)` they were made with.
type TargetsAndCones = (Vec<f64>, Vec<(u32, f64)>);

/// Per-vertex targets of `fixed-angles` with cones `(vertex, K̄)` at interior vertices (module
/// docs): the cones keep theirs, the boundary vertex `i` takes `κ_i + ρ ℓ*_i / Σ ℓ*` with
/// `ρ = 2πχ − Σκ − Σ K̄` and `ℓ*` the dual boundary lengths (`ρ = 0` when the cones carry
/// what the interior had: the boundary's corner angles are then the surface's). With
/// `seamless` the cones are rounded to quarter turns first (at most three: the cone angle stays
/// positive), then the boundary targets (at most one) to the total the rounded cones leave, so
/// every turning is a multiple of π/2 and the sum is still `2πχ` ([`quarter_turn_boundary`]:
/// loop by loop, corners spread along each loop). Returns the targets and the cones used.
pub(crate) fn fixed_angle_targets(
    mesh: &Mesh,
    lengths: &[f64],
    cones: &[(u32, f64)],
    seamless: bool,
) -> Result<TargetsAndCones> {
    let k = super::cones::angle_defects(mesh, &IntrinsicMetric::euclidean(lengths.to_vec()));
    let n = mesh.n_vertices();
    let chi = crate::metric::euler_characteristic(mesh) as f64;
    let cones = if seamless {
        let q = PI / 2.0;
        let sum: f64 = cones.iter().map(|c| c.1).sum();
        round_to_quarter_turns(cones, q * (sum / q).round(), 3)
    } else {
        cones.to_vec()
    };
    let mut dual = vec![0.0; n];
    for e in 0..mesh.n_edges() as u32 {
        if mesh.is_boundary_edge(e) {
            let [a, b] = mesh.edge_vertices(e);
            dual[a as usize] += 0.5 * lengths[e as usize];
            dual[b as usize] += 0.5 * lengths[e as usize];
        }
    }
    let total_dual: f64 = dual.iter().sum();
    let kb: f64 = (0..n)
        .filter(|&v| mesh.is_boundary_vertex(v as u32))
        .map(|v| k[v])
        .sum();
    let cone_sum: f64 = cones.iter().map(|c| c.1).sum();
    let rest = 2.0 * PI * chi - kb - cone_sum;
    let mut t = vec![0.0; n];
    for v in 0..n {
        if mesh.is_boundary_vertex(v as u32) {
            t[v] = k[v] + rest * dual[v] / total_dual;
        }
    }
    if seamless {
        t = quarter_turn_boundary(mesh, &t, &dual, 2.0 * PI * chi - cone_sum)?;
    }
    for &(v, x) in &cones {
        t[v as usize] = x;
    }
    Ok((t, cones))
}

/// Fewest and most quarter turns of a boundary vertex's turning `π − Θ` under `--seamless`:
/// corner angles `Θ` from `π/2` to `2π`; a vertex with a single triangle keeps `π/2` (its one
/// triangle cannot open to `π`).
const MIN_QUARTERS: i64 = -2;
const MAX_QUARTERS: i64 = 1;

/// The boundary turnings `t` (per vertex; interior entries ignored) rounded to quarter turns
/// adding up to `total`, loop by loop (module docs of [`super`], `--seamless`): each loop's
/// total is rounded first (all loops together keeping `total`), then spread over its vertices
/// by rounding the **running sum** along the loop (the loop's difference to its rounded total
/// shared in proportion to `weight`), so a loop's corners fall where the boundary turns and
/// are as far apart as its turning allows — a round hole of turning `−2π` becomes four corners
/// a quarter of the loop apart. Rounding vertex by vertex with one global correction (before)
/// put a hole's `−2π` on arbitrary vertices of any loop, with conformal factors `e^{±20}` and
/// folded triangles (beetle). Each vertex takes `MIN_QUARTERS..=MAX_QUARTERS` quarters (at least
/// one with a single triangle); refused when a loop cannot carry its total within them.
fn quarter_turn_boundary(mesh: &Mesh, t: &[f64], weight: &[f64], total: f64) -> Result<Vec<f64>> {
    let q = PI / 2.0;
    let mut triangles = vec![0usize; mesh.n_vertices()];
    for tri in mesh.faces() {
        for &v in tri {
            triangles[v as usize] += 1;
        }
    }
    let bounds = |v: u32| {
        let lo = if triangles[v as usize] == 1 {
            1
        } else {
            MIN_QUARTERS
        };
        (lo, MAX_QUARTERS)
    };
    let loops = mesh.boundary_loops();
    let sums: Vec<(u32, f64)> = loops
        .iter()
        .enumerate()
        .map(|(i, l)| (i as u32, l.iter().map(|&v| t[v as usize]).sum()))
        .collect();
    let mut loop_quarters = vec![0i64; loops.len()];
    for (i, x) in round_to_quarter_turns(&sums, total, i64::MAX) {
        loop_quarters[i as usize] = (x / q).round() as i64;
    }
    let mut out = vec![0.0; mesh.n_vertices()];
    for ((l, &(_, sum)), &m) in loops.iter().zip(&sums).zip(&loop_quarters) {
        let w: f64 = l.iter().map(|&v| weight[v as usize]).sum();
        let x: Vec<f64> = l
            .iter()
            .map(|&v| (t[v as usize] + (m as f64 * q - sum) * weight[v as usize] / w) / q)
            .collect();
        let b: Vec<(i64, i64)> = l.iter().map(|&v| bounds(v)).collect();
        let k = spread_quarters(&x, m, &b).ok_or_else(|| {
            Error::input(format!(
                "--seamless: a boundary loop of {} vertices cannot turn by {m} quarter turns \
                 with every corner angle between π/2 and 2π (and π/2 at a vertex with one \
                 triangle)",
                l.len()
            ))
        })?;
        for (&v, k) in l.iter().zip(k) {
            out[v as usize] = k as f64 * q;
        }
    }
    Ok(out)
}

/// Integers `k_i` within `bounds` adding up to `m` that round the running sum of `x` (in
/// quarters, `Σ x = m`) along the cyclic sequence, starting at its largest entry; what the
/// bounds hold back is carried to the next entries, and what is left at the end goes to the
/// entries with room whose `x_i − k_i` points most in the needed direction. `None` when the
/// bounds cannot add up to `m`.
fn spread_quarters(x: &[f64], m: i64, bounds: &[(i64, i64)]) -> Option<Vec<i64>> {
    let n = x.len();
    let lo: i64 = bounds.iter().map(|b| b.0).sum();
    let hi: i64 = bounds.iter().map(|b| b.1).sum();
    if n == 0 || m < lo || m > hi {
        return None;
    }
    let start = (0..n).max_by(|&a, &b| x[a].total_cmp(&x[b]))?;
    let mut k = vec![0i64; n];
    let mut carry = 0.0;
    for i in 0..n {
        let j = (start + i) % n;
        let y = x[j] + carry;
        k[j] = (y.round() as i64).clamp(bounds[j].0, bounds[j].1);
        carry = y - k[j] as f64;
    }
    let mut left = m - k.iter().sum::<i64>();
    while left != 0 {
        let up = left > 0;
        let j = (0..n)
            .filter(|&j| {
                if up {
                    k[j] < bounds[j].1
                } else {
                    k[j] > bounds[j].0
                }
            })
            .max_by(|&a, &b| {
                let (ra, rb) = (x[a] - k[a] as f64, x[b] - k[b] as f64);
                if up {
                    ra.total_cmp(&rb)
                } else {
                    rb.total_cmp(&ra)
                }
            })?;
        k[j] += if up { 1 } else { -1 };
        left += if up { -1 } else { 1 };
    }
    Some(k)
}

/// Greedy cones inside a `fixed-angles` boundary: the curvatures the greedy chose with the
/// boundary held, moved so that together they carry the interior's curvature
/// `Σ_inside (2π − Σθ)` and the boundary keeps its own (Gauss–Bonnet): a deficit `Δ > 0` is
/// shared in proportion to each cone's room below 2π (`Δ (2π − K̄_c) / Σ (2π − K̄)`, so every
/// cone keeps an angle), an excess equally. Refused when the cones have not room enough.
pub(crate) fn cones_carrying_the_interior(
    mesh: &Mesh,
    lengths: &[f64],
    cones: &[(u32, f64)],
    component: usize,
) -> Result<Vec<(u32, f64)>> {
    if cones.is_empty() {
        return Ok(Vec::new());
    }
    let k = super::cones::angle_defects(mesh, &IntrinsicMetric::euclidean(lengths.to_vec()));
    let inside: f64 = (0..mesh.n_vertices() as u32)
        .filter(|&v| !mesh.is_boundary_vertex(v) && !mesh.is_isolated(v))
        .map(|v| k[v as usize])
        .sum();
    let delta = inside - cones.iter().map(|c| c.1).sum::<f64>();
    let room: f64 = cones.iter().map(|c| 2.0 * PI - c.1).sum();
    if delta >= room {
        return Err(Error::input(format!(
            "component {component}: with --boundary fixed-angles the {} cones must carry the \
             interior's curvature {inside:.6}, more than they can (each below 2π); use more \
             cones or another --boundary",
            cones.len()
        )));
    }
    Ok(cones
        .iter()
        .map(|&(v, x)| {
            let share = if delta > 0.0 {
                (2.0 * PI - x) / room
            } else {
                1.0 / cones.len() as f64
            };
            (v, x + delta * share)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A round hole: 32 vertices turning by −2π/32 each. The running sum puts its four
    /// quarter turns eight vertices apart (a square), where rounding each vertex on its own
    /// gives 0 everywhere.
    #[test]
    fn a_round_hole_becomes_a_square() {
        let x = vec![-4.0 / 32.0; 32];
        let k = spread_quarters(&x, -4, &vec![(MIN_QUARTERS, MAX_QUARTERS); 32]).unwrap();
        let corners: Vec<usize> = (0..32).filter(|&i| k[i] != 0).collect();
        assert_eq!(corners.len(), 4, "{k:?}");
        assert!(corners.iter().all(|&i| k[i] == -1));
        for w in corners.windows(2) {
            assert_eq!(w[1] - w[0], 8, "{corners:?}");
        }
    }

    /// Bounds: a vertex that must take one quarter (a single triangle) takes it, a sharp
    /// corner of 1.8 quarters is held to one and its excess carried on; impossible totals
    /// are refused.
    #[test]
    fn bounds_are_kept_and_the_total_met() {
        let x = [1.8, 0.1, 0.1, 0.0, -0.2, 0.2];
        let mut b = vec![(MIN_QUARTERS, MAX_QUARTERS); 6];
        b[3] = (1, 1);
        let k = spread_quarters(&x, 2, &b).unwrap();
        assert_eq!(k.iter().sum::<i64>(), 2, "{k:?}");
        assert_eq!(k[0], 1);
        assert_eq!(k[3], 1);
        assert!(k.iter().zip(&b).all(|(k, b)| (b.0..=b.1).contains(k)));
        assert!(spread_quarters(&[0.5; 3], 4, &[(MIN_QUARTERS, MAX_QUARTERS); 3]).is_none());
        assert!(spread_quarters(&[-3.0; 3], -7, &[(MIN_QUARTERS, MAX_QUARTERS); 3]).is_none());
    }
}
