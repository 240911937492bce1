//! Charts of a surface with a flat cone metric: the interface between the affine atlas
//! (paper 000 §4, Steps 4–5) and the manifold splines built on it (paper 000 §5).
//!
//! A flat metric with cone singularities makes every simply connected neighbourhood that
//! avoids the cones developable into the plane, uniquely up to a rigid motion. A *chart* is
//! such a development of a set of faces: each face of the chart has three corner coordinates
//! in the plane, faces that are adjacent in the chart share the coordinates of their common
//! edge, and no face is flipped. Two charts that both contain a face `f` are related on `f`
//! by a rigid motion (the transition map); the same pair of charts can be related by
//! *different* rigid motions on different faces (e.g. a cut-curve chart overlaps the central
//! fundamental domain on both sides of the cut), so transitions are always asked for per face.

use crate::layout::RigidMotion;
use crate::mesh::Mesh;
use num_complex::Complex64 as C;

/// Index of a chart.
pub type ChartId = u32;

/// A surface with a flat cone metric and a set of charts covering it.
///
/// Corner coordinates are given in the corner order of [`Mesh::face`].
pub trait FlatCharts {
    /// The domain connectivity (after any connectivity modification).
    fn mesh(&self) -> &Mesh;
    /// The flat metric: one length per edge id of [`FlatCharts::mesh`].
    fn lengths(&self) -> &[f64];
    /// The embedding of [`FlatCharts::mesh`] in R³ (what the splines fit).
    fn positions(&self) -> &[[f64; 3]];
    /// Interior vertices whose cone angle differs from 2π (empty for a flat torus or an
    /// open surface whose curvature sits on the boundary).
    fn singular_vertices(&self) -> &[u32];
    /// Number of charts.
    fn n_charts(&self) -> usize;
    /// Corner coordinates of face `f` in chart `c`, or `None` when `f` is not in `c`.
    fn face_coords(&self, c: ChartId, f: u32) -> Option<[[f64; 2]; 3]>;
    /// The charts that contain face `f`.
    fn charts_of_face(&self, f: u32) -> Vec<ChartId>;
    /// A chart that contains, consistently developed, every face that shares a vertex with
    /// `f` (the closed stars of `f`'s three vertices) except faces incident to a singular
    /// vertex — the support of the spline basis of the domain triangle `f`. `None` for faces
    /// incident to a singular vertex (paper 000 §5 removes the one-ring of the extraordinary
    /// point from the spline domain).
    fn home_chart(&self, f: u32) -> Option<ChartId>;

    /// The rigid motion that maps the coordinates of face `f` in chart `from` to its
    /// coordinates in chart `to`, with the largest corner residual of the fit (≈ 0 up to
    /// rounding for an exactly flat metric). `None` when `f` is not in both charts.
    fn transition(&self, from: ChartId, to: ChartId, f: u32) -> Option<(RigidMotion, f64)> {
        let a = self.face_coords(from, f)?;
        let b = self.face_coords(to, f)?;
        Some(fit_rigid(&a, &b))
    }
}

/// Least-squares rigid motion (rotation + translation, no reflection) taking the points `a`
/// to the points `b`, and the largest residual `max_i |m(a_i) − b_i|`.
pub fn fit_rigid(a: &[[f64; 2]], b: &[[f64; 2]]) -> (RigidMotion, f64) {
    let n = a.len().min(b.len()).max(1) as f64;
    let za: Vec<C> = a.iter().map(|p| C::new(p[0], p[1])).collect();
    let zb: Vec<C> = b.iter().map(|p| C::new(p[0], p[1])).collect();
    let ca = za.iter().sum::<C>() / n;
    let cb = zb.iter().sum::<C>() / n;
    // Procrustes in the complex plane: rot ∝ Σ (b − cb) conj(a − ca).
    let s: C = za
        .iter()
        .zip(&zb)
        .map(|(&p, &q)| (q - cb) * (p - ca).conj())
        .sum();
    let rot = if s.norm() > 0.0 {
        s / s.norm()
    } else {
        C::new(1.0, 0.0)
    };
    let m = RigidMotion {
        rot,
        t: cb - rot * ca,
    };
    let res = za
        .iter()
        .zip(&zb)
        .map(|(&p, &q)| (rot * p + m.t - q).norm())
        .fold(0.0, f64::max);
    (m, res)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_rigid_recovers_a_motion() {
        let m = RigidMotion::new(0.7, C::new(2.0, -1.0));
        let a = [[0.0, 0.0], [1.0, 0.2], [0.3, 0.9]];
        let b: Vec<[f64; 2]> = a
            .iter()
            .map(|p| {
                let z = m.rot * C::new(p[0], p[1]) + m.t;
                [z.re, z.im]
            })
            .collect();
        let (f, res) = fit_rigid(&a, &b);
        assert!(res < 1e-14);
        assert!((f.rot - m.rot).norm() < 1e-14 && (f.t - m.t).norm() < 1e-14);
    }
}
