//! Bézier extraction of a T-spline (Scott, Borden, Verhoosel, Sederberg, Hughes 2011 in
//! spirit): the domain is cut into **Bézier elements** on which every blending function is one
//! bicubic polynomial, and each element becomes a bicubic Bézier patch.
//!
//! Elements: every T-mesh face, cut by the knot lines of the (translated) local knot vectors of
//! the anchors whose supports meet it (for an analysis-suitable T-mesh these are the face
//! extensions). The patch of an element is found by interpolating the T-spline at the 4×4
//! tensor nodes `x ∈ {0.05, 0.35, 0.65, 0.95}` of the element — exact up to rounding because the
//! T-spline restricted to the element is a bicubic polynomial; the extraction test checks it.
//! Cells of one face on which the spline (not only every blending function) is one polynomial
//! are merged into maximal rectangles, the exported Bézier elements
//! ([`super::bezier_elements`]). Patches also measure the continuity of the surface: the jumps of the partial derivatives of
//! neighbouring patches across their common side, per order.

use super::bezier_elements::{merge_grid, MergeStats};
use super::surface::{TBasis, TSpline};

/// A bicubic Bézier patch over `[u0, u1] × [v0, v1]`; `control[i][j]`: `i` along `u`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BezierPatch {
    pub u0: f64,
    pub u1: f64,
    pub v0: f64,
    pub v1: f64,
    pub control: [[[f64; 3]; 4]; 4],
}

/// Cubic Bernstein polynomials and their first three derivatives at `t`.
fn bernstein(t: f64) -> [[f64; 4]; 4] {
    let s = 1.0 - t;
    [
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * s - 6.0 * t * s,
            6.0 * t * s - 3.0 * t * t,
            3.0 * t * t,
        ],
        [6.0 * s, -12.0 * s + 6.0 * t, 6.0 * s - 12.0 * t, 6.0 * t],
        [-6.0, 18.0, -18.0, 6.0],
    ]
}

impl BezierPatch {
    /// `∂^{a+b} S / ∂u^a ∂v^b` at `(u, v)` (any point: the polynomial is extended).
    pub fn partial(&self, u: f64, v: f64, a: usize, b: usize) -> [f64; 3] {
        let (du, dv) = (self.u1 - self.u0, self.v1 - self.v0);
        let bu = bernstein((u - self.u0) / du)[a];
        let bv = bernstein((v - self.v0) / dv)[b];
        let scale = du.powi(-(a as i32)) * dv.powi(-(b as i32));
        let mut p = [0.0; 3];
        for i in 0..4 {
            for j in 0..4 {
                let w = bu[i] * bv[j] * scale;
                for d in 0..3 {
                    p[d] += w * self.control[i][j][d];
                }
            }
        }
        p
    }

    pub fn point(&self, u: f64, v: f64) -> [f64; 3] {
        self.partial(u, v, 0, 0)
    }

    /// The same polynomial as a patch over `[u0, u1] × [v0, v1]` (subdivision by blossoming:
    /// the new Bézier points are the blossom at the new ends, `u` then `v`).
    pub fn restrict(&self, u0: f64, u1: f64, v0: f64, v1: f64) -> BezierPatch {
        let (su, eu) = (
            (u0 - self.u0) / (self.u1 - self.u0),
            (u1 - self.u0) / (self.u1 - self.u0),
        );
        let (sv, ev) = (
            (v0 - self.v0) / (self.v1 - self.v0),
            (v1 - self.v0) / (self.v1 - self.v0),
        );
        let mut along_u = [[[0.0; 3]; 4]; 4];
        for j in 0..4 {
            let c = [
                self.control[0][j],
                self.control[1][j],
                self.control[2][j],
                self.control[3][j],
            ];
            let d = restrict_cubic(c, su, eu);
            for i in 0..4 {
                along_u[i][j] = d[i];
            }
        }
        let mut control = [[[0.0; 3]; 4]; 4];
        for i in 0..4 {
            control[i] = restrict_cubic(along_u[i], sv, ev);
        }
        BezierPatch {
            u0,
            u1,
            v0,
            v1,
            control,
        }
    }
}

/// The blossom of the cubic with Bézier points `c` (over `[0, 1]`) at `t`: de Casteljau with
/// one parameter per level.
fn blossom(c: [[f64; 3]; 4], t: [f64; 3]) -> [f64; 3] {
    let mut p = c;
    for (level, &x) in t.iter().enumerate() {
        for k in 0..3 - level {
            for d in 0..3 {
                p[k][d] = (1.0 - x) * p[k][d] + x * p[k + 1][d];
            }
        }
    }
    p[0]
}

/// The Bézier points over `[s, e]` (local parameters) of the cubic with points `c` over
/// `[0, 1]`: `f(s, s, s)`, `f(s, s, e)`, `f(s, e, e)`, `f(e, e, e)`.
fn restrict_cubic(c: [[f64; 3]; 4], s: f64, e: f64) -> [[f64; 3]; 4] {
    [
        blossom(c, [s, s, s]),
        blossom(c, [s, s, e]),
        blossom(c, [s, e, e]),
        blossom(c, [e, e, e]),
    ]
}

