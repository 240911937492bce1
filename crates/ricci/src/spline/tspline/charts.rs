//! Chart independence of a T-spline over the flat torus (paper 003 §2: the domain manifold is
//! covered by charts whose transition functions, for genus 1, are the translations by the
//! lattice vectors `λ ∈ Λ = Z ω₁ + Z ω₂`).
//!
//! A point of the torus has the coordinates `p + λ` in the charts of the universal cover. The
//! spline is well defined when its value and derivatives computed in chart `p + λ` equal those
//! computed in chart `p` (the transitions are translations, so the Jacobian is the identity and
//! the partials must agree as they are). [`jet_in_cover`] evaluates the spline directly in the
//! universal cover — every anchor's unwrapped support translated by every lattice vector that
//! reaches the point; no reduction to the fundamental rectangle and no bucket grid, so it shares
//! only the knot vectors and [`super::basis::cubic`] with [`TSpline::jet`].
//! [`chart_independence`] compares `jet_in_cover(p + λ)` with `TSpline::jet(p)` at sample
//! points `p` (an interior grid and points on the seams of the fundamental rectangle) for
//! several lattice vectors `λ`, per derivative order.

use super::basis::cubic;
use super::surface::TSpline;
use super::tmesh::Lattice;

/// Largest differences between charts, per derivative order 0..=2.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ChartIndependence {
    /// `max |D^k S(p + λ) − D^k S(p)|` (Euclidean norm in R³) over samples, translations and
    /// the partials of order `k`.
    pub differences: [f64; 3],
    /// Largest norm of a partial of each order at the samples (the scale of the differences).
    pub magnitudes: [f64; 3],
    /// Sample points × translations compared.
    pub comparisons: usize,
}

impl ChartIndependence {
    /// `differences / magnitudes` per order.
    pub fn relative(&self) -> [f64; 3] {
        let mut r = [0.0; 3];
        for k in 0..3 {
            if self.magnitudes[k] > 0.0 {
                r[k] = self.differences[k] / self.magnitudes[k];
            }
        }
        r
    }

    /// The largest relative difference over the orders.
    pub fn max_relative(&self) -> f64 {
        self.relative().into_iter().fold(0.0, f64::max)
    }
}

/// `[S, S_u, S_v, S_uu, S_uv, S_vv]` at `(u, v)` of the universal cover of the torus with
/// lattice `lattice`, summing every anchor over every translate of its support containing the
/// point (half-open supports, as in [`super::surface::TBasis::eval`]).
pub fn jet_in_cover(ts: &TSpline, lattice: Lattice, u: f64, v: f64) -> [[f64; 3]; 6] {
    let (w, h, s) = (lattice.width, lattice.height, lattice.shift);
    let mut out = [[0.0; 3]; 6];
    for (a, p) in ts.basis.anchors.iter().zip(&ts.control) {
        // translates (m W + n s, n H) with v − n H ∈ [v₋₂, v₊₂) and u − n s − m W ∈ [u₋₂, u₊₂)
        let n0 = ((v - a.knots_v[4]) / h).floor() as i64;
        let n1 = ((v - a.knots_v[0]) / h).ceil() as i64;
        for n in n0..=n1 {
            let y = v - n as f64 * h;
            if !(y >= a.knots_v[0] && y < a.knots_v[4]) {
                continue;
            }
            let su = n as f64 * s;
            let m0 = ((u - su - a.knots_u[4]) / w).floor() as i64;
            let m1 = ((u - su - a.knots_u[0]) / w).ceil() as i64;
            for m in m0..=m1 {
                let x = u - su - m as f64 * w;
                if !(x >= a.knots_u[0] && x < a.knots_u[4]) {
                    continue;
                }
                let nu = cubic(&a.knots_u, x);
                let nv = cubic(&a.knots_v, y);
                let j = [
                    nu[0] * nv[0],
                    nu[1] * nv[0],
                    nu[0] * nv[1],
                    nu[2] * nv[0],
                    nu[1] * nv[1],
                    nu[0] * nv[2],
                ];
                for k in 0..6 {
                    for d in 0..3 {
                        out[k][d] += j[k] * p[d];
                    }
                }
            }
        }
    }
    out
}

/// Compare the spline in chart `p` ([`TSpline::jet`]) with the spline in the charts `p + λ`
/// ([`jet_in_cover`] with the lattice `lattice`, normally the spline's own) for `λ` among
/// `±ω₁, ±ω₂, ω₁ + ω₂, 2ω₁ − ω₂`, at a `grid × grid` set of interior points and `grid` points
/// on each seam of the fundamental rectangle (`u = 0`, `v = 0`, just below `u = W` and `v = H`).
pub fn chart_independence(ts: &TSpline, lattice: Lattice, grid: usize) -> ChartIndependence {
    let own = ts.basis.mesh.lattice;
    let (w, h) = (own.width, own.height);
    let g = grid.max(1);
    let mut points = Vec::with_capacity(g * g + 4 * g);
    for i in 0..g {
        let a = (i as f64 + 0.37) / g as f64;
        for j in 0..g {
            let b = (j as f64 + 0.61) / g as f64;
            points.push((a * w, b * h));
        }
        let below = 1.0 - 1e-9;
        points.extend([
            (0.0, a * h),
            (a * w, 0.0),
            (below * w, a * h),
            (a * w, below * h),
        ]);
    }
    let (o1, o2) = ((lattice.width, 0.0), (lattice.shift, lattice.height));
    let translations = [
        o1,
        (-o1.0, -o1.1),
        o2,
        (-o2.0, -o2.1),
        (o1.0 + o2.0, o1.1 + o2.1),
        (2.0 * o1.0 - o2.0, 2.0 * o1.1 - o2.1),
    ];
    let mut differences = [0.0f64; 3];
    let mut magnitudes = [0.0f64; 3];
    let order = [0usize, 1, 1, 2, 2, 2];
    for &(u, v) in &points {
        let reference = ts.jet(u, v);
        for (k, x) in reference.iter().enumerate() {
            magnitudes[order[k]] = magnitudes[order[k]].max(norm(x));
        }
        for &(du, dv) in &translations {
            let other = jet_in_cover(ts, lattice, u + du, v + dv);
            for k in 0..6 {
                let d = [
                    other[k][0] - reference[k][0],
                    other[k][1] - reference[k][1],
                    other[k][2] - reference[k][2],
                ];
                differences[order[k]] = differences[order[k]].max(norm(&d));
            }
        }
    }
    ChartIndependence {
        differences,
        magnitudes,
        comparisons: points.len() * translations.len(),
    }
}

fn norm(x: &[f64; 3]) -> f64 {
    (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt()
}
