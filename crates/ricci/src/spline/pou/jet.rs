//! Truncated bivariate Taylor polynomials ("jets") of order ≤ 3: the exact partial
//! derivatives of a composition of smooth functions, by the chain rule carried out on the
//! polynomials. The partition-of-unity surface ([`super::surface`]) builds its value and its
//! partials in a chart coordinate `z = x + iy` from jets of `x` and `y`, so the first, second
//! and third derivatives are analytic (no finite differences), and a chart transition is the
//! composition of a jet with the Möbius map's jet ([`compose`]).
//!
//! Coefficients are Taylor coefficients `∂ˣᵃ∂ʸᵇ f / (a! b!)`, stored by total degree:
//! `1, x, y, x², xy, y², x³, x²y, xy², y³`.

use num_complex::Complex64 as C;

/// Highest order a jet carries.
pub const MAX_ORDER: usize = 3;
/// Number of coefficients of a jet of order [`MAX_ORDER`].
pub const N_COEFFS: usize = 10;

/// Number of coefficients (monomials of degree ≤ `order`).
#[inline]
pub fn n_coeffs(order: usize) -> usize {
    (order + 1) * (order + 2) / 2
}

/// Index of the monomial `xᵃ yᵇ`.
#[inline]
pub fn index(a: usize, b: usize) -> usize {
    let k = a + b;
    k * (k + 1) / 2 + b
}

/// The exponents `(a, b)` of coefficient `i`.
#[inline]
pub fn exponents(i: usize) -> (usize, usize) {
    const E: [(usize, usize); N_COEFFS] = [
        (0, 0),
        (1, 0),
        (0, 1),
        (2, 0),
        (1, 1),
        (0, 2),
        (3, 0),
        (2, 1),
        (1, 2),
        (0, 3),
    ];
    E[i]
}

const FACT: [f64; 4] = [1.0, 1.0, 2.0, 6.0];

/// Pairs of monomials `(i, j)` with their product's index `k`, ordered by the product's total
/// degree, so that the pairs of a product truncated at order `n` are the first
/// `PRODUCT_LEN[n]`.
const PRODUCT_PAIRS: usize = 35;
const PRODUCT: [(u8, u8, u8); PRODUCT_PAIRS] = product_table();
const PRODUCT_LEN: [usize; MAX_ORDER + 1] = [1, 5, 15, 35];

const fn product_table() -> [(u8, u8, u8); PRODUCT_PAIRS] {
    const E: [(usize, usize); N_COEFFS] = [
        (0, 0),
        (1, 0),
        (0, 1),
        (2, 0),
        (1, 1),
        (0, 2),
        (3, 0),
        (2, 1),
        (1, 2),
        (0, 3),
    ];
    let mut t = [(0u8, 0u8, 0u8); PRODUCT_PAIRS];
    let mut n = 0;
    let mut deg = 0;
    while deg <= MAX_ORDER {
        let mut i = 0;
        while i < N_COEFFS {
            let mut j = 0;
            while j < N_COEFFS {
                let (a, b) = (E[i].0 + E[j].0, E[i].1 + E[j].1);
                if a + b == deg {
                    let k = (a + b) * (a + b + 1) / 2 + b;
                    t[n] = (i as u8, j as u8, k as u8);
                    n += 1;
                }
                j += 1;
            }
            i += 1;
        }
        deg += 1;
    }
    t
}

/// A bivariate Taylor polynomial truncated at `order`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jet {
    pub c: [f64; N_COEFFS],
    pub order: usize,
}

