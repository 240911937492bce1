//! Double-double arithmetic for the hyperbolic layout and deck group (about 32 significant
//! digits), built from error-free transformations: `two_sum` (Knuth) and `two_prod` through
//! a fused multiply-add (`f64::mul_add`), as in Dekker (1971) and the QD library of Hida, Li
//! and Bailey.
//!
//! Why it is needed (paper 001 §VI lists the accuracy problems of hyperbolic layouts): a face at
//! hyperbolic distance `r` from the centre of the Poincaré disk has a frame (the Möbius map
//! placing its canonical triangle) with entries of size `~e^{r/2}`. Composing such frames in
//! double precision perturbs every step by `~1e-16·e^r` (an SU(1,1) matrix `M` has
//! `|M⁻¹| = |M|`), and a point at distance `r` is stored with a resolution of
//! `~1e-16·e^r` in hyperbolic distance (`1 − |z| ≈ 2e^{−r}`). On meshes whose canonical
//! loops are long (fertility: polygon corners at `r ≈ 13`, sides of length up to 18) this
//! loses 6–10 digits in the layout and all of them in the deck generators and their product.
//! In double-double both effects drop to `~1e-32·e^r`; what remains is the metric (the
//! flow's curvature error) and the `~1e-16` relative rounding of each face's canonical
//! triangle, which is computed near the origin in double precision and acts like a
//! perturbation of the input lengths at the 1e-16 level.
//!
//! Only what the layout needs is here: [`Dd`] (+, −, ×, ÷, √), [`Cdd`] (complex) and
//! [`MobiusDd`] (SU(1,1) maps: composition, inverse, application, normalization, the map
//! between two point pairs, the Lie-algebra difference of two nearby maps). Transcendental
//! functions are evaluated in double precision on quantities near the origin (angles and
//! small length mismatches), where that is accurate to the last digit.

// `!(x > 0.0)` is used on purpose: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::isometry::{Complex, Mobius};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// An unevaluated sum `hi + lo` with `|lo| ≤ ulp(hi)/2`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Dd {
    pub hi: f64,
    pub lo: f64,
}

#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

#[inline]
fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

#[inline]
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

impl Dd {
    pub const ZERO: Dd = Dd { hi: 0.0, lo: 0.0 };
    pub const ONE: Dd = Dd { hi: 1.0, lo: 0.0 };
    #[inline]
    pub fn new(x: f64) -> Dd {
        Dd { hi: x, lo: 0.0 }
    }
    /// The value rounded to double precision.
    #[inline]
    pub fn f64(self) -> f64 {
        self.hi + self.lo
    }
    #[inline]
    pub fn sqr(self) -> Dd {
        self * self
    }
    /// Square root (one Newton step from the double-precision root); 0 for `x ≤ 0`.
    pub fn sqrt(self) -> Dd {
        if !(self.hi > 0.0) {
            return Dd::ZERO;
        }
        let x = self.hi.sqrt();
        let (p, e) = two_prod(x, x);
        let r = (self - Dd { hi: p, lo: e }).f64();
        let (s, t) = quick_two_sum(x, r / (2.0 * x));
        Dd { hi: s, lo: t }
    }
    #[inline]
    pub fn abs(self) -> Dd {
        if self.hi < 0.0 {
            -self
        } else {
            self
        }
    }
}

/// `ln 2` as a double-double (QD library constant).
const LN2: Dd = Dd {
    hi: std::f64::consts::LN_2,
    lo: 2.319_046_813_846_299_6e-17,
};

