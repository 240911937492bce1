//! Sharp boundary corners widened by a discrete conformal change before doubling.
//!
//! A boundary vertex of boundary angle `θ` is a cone point of angle `2θ` of the doubled flat
//! metric. In the flat frame around a cone of angle `α` a holomorphic form that does not vanish
//! there is `ω ≈ c z^{2π/α − 1} dz`: it turns `2π/α − 1` times as fast as the frame and is tiny
//! on the cone's faces. For a sharp cone (bunny's "ears": boundary vertices with a single face,
//! `θ` = 0.41 and 0.76 rad) the face-constant discrete form cannot follow it, and the
//! Poincaré–Hopf count (`zeros`) finds a positive index there and extra zeros elsewhere
//! (docs/notes/wave2-s10-spec10.md).
//!
//! The fix keeps the discrete conformal class: a vertex scaling `l̃_ij = e^{(u_i + u_j)/2} l_ij`
//! with `u` supported on the sharp vertices (Luo's discrete conformal equivalence; on the double
//! it is the σ-symmetric scaling `u_{σv} = u_v`, Gu–Luo–Sun–Wu's conformal class of a surface
//! with boundary). Each boundary vertex with `θ < θ_min` gets the `u_v < 0` (found by bisection:
//! `θ` decreases strictly with `u_v`, and reaches `π` per face before a triangle degenerates)
//! that makes its boundary angle `θ_min` = π/2 (cone angle π on the double), in increasing order
//! of `θ`, each on the lengths left by the previous ones.

use serde::Serialize;
use std::f64::consts::PI;

use crate::mesh::Mesh;

/// The boundary angle below which a corner is widened: cone angle `π` on the double.
pub const MIN_BOUNDARY_ANGLE: f64 = 0.5 * PI;

/// One widened corner.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct WidenedCorner {
    pub vertex: u32,
    /// Boundary angle before and after (radians).
    pub angle_before: f64,
    pub angle_after: f64,
    /// Log scale factor `u_v` (the vertex's edges are multiplied by `e^{u_v/2}`).
    pub u: f64,
}

/// Angle at `v` in the triangle with sides `a = |v p|`, `b = |v q|` and opposite `c = |p q|`
/// (clamped: `π` once the triangle degenerates).
fn angle(a: f64, b: f64, c: f64) -> f64 {
    ((a * a + b * b - c * c) / (2.0 * a * b))
        .clamp(-1.0, 1.0)
        .acos()
}

/// For each face at `v`: the edges `v p`, `v q` and the opposite edge `p q`.
fn corner_edges(mesh: &Mesh, v: u32) -> Vec<[usize; 3]> {
    mesh.vertex_corners(v)
        .map(|h| {
            let n = mesh.he_next(h);
            let p = mesh.he_prev(h);
            [
                mesh.he_edge(h) as usize,
                mesh.he_edge(p) as usize,
                mesh.he_edge(n) as usize,
            ]
        })
        .collect()
}

/// Boundary angle at `v` with the edges at `v` scaled by `s`.
fn scaled_angle(lengths: &[f64], corners: &[[usize; 3]], s: f64) -> f64 {
    corners
        .iter()
        .map(|&[a, b, c]| angle(s * lengths[a], s * lengths[b], lengths[c]))
        .sum()
}

/// Widen every boundary corner sharper than [`MIN_BOUNDARY_ANGLE`] (module docs): the new
/// lengths and the corners changed (empty when none; `lengths` is then returned unchanged).
pub(crate) fn widen_sharp_corners(mesh: &Mesh, lengths: &[f64]) -> (Vec<f64>, Vec<WidenedCorner>) {
    let mut out = lengths.to_vec();
    let mut sharp: Vec<(f64, u32)> = (0..mesh.n_vertices() as u32)
        .filter(|&v| !mesh.is_isolated(v) && mesh.is_boundary_vertex(v))
        .map(|v| (scaled_angle(lengths, &corner_edges(mesh, v), 1.0), v))
        .filter(|&(a, _)| a < MIN_BOUNDARY_ANGLE)
        .collect();
    sharp.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    let mut widened = Vec::with_capacity(sharp.len());
    for (_, v) in sharp {
        let corners = corner_edges(mesh, v);
        let before = scaled_angle(&out, &corners, 1.0);
        if before >= MIN_BOUNDARY_ANGLE {
            continue; // widened enough by an earlier neighbour's scaling
        }
        // θ(u) is decreasing in u: θ(0) < θ_min, and θ(lo) = (faces)·π > θ_min for u small
        // enough (the triangles at v flatten).
        let (mut lo, mut hi) = (-1.0f64, 0.0f64);
        while scaled_angle(&out, &corners, (0.5 * lo).exp()) < MIN_BOUNDARY_ANGLE && lo > -200.0 {
            lo *= 2.0;
        }
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if scaled_angle(&out, &corners, (0.5 * mid).exp()) > MIN_BOUNDARY_ANGLE {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let u = 0.5 * (lo + hi);
        let s = (0.5 * u).exp();
        for h in mesh.outgoing(v) {
            out[mesh.he_edge(h) as usize] *= s;
        }
        widened.push(WidenedCorner {
            vertex: v,
            angle_before: before,
            angle_after: scaled_angle(&out, &corners, 1.0),
            u,
        });
    }
    (out, widened)
}
