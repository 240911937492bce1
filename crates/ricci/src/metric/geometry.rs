//! The three background geometries of discrete Ricci flow (paper 001 §IV): Euclidean E²
//! (curvature 0), hyperbolic H² (−1) and spherical S² (+1).
//!
//! Code that differs per geometry (cosine laws, areas, later their derivatives and layouts) is
//! written once against the [`Background`] trait; the runtime [`Geometry`] enum picks the
//! implementation once at the top (`match g { Geometry::Euclidean => f::<Euclidean>(), … }`).
//!
//! Notation (docs/DESIGN.md §3): `s(x), c(x)` are `x, 1` (E²), `sinh x, cosh x` (H²),
//! `sin x, cos x` (S²).

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::fmt;
use std::str::FromStr;

/// Background geometry chosen at run time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Geometry {
    Euclidean,
    Hyperbolic,
    Spherical,
}

impl Geometry {
    /// Gaussian curvature λ of the background (0, −1, +1), as in Gauss–Bonnet
    /// `Σ K_i + λ·Area = 2πχ`.
    pub fn curvature(self) -> f64 {
        match self {
            Geometry::Euclidean => 0.0,
            Geometry::Hyperbolic => -1.0,
            Geometry::Spherical => 1.0,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Geometry::Euclidean => "euclidean",
            Geometry::Hyperbolic => "hyperbolic",
            Geometry::Spherical => "spherical",
        }
    }
    /// Corner angle opposite side `a` (see [`Background::angle`]).
    pub fn angle(self, a: f64, b: f64, c: f64) -> f64 {
        match self {
            Geometry::Euclidean => Euclidean::angle(a, b, c),
            Geometry::Hyperbolic => Hyperbolic::angle(a, b, c),
            Geometry::Spherical => Spherical::angle(a, b, c),
        }
    }
    /// Side opposite the angle `theta` enclosed by sides `b` and `c`.
    pub fn side(self, b: f64, c: f64, theta: f64) -> f64 {
        match self {
            Geometry::Euclidean => Euclidean::side(b, c, theta),
            Geometry::Hyperbolic => Hyperbolic::side(b, c, theta),
            Geometry::Spherical => Spherical::side(b, c, theta),
        }
    }
    /// Area of the triangle with sides `a, b, c`.
    pub fn area(self, a: f64, b: f64, c: f64) -> f64 {
        match self {
            Geometry::Euclidean => Euclidean::area(a, b, c),
            Geometry::Hyperbolic => Hyperbolic::area(a, b, c),
            Geometry::Spherical => Spherical::area(a, b, c),
        }
    }
}

impl fmt::Display for Geometry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Geometry {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "euclidean" | "e2" | "flat" => Ok(Geometry::Euclidean),
            "hyperbolic" | "h2" => Ok(Geometry::Hyperbolic),
            "spherical" | "s2" => Ok(Geometry::Spherical),
            _ => Err(format!(
                "unknown geometry '{s}' (expected euclidean, hyperbolic or spherical)"
            )),
        }
    }
}