/// Transcendental functions in double-double (relative accuracy ~1e-31 for the arguments
/// the layout and the metric polish use, |x| ≲ 50; tested against known digits and identities): `exp`
/// by argument reduction `x = k ln 2 + 2⁹ r` and a Taylor series of `e^r`, squared nine
/// times; `ln` by one Newton step on `exp` from the double-precision logarithm (which
/// doubles the number of correct digits); `sinh` by its Taylor series below 1/2 (no
/// cancellation near 0) and by `(eˣ − e⁻ˣ)/2` above; `asinh` by one Newton step on `sinh`.
impl Dd {
    /// `eˣ` (∞ above ~709, 0 below ~−745).
    pub fn exp(self) -> Dd {
        if !self.hi.is_finite() {
            return Dd::new(self.hi.exp());
        }
        if self.hi > 709.0 {
            return Dd::new(f64::INFINITY);
        }
        if self.hi < -745.0 {
            return Dd::ZERO;
        }
        let k = (self.hi / LN2.hi).round();
        let r = self - LN2 * Dd::new(k);
        // e^r = (e^{r/512})^512; the series of e^s with |s| < 7e-4 needs 10 terms.
        let s = r * Dd::new(1.0 / 512.0);
        let mut term = s;
        let mut sum = s;
        for n in 2..=12 {
            term = term * s / Dd::new(n as f64);
            sum = sum + term;
            if term.hi.abs() < 1e-36 {
                break;
            }
        }
        // (1 + sum)^512 via squaring expm1: (1 + x)² − 1 = 2x + x².
        for _ in 0..9 {
            sum = sum * Dd::new(2.0) + sum.sqr();
        }
        let e = sum + Dd::ONE;
        let f = 2f64.powi(k as i32);
        Dd {
            hi: e.hi * f,
            lo: e.lo * f,
        }
    }
    /// Natural logarithm; NaN for `x < 0`, −∞ at 0.
    pub fn ln(self) -> Dd {
        if !(self.hi > 0.0) || !self.hi.is_finite() {
            return Dd::new(self.hi.ln());
        }
        let y = Dd::new(self.hi.ln());
        // y + x e^{−y} − 1
        y + self * (-y).exp() - Dd::ONE
    }
    /// Hyperbolic sine.
    pub fn sinh(self) -> Dd {
        if self.hi.abs() < 0.5 {
            let x2 = self.sqr();
            let mut term = self;
            let mut sum = self;
            for n in 1..30 {
                term = term * x2 / Dd::new(((2 * n) * (2 * n + 1)) as f64);
                sum = sum + term;
                if term.hi.abs() < 1e-34 * sum.hi.abs() {
                    break;
                }
            }
            return sum;
        }
        let e = self.exp();
        (e - Dd::ONE / e) * Dd::new(0.5)
    }
    /// Hyperbolic cosine.
    pub fn cosh(self) -> Dd {
        let e = self.exp();
        (e + Dd::ONE / e) * Dd::new(0.5)
    }
    /// Inverse hyperbolic sine (one Newton step on [`Dd::sinh`] from the double-precision
    /// value).
    pub fn asinh(self) -> Dd {
        let y = Dd::new(self.hi.asinh());
        let c = y.cosh();
        y + (self - y.sinh()) / c
    }
    /// `tanh(x)` as `sinh x / cosh x` (relative accuracy ~1e-31 also near 0).
    pub fn tanh(self) -> Dd {
        if self.hi.abs() > 40.0 {
            return Dd::new(self.hi.signum());
        }
        self.sinh() / self.cosh()
    }
}

impl From<f64> for Dd {
    fn from(x: f64) -> Dd {
        Dd::new(x)
    }
}

impl Add for Dd {
    type Output = Dd;
    #[inline]
    fn add(self, b: Dd) -> Dd {
        let (s, e) = two_sum(self.hi, b.hi);
        let (t, f) = two_sum(self.lo, b.lo);
        let (s, e) = quick_two_sum(s, e + t);
        let (hi, lo) = quick_two_sum(s, e + f);
        Dd { hi, lo }
    }
}
impl Neg for Dd {
    type Output = Dd;
    #[inline]
    fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}
