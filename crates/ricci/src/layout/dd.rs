//! Möbius maps of the Poincaré disk in double-double, the working precision of hyperbolic
//! layouts and deck groups (paper 001 §VI): [`MobiusDd`] (SU(1,1) maps: composition, inverse,
//! application, normalization, the map between two point pairs, the Lie-algebra difference of
//! two nearby maps), [`disk_distance_dd`], [`disk_orientation_dd`].
//!
//! The arithmetic itself ([`Dd`], [`Cdd`]) lives in [`crate::numeric::dd`], which explains why
//! hyperbolic layouts need it.

// `!(x > 0.0)` is used on purpose: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::isometry::{Complex, Mobius};

use crate::numeric::dd::{Cdd, Dd};

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
    /// Rounded to a double-precision Möbius map, scaled onto `|a|² − |b|² = 1` with the
    /// determinant formed in double-double (unchanged if it is not positive).
    ///
    /// Renormalizing the rounded entries in double precision, as [`Mobius::new`] does, forms
    /// `|a|² − |b|² = 1` from two numbers of size `|a|²` and rescales the entries by
    /// `1 ± 1e-16·|a|²`: a deck generator with `|a| ≈ 2·10³` (botijo's `a3` in the layout's
    /// frame) lost 2e-9 of its translation length `2 acosh|Re a|` that way.
    pub fn round(&self) -> Mobius {
        let m = Mobius {
            a: self.a.hi() + self.a.lo(),
            b: self.b.hi() + self.b.lo(),
        };
        let det = (self.a.norm_sqr() - self.b.norm_sqr()).f64();
        if !(det > 0.0) || !det.is_finite() {
            return m;
        }
        let s = det.sqrt();
        Mobius {
            a: m.a / s,
            b: m.b / s,
        }
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

    /// A hyperbolic element conjugated far out into the disk keeps its translation length
    /// (a conjugation invariant) through the rounding to double precision: the axis of
    /// `T⁻¹ R T` passes at distance 12 from the centre (`|a| ≈ cosh²6 ≈ 4·10⁴`), and the
    /// rounded map's `2 acosh|Re a|` equals `R`'s to 1e-14; renormalizing the rounded entries
    /// in double precision instead loses up to ~1e-16·|a|² of it.
    #[test]
    fn rounding_a_far_map_keeps_its_translation_length() {
        let mut worst_old: f64 = 0.0;
        for (len, angle) in [(1.06, 0.3), (0.91, 2.0), (5.6, -1.2), (2.0, 1.1)] {
            let r = MobiusDd::from(Mobius::real_translation(len)).normalized();
            let want = r.round().translation_length();
            assert!((want - len).abs() < 1e-12, "{want} vs {len}");
            let t = MobiusDd::to_origin(Complex::from_polar((6.0f64).tanh(), angle).into());
            let g = t.inverse().compose(&r).compose(&t).normalized();
            assert!(g.a.hi().norm() > 1e4, "{:?}", g.a.hi());
            let got = g.round().translation_length();
            assert!((got - want).abs() < 1e-14, "{got} vs {want}");
            let old = Mobius::new(g.a.hi(), g.b.hi())
                .unwrap()
                .translation_length();
            worst_old = worst_old.max((old - want).abs());
        }
        assert!(
            worst_old > 1e-12,
            "double renormalization lost only {worst_old:e}"
        );
    }
}
