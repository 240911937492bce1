//! Boundary conditions of charts with boundary (`ricci param --boundary`), see the module
//! docs of [`super`]: the targets of `fixed-angles` — the boundary keeps its geodesic
//! curvature `κ_i = π − Σθ`, the interior curvature `2πχ − Σκ` moved to the boundary in
//! proportion to the dual boundary lengths (Sawhney–Crane 2017 §4.2, "prescribed
//! curvature").

use super::cones::round_to_quarter_turns;
use crate::mesh::Mesh;
use crate::metric::IntrinsicMetric;
use std::f64::consts::PI;

/// Boundary targets of `fixed-angles` (module docs), optionally rounded to quarter turns.
pub(crate) fn fixed_angle_targets(mesh: &Mesh, lengths: &[f64], seamless: bool) -> Vec<f64> {
    let k = super::cones::angle_defects(mesh, &IntrinsicMetric::euclidean(lengths.to_vec()));
    let n = mesh.n_vertices();
    let chi = crate::metric::euler_characteristic(mesh) as f64;
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
    let rest = 2.0 * PI * chi - kb;
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
        for (v, x) in round_to_quarter_turns(&list, 2.0 * PI * chi, 1) {
            t[v as usize] = x;
        }
    }
    t
}