impl Sub for Dd {
    type Output = Dd;
    #[inline]
    fn sub(self, b: Dd) -> Dd {
        self + (-b)
    }
}
impl Mul for Dd {
    type Output = Dd;
    #[inline]
    fn mul(self, b: Dd) -> Dd {
        let (p, e) = two_prod(self.hi, b.hi);
        let e = e + (self.hi * b.lo + self.lo * b.hi);
        let (hi, lo) = quick_two_sum(p, e);
        Dd { hi, lo }
    }
}
impl Div for Dd {
    type Output = Dd;
    /// Long division with three quotient digits.
    fn div(self, b: Dd) -> Dd {
        let q1 = self.hi / b.hi;
        let r = self - b * Dd::new(q1);
        let q2 = r.hi / b.hi;
        let r = r - b * Dd::new(q2);
        let q3 = r.hi / b.hi;
        let (s, e) = quick_two_sum(q1, q2);
        Dd { hi: s, lo: e } + Dd::new(q3)
    }
}

/// A complex number with double-double parts.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Cdd {
    pub re: Dd,
    pub im: Dd,
}

impl Cdd {
    pub const ZERO: Cdd = Cdd {
        re: Dd::ZERO,
        im: Dd::ZERO,
    };
    pub const ONE: Cdd = Cdd {
        re: Dd::ONE,
        im: Dd::ZERO,
    };
    /// `hi + lo` from two double-precision complex numbers.
    #[inline]
    pub fn from_parts(hi: Complex, lo: Complex) -> Cdd {
        Cdd {
            re: Dd::new(hi.re) + Dd::new(lo.re),
            im: Dd::new(hi.im) + Dd::new(lo.im),
        }
    }
    /// The leading parts.
    #[inline]
    pub fn hi(self) -> Complex {
        Complex::new(self.re.hi, self.im.hi)
    }
    /// The trailing parts (`self ≈ hi() + lo()` to ~32 digits).
    #[inline]
    pub fn lo(self) -> Complex {
        Complex::new(self.re.lo, self.im.lo)
    }
    #[inline]
    pub fn conj(self) -> Cdd {
        Cdd {
            re: self.re,
            im: -self.im,
        }
    }
    #[inline]
    pub fn norm_sqr(self) -> Dd {
        self.re.sqr() + self.im.sqr()
    }
    #[inline]
    pub fn norm(self) -> Dd {
        self.norm_sqr().sqrt()
    }
    #[inline]
    pub fn scale(self, s: Dd) -> Cdd {
        Cdd {
            re: self.re * s,
            im: self.im * s,
        }
    }
    pub fn inv(self) -> Cdd {
        let n = self.norm_sqr();
        Cdd {
            re: self.re / n,
            im: -self.im / n,
        }
    }
}

impl From<Complex> for Cdd {
    fn from(z: Complex) -> Cdd {
        Cdd {
            re: Dd::new(z.re),
            im: Dd::new(z.im),
        }
    }
}
impl Add for Cdd {
    type Output = Cdd;
    #[inline]
    fn add(self, b: Cdd) -> Cdd {
        Cdd {
            re: self.re + b.re,
            im: self.im + b.im,
        }
    }
}
impl Sub for Cdd {
    type Output = Cdd;
    #[inline]
    fn sub(self, b: Cdd) -> Cdd {
        Cdd {
            re: self.re - b.re,
            im: self.im - b.im,
        }
    }
}
impl Neg for Cdd {
    type Output = Cdd;
    #[inline]
    fn neg(self) -> Cdd {
        Cdd {
            re: -self.re,
            im: -self.im,
        }
    }
}
impl Mul for Cdd {
    type Output = Cdd;
    #[inline]
    fn mul(self, b: Cdd) -> Cdd {
        Cdd {
            re: self.re * b.re - self.im * b.im,
            im: self.re * b.im + self.im * b.re,
        }
    }
}
impl Div for Cdd {
    type Output = Cdd;
    fn div(self, b: Cdd) -> Cdd {
        let n = b.norm_sqr();
        let p = self * b.conj();
        Cdd {
            re: p.re / n,
            im: p.im / n,
        }
    }
}