const NODES: [f64; 4] = [0.05, 0.35, 0.65, 0.95];

/// Inverse of the 4×4 collocation matrix `M[i][k] = b_k(NODES[i])`.
fn collocation_inverse() -> [[f64; 4]; 4] {
    let mut m = [[0.0; 8]; 4];
    for i in 0..4 {
        let b = bernstein(NODES[i])[0];
        m[i][..4].copy_from_slice(&b);
        m[i][4 + i] = 1.0;
    }
    for c in 0..4 {
        let p = (c..4)
            .max_by(|&a, &b| m[a][c].abs().total_cmp(&m[b][c].abs()))
            .unwrap_or(c);
        m.swap(c, p);
        let d = m[c][c];
        for k in 0..8 {
            m[c][k] /= d;
        }
        for r in 0..4 {
            if r != c {
                let f = m[r][c];
                for k in 0..8 {
                    m[r][k] -= f * m[c][k];
                }
            }
        }
    }
    let mut inv = [[0.0; 4]; 4];
    for i in 0..4 {
        for k in 0..4 {
            inv[i][k] = m[i][4 + k];
        }
    }
    inv
}

/// The cells `[u0, u1, v0, v1]` of the T-spline's domain on which every blending function is
/// one polynomial ([`face_grids`] flattened).
pub fn elements(basis: &TBasis) -> Vec<[f64; 4]> {
    let mut out = Vec::new();
    for (us, vs) in face_grids(basis) {
        for j in 0..vs.len() - 1 {
            for i in 0..us.len() - 1 {
                out.push([us[i], us[i + 1], vs[j], vs[j + 1]]);
            }
        }
    }
    out
}

/// Per T-mesh face, the knots `us`, `vs` (increasing, the face's sides first and last) of the
/// tensor grid that cuts it along the knot lines of the anchors whose supports meet it.
pub fn face_grids(basis: &TBasis) -> Vec<(Vec<f64>, Vec<f64>)> {
    let mut out = Vec::new();
    for f in basis.mesh.faces() {
        let mut us = vec![f.u0, f.u1];
        let mut vs = vec![f.v0, f.v1];
        let span = (f.u1 - f.u0).min(f.v1 - f.v0);
        let eps = 1e-9 * span;
        for &(i, du, dv) in &basis.candidates_in(f.u0, f.u1, f.v0, f.v1) {
            let a = &basis.anchors[i as usize];
            let overl = a.knots_u[0] + du < f.u1 - eps
                && a.knots_u[4] + du > f.u0 + eps
                && a.knots_v[0] + dv < f.v1 - eps
                && a.knots_v[4] + dv > f.v0 + eps;
            if !overl {
                continue;
            }
            for k in 0..5 {
                let x = a.knots_u[k] + du;
                if x > f.u0 + eps && x < f.u1 - eps {
                    us.push(x);
                }
                let y = a.knots_v[k] + dv;
                if y > f.v0 + eps && y < f.v1 - eps {
                    vs.push(y);
                }
            }
        }
        for xs in [&mut us, &mut vs] {
            xs.sort_by(f64::total_cmp);
            xs.dedup_by(|a, b| (*a - *b).abs() <= eps);
        }
        out.push((us, vs));
    }
    out
}

/// The bicubic Bézier patch over `[u0, u1] × [v0, v1]` interpolating `f` at the 4×4 nodes of
/// the rectangle (exact when `f` is a bicubic polynomial there).
pub fn interpolate_patch(
    u0: f64,
    u1: f64,
    v0: f64,
    v1: f64,
    f: impl Fn(f64, f64) -> [f64; 3],
) -> BezierPatch {
    let inv = collocation_inverse();
    let mut values = [[[0.0; 3]; 4]; 4];
    for (a, &x) in NODES.iter().enumerate() {
        for (b, &y) in NODES.iter().enumerate() {
            values[a][b] = f(u0 + x * (u1 - u0), v0 + y * (v1 - v0));
        }
    }
    // C = inv · F · invᵀ
    let mut control = [[[0.0; 3]; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            for a in 0..4 {
                for b in 0..4 {
                    let w = inv[i][a] * inv[j][b];
                    for d in 0..3 {
                        control[i][j][d] += w * values[a][b][d];
                    }
                }
            }
        }
    }
    BezierPatch {
        u0,
        u1,
        v0,
        v1,
        control,
    }
}

/// Extract the Bézier elements: one bicubic patch per maximal rectangle on which the
/// T-spline is one polynomial ([`extract_elements`]).
pub fn extract(ts: &TSpline) -> Vec<BezierPatch> {
    extract_elements(ts).0
}

