//! Double-double arithmetic (about 32 significant digits), built from error-free
//! transformations: `two_sum` (Knuth) and `two_prod` through a fused multiply-add
//! (`f64::mul_add`), as in Dekker (1971) and the QD library of Hida, Li and Bailey.
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
//! Here: [`Dd`] (+, −, ×, ÷, √, exp, ln, sinh, asinh) and [`Cdd`] (complex); the Möbius maps
//! in double-double of the hyperbolic layouts are built on them.
//! Other transcendental functions are evaluated in double precision on quantities near the
//! origin, where that is accurate to the last digit.

// `!(x > 0.0)` is used on purpose: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use num_complex::Complex64 as Complex;
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
    /// `self / b` for a double `b` (two quotient digits with the exact remainder, relative
    /// accuracy ~1e-32; no double-double multiplication).
    #[inline]
    pub fn div_f64(self, b: f64) -> Dd {
        let q1 = self.hi / b;
        let (p1, p2) = two_prod(q1, b);
        let (s, e) = two_sum(self.hi, -p1);
        let e = e + self.lo - p2;
        let q2 = (s + e) / b;
        let (hi, lo) = quick_two_sum(q1, q2);
        Dd { hi, lo }
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

/// `1/(2n+1)!` for `n = 0..18` in double-double (each from the previous one by an exact-remainder
/// division, relative error ≲ 1e-31), for the Taylor series of `sinh`.
fn sinh_coefficients() -> &'static [Dd; 18] {
    static C: std::sync::OnceLock<[Dd; 18]> = std::sync::OnceLock::new();
    C.get_or_init(|| {
        let mut c = [Dd::ONE; 18];
        for n in 1..18 {
            c[n] = c[n - 1].div_f64(((2 * n) * (2 * n + 1)) as f64);
        }
        c
    })
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
            term = (term * s).div_f64(n as f64);
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
            return self.sinh_series();
        }
        let e = self.exp();
        (e - Dd::ONE / e) * Dd::new(0.5)
    }
    /// Taylor series of `sinh` (for `|x| < 1/2`: no cancellation near 0), summed by Horner's
    /// rule in `x²` with the coefficients `1/(2n+1)!` in double-double, from the first term
    /// below `1e-34` of the sum (at most 14 terms at `|x| = 1/2`).
    fn sinh_series(self) -> Dd {
        let c = sinh_coefficients();
        let x2 = self.sqr();
        let a = x2.hi.abs();
        // Highest term kept: the first n with c_n·x^{2n} < 1e-34 (bounded by the table).
        let mut n = 1;
        let mut t = a * c[1].hi;
        while n + 1 < c.len() && t >= 1e-34 {
            n += 1;
            t *= a * c[n].hi / c[n - 1].hi;
        }
        let mut sum = c[n];
        for k in (0..n).rev() {
            sum = sum * x2 + c[k];
        }
        self * sum
    }
    /// `(sinh x, cosh x)` with one exponential (below 1/2: the series of `sinh` and
    /// `cosh = √(1 + sinh²)`, which has no cancellation there).
    pub fn sinh_cosh(self) -> (Dd, Dd) {
        if self.hi.abs() < 0.5 {
            let s = self.sinh_series();
            return (s, (Dd::ONE + s.sqr()).sqrt());
        }
        let e = self.exp();
        let inv = Dd::ONE / e;
        ((e - inv) * Dd::new(0.5), (e + inv) * Dd::new(0.5))
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
        let (s, c) = y.sinh_cosh();
        y + (self - s) / c
    }
    /// `tanh(x)` as `sinh x / cosh x` (relative accuracy ~1e-31 also near 0).
    pub fn tanh(self) -> Dd {
        if self.hi.abs() > 40.0 {
            return Dd::new(self.hi.signum());
        }
        let (s, c) = self.sinh_cosh();
        s / c
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
#[cfg(test)]
mod tests {
    use super::*;

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
}