/// Hyperbolic distance between two points of the Poincaré disk given in double-double,
/// `2 asinh(|p − q| / √((1 − |p|²)(1 − |q|²)))`; the ratio is formed in double-double, so
/// the result is accurate to ~1e-16 relative wherever the points are.
pub fn disk_distance_dd(p: Cdd, q: Cdd) -> f64 {
    let den = (Dd::ONE - p.norm_sqr()) * (Dd::ONE - q.norm_sqr());
    if !(den.hi > 0.0) {
        return f64::INFINITY;
    }
    2.0 * ((p - q).norm() / den.sqrt()).f64().asinh()
}

/// Orientation of the disk triangle `(a, b, c)` (positive counter-clockwise), evaluated after
/// moving `a` to the centre, in double-double.
pub fn disk_orientation_dd(a: Cdd, b: Cdd, c: Cdd) -> f64 {
    let wb = (b - a) / (Cdd::ONE - a.conj() * b);
    let wc = (c - a) / (Cdd::ONE - a.conj() * c);
    (wb.conj() * wc).im.f64()
}

/// `z ↦ (a z + b)/(b̄ z + ā)` with double-double coefficients, `|a|² − |b|² = 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MobiusDd {
    pub a: Cdd,
    pub b: Cdd,
}

impl From<Mobius> for MobiusDd {
    fn from(m: Mobius) -> MobiusDd {
        MobiusDd {
            a: m.a.into(),
            b: m.b.into(),
        }
    }
}

