//! The partition-of-unity surface over the hyperbolic atlas (paper 004 §4.2, completed).
//!
//! **What we chose** (the paper's text stops after the definition of the hyperbolic disks):
//! one control point `P_i` per vertex `c_i` of the domain, a hyperbolic disk `D(c_i, r_i)`
//! with `r_i = ρ·R₂(c_i)`, `R₂` the largest two-edge path length from `c_i` to a vertex of its
//! two-ring (so the disk covers the two-ring, paper 004 Fig. 5; `ρ ≥ 1` is `--radius`), and
//! the radial exponential bump
//!
//! `b_i(p) = exp(1 − 1/(1 − τ)),  τ = tanh²(d(p, c_i)/2) / tanh²(r_i/2)`  for `d < r_i`, 0 else.
//!
//! `tanh²(d/2) = |(z − c)/(1 − c̄z)|²` is a rational function of the chart coordinate that
//! every Möbius map preserves, so `b_i` is C∞ on the surface (all derivatives vanish at the
//! rim of the disk, including the centre where `d` itself is not smooth) and the same in
//! every chart. (The profile `exp(−1/(1 − (d/r)²))` of the issue differs only by the monotone
//! reparametrisation `d ↦ tanh²(d/2)` and would need `d` at the centre.) The weights are
//! `w_i = b_i / Σ_j b_j` and `F(p) = Σ_i w_i(p) P_i`, the sums running over all lifts of the
//! control points to the universal cover (a disk that wraps around a handle contributes
//! once per lift it reaches). Every point is within `R₁ ≤ R₂ ≤ r_i` of some vertex, so
//! `Σ b_j > 0` everywhere.
//!
//! Values and partials of `F` in a chart coordinate are exact: they are built from jets
//! ([`super::jet`]) of the chart coordinate.

use crate::error::{Error, Result};
use crate::layout::isometry::Complex;

use super::atlas::{point_in_face, Chart, ControlLift, HyperbolicAtlas};
use super::jet::{su11_jet, CJet, Jet};
use super::local::LocalPolynomial;

/// `r_i = factor · R₂(c_i)` (module docs).
pub fn two_ring_radii(atlas: &HyperbolicAtlas, factor: f64) -> Result<Vec<f64>> {
    if !(factor >= 1.0 && factor.is_finite()) {
        return Err(Error::input(format!(
            "the radius factor {factor} must be ≥ 1 (a disk must cover the two-ring)"
        )));
    }
    let m = &atlas.mesh;
    let nv = m.n_vertices();
    let len = |h: u32| atlas.lengths[m.he_edge(h) as usize];
    let mut radii = vec![0.0; nv];
    for v in 0..nv as u32 {
        let mut r2 = 0.0f64;
        for h in m.outgoing(v) {
            let l1 = len(h);
            let u = m.he_tip(h);
            for h2 in m.outgoing(u) {
                r2 = r2.max(l1 + len(h2));
            }
        }
        radii[v as usize] = factor * r2;
    }
    Ok(radii)
}

/// The bump of a jet of `τ`: `f(τ) = exp(1 − 1/(1 − τ))` composed through its Taylor
/// coefficients (`g = 1/(1 − τ)`: `f′ = −g² f`, `f″ = (g⁴ − 2g³) f`,
/// `f‴ = (−g⁶ + 6g⁵ − 6g⁴) f`); `None` outside the disk.
#[inline]
fn bump_of_tau(tau: &Jet) -> Option<Jet> {
    let t0 = tau.value();
    if !(t0 < 1.0) {
        return None;
    }
    let g = 1.0 / (1.0 - t0);
    let f = (1.0 - g).exp();
    if f == 0.0 {
        return None;
    }
    let (g2, g3) = (g * g, g * g * g);
    let (g4, g5, g6) = (g3 * g, g3 * g2, g3 * g3);
    Some(tau.compose_univariate(&[
        f,
        -g2 * f,
        0.5 * (g4 - 2.0 * g3) * f,
        (-g6 + 6.0 * g5 - 6.0 * g4) * f / 6.0,
    ]))
}

/// The scalar bump at `s = tanh²(d/2)` for `σ = tanh²(r/2)`.
#[inline]
pub fn bump(s: f64, sigma: f64) -> f64 {
    let t = s / sigma;
    if !(t < 1.0) {
        return 0.0;
    }
    (1.0 - 1.0 / (1.0 - t)).exp()
}

/// `tanh²(d(z, c)/2) = |z − c|² / |1 − c̄ z|²`.
#[inline]
pub fn pseudo_distance_sqr(z: Complex, c: Complex) -> f64 {
    let one = Complex::new(1.0, 0.0);
    (z - c).norm_sqr() / (one - c.conj() * z).norm_sqr()
}