/// The Bézier elements of the T-spline: every T-mesh face's grid of [`face_grids`] extracted
/// cell by cell, the cells merged where they are one polynomial
/// ([`super::bezier_elements::merge_grid`]); and what the merging did.
pub fn extract_elements(ts: &TSpline) -> (Vec<BezierPatch>, MergeStats) {
    let mut stats = MergeStats::default();
    let mut out = Vec::new();
    for (us, vs) in face_grids(&ts.basis) {
        let (nu, nv) = (us.len() - 1, vs.len() - 1);
        let mut cells = Vec::with_capacity(nu * nv);
        for j in 0..nv {
            for i in 0..nu {
                cells.push(interpolate_patch(
                    us[i],
                    us[i + 1],
                    vs[j],
                    vs[j + 1],
                    |u, v| ts.point(u, v),
                ));
            }
        }
        out.extend(
            merge_grid(nu, nv, &cells, &mut stats)
                .into_iter()
                .map(|e| e.patch),
        );
    }
    (out, stats)
}

/// Jumps of the partial derivatives across patch sides, per order 0..=3.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct Continuity {
    /// Largest jump (Euclidean norm in R³) over the sampled side points and the partials of
    /// each order.
    pub jumps: [f64; 4],
    /// Largest norm of a partial of each order at the sampled points (the scale of the jumps).
    pub magnitudes: [f64; 4],
    /// Side points compared (each with its neighbour across the side).
    pub comparisons: usize,
}

impl Continuity {
    /// `jumps / magnitudes` per order.
    pub fn relative(&self) -> [f64; 4] {
        let mut r = [0.0; 4];
        for k in 0..4 {
            r[k] = if self.magnitudes[k] > 0.0 {
                self.jumps[k] / self.magnitudes[k]
            } else {
                0.0
            };
        }
        r
    }

    /// Compare every partial of orders 0..=3 of `a` at `pa` with that of `b` at `pb` (the same
    /// point of the surface in the two patches' parameters).
    pub fn compare(&mut self, a: &BezierPatch, pa: (f64, f64), b: &BezierPatch, pb: (f64, f64)) {
        self.comparisons += 1;
        for order in 0..4 {
            for i in 0..=order {
                let x = a.partial(pa.0, pa.1, i, order - i);
                let y = b.partial(pb.0, pb.1, i, order - i);
                let d =
                    ((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2) + (x[2] - y[2]).powi(2)).sqrt();
                self.jumps[order] = self.jumps[order].max(d);
                let m = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
                self.magnitudes[order] = self.magnitudes[order].max(m);
            }
        }
    }

    /// The largest `k` with relative jumps of orders ≤ k below `threshold` (`None`: the
    /// values themselves jump).
    pub fn class(&self, threshold: f64) -> Option<usize> {
        let r = self.relative();
        (0..4).take_while(|&k| r[k] < threshold).last()
    }
}

/// Jumps of the partial derivatives of orders 0..=3 across the common sides of neighbouring
/// patches, at `samples` points per side. C^k means the jumps of orders ≤ k vanish.
pub fn continuity(
    patches: &[BezierPatch],
    lattice: super::tmesh::Lattice,
    samples: usize,
) -> Continuity {
    let (w, h) = (lattice.width, lattice.height);
    let n = patches.len().max(1);
    let side = (w * h / n as f64).sqrt();
    let nx = ((w / side).ceil() as usize).clamp(1, 1024);
    let ny = ((h / side).ceil() as usize).clamp(1, 1024);
    let cell =
        |x: f64, len: f64, k: usize| ((x / len * k as f64).floor().max(0.0) as usize).min(k - 1);
    let mut grid = vec![Vec::new(); nx * ny];
    for (p, q) in patches.iter().enumerate() {
        for iy in cell(q.v0, h, ny)..=cell(q.v1, h, ny) {
            for ix in cell(q.u0, w, nx)..=cell(q.u1, w, nx) {
                grid[iy * nx + ix].push(p);
            }
        }
    }
    let find = |u: f64, v: f64| -> Option<usize> {
        let (cu, cv) = lattice.canonical(u, v);
        grid[cell(cv, h, ny) * nx + cell(cu, w, nx)]
            .iter()
            .copied()
            .find(|&p| {
                let q = &patches[p];
                cu >= q.u0 && cu < q.u1 && cv >= q.v0 && cv < q.v1
            })
    };
    let mut out = Continuity::default();
    for q in patches {
        let dmin = (q.u1 - q.u0).min(q.v1 - q.v0) * 1e-6;
        for s in 0..samples {
            let t = (s as f64 + 0.5) / samples as f64;
            // right side and top side
            for (u, v, nu, nv) in [
                (q.u1, q.v0 + t * (q.v1 - q.v0), dmin, 0.0),
                (q.u0 + t * (q.u1 - q.u0), q.v1, 0.0, dmin),
            ] {
                let Some(o) = find(u + nu, v + nv) else {
                    continue;
                };
                let other = &patches[o];
                // the same point in the neighbour's copy of the domain
                let (cu, cv) = lattice.canonical(u + nu, v + nv);
                out.compare(q, (u, v), other, (cu - nu, cv - nv));
            }
        }
    }
    out
}