impl MobiusDd {
    pub const IDENTITY: MobiusDd = MobiusDd {
        a: Cdd::ONE,
        b: Cdd::ZERO,
    };
    /// Rounded to a double-precision Möbius map (renormalized).
    pub fn round(&self) -> Mobius {
        let m = Mobius {
            a: self.a.hi() + self.a.lo(),
            b: self.b.hi() + self.b.lo(),
        };
        Mobius::new(m.a, m.b).unwrap_or(m)
    }
    #[inline]
    pub fn compose(&self, o: &MobiusDd) -> MobiusDd {
        MobiusDd {
            a: self.a * o.a + self.b * o.b.conj(),
            b: self.a * o.b + self.b * o.a.conj(),
        }
    }
    #[inline]
    pub fn inverse(&self) -> MobiusDd {
        MobiusDd {
            a: self.a.conj(),
            b: -self.b,
        }
    }
    #[inline]
    pub fn apply(&self, z: Cdd) -> Cdd {
        (self.a * z + self.b) / (self.b.conj() * z + self.a.conj())
    }
    /// Scaled back onto `|a|² − |b|² = 1` (unchanged if the determinant is not positive).
    pub fn normalized(&self) -> MobiusDd {
        let det = self.a.norm_sqr() - self.b.norm_sqr();
        if !(det.hi > 0.0) || !det.hi.is_finite() {
            return *self;
        }
        let s = Dd::ONE / det.sqrt();
        MobiusDd {
            a: self.a.scale(s),
            b: self.b.scale(s),
        }
    }
    /// `z ↦ (z − p)/(1 − p̄ z)`.
    pub fn to_origin(p: Cdd) -> MobiusDd {
        let s = Dd::ONE / (Dd::ONE - p.norm_sqr()).sqrt();
        MobiusDd {
            a: Cdd {
                re: s,
                im: Dd::ZERO,
            },
            b: (-p).scale(s),
        }
    }
    /// The frame of paper 001 §V (τ): `p ↦ 0` and `q` onto the positive real axis; also
    /// returns `|τ(q)|`.
    fn frame(p: Cdd, q: Cdd) -> (MobiusDd, Dd) {
        let t = MobiusDd::to_origin(p);
        let w = t.apply(q);
        let r = w.norm();
        if !(r.hi > 0.0) {
            return (t, Dd::ZERO);
        }
        // Rotation z ↦ ū z (u = w/|w|) as [[c̄, 0], [0, c]] with c² = u: c = (1 + u)/|1 + u|.
        let u = Cdd {
            re: w.re / r,
            im: w.im / r,
        };
        let s = Cdd::ONE + u;
        let c = if s.norm_sqr().hi > 1e-12 {
            s.scale(Dd::ONE / s.norm())
        } else {
            // u ≈ −1: c ≈ ±i; one Newton step for √u from i.
            let i = Cdd {
                re: Dd::ZERO,
                im: Dd::ONE,
            };
            let half = Dd::new(0.5);
            (i + u / i).scale(half)
        };
        let rot = MobiusDd {
            a: c.conj(),
            b: Cdd::ZERO,
        };
        (rot.compose(&t), r)
    }
    /// The map taking `p0 ↦ p1` and the direction towards `q0` onto the direction towards
    /// `q1`, splitting a length mismatch evenly (same construction as
    /// [`super::Isometry::from_pairs`] for [`Mobius`], τ₁⁻¹∘shift∘τ₀, in double-double).
    pub fn from_pairs(p0: Cdd, q0: Cdd, p1: Cdd, q1: Cdd) -> MobiusDd {
        let (t0, r0) = MobiusDd::frame(p0, q0);
        let (t1, r1) = MobiusDd::frame(p1, q1);
        // Half the length mismatch, atanh r1 − atanh r0 = atanh((r1 − r0)/(1 − r0 r1)), with
        // the ratio in double-double (the mismatch is tiny when both pairs are isometric).
        let den = Dd::ONE - r0 * r1;
        let half = if den.hi > 0.0 {
            ((r1 - r0) / den)
                .f64()
                .clamp(-1.0 + f64::EPSILON, 1.0 - f64::EPSILON)
                .atanh()
        } else {
            let d0 = r0.f64().min(1.0 - f64::EPSILON).atanh();
            let d1 = r1.f64().min(1.0 - f64::EPSILON).atanh();
            d1 - d0
        };
        let shift = MobiusDd::from(Mobius::real_translation(half));
        t1.inverse().compose(&shift).compose(&t0).normalized()
    }
    /// Frobenius distance `min(|M₁ − M₂|, |M₁ + M₂|)` (±M act alike), evaluated in
    /// double-double.
    pub fn distance(&self, o: &MobiusDd) -> f64 {
        let d1 = (self.a - o.a).norm_sqr() + (self.b - o.b).norm_sqr();
        let d2 = (self.a + o.a).norm_sqr() + (self.b + o.b).norm_sqr();
        let d = if d1.hi < d2.hi { d1 } else { d2 };
        (2.0 * d.f64()).sqrt()
    }
    /// Coordinates `(α, β)` of `X` with `self⁻¹ ∘ other = exp X`, `X = [[iα, β], [β̄, −iα]]`,
    /// to first order (the two maps must be close).
    pub fn log_difference(&self, other: &MobiusDd) -> [f64; 3] {
        let mut d = self.inverse().compose(other);
        if d.a.re.hi < 0.0 {
            d = MobiusDd { a: -d.a, b: -d.b };
        }
        [d.a.im.f64(), d.b.re.f64(), d.b.im.f64()]
    }
    /// `self ∘ exp X` for a small Lie-algebra element `X = (α, β)` (second-order series, so
    /// `|X|` below ~1e-5 keeps the result exact to double-double rounding after
    /// normalization); larger steps go through the double-precision exponential.
    pub fn exp_step(&self, x: [f64; 3]) -> MobiusDd {
        let s2 = x[1] * x[1] + x[2] * x[2] - x[0] * x[0];
        let step = if x.iter().all(|v| v.abs() < 1e-5) {
            // exp X = cosh(√s2) I + sinh(√s2)/√s2 · X ≈ (1 + s2/2) I + (1 + s2/6) X.
            let sh = Dd::ONE + Dd::new(s2 / 6.0);
            MobiusDd {
                a: Cdd {
                    re: Dd::ONE + Dd::new(0.5 * s2),
                    im: Dd::new(x[0]) * sh,
                },
                b: Cdd {
                    re: Dd::new(x[1]) * sh,
                    im: Dd::new(x[2]) * sh,
                },
            }
        } else {
            MobiusDd::from(Mobius::exp_algebra(x[0], Complex::new(x[1], x[2])))
        };
        self.compose(&step).normalized()
    }
}