/// The local coordinate `W = T(z)` of a control lift (`T` its map to the basis' chart).
#[inline]
fn local_coordinate(c: &ControlLift, z: Complex) -> Complex {
    (c.map.a * z + c.map.b) / (c.map.b.conj() * z + c.map.a.conj())
}

/// A basis' contribution at a point of a chart, as jets: `b` and its local coordinate.
pub struct BumpJet {
    pub vertex: u32,
    pub bump: Jet,
    /// `W/s` (real and imaginary parts), `s = tanh(r/2)`.
    pub local: CJet,
}

/// The jet of `b` at the chart point `z` (jets of the coordinate `x`, `y` in `zj`) from the
/// lift's position `c`, by the arithmetic of jets (the independent reference of the
/// closed-form [`PouBasis::bump_jets`] in the tests).
pub fn bump_jet(zj: &CJet, c: Complex, sigma: f64) -> Option<Jet> {
    let x = &zj.re;
    let y = &zj.im;
    let dx = x.add_const(-c.re);
    let dy = y.add_const(-c.im);
    let num = dx.mul(&dx).add(&dy.mul(&dy));
    // 1 − c̄ z = (1 − cx x − cy y) − i (cx y − cy x).
    let re = x.scale(-c.re).sub(&y.scale(c.im)).add_const(1.0);
    let im = y.scale(c.re).sub(&x.scale(c.im));
    let den = re.mul(&re).add(&im.mul(&im));
    let tau = num.div(&den).scale(1.0 / sigma);
    bump_of_tau(&tau)
}

/// The bases of a partition-of-unity surface: radii and the atlas.
pub struct PouBasis<'a> {
    pub atlas: &'a HyperbolicAtlas,
    pub radii: Vec<f64>,
    /// `tanh²(r_i/2)`.
    pub sigma: Vec<f64>,
}

impl<'a> PouBasis<'a> {
    pub fn new(atlas: &'a HyperbolicAtlas, radii: Vec<f64>) -> PouBasis<'a> {
        let sigma = radii.iter().map(|r| (0.5 * r).tanh().powi(2)).collect();
        PouBasis {
            atlas,
            radii,
            sigma,
        }
    }

    fn chart(&self, v: u32) -> Result<&Chart> {
        self.atlas
            .charts
            .get(v as usize)
            .ok_or_else(|| Error::input(format!("no chart for vertex {v}")))
    }

    /// Weights `w_i` (values) at the chart point `z` of chart `v`: `(vertex, w)` per lift
    /// (a vertex may appear more than once). Errors if no basis covers the point.
    pub fn weights(&self, v: u32, z: Complex, out: &mut Vec<(u32, f64)>) -> Result<()> {
        out.clear();
        let chart = self.chart(v)?;
        let mut sum = 0.0;
        for c in &chart.controls {
            let b = bump(
                local_coordinate(c, z).norm_sqr(),
                self.sigma[c.vertex as usize],
            );
            if b > 0.0 {
                out.push((c.vertex, b));
                sum += b;
            }
        }
        if !(sum > 0.0) {
            return Err(Error::numerical(format!(
                "no basis covers the point {z} of the chart of vertex {v}"
            )));
        }
        for w in out.iter_mut() {
            w.1 /= sum;
        }
        Ok(())
    }

    /// The bumps (not normalized) that are non-zero at the chart point `z` of chart `v`, with
    /// their local coordinates, as jets of order `order` (≤ 3); returns `Σ b`. The local
    /// coordinate's jet comes from the SU(1,1) map's closed-form derivatives and
    /// `τ = |W|²/σ`, so a bump costs five jet products.
    pub fn bump_jets(
        &self,
        v: u32,
        z: Complex,
        order: usize,
        out: &mut Vec<BumpJet>,
    ) -> Result<Jet> {
        out.clear();
        let chart = self.chart(v)?;
        let mut sum = Jet::constant(0.0, order);
        for c in &chart.controls {
            let sigma = self.sigma[c.vertex as usize];
            if local_coordinate(c, z).norm_sqr() >= sigma {
                continue;
            }
            let w = su11_jet(c.map.a, c.map.b, z, order);
            let tau = w.re.mul(&w.re).add(&w.im.mul(&w.im)).scale(1.0 / sigma);
            if let Some(b) = bump_of_tau(&tau) {
                sum = sum.add(&b);
                let s = 1.0 / sigma.sqrt();
                out.push(BumpJet {
                    vertex: c.vertex,
                    bump: b,
                    local: CJet {
                        re: w.re.scale(s),
                        im: w.im.scale(s),
                    },
                });
            }
        }
        if !(sum.value() > 0.0) {
            return Err(Error::numerical(format!(
                "no basis covers the point {z} of the chart of vertex {v}"
            )));
        }
        Ok(sum)
    }

    /// Weights with their partials up to `order` (≤ 3) in the chart coordinate.
    pub fn weight_jets(
        &self,
        v: u32,
        z: Complex,
        order: usize,
        out: &mut Vec<(u32, Jet)>,
    ) -> Result<()> {
        let mut b = Vec::new();
        let sum = self.bump_jets(v, z, order, &mut b)?;
        let inv = sum.recip();
        out.clear();
        out.extend(b.iter().map(|x| (x.vertex, x.bump.mul(&inv))));
        Ok(())
    }
}

/// A partition-of-unity surface: bases, control points (one per vertex) and, optionally,
/// local polynomials (one per vertex, [`super::local`]; empty: constants only).
pub struct PouSurface<'a> {
    pub basis: PouBasis<'a>,
    pub control: Vec<[f64; 3]>,
    pub local: Vec<LocalPolynomial>,
}