/// A background geometry at compile time.
pub trait Background: Copy + Send + Sync + 'static {
    const KIND: Geometry;
    /// `x`, `sinh x`, `sin x`.
    fn s(x: f64) -> f64;
    /// `1`, `cosh x`, `cos x`.
    fn c(x: f64) -> f64;

    /// Corner angle opposite side `a` in the triangle with sides `a, b, c`, by the half-angle
    /// form of the cosine law, `tan²(θ/2) = s(σ−b)s(σ−c) / (s(σ)s(σ−a))` with σ the
    /// semi-perimeter, which is accurate for small and large angles alike. Degenerate
    /// triangles get the continuous extension: θ = π if `a ≥ b + c`, θ = 0 if `b ≥ a + c` or
    /// `c ≥ a + b`.
    #[inline]
    fn angle(a: f64, b: f64, c: f64) -> f64 {
        let sig = 0.5 * (a + b + c);
        let (sa, sb, sc) = (sig - a, sig - b, sig - c);
        if sa <= 0.0 {
            return PI;
        }
        if sb <= 0.0 || sc <= 0.0 {
            return 0.0;
        }
        let den = Self::s(sig) * Self::s(sa);
        if den <= 0.0 {
            // Spherical triangles with perimeter ≥ 2π: fall back to the cosine law.
            return Self::angle_cosine_law(a, b, c);
        }
        2.0 * ((Self::s(sb) * Self::s(sc) / den).max(0.0)).sqrt().atan()
    }

    /// Corner angle by the plain cosine law (clamped), for reference and fallbacks.
    fn angle_cosine_law(a: f64, b: f64, c: f64) -> f64;

    /// Side opposite the angle `theta` enclosed by sides `b` and `c`.
    fn side(b: f64, c: f64, theta: f64) -> f64;

    /// Area of the triangle with sides `a, b, c` (Heron; angle defect / excess).
    fn area(a: f64, b: f64, c: f64) -> f64;

    // ----- conformal structure helpers (paper 001 eq. 9, 12; docs/DESIGN.md §3) -----

    /// Circle radius γ of the circle-packing variable `u` (paper 001 eq. 9): E² `u = log γ`,
    /// H² `u = log tanh(γ/2)` (defined for `u < 0` only; NaN otherwise), S² `u = log tan(γ/2)`.
    fn radius_of_variable(u: f64) -> f64;

    /// Inverse of [`Background::radius_of_variable`].
    fn variable_of_radius(gamma: f64) -> f64;

    /// `s(l/2)` of a length `l` (the "half-length sine": `l/2`, `sinh(l/2)`, `sin(l/2)`).
    #[inline]
    fn half_sine(l: f64) -> f64 {
        Self::s(0.5 * l)
    }

    /// Inverse of [`Background::half_sine`]: the length `l` with `s(l/2) = x` (NaN when no
    /// such length exists, i.e. `x > 1` on the sphere).
    fn length_of_half_sine(x: f64) -> f64;

    /// `s(l/2) / c(l/2)`: the derivative `dl/du_i` of vertex scaling
    /// `s(l/2) = e^{(u_i+u_j)/2} s(l⁰/2)`.
    #[inline]
    fn half_tangent(l: f64) -> f64 {
        Self::s(0.5 * l) / Self::c(0.5 * l)
    }

    /// Length of the edge between circles of radii `gi, gj` meeting with "cosine" `eta`
    /// (`cos φ` for Thurston packings, the inversive distance `I` for inversive packings), by
    /// the cosine law of paper 001 eq. 12 written without cancellation:
    /// `s(l/2)² = s((γi − γj)/2)² + ½ s(γi) s(γj) (1 + η)`. NaN when no such length exists.
    fn circle_packing_length(gi: f64, gj: f64, eta: f64) -> f64;

    /// Inverse of [`Background::circle_packing_length`] in `eta`: the coefficient that makes
    /// circles of radii `gi, gj` produce length `l`.
    fn circle_packing_coefficient(gi: f64, gj: f64, l: f64) -> f64 {
        let x = Self::half_sine(l);
        let d = Self::s(0.5 * (gi - gj));
        2.0 * (x * x - d * d) / (Self::s(gi) * Self::s(gj)) - 1.0
    }
}

#[derive(Debug, Clone, Copy, Default)]
pub struct Euclidean;
#[derive(Debug, Clone, Copy, Default)]
pub struct Hyperbolic;
#[derive(Debug, Clone, Copy, Default)]
pub struct Spherical;

impl Background for Euclidean {
    const KIND: Geometry = Geometry::Euclidean;
    #[inline]
    fn s(x: f64) -> f64 {
        x
    }
    #[inline]
    fn c(_: f64) -> f64 {
        1.0
    }
    fn angle_cosine_law(a: f64, b: f64, c: f64) -> f64 {
        ((b * b + c * c - a * a) / (2.0 * b * c))
            .clamp(-1.0, 1.0)
            .acos()
    }
    fn side(b: f64, c: f64, theta: f64) -> f64 {
        // a² = (b − c)² + 4bc sin²(θ/2): no cancellation for small θ.
        let h = (0.5 * theta).sin();
        ((b - c) * (b - c) + 4.0 * b * c * h * h).max(0.0).sqrt()
    }
    fn radius_of_variable(u: f64) -> f64 {
        u.exp()
    }
    fn variable_of_radius(gamma: f64) -> f64 {
        gamma.ln()
    }
    fn length_of_half_sine(x: f64) -> f64 {
        2.0 * x
    }
    fn circle_packing_length(gi: f64, gj: f64, eta: f64) -> f64 {
        let d = gi - gj;
        let l2 = d * d + 2.0 * gi * gj * (1.0 + eta);
        if l2 >= 0.0 {
            l2.sqrt()
        } else {
            f64::NAN
        }
    }
    fn area(a: f64, b: f64, c: f64) -> f64 {
        crate::numeric::heron([a, b, c])
    }
}