impl MobiusDd {
    /// `exp X` for a Lie-algebra element `X = (α, β)` (see [`MobiusDd::exp_step`]).
    pub fn exp(x: [f64; 3]) -> MobiusDd {
        MobiusDd::IDENTITY.exp_step(x)
    }

    /// Least-squares fit of `x_i ↦ y_i`: Gauss–Newton on `Σ w_i² |M(x_i) − y_i|²` with
    /// `w_i = 2/(1 − |y_i|²)` (the disk metric at `y_i`, so the residuals are hyperbolic
    /// displacements to first order), steps `M ← exp(ξ) M` in su(1,1), started from
    /// [`MobiusDd::from_pairs`] on the first pair and the pair farthest from it. The targets
    /// are first moved near the origin (an isometry, which leaves the objective unchanged)
    /// and the residuals are formed in double-double; the Jacobian only needs double
    /// precision. Stops when the step is below 1e-28, when it stops shrinking (the residual
    /// floor of the data) or after 40 iterations. Fails with fewer than two distinct points.
    pub fn fit(pairs: &[(Cdd, Cdd)]) -> crate::error::Result<MobiusDd> {
        use crate::error::Error;
        if pairs.len() < 2 {
            return Err(Error::numerical(
                "a Möbius transformation needs at least two point pairs to be fitted",
            ));
        }
        let (x0, y0) = pairs[0];
        let far = pairs
            .iter()
            .max_by(|p, q| disk_distance_dd(x0, p.0).total_cmp(&disk_distance_dd(x0, q.0)))
            .copied()
            .unwrap_or(pairs[1]);
        if !(disk_distance_dd(x0, far.0) > 0.0) {
            return Err(Error::numerical(
                "cannot fit a Möbius transformation: the points coincide",
            ));
        }
        let centre = MobiusDd::to_origin(pairs[pairs.len() / 2].1);
        let targets: Vec<Cdd> = pairs.iter().map(|p| centre.apply(p.1)).collect();
        let mut m = centre.compose(&MobiusDd::from_pairs(x0, far.0, y0, far.1));
        let mut last = f64::INFINITY;
        for _ in 0..40 {
            let mut jtj = [[0.0f64; 3]; 3];
            let mut jtr = [0.0f64; 3];
            for (&(x, _), &y) in pairs.iter().zip(&targets) {
                let wd = m.apply(x);
                let wt = 2.0 / (Dd::ONE - y.norm_sqr()).f64().max(1e-300);
                let d = wd - y;
                let r = Complex::new(d.re.f64(), d.im.f64()) * wt;
                let w = wd.hi();
                let one = Complex::new(1.0, 0.0);
                let cols = [
                    Complex::new(0.0, 2.0) * w * wt,
                    (one - w * w) * wt,
                    Complex::new(0.0, 1.0) * (one + w * w) * wt,
                ];
                for i in 0..3 {
                    jtr[i] += cols[i].re * r.re + cols[i].im * r.im;
                    for j in 0..3 {
                        jtj[i][j] += cols[i].re * cols[j].re + cols[i].im * cols[j].im;
                    }
                }
            }
            let xi = super::isometry::solve3(jtj, [-jtr[0], -jtr[1], -jtr[2]])?;
            let size = xi.iter().map(|v| v.abs()).fold(0.0, f64::max);
            m = MobiusDd::exp(xi).compose(&m).normalized();
            if size < 1e-28 || size > 0.5 * last {
                break;
            }
            last = size;
        }
        Ok(centre.inverse().compose(&m).normalized())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::isometry::Isometry;

    #[test]
    fn double_double_operations_are_exact_to_32_digits() {
        // (1 + 2^-60)² = 1 + 2^-59 + 2^-120: the square keeps the 2^-59 term that f64 loses.
        let x = Dd::ONE + Dd::new(2f64.powi(-60));
        let y = x * x;
        assert_eq!(y.hi, 1.0);
        assert_eq!(y.lo, 2f64.powi(-59));
        // 1/3 · 3 = 1 and √2² = 2 to ~1e-32.
        let third = Dd::ONE / Dd::new(3.0);
        assert!(((third * Dd::new(3.0)) - Dd::ONE).f64().abs() < 1e-31);
        let r = Dd::new(2.0).sqrt();
        assert!((r * r - Dd::new(2.0)).f64().abs() < 1e-31);
        // The low part of 1/3 is what f64 drops: 1/3 − fl(1/3).
        let r = -(3.0f64).mul_add(1.0 / 3.0, -1.0); // 1 − 3·fl(1/3), exactly
        assert!((third.lo - r / 3.0).abs() < 1e-40);
    }

    /// A decimal string read in double-double (digit by digit; ~1e-32 relative).
    fn parse(s: &str) -> Dd {
        let (int, frac) = s.split_once('.').unwrap_or((s, ""));
        let mut v = Dd::ZERO;
        for c in int.chars().chain(frac.chars()) {
            v = v * Dd::new(10.0) + Dd::new(c.to_digit(10).unwrap() as f64);
        }
        let mut p = Dd::ONE;
        for _ in 0..frac.len() {
            p = p * Dd::new(10.0);
        }
        v / p
    }

    fn rel(a: Dd, b: Dd) -> f64 {
        ((a - b).f64() / b.f64()).abs()
    }

    #[test]
    fn double_double_transcendentals_match_known_digits_and_identities() {
        // Known digits (40 significant): e, ln 10, sinh 1, asinh 1 = ln(1 + √2), tanh ½.
        let e = parse("2.718281828459045235360287471352662497757");
        assert!(rel(Dd::ONE.exp(), e) < 1e-31, "{:e}", rel(Dd::ONE.exp(), e));
        let ln10 = parse("2.302585092994045684017991454684364207601");
        assert!(rel(Dd::new(10.0).ln(), ln10) < 1e-31);
        let sinh1 = parse("1.175201193643801456882381850595600815156");
        assert!(rel(Dd::ONE.sinh(), sinh1) < 1e-31);
        let asinh1 = parse("0.8813735870195430252326093249797923090282");
        assert!(rel(Dd::ONE.asinh(), asinh1) < 1e-31);
        let tanh_half = parse("0.4621171572600097585023184836436725487302");
        assert!(rel(Dd::new(0.5).tanh(), tanh_half) < 1e-31);
        // Small arguments keep their relative accuracy (series, no cancellation):
        // sinh x = x + x³/6 + x⁵/120 for x = 1e-6 to 1e-40.
        let x = Dd::new(1e-6);
        let want = x + x * x * x / Dd::new(6.0) + x.sqr().sqr() * x / Dd::new(120.0);
        assert!(rel(x.sinh(), want) < 1e-31);
        assert!(rel(x.asinh().sinh(), x) < 1e-31);
        // Identities over a range of arguments (both branches of sinh, large and negative x).
        for &v in &[-7.3, -0.49, -1e-3, 1e-9, 0.3, 0.5, 0.77, 2.0, 13.0, 41.5] {
            let x = Dd::new(v) + Dd::new(v * 1e-17);
            let (s, c) = (x.sinh(), x.cosh());
            let one = c.sqr() - s.sqr();
            assert!(
                ((one - Dd::ONE).f64() / c.sqr().f64()).abs() < 1e-30,
                "cosh² − sinh² at {v}"
            );
            // ln near 1 is limited by the absolute resolution of eˣ (~1e-32).
            let err = (x.exp().ln() - x).f64().abs();
            assert!(err < 1e-30 * v.abs().max(1.0), "ln(exp) at {v}");
            assert!(rel(x.asinh().sinh(), x) < 1e-30, "sinh(asinh) at {v}");
            assert!(rel(x.sinh().asinh(), x) < 1e-30, "asinh(sinh) at {v}");
            let y = Dd::new(0.37);
            assert!(
                rel((x + y).exp(), x.exp() * y.exp()) < 1e-30,
                "exp(x + y) at {v}"
            );
            if v.abs() < 40.0 {
                assert!(rel(x.tanh(), s / c) < 1e-30);
            }
        }
        for &v in &[1e-10, 1e-5, 0.9, 1.0, 3.5, 1e10] {
            let x = Dd::new(v) * (Dd::ONE + Dd::new(3e-17));
            // exp amplifies the absolute rounding of ln x (~1e-32·|ln x|).
            let tol = 1e-31 * (1.0 + v.ln().abs());
            assert!(
                rel(x.ln().exp(), x) < tol,
                "exp(ln) at {v}: {:e}",
                rel(x.ln().exp(), x)
            );
        }
    }

    #[test]
    fn dd_mobius_maps_agree_with_double_precision_ones_and_keep_more_digits() {
        let m1 = Mobius::from_theta_center(0.7, Complex::new(0.3, -0.4));
        let m2 = Mobius::from_theta_center(-1.9, Complex::new(-0.5, 0.2));
        let (d1, d2) = (MobiusDd::from(m1), MobiusDd::from(m2));
        let z = Complex::new(0.1, 0.6);
        let want = m1.compose(&m2).apply(z);
        let got = d1.compose(&d2).apply(z.into());
        assert!((got.hi() - want).norm() < 1e-15);
        // from_pairs reproduces the map from two image pairs, as in double precision.
        let (p, q) = (Complex::new(0.2, 0.1), Complex::new(-0.3, 0.4));
        let f = MobiusDd::from_pairs(p.into(), q.into(), m1.apply(p).into(), m1.apply(q).into());
        assert!(f.round().distance(&m1) < 1e-14);
        // A long product undone factor by factor: with partial products P of size ~e^24 the
        // rounding is ~ε·|P|² (ε = 1e-16 in double precision, all digits lost; 1e-32 in
        // double-double).
        let big = Mobius::real_translation(12.0).compose(&m1);
        let mut p = MobiusDd::IDENTITY;
        let mut pf = Mobius::identity();
        for _ in 0..4 {
            p = p.compose(&MobiusDd::from(big)).normalized();
            pf = pf.compose(&big).normalized();
        }
        let (mut back, mut backf) = (p, pf);
        for _ in 0..4 {
            back = back.compose(&MobiusDd::from(big.inverse())).normalized();
            backf = backf.compose(&big.inverse()).normalized();
        }
        let (e, ef) = (
            back.distance(&MobiusDd::IDENTITY),
            backf.distance(&Mobius::identity()),
        );
        assert!(e < 1e-12 && ef > 1e-3, "double-double {e:e}, double {ef:e}");
        // Least squares far out in the disk: points at distance ~12 (f64 resolution there
        // ~1e-11) are fitted to ~1e-20 in double-double.
        let pairs: Vec<(Cdd, Cdd)> = (0..8)
            .map(|i| {
                let x = MobiusDd::from(Mobius::real_translation(11.0))
                    .apply(Complex::from_polar(0.3, i as f64).into());
                (x, MobiusDd::from(big).apply(x))
            })
            .collect();
        let f = MobiusDd::fit(&pairs).unwrap();
        for &(x, y) in &pairs {
            assert!(disk_distance_dd(f.apply(x), y) < 1e-18);
        }
        // Lie-algebra difference and step are inverse to each other.
        let x = [1e-7, -2e-7, 3e-8];
        let e = d1.exp_step(x);
        let l = d1.log_difference(&e);
        for i in 0..3 {
            assert!((l[i] - x[i]).abs() < 1e-20, "{l:?}");
        }
    }
}
