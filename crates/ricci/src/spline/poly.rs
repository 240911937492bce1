//! Bivariate polynomials and their blossoms (polar forms).
//!
//! The blossom of a polynomial `p` of degree `≤ n`, taken as a polynomial of degree `n`, is the
//! unique symmetric function `f(x_1, …, x_n)` that is affine in each argument and satisfies
//! `f(u, …, u) = p(u)` (Ramshaw; Seidel). For the monomial `X^a Y^b` it is the average over
//! all ways of choosing `a` arguments for `X` and `b` others for `Y`:
//! `f = a! b! (n−a−b)! / n! · e_{a,b}(x_1..x_n)`, where `e_{a,b}` is the coefficient of
//! `s^a t^b` in `Π_i (1 + s X_i + t Y_i)`. DMS control points of a polynomial are blossom
//! values at knots ([`crate::spline::dms`]).
//!
//! Polynomials are stored in a local frame `X = (x − c_x)/s`, `Y = (y − c_y)/s` so that their
//! coefficients stay well scaled for domains far from the origin.

use super::simplex::{n_partials, partial_index, Point};

/// A scalar bivariate polynomial `Σ_{a+b≤n} c_ab X^a Y^b` in the local frame
/// `X = (x − center_x)/scale`, `Y = (y − center_y)/scale`.
#[derive(Debug, Clone, PartialEq)]
pub struct Polynomial {
    degree: usize,
    center: Point,
    scale: f64,
    /// `coeffs[partial_index(a, b)] = c_ab`.
    coeffs: Vec<f64>,
}

impl Polynomial {
    /// The zero polynomial of the given degree in the given frame.
    pub fn zero(degree: usize, center: Point, scale: f64) -> Polynomial {
        Polynomial {
            degree,
            center,
            scale,
            coeffs: vec![0.0; n_partials(degree)],
        }
    }
    /// The monomial `X^a Y^b` (local frame), as a polynomial of degree `degree ≥ a + b`.
    pub fn monomial(degree: usize, a: usize, b: usize, center: Point, scale: f64) -> Polynomial {
        assert!(a + b <= degree);
        let mut p = Polynomial::zero(degree, center, scale);
        p.coeffs[partial_index(a, b)] = 1.0;
        p
    }
    /// Build from coefficients `c[partial_index(a, b)]` of `X^a Y^b`.
    pub fn from_coeffs(degree: usize, center: Point, scale: f64, coeffs: Vec<f64>) -> Polynomial {
        assert_eq!(coeffs.len(), n_partials(degree));
        Polynomial {
            degree,
            center,
            scale,
            coeffs,
        }
    }
    pub fn degree(&self) -> usize {
        self.degree
    }
    pub fn coeffs(&self) -> &[f64] {
        &self.coeffs
    }

    #[inline]
    fn local(&self, u: Point) -> Point {
        [
            (u[0] - self.center[0]) / self.scale,
            (u[1] - self.center[1]) / self.scale,
        ]
    }

    /// Value at `u`.
    pub fn eval(&self, u: Point) -> f64 {
        self.partials(u, 0)[0]
    }

    /// All partial derivatives `∂_x^a ∂_y^b p(u)` with `a + b ≤ order`, in the layout of
    /// [`partial_index`].
    pub fn partials(&self, u: Point, order: usize) -> Vec<f64> {
        let x = self.local(u);
        let n = self.degree;
        let mut out = vec![0.0; n_partials(order)];
        for k in 0..=order {
            for db in 0..=k {
                let da = k - db;
                let mut s = 0.0;
                for tot in 0..=n {
                    for b in 0..=tot {
                        let a = tot - b;
                        if a < da || b < db {
                            continue;
                        }
                        let c = self.coeffs[partial_index(a, b)];
                        if c == 0.0 {
                            continue;
                        }
                        s += c
                            * falling(a, da)
                            * falling(b, db)
                            * x[0].powi((a - da) as i32)
                            * x[1].powi((b - db) as i32);
                    }
                }
                out[partial_index(da, db)] = s / self.scale.powi(k as i32);
            }
        }
        out
    }

