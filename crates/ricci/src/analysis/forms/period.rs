//! The normalized basis of holomorphic 1-forms and the Riemann period matrix (paper 002
//! §4.2.2–4.2.3; Farkas–Kra III.2).
//!
//! Coordinates: a harmonic 1-form is written in the basis `ζ_1 … ζ_2g` dual to the loops
//! `a₁, b₁, …, a_g, b_g` (`∫_{γ_l} ζ_k = δ_kl`), so its coordinates **are** its periods
//! (interleaved: index `2j` is `a_{j+1}`, `2j + 1` is `b_{j+1}`). A holomorphic 1-form is
//! `ω = α + i *α`, `α` harmonic with coordinates `x`, `*α` with coordinates `J x`
//! ([`super::hodge`]). The basis `ω_1 … ω_g` normalized on the a-cycles
//! (`∫_{a_j} ω_i = δ_ij`) solves, for each `i`, the real `2g × 2g` system
//! `x_{a_j} = δ_ij`, `(J x)_{a_j} = 0`; the **period matrix** is
//! `Ω_ij = ∫_{b_j} ω_i = x_{b_j} + i (J x)_{b_j}`.
//!
//! Riemann's bilinear relations: `Ω = Ωᵀ` and `Im Ω > 0`. A change of canonical basis by
//! `M = (A B; C D) ∈ Sp(2g, Z)` changes `Ω` to `(AΩ + B)(CΩ + D)⁻¹`; what does not change is
//! the **energy form** of the period lattice — the Dirichlet energy of the harmonic form with
//! given integer periods — `E(p, q) = pᵀ(Y + X Y⁻¹ X)p − 2 pᵀ X Y⁻¹ q + qᵀ Y⁻¹ q` for
//! `Ω = X + iY`, `p` the a-periods and `q` the b-periods, up to the integer change of
//! variables. Its values on the integer lattice ([`lattice_energies`]) are therefore the same
//! for every canonical basis: the basis-free check of a period matrix.

use super::small::{self, Matrix};
use crate::error::{Error, Result};
use serde::Serialize;

/// A `g × g` complex matrix as real and imaginary parts.
#[derive(Debug, Clone, Serialize)]
pub struct PeriodMatrix {
    pub re: Matrix,
    pub im: Matrix,
}

impl PeriodMatrix {
    pub fn genus(&self) -> usize {
        self.re.len()
    }

    /// `max |Ω − Ωᵀ|`.
    pub fn asymmetry(&self) -> f64 {
        small::max_diff(&self.re, &small::transpose(&self.re))
            .max(small::max_diff(&self.im, &small::transpose(&self.im)))
    }

    /// The eigenvalues of the symmetric part of `Im Ω` (all positive by Riemann's relations).
    pub fn im_eigenvalues(&self) -> Result<Vec<f64>> {
        let g = self.genus();
        let sym: Matrix = (0..g)
            .map(|i| {
                (0..g)
                    .map(|j| 0.5 * (self.im[i][j] + self.im[j][i]))
                    .collect()
            })
            .collect();
        small::symmetric_eigenvalues(&sym)
    }

    /// The energy form of the period lattice in interleaved coordinates (module docs).
    pub fn energy_form(&self) -> Result<Matrix> {
        let g = self.genus();
        let x = &self.re;
        let yinv = small::inverse(&self.im, "Im Ω")?;
        let yinv_x = small::mul(&yinv, x);
        let x_yinv_x = small::mul(x, &yinv_x);
        let mut e = vec![vec![0.0; 2 * g]; 2 * g];
        for i in 0..g {
            for j in 0..g {
                e[2 * i][2 * j] = self.im[i][j] + x_yinv_x[i][j];
                // pᵀ(−X Y⁻¹)q: entry (a_i, b_j) is −(X Y⁻¹)_ij = −(Y⁻¹ X)_ji.
                e[2 * i][2 * j + 1] = -yinv_x[j][i];
                e[2 * j + 1][2 * i] = -yinv_x[j][i];
                e[2 * i + 1][2 * j + 1] = yinv[i][j];
            }
        }
        Ok(e)
    }
}

/// Coordinates of `Re ω_i`, of `Im ω_i` (both in the `ζ` basis), and the period matrix.
pub type NormalizedBasis = (Vec<Vec<f64>>, Vec<Vec<f64>>, PeriodMatrix);

/// The normalized holomorphic basis from the complex structure `J` (in the coordinates dual to
/// `a₁, b₁, …`): for each `i`, the coordinates `x` of `Re ω_i` and `J x` of `Im ω_i`, and the
/// period matrix.
pub fn normalized_basis(j: &Matrix) -> Result<NormalizedBasis> {
    let n = j.len();
    if n == 0 || !n.is_multiple_of(2) {
        return Err(Error::input(format!(
            "a complex structure on H¹ needs an even positive dimension, got {n}"
        )));
    }
    let g = n / 2;
    // Rows: x_{a_k} (k < g), then (J x)_{a_k}.
    let mut m = vec![vec![0.0; n]; n];
    for k in 0..g {
        m[k][2 * k] = 1.0;
        m[g + k] = j[2 * k].clone();
    }
    small::inverse(&m, "a-period")?;
    let (mut re, mut im) = (Vec::with_capacity(g), Vec::with_capacity(g));
    let mut omega = PeriodMatrix {
        re: vec![vec![0.0; g]; g],
        im: vec![vec![0.0; g]; g],
    };
    for i in 0..g {
        let mut rhs = vec![0.0; n];
        rhs[i] = 1.0;
        let x = small::solve(&m, &rhs);
        let jx: Vec<f64> = j
            .iter()
            .map(|r| r.iter().zip(&x).map(|(a, b)| a * b).sum())
            .collect();
        for k in 0..g {
            omega.re[i][k] = x[2 * k + 1];
            omega.im[i][k] = jx[2 * k + 1];
        }
        re.push(x);
        im.push(jx);
    }
    Ok((re, im, omega))
}

