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

/// Per-vertex targets of `fixed-angles` with cones `(vertex, K̄)` at interior vertices (module
/// docs): the cones keep theirs, the boundary vertex `i` takes `κ_i + ρ ℓ*_i / Σ ℓ*` with
/// `ρ = 2πχ − Σκ − Σ K̄` and `ℓ*` the dual boundary lengths (`ρ = 0` when the cones carry
/// what the interior had: the boundary's corner angles are then the surface's). With
/// `seamless` the cones are rounded to quarter turns first (at most three: the cone angle stays
/// positive), then the boundary targets (at most one) to the total the rounded cones leave, so
/// every turning is a multiple of π/2 and the sum is still `2πχ`. Returns the targets and the
/// cones used.
pub(crate) fn fixed_angle_targets(
    mesh: &Mesh,
    lengths: &[f64],
    cones: &[(u32, f64)],
    seamless: bool,
) -> (Vec<f64>, Vec<(u32, f64)>) {
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
        let list: Vec<(u32, f64)> = (0..n as u32)
            .filter(|&v| mesh.is_boundary_vertex(v))
            .map(|v| (v, t[v as usize]))
            .collect();
        t = vec![0.0; n];
        for (v, x) in round_to_quarter_turns(&list, 2.0 * PI * chi - cone_sum, 1) {
            t[v as usize] = x;
        }
    }
    for &(v, x) in &cones {
        t[v as usize] = x;
    }
    (t, cones)
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