/// Area of a hyperbolic (`t = tanh`) or spherical (`t = tan`) triangle from its sides by
/// L'Huilier's formula `tan(A/4) = √(t(s/2) t((s−a)/2) t((s−b)/2) t((s−c)/2))`, with the
/// differences formed as in Kahan's Heron formula (sides sorted `a ≥ b ≥ c`:
/// `2(s − a) = c − (a − b)`, …), so it keeps its relative accuracy for tiny and needle
/// triangles, where the angle defect or excess cancels. Sides that violate the triangle
/// inequality (and NaN) give 0.
fn lhuilier(l: [f64; 3], t: fn(f64) -> f64) -> f64 {
    let mut s = l;
    s.sort_by(|a, b| b.total_cmp(a));
    let [a, b, c] = s;
    let (x0, x1, x2, x3) = (a + (b + c), c - (a - b), c + (a - b), a + (b - c));
    if x1.is_nan() || x1 <= 0.0 {
        return 0.0;
    }
    let p = t(0.25 * x0) * t(0.25 * x1) * t(0.25 * x2) * t(0.25 * x3);
    if p > 0.0 {
        4.0 * p.sqrt().atan()
    } else {
        0.0
    }
}

impl Background for Hyperbolic {
    const KIND: Geometry = Geometry::Hyperbolic;
    #[inline]
    fn s(x: f64) -> f64 {
        x.sinh()
    }
    #[inline]
    fn c(x: f64) -> f64 {
        x.cosh()
    }
    fn angle_cosine_law(a: f64, b: f64, c: f64) -> f64 {
        ((b.cosh() * c.cosh() - a.cosh()) / (b.sinh() * c.sinh()))
            .clamp(-1.0, 1.0)
            .acos()
    }
    fn side(b: f64, c: f64, theta: f64) -> f64 {
        // cosh a = cosh(b − c) + 2 sinh b sinh c sin²(θ/2).
        let h = (0.5 * theta).sin();
        let ch = (b - c).cosh() + 2.0 * b.sinh() * c.sinh() * h * h;
        ch.max(1.0).acosh()
    }
    fn area(a: f64, b: f64, c: f64) -> f64 {
        // L'Huilier: tan(A/4)² = Π tanh(x/2) over x = s, s − a, s − b, s − c (the angle
        // defect π − Σθ cancels for small triangles: below ~1e-15 it rounded to ≤ 0).
        lhuilier([a, b, c], f64::tanh)
    }
    fn radius_of_variable(u: f64) -> f64 {
        // γ = 2 atanh(e^u) = log((1 + e^u) / (1 − e^u)).
        if u < 0.0 {
            let t = u.exp();
            (t.ln_1p() - (-t).ln_1p()).max(0.0)
        } else {
            f64::NAN
        }
    }
    fn variable_of_radius(gamma: f64) -> f64 {
        (0.5 * gamma).tanh().ln()
    }
    fn length_of_half_sine(x: f64) -> f64 {
        2.0 * x.asinh()
    }
    fn circle_packing_length(gi: f64, gj: f64, eta: f64) -> f64 {
        let d = (0.5 * (gi - gj)).sinh();
        let x2 = d * d + 0.5 * gi.sinh() * gj.sinh() * (1.0 + eta);
        if x2 >= 0.0 {
            2.0 * x2.sqrt().asinh()
        } else {
            f64::NAN
        }
    }
}

