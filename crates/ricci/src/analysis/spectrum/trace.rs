//! A closed geodesic drawn on the surface (paper 002 §6.3.3, the pictures of the shortest
//! closed geodesics): the axis of a deck transformation `γ`, walked for one period `ℓ(γ)` and
//! pulled back into the fundamental polygon `F` piece by piece.
//!
//! Points `p(s)` of the axis at arc length `s` are mapped into `F` by the deck transformation
//! `h` of the tile they lie in (`h⁻¹ p ∈ F`); when a point leaves `F`, `h` is composed with the
//! side pairing (or its inverse) that brings it back, which is how the closed geodesic crosses
//! the cut. Each point is located in a triangle of the layout (triangles drawn with straight
//! sides in the disk; points in the thin gaps along curved sides take the nearest triangle)
//! and returned as a face of the cut mesh with barycentric coordinates, so that it can be
//! placed on the surface in space. `p(s + ℓ) = γ p(s)`, so the curve closes.

use super::axis_frame;
use crate::error::{Error, Result};
use crate::layout::deck::{DeckGroup, Polygon};
use crate::layout::isometry::{Complex, Isometry, Mobius};
use crate::layout::place::Layout;
use crate::mesh::Mesh;

/// Uniform grid over the disk's bounding square with the faces whose bounding box meets each
/// cell.
struct FaceGrid {
    tris: Vec<[Complex; 3]>,
    cells: Vec<Vec<u32>>,
    n: usize,
}

impl FaceGrid {
    fn new(mesh: &Mesh, pos: &[Complex], n: usize) -> Self {
        let tris: Vec<[Complex; 3]> = mesh
            .faces()
            .iter()
            .map(|f| [pos[f[0] as usize], pos[f[1] as usize], pos[f[2] as usize]])
            .collect();
        let mut cells = vec![Vec::new(); n * n];
        let cell = |x: f64| (((x + 1.0) * 0.5 * n as f64).floor().max(0.0) as usize).min(n - 1);
        for (f, t) in tris.iter().enumerate() {
            let (x0, x1) = (
                t.iter().map(|p| p.re).fold(f64::INFINITY, f64::min),
                t.iter().map(|p| p.re).fold(f64::NEG_INFINITY, f64::max),
            );
            let (y0, y1) = (
                t.iter().map(|p| p.im).fold(f64::INFINITY, f64::min),
                t.iter().map(|p| p.im).fold(f64::NEG_INFINITY, f64::max),
            );
            for j in cell(y0)..=cell(y1) {
                for i in cell(x0)..=cell(x1) {
                    cells[j * n + i].push(f as u32);
                }
            }
        }
        FaceGrid { tris, cells, n }
    }

    /// The face of the cell of `z` where `z` is most inside: (face, barycentric, smallest
    /// barycentric coordinate; ≥ 0 inside).
    fn locate(&self, z: Complex) -> Option<(u32, [f64; 3], f64)> {
        let r2 = z.norm_sqr();
        if r2.is_nan() || r2 >= 1.0 {
            return None;
        }
        let n = self.n;
        let cell = |x: f64| (((x + 1.0) * 0.5 * n as f64).floor().max(0.0) as usize).min(n - 1);
        let mut best: Option<(u32, [f64; 3], f64)> = None;
        for &f in &self.cells[cell(z.im) * n + cell(z.re)] {
            let [a, b, c] = self.tris[f as usize];
            let det = (b - a).re * (c - a).im - (b - a).im * (c - a).re;
            if det.abs() < 1e-300 {
                continue;
            }
            let d = z - a;
            let l1 = (d.re * (c - a).im - d.im * (c - a).re) / det;
            let l2 = ((b - a).re * d.im - (b - a).im * d.re) / det;
            let bary = [1.0 - l1 - l2, l1, l2];
            let m = bary[0].min(bary[1]).min(bary[2]);
            if best.is_none_or(|x| m > x.2) {
                best = Some((f, bary, m));
            }
        }
        best
    }
}

/// Points of the closed geodesic of `gamma` (a hyperbolic deck transformation whose axis
/// meets the polygon): `samples` points, one period, each as (face of the laid-out cut mesh,
/// barycentric coordinates clamped to the triangle). Points farther than a tolerance outside
/// every triangle of their tile are left out.
pub fn closed_geodesic(
    mesh: &Mesh,
    layout: &Layout<Complex>,
    poly: &Polygon,
    group: &DeckGroup<Mobius>,
    gamma: &Mobius,
    samples: usize,
) -> Result<Vec<(u32, [f64; 3])>> {
    let len = gamma.translation_length();
    let fr = axis_frame(gamma)
        .filter(|_| len > 0.0)
        .ok_or_else(|| Error::numerical("the element is not hyperbolic: it has no axis"))?;
    let back = fr.inverse();
    let mut maps: Vec<Mobius> = Vec::new();
    for s in 0..poly.sides.len() {
        if let Some(m) = group.side_map(s) {
            maps.push(m);
            maps.push(m.inverse());
        }
    }
    let grid = FaceGrid::new(mesh, &layout.positions, 96);
    let point = |s: f64| back.apply(Complex::new((0.5 * s).tanh(), 0.0));
    // A start on the axis inside F.
    let s0 = (-2400..=2400)
        .map(|i| i as f64 * 0.005)
        .find(|&s| grid.locate(point(s)).is_some_and(|x| x.2 >= 0.0))
        .ok_or_else(|| Error::numerical("the axis does not meet the fundamental polygon"))?;
    let mut h_inv = Mobius::identity();
    let mut out = Vec::with_capacity(samples + 1);
    for i in 0..=samples {
        let p = point(s0 + len * i as f64 / samples as f64);
        let mut best = grid
            .locate(h_inv.apply(p))
            .map(|x| (x, h_inv))
            .filter(|x| x.0 .2 >= -1e-9);
        if best.is_none() {
            for m in &maps {
                let cand = m.inverse().compose(&h_inv);
                if let Some(x) = grid.locate(cand.apply(p)) {
                    if best.as_ref().is_none_or(|b| x.2 > b.0 .2) {
                        best = Some((x, cand));
                    }
                }
            }
        }
        if let Some(((f, b, m), hi)) = best {
            h_inv = hi;
            if m > -0.05 {
                let c = [b[0].max(0.0), b[1].max(0.0), b[2].max(0.0)];
                let t = c[0] + c[1] + c[2];
                out.push((f, [c[0] / t, c[1] / t, c[2] / t]));
            }
        }
    }
    Ok(out)
}