/// `Q(X, Y)` of a local polynomial.
#[inline]
fn local_value(q: &[f64; 5], x: f64, y: f64) -> f64 {
    q[0] * x + q[1] * y + q[2] * x * x + q[3] * x * y + q[4] * y * y
}

impl<'a> PouSurface<'a> {
    /// `F` at the chart point `z` of chart `v`.
    pub fn value(&self, v: u32, z: Complex, scratch: &mut Vec<(u32, f64)>) -> Result<[f64; 3]> {
        let chart = self.basis.chart(v)?;
        let mut p = [0.0; 3];
        let mut sum = 0.0;
        scratch.clear();
        for c in &chart.controls {
            let i = c.vertex as usize;
            let w = local_coordinate(c, z);
            let b = bump(w.norm_sqr(), self.basis.sigma[i]);
            if b <= 0.0 {
                continue;
            }
            sum += b;
            let l = self.local_at(i, w);
            for d in 0..3 {
                p[d] += b * l[d];
            }
        }
        if !(sum > 0.0) {
            return Err(Error::numerical(format!(
                "no basis covers the point {z} of the chart of vertex {v}"
            )));
        }
        Ok(p.map(|x| x / sum))
    }

    /// `Lᵢ(W)` for the local coordinate `W` of a lift of vertex `i`.
    #[inline]
    fn local_at(&self, i: usize, w: Complex) -> [f64; 3] {
        let mut l = self.control[i];
        if let Some(q) = self.local.get(i) {
            let s = 1.0 / self.basis.sigma[i].sqrt();
            let (x, y) = (w.re * s, w.im * s);
            for d in 0..3 {
                l[d] += local_value(&q[d], x, y);
            }
        }
        l
    }

    /// `F` and its partials up to `order` at the chart point `z` of chart `v`.
    pub fn jets(&self, v: u32, z: Complex, order: usize) -> Result<[Jet; 3]> {
        let mut b = Vec::new();
        let sum = self.basis.bump_jets(v, z, order, &mut b)?;
        let mut acc = [Jet::constant(0.0, order); 3];
        for x in &b {
            let i = x.vertex as usize;
            let p = self.control[i];
            match self.local.get(i) {
                None => {
                    for d in 0..3 {
                        acc[d].axpy(p[d], &x.bump);
                    }
                }
                Some(q) => {
                    let (lx, ly) = (&x.local.re, &x.local.im);
                    let mono = [*lx, *ly, lx.mul(lx), lx.mul(ly), ly.mul(ly)];
                    for d in 0..3 {
                        let mut l = Jet::constant(p[d], order);
                        for k in 0..5 {
                            if q[d][k] != 0.0 {
                                l.axpy(q[d][k], &mono[k]);
                            }
                        }
                        acc[d] = acc[d].add(&x.bump.mul(&l));
                    }
                }
            }
        }
        let inv = sum.recip();
        Ok(acc.map(|a| a.mul(&inv)))
    }

    /// `F` at the surface point `(f, λ)` (evaluated in the chart of the face's first vertex).
    pub fn at(&self, f: u32, lambda: [f64; 3], scratch: &mut Vec<(u32, f64)>) -> Result<[f64; 3]> {
        let atlas = self.basis.atlas;
        let v = atlas.mesh.face(f)[0];
        let i = atlas
            .star_index(v, f)
            .ok_or_else(|| Error::input(format!("face {f} is not in the star of vertex {v}")))?;
        let z = point_in_face(&atlas.charts[v as usize].star[i].z, lambda);
        self.value(v, z, scratch)
    }
}