impl Jet {
    /// The constant `v`.
    #[inline]
    pub fn constant(v: f64, order: usize) -> Jet {
        let mut c = [0.0; N_COEFFS];
        c[0] = v;
        Jet { c, order }
    }
    /// The coordinate `x` (`axis` 0) or `y` (`axis` 1) at the value `v`.
    #[inline]
    pub fn variable(v: f64, axis: usize, order: usize) -> Jet {
        let mut j = Jet::constant(v, order);
        if order >= 1 {
            j.c[1 + axis] = 1.0;
        }
        j
    }
    #[inline]
    pub fn value(&self) -> f64 {
        self.c[0]
    }
    /// The partial derivative `∂ˣᵃ∂ʸᵇ` (0 above the order).
    #[inline]
    pub fn partial(&self, a: usize, b: usize) -> f64 {
        if a + b > self.order {
            return 0.0;
        }
        self.c[index(a, b)] * FACT[a] * FACT[b]
    }
    /// All partials up to the order, in coefficient order.
    pub fn partials(&self) -> Vec<f64> {
        (0..n_coeffs(self.order))
            .map(|i| {
                let (a, b) = exponents(i);
                self.partial(a, b)
            })
            .collect()
    }
    #[inline]
    pub fn add(&self, o: &Jet) -> Jet {
        let mut r = *self;
        for i in 0..n_coeffs(self.order) {
            r.c[i] += o.c[i];
        }
        r
    }
    #[inline]
    pub fn sub(&self, o: &Jet) -> Jet {
        let mut r = *self;
        for i in 0..n_coeffs(self.order) {
            r.c[i] -= o.c[i];
        }
        r
    }
    #[inline]
    pub fn scale(&self, s: f64) -> Jet {
        let mut r = *self;
        for i in 0..n_coeffs(self.order) {
            r.c[i] *= s;
        }
        r
    }
    #[inline]
    pub fn add_const(&self, s: f64) -> Jet {
        let mut r = *self;
        r.c[0] += s;
        r
    }
    /// `self += s · o`.
    #[inline]
    pub fn axpy(&mut self, s: f64, o: &Jet) {
        for i in 0..n_coeffs(self.order) {
            self.c[i] += s * o.c[i];
        }
    }
    /// The truncated product (the pairs of monomials of total degree ≤ the order come from a
    /// table built at compile time).
    #[inline]
    pub fn mul(&self, o: &Jet) -> Jet {
        let n = self.order;
        let mut c = [0.0; N_COEFFS];
        for &(i, j, k) in &PRODUCT[..PRODUCT_LEN[n.min(MAX_ORDER)]] {
            c[k as usize] += self.c[i as usize] * o.c[j as usize];
        }
        Jet { c, order: n }
    }
    /// `f(self)` for a univariate `f` given by its Taylor coefficients `t[k] = f⁽ᵏ⁾(v)/k!` at
    /// `v = self.value()` (Horner in the jet without its constant term).
    #[inline]
    pub fn compose_univariate(&self, t: &[f64; MAX_ORDER + 1]) -> Jet {
        let n = self.order;
        let mut h = *self;
        h.c[0] = 0.0;
        let mut r = Jet::constant(t[n], n);
        for k in (0..n).rev() {
            r = r.mul(&h).add_const(t[k]);
        }
        r
    }
    /// `1 / self`.
    #[inline]
    pub fn recip(&self) -> Jet {
        let v = self.c[0];
        let i = 1.0 / v;
        let t = [i, -i * i, i * i * i, -i * i * i * i];
        self.compose_univariate(&t)
    }
    /// `exp(self)`.
    #[inline]
    pub fn exp(&self) -> Jet {
        let e = self.c[0].exp();
        self.compose_univariate(&[e, e, e / 2.0, e / 6.0])
    }
    /// `self / o`.
    #[inline]
    pub fn div(&self, o: &Jet) -> Jet {
        self.mul(&o.recip())
    }
}

/// A complex-valued jet (real and imaginary parts).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CJet {
    pub re: Jet,
    pub im: Jet,
}