/// The `count` smallest values of `cᵀ E c` over nonzero integer vectors `c` (up to sign), for
/// a symmetric positive definite `E` — complete: every lattice vector below the largest value
/// returned is counted. Errors when `E` is not positive definite or the enumeration would
/// exceed 5·10⁷ vectors.
pub fn lattice_energies(e: &Matrix, count: usize) -> Result<Vec<f64>> {
    let n = e.len();
    let eig = small::symmetric_eigenvalues(e)?;
    if eig.first().is_none_or(|&l| l.is_nan() || l <= 0.0) {
        return Err(Error::numerical("the energy form is not positive definite"));
    }
    let q = |c: &[i64]| -> f64 {
        let mut s = 0.0;
        for i in 0..n {
            for j in 0..n {
                s += e[i][j] * c[i] as f64 * c[j] as f64;
            }
        }
        s
    };
    // An upper bound for the count-th value: the smallest ones in the box [-1, 1]ⁿ.
    let mut small_box = Vec::new();
    let mut c = vec![0i64; n];
    enumerate_box(&mut c, 0, &vec![1; n], &mut |c| small_box.push(q(c)))?;
    small_box.sort_by(f64::total_cmp);
    let t = small_box[(count.max(1) - 1).min(small_box.len() - 1)] * (1.0 + 1e-12);
    // |c_i| ≤ sqrt(t (E⁻¹)_ii) on the ellipsoid cᵀEc ≤ t.
    let inv = small::inverse(e, "energy form")?;
    let bounds: Vec<i64> = (0..n)
        .map(|i| (t * inv[i][i]).max(0.0).sqrt().floor() as i64)
        .collect();
    let size: f64 = bounds.iter().map(|&b| (2 * b + 1) as f64).product();
    if size > 5e7 {
        return Err(Error::numerical(format!(
            "the period lattice is too skewed to enumerate ({size:.1e} vectors)"
        )));
    }
    let mut vals = Vec::new();
    enumerate_box(&mut c, 0, &bounds, &mut |c| {
        let v = q(c);
        if v <= t {
            vals.push(v);
        }
    })?;
    vals.sort_by(f64::total_cmp);
    vals.truncate(count);
    Ok(vals)
}

/// Calls `f` on every nonzero `c` with `|c_i| ≤ bounds[i]` whose first nonzero entry is
/// positive.
fn enumerate_box(
    c: &mut Vec<i64>,
    i: usize,
    bounds: &[i64],
    f: &mut dyn FnMut(&[i64]),
) -> Result<()> {
    if i == c.len() {
        if let Some(&first) = c.iter().find(|&&x| x != 0) {
            if first > 0 {
                f(c);
            }
        }
        return Ok(());
    }
    for v in -bounds[i]..=bounds[i] {
        c[i] = v;
        enumerate_box(c, i + 1, bounds, f)?;
    }
    c[i] = 0;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The square torus: J = (0 −1; 1 0) gives τ = i; the hexagonal lattice's energies.
    #[test]
    fn square_torus_and_lattice_energies() {
        let j = vec![vec![0.0, -1.0], vec![1.0, 0.0]];
        let (_, _, om) = normalized_basis(&j).unwrap();
        assert!((om.re[0][0]).abs() < 1e-15 && (om.im[0][0] - 1.0).abs() < 1e-15);
        // Energy of the form with periods (p, q) on C/(Z + iZ) is p² + q²: values 1, 2, 4, 5.
        let e = om.energy_form().unwrap();
        let v = lattice_energies(&e, 5).unwrap();
        let want = [1.0, 1.0, 2.0, 2.0, 4.0];
        for (a, b) in v.iter().zip(want) {
            assert!((a - b).abs() < 1e-12, "{v:?}");
        }
        // τ = 1/2 + i√3/2 and its image under τ ↦ −1/τ have the same energies.
        let tau = num_complex::Complex64::new(0.3, 1.7);
        let t2 = -1.0 / (tau + 2.0);
        let pm = |t: num_complex::Complex64| PeriodMatrix {
            re: vec![vec![t.re]],
            im: vec![vec![t.im]],
        };
        let a = lattice_energies(&pm(tau).energy_form().unwrap(), 8).unwrap();
        let b = lattice_energies(&pm(t2).energy_form().unwrap(), 8).unwrap();
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-12 * x, "{a:?} vs {b:?}");
        }
    }
}