impl Background for Spherical {
    const KIND: Geometry = Geometry::Spherical;
    #[inline]
    fn s(x: f64) -> f64 {
        x.sin()
    }
    #[inline]
    fn c(x: f64) -> f64 {
        x.cos()
    }
    fn angle_cosine_law(a: f64, b: f64, c: f64) -> f64 {
        ((a.cos() - b.cos() * c.cos()) / (b.sin() * c.sin()))
            .clamp(-1.0, 1.0)
            .acos()
    }
    fn side(b: f64, c: f64, theta: f64) -> f64 {
        // cos a = cos(b − c) − 2 sin b sin c sin²(θ/2).
        let h = (0.5 * theta).sin();
        let ca = (b - c).cos() - 2.0 * b.sin() * c.sin() * h * h;
        ca.clamp(-1.0, 1.0).acos()
    }
    fn area(a: f64, b: f64, c: f64) -> f64 {
        // L'Huilier: tan(A/4)² = Π tan(x/2) over x = s, s − a, s − b, s − c.
        lhuilier([a, b, c], f64::tan)
    }
    fn radius_of_variable(u: f64) -> f64 {
        2.0 * u.exp().atan()
    }
    fn variable_of_radius(gamma: f64) -> f64 {
        (0.5 * gamma).tan().ln()
    }
    fn length_of_half_sine(x: f64) -> f64 {
        if x <= 1.0 {
            2.0 * x.asin()
        } else {
            f64::NAN
        }
    }
    fn circle_packing_length(gi: f64, gj: f64, eta: f64) -> f64 {
        // sin²(l/2) = sin²((γi−γj)/2) + ½ sin γi sin γj (1 + η),
        // cos²(l/2) = cos²((γi+γj)/2) + ½ sin γi sin γj (1 − η): atan2 keeps l accurate near 0 and π.
        let p = 0.5 * gi.sin() * gj.sin();
        let d = (0.5 * (gi - gj)).sin();
        let e = (0.5 * (gi + gj)).cos();
        let x2 = d * d + p * (1.0 + eta);
        let y2 = e * e + p * (1.0 - eta);
        if x2 >= 0.0 && y2 >= 0.0 {
            2.0 * x2.sqrt().atan2(y2.sqrt())
        } else {
            f64::NAN
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check<B: Background>(a: f64, b: f64, c: f64) {
        let t = B::angle(a, b, c);
        let t2 = B::angle_cosine_law(a, b, c);
        assert!((t - t2).abs() < 1e-9, "{:?}: {t} vs {t2}", B::KIND);
        let a2 = B::side(b, c, t);
        assert!(
            (a - a2).abs() < 1e-12 * (1.0 + a),
            "{:?}: side {a} vs {a2}",
            B::KIND
        );
    }

    #[test]
    fn half_angle_agrees_with_cosine_law_and_side_inverts_angle() {
        for &(a, b, c) in &[
            (0.3, 0.4, 0.5),
            (0.1, 0.2, 0.25),
            (0.5, 0.5, 0.5),
            (0.05, 0.9, 0.93),
        ] {
            check::<Euclidean>(a, b, c);
            check::<Hyperbolic>(a, b, c);
            check::<Spherical>(a, b, c);
        }
    }

    #[test]
    fn angle_sums_match_curvature_of_background() {
        // Equilateral triangles: E² sum π; H² less; S² more; area = |π − sum|.
        let l = 0.7;
        let e = 3.0 * Euclidean::angle(l, l, l);
        let h = 3.0 * Hyperbolic::angle(l, l, l);
        let s = 3.0 * Spherical::angle(l, l, l);
        assert!((e - PI).abs() < 1e-14);
        assert!(h < PI && s > PI);
        // Octant of the unit sphere: sides π/2, angles π/2, area π/2.
        let q = PI / 2.0;
        assert!((Spherical::angle(q, q, q) - q).abs() < 1e-12);
        assert!((Spherical::area(q, q, q) - q).abs() < 1e-12);
        assert!((Euclidean::area(3.0, 4.0, 5.0) - 6.0).abs() < 1e-12);
    }

    #[test]
    fn lhuilier_areas_match_the_angle_defect_and_keep_tiny_triangles() {
        // Moderate triangles: the angle defect / excess is accurate there.
        for (a, b, c) in [(0.3, 0.4, 0.5), (1.0, 1.2, 0.7), (2.0, 1.5, 0.9)] {
            let defect = PI
                - Hyperbolic::angle(a, b, c)
                - Hyperbolic::angle(b, c, a)
                - Hyperbolic::angle(c, a, b);
            assert!(
                (Hyperbolic::area(a, b, c) - defect).abs() < 1e-14,
                "{a} {b} {c}"
            );
            let excess =
                Spherical::angle(a, b, c) + Spherical::angle(b, c, a) + Spherical::angle(c, a, b)
                    - PI;
            assert!(
                (Spherical::area(a, b, c) - excess).abs() < 1e-14,
                "{a} {b} {c}"
            );
        }
        // Tiny triangles and needles: the area tends to the Euclidean one (relative
        // correction ~ area), where π − Σθ rounds to 0 or below.
        for l in [
            [3e-8, 4e-8, 5e-8],
            [1e-6, 1e-6, 1e-13],
            [2e-9, 1.5e-9, 1e-9],
        ] {
            let e = Euclidean::area(l[0], l[1], l[2]);
            for got in [
                Hyperbolic::area(l[0], l[1], l[2]),
                Spherical::area(l[0], l[1], l[2]),
            ] {
                assert!(
                    got > 0.0 && ((got - e) / e).abs() < 1e-12,
                    "{l:?}: {got} vs {e}"
                );
            }
        }
        assert_eq!(Hyperbolic::area(3.0, 1.0, 1.0), 0.0);
        assert_eq!(Spherical::area(1.0, 0.2, 0.3), 0.0);
    }

    #[test]
    fn degenerate_triangles_get_the_continuous_extension() {
        assert_eq!(Euclidean::angle(2.0, 1.0, 1.0), PI);
        assert_eq!(Euclidean::angle(1.0, 2.5, 1.0), 0.0);
        assert_eq!(Hyperbolic::angle(3.0, 1.0, 1.0), PI);
    }
}