impl CJet {
    /// The coordinate `z = x + iy` at `z0`.
    pub fn variable(z0: C, order: usize) -> CJet {
        CJet {
            re: Jet::variable(z0.re, 0, order),
            im: Jet::variable(z0.im, 1, order),
        }
    }
    pub fn constant(z: C, order: usize) -> CJet {
        CJet {
            re: Jet::constant(z.re, order),
            im: Jet::constant(z.im, order),
        }
    }
    pub fn value(&self) -> C {
        C::new(self.re.value(), self.im.value())
    }
    pub fn add(&self, o: &CJet) -> CJet {
        CJet {
            re: self.re.add(&o.re),
            im: self.im.add(&o.im),
        }
    }
    pub fn mul(&self, o: &CJet) -> CJet {
        CJet {
            re: self.re.mul(&o.re).sub(&self.im.mul(&o.im)),
            im: self.re.mul(&o.im).add(&self.im.mul(&o.re)),
        }
    }
    pub fn mul_c(&self, s: C) -> CJet {
        CJet {
            re: self.re.scale(s.re).sub(&self.im.scale(s.im)),
            im: self.re.scale(s.im).add(&self.im.scale(s.re)),
        }
    }
    pub fn add_c(&self, s: C) -> CJet {
        CJet {
            re: self.re.add_const(s.re),
            im: self.im.add_const(s.im),
        }
    }
    pub fn div(&self, o: &CJet) -> CJet {
        let n = o.re.mul(&o.re).add(&o.im.mul(&o.im)).recip();
        let conj = CJet {
            re: o.re,
            im: o.im.scale(-1.0),
        };
        let p = self.mul(&conj);
        CJet {
            re: p.re.mul(&n),
            im: p.im.mul(&n),
        }
    }
}

/// The complex jet of a holomorphic function given its complex Taylor coefficients
/// `t[k] = g⁽ᵏ⁾(z0)/k!`: `(x + iy)ᵏ = Σ_b C(k, b) iᵇ xᵏ⁻ᵇ yᵇ`, no products needed.
#[inline]
pub fn holomorphic_jet(t: &[C; MAX_ORDER + 1], order: usize) -> CJet {
    const BINOM: [[f64; 4]; 4] = [
        [1.0, 0.0, 0.0, 0.0],
        [1.0, 1.0, 0.0, 0.0],
        [1.0, 2.0, 1.0, 0.0],
        [1.0, 3.0, 3.0, 1.0],
    ];
    let mut re = Jet::constant(t[0].re, order);
    let mut im = Jet::constant(t[0].im, order);
    for k in 1..=order.min(MAX_ORDER) {
        let mut ib = C::new(1.0, 0.0);
        for b in 0..=k {
            let c = t[k] * ib * BINOM[k][b];
            let i = index(k - b, b);
            re.c[i] = c.re;
            im.c[i] = c.im;
            ib *= C::new(0.0, 1.0);
        }
    }
    CJet { re, im }
}

/// The jet of the Möbius map `z ↦ (a z + b)/(b̄ z + ā)` (`|a|² − |b|² = 1`) at `z0`, from its
/// closed-form derivatives `T⁽ᵏ⁾/k! = (−b̄)ᵏ⁻¹ / (b̄ z0 + ā)ᵏ⁺¹`.
#[inline]
pub fn su11_jet(a: C, b: C, z0: C, order: usize) -> CJet {
    let d = b.conj() * z0 + a.conj();
    let inv = 1.0 / d;
    let mut t = [C::new(0.0, 0.0); MAX_ORDER + 1];
    t[0] = (a * z0 + b) * inv;
    let mut p = inv * inv;
    for tk in t.iter_mut().skip(1) {
        *tk = p;
        p *= -b.conj() * inv;
    }
    holomorphic_jet(&t, order)
}

/// The jet of the Möbius map `z ↦ (a z + b)/(b̄ z + ā)` at `z0`.
pub fn mobius_jet(a: C, b: C, z0: C, order: usize) -> CJet {
    let z = CJet::variable(z0, order);
    z.mul_c(a).add_c(b).div(&z.mul_c(b.conj()).add_c(a.conj()))
}