    /// The blossom of `p`, viewed as a polynomial of degree `args.len()` (which must be at
    /// least its degree), at the arguments `args`.
    pub fn blossom(&self, args: &[Point]) -> f64 {
        let n = args.len();
        assert!(
            n >= self.degree,
            "blossom needs at least `degree` arguments"
        );
        // e[a][b] = coefficient of s^a t^b in Π (1 + s X_i + t Y_i), truncated at a+b ≤ degree.
        let d = self.degree;
        let mut e = vec![0.0; (d + 1) * (d + 1)];
        e[0] = 1.0;
        for arg in args {
            let x = self.local(*arg);
            for tot in (1..=d).rev() {
                for b in 0..=tot {
                    let a = tot - b;
                    let mut v = e[a * (d + 1) + b];
                    if a > 0 {
                        v += x[0] * e[(a - 1) * (d + 1) + b];
                    }
                    if b > 0 {
                        v += x[1] * e[a * (d + 1) + b - 1];
                    }
                    e[a * (d + 1) + b] = v;
                }
            }
        }
        let mut s = 0.0;
        for tot in 0..=d {
            for b in 0..=tot {
                let a = tot - b;
                let c = self.coeffs[partial_index(a, b)];
                if c != 0.0 {
                    s += c * e[a * (d + 1) + b] / multinomial(n, a, b);
                }
            }
        }
        s
    }
}

/// `a (a−1) ⋯ (a−k+1)`.
fn falling(a: usize, k: usize) -> f64 {
    (0..k).map(|i| (a - i) as f64).product()
}

/// `n! / (a! b! (n−a−b)!)`.
fn multinomial(n: usize, a: usize, b: usize) -> f64 {
    let mut r = 1.0;
    // C(n, a) * C(n − a, b)
    for i in 0..a {
        r = r * (n - i) as f64 / (i + 1) as f64;
    }
    for i in 0..b {
        r = r * (n - a - i) as f64 / (i + 1) as f64;
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blossom_is_diagonal_symmetric_and_multiaffine() {
        let coeffs: Vec<f64> = (0..n_partials(3)).map(|i| (i as f64 * 0.7).sin()).collect();
        let p = Polynomial::from_coeffs(3, [0.5, -0.2], 2.0, coeffs);
        let u = [0.3, 0.8];
        // Diagonal, with the polynomial viewed as degree 3 and as degree 5.
        assert!((p.blossom(&[u; 3]) - p.eval(u)).abs() < 1e-14);
        assert!((p.blossom(&[u; 5]) - p.eval(u)).abs() < 1e-14);
        // Symmetry.
        let a = [[0.1, 0.2], [1.3, -0.4], [0.7, 0.9], [-0.5, 0.3]];
        let f1 = p.blossom(&a);
        let f2 = p.blossom(&[a[2], a[0], a[3], a[1]]);
        assert!((f1 - f2).abs() < 1e-14);
        // Affine in the first argument.
        let (x, y, t) = ([0.2, 0.6], [-1.0, 0.4], 0.3);
        let z = [(1.0 - t) * x[0] + t * y[0], (1.0 - t) * x[1] + t * y[1]];
        let fz = p.blossom(&[z, a[1], a[2], a[3]]);
        let fx = p.blossom(&[x, a[1], a[2], a[3]]);
        let fy = p.blossom(&[y, a[1], a[2], a[3]]);
        assert!((fz - ((1.0 - t) * fx + t * fy)).abs() < 1e-14);
    }

    #[test]
    fn partials_match_finite_differences() {
        let coeffs: Vec<f64> = (0..n_partials(4)).map(|i| (i as f64 * 1.3).cos()).collect();
        let p = Polynomial::from_coeffs(4, [0.1, 0.2], 1.5, coeffs);
        let u = [0.4, -0.3];
        let d = p.partials(u, 2);
        let h = 1e-5;
        let fx = (p.eval([u[0] + h, u[1]]) - p.eval([u[0] - h, u[1]])) / (2.0 * h);
        let fy = (p.eval([u[0], u[1] + h]) - p.eval([u[0], u[1] - h])) / (2.0 * h);
        assert!((fx - d[1]).abs() < 1e-8 && (fy - d[2]).abs() < 1e-8);
        let gx = |v: Point| p.partials(v, 1)[2];
        let fxy = (gx([u[0] + h, u[1]]) - gx([u[0] - h, u[1]])) / (2.0 * h);
        assert!((fxy - d[4]).abs() < 1e-7);
    }
}