/// `g ∘ w`: `g` a jet in the variables `(X, Y)` about `w.value()`, `w` a complex jet in
/// `(x, y)` (the change of coordinates). The result is the jet of `g(X(x, y), Y(x, y))`.
pub fn compose(g: &Jet, w: &CJet) -> Jet {
    let n = g.order;
    let mut dx = w.re;
    dx.c[0] = 0.0;
    let mut dy = w.im;
    dy.c[0] = 0.0;
    let one = Jet::constant(1.0, n);
    let mut px = [one; MAX_ORDER + 1];
    let mut py = [one; MAX_ORDER + 1];
    for k in 1..=n {
        px[k] = px[k - 1].mul(&dx);
        py[k] = py[k - 1].mul(&dy);
    }
    let mut r = Jet::constant(0.0, n);
    for i in 0..n_coeffs(n) {
        let (a, b) = exponents(i);
        if g.c[i] != 0.0 {
            r.axpy(g.c[i], &px[a].mul(&py[b]));
        }
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(x: f64, y: f64) -> f64 {
        ((x * x - 0.3 * y) / (1.5 + x * y)).exp()
    }

    #[test]
    fn product_quotient_exp_match_finite_differences() {
        let (x0, y0) = (0.3, -0.2);
        let x = Jet::variable(x0, 0, 3);
        let y = Jet::variable(y0, 1, 3);
        let j = x
            .mul(&x)
            .sub(&y.scale(0.3))
            .div(&y.mul(&x).add_const(1.5))
            .exp();
        let h = 1e-3;
        let fd = |a: usize, b: usize| -> f64 {
            // Central differences of the mixed partial.
            let mut s = 0.0;
            for i in 0..=a {
                for k in 0..=b {
                    let ci = binom(a, i) * if i % 2 == 0 { 1.0 } else { -1.0 };
                    let ck = binom(b, k) * if k % 2 == 0 { 1.0 } else { -1.0 };
                    s += ci
                        * ck
                        * f(
                            x0 + (a as f64 / 2.0 - i as f64) * h,
                            y0 + (b as f64 / 2.0 - k as f64) * h,
                        );
                }
            }
            s / h.powi((a + b) as i32)
        };
        for i in 0..n_coeffs(3) {
            let (a, b) = exponents(i);
            let want = fd(a, b);
            let got = j.partial(a, b);
            assert!(
                (got - want).abs() < 1e-4 * (1.0 + want.abs()),
                "∂({a},{b}): jet {got}, finite differences {want}"
            );
        }
    }

    fn binom(n: usize, k: usize) -> f64 {
        (1..=k).fold(1.0, |acc, i| acc * (n + 1 - i) as f64 / i as f64)
    }

    #[test]
    fn composition_is_the_chain_rule() {
        // g(X, Y) = X² Y + sin-free polynomial; w = Möbius map; compare with the direct jet.
        let (a, b) = (C::new(1.3, 0.2), C::new(0.5, -0.6));
        let s = (a.norm_sqr() - b.norm_sqr()).sqrt();
        let (a, b) = (a / s, b / s);
        let z0 = C::new(0.1, 0.25);
        let w = mobius_jet(a, b, z0, 3);
        let w0 = w.value();
        let gx = Jet::variable(w0.re, 0, 3);
        let gy = Jet::variable(w0.im, 1, 3);
        let g = gx.mul(&gx).mul(&gy).add(&gy.exp());
        let direct = w.re.mul(&w.re).mul(&w.im).add(&w.im.exp());
        let composed = compose(&g, &w);
        for i in 0..n_coeffs(3) {
            assert!((direct.c[i] - composed.c[i]).abs() < 1e-12 * (1.0 + direct.c[i].abs()));
        }
    }

    #[test]
    fn su11_jet_matches_the_quotient_of_jets() {
        // Closed-form derivatives of an SU(1,1) map against the jet arithmetic of the quotient.
        let (a, b) = (C::new(1.3, 0.2), C::new(0.5, -0.6));
        let s = (a.norm_sqr() - b.norm_sqr()).sqrt();
        let (a, b) = (a / s, b / s);
        let z0 = C::new(-0.3, 0.45);
        let q = mobius_jet(a, b, z0, 3);
        let h = su11_jet(a, b, z0, 3);
        for i in 0..n_coeffs(3) {
            assert!((q.re.c[i] - h.re.c[i]).abs() < 1e-12 * (1.0 + q.re.c[i].abs()));
            assert!((q.im.c[i] - h.im.c[i]).abs() < 1e-12 * (1.0 + q.im.c[i].abs()));
        }
    }
}
