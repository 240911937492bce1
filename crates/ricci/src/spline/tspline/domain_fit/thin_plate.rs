//! The thin-plate fairness of the domain-mesh fit (paper 003 §3.3): the energy
//! `∫∫ S_uu² + 2 S_uv² + S_vv² du dv` of the spline over the domain, in the parameters of the
//! strips (every cell's own width and height), exact on the cells' bicubic Bézier patches.
//!
//! On a cell of width `a` and height `b` with local coordinates `s = (u − u₀)/a`,
//! `t = (v − v₀)/b` the energy is
//! `(b/a³) ∫∫ S_ss² + (2/(a b)) ∫∫ S_st² + (a/b³) ∫∫ S_tt²` over `[0, 1]²`, and for the
//! tensor-product Bernstein basis each term is a Kronecker product of the 1-D Gram matrices
//! `G_k[i][j] = ∫₀¹ B_i⁽ᵏ⁾ B_j⁽ᵏ⁾` (`k = 0, 1, 2`): `G₂ ⊗ G₀`, `G₁ ⊗ G₁`, `G₀ ⊗ G₂`. A thin or
//! graded cell costs what its curvature costs per unit area, unlike second differences of the
//! control net in index space (which weigh a cell a thousand times thinner than its
//! neighbour as much as it, and leave the twist `S_uv` free).

use crate::numeric::sparse::BlockAssembly;
use crate::spline::tspline::domain_mesh::{DomainMesh, Rect};

/// `G_k[i][j] = ∫₀¹ B_i⁽ᵏ⁾(x) B_j⁽ᵏ⁾(x) dx` for the cubic Bernstein polynomials, `k = 0, 1, 2`
/// (integrated in closed form: `G₀ = [20 10 4 1; …]/140`, `G₁ = [18 −9 −6 −3; …]/10`,
/// `G₂ = [12 −18 0 6; …]`, each row of `G₁` and `G₂` summing to 0).
pub(super) fn gram() -> [[[f64; 4]; 4]; 3] {
    let g0 = [
        [20.0, 10.0, 4.0, 1.0],
        [10.0, 12.0, 9.0, 4.0],
        [4.0, 9.0, 12.0, 10.0],
        [1.0, 4.0, 10.0, 20.0],
    ];
    let g1 = [
        [18.0, -9.0, -6.0, -3.0],
        [-9.0, 12.0, 3.0, -6.0],
        [-6.0, 3.0, 12.0, -9.0],
        [-3.0, -6.0, -9.0, 18.0],
    ];
    let g2 = [
        [12.0, -18.0, 0.0, 6.0],
        [-18.0, 36.0, -18.0, 0.0],
        [0.0, -18.0, 36.0, -18.0],
        [6.0, 0.0, -18.0, 12.0],
    ];
    [
        g0.map(|r| r.map(|x| x / 140.0)),
        g1.map(|r| r.map(|x| x / 10.0)),
        g2,
    ]
}

/// The thin-plate energy of a `width × height` cell as a quadratic form in its 16 Bézier
/// points (index `4 i + j`, `i` along `u`).
pub(super) fn cell_energy(g: &[[[f64; 4]; 4]; 3], (width, height): (f64, f64)) -> [[f64; 16]; 16] {
    let (a, b) = (width, height);
    let (cuu, cuv, cvv) = (b / (a * a * a), 2.0 / (a * b), a / (b * b * b));
    let mut k = [[0.0; 16]; 16];
    for (p, row) in k.iter_mut().enumerate() {
        let (i, j) = (p / 4, p % 4);
        for (q, x) in row.iter_mut().enumerate() {
            let (l, m) = (q / 4, q % 4);
            *x = cuu * g[2][i][l] * g[0][j][m]
                + cuv * g[1][i][l] * g[1][j][m]
                + cvv * g[0][i][l] * g[2][j][m];
        }
    }
    k
}

/// The factor on the thin-plate energy of the cell centred at `(x, y)` of strip `rc`:
/// `min(1, r² / E²)`, `r` the distance to the nearest strip corner (a zero) and `E` the larger
/// ungraded edge interval. At a simple zero the strip coordinate is the square of a smooth one
/// (`w ∝ z²`), the surface goes as `√w` and its thin-plate density as `|w|⁻³`, whose integral
/// diverges at the zero: the factor keeps it finite and, in the graded corner blocks (cells of
/// size ∝ `r`), scales the energy as the index-space second differences do.
fn near_zero_factor(rc: &Rect, x: f64, y: f64) -> f64 {
    let (du, dv) = (x.min(rc.length - x), y.min(rc.height - y));
    let e = rc.edge_u.max(rc.edge_v) * (1u64 << rc.levels) as f64;
    ((du * du + dv * dv) / (e * e).max(1e-300)).min(1.0)
}

/// Adds `weight ×` the thin-plate energy of every cell of `mesh` (times
/// [`near_zero_factor`]) to `asm`, in the cell's unknowns ([`super::cell_local`]; the free
/// values of the reduction with `g1`; `n` unknowns).
pub(super) fn thin_plate_term(
    mesh: &DomainMesh,
    g1: bool,
    weight: f64,
    asm: &mut BlockAssembly,
    n: usize,
) {
    let g = gram();
    let mut slot = vec![u32::MAX; n];
    let mut ids = Vec::<u32>::new();
    let mut local: Vec<Vec<(usize, f64)>> = vec![Vec::new(); 16];
    let (mut kl, mut block) = (Vec::<f64>::new(), Vec::<f64>::new());
    for c in 0..mesh.n_cells() {
        let [u0, u1, v0, v1] = mesh.cell_box(c as u32);
        let rc = &mesh.rects[mesh.cell_at[c].0 as usize];
        let wc = weight * near_zero_factor(rc, 0.5 * (u0 + u1), 0.5 * (v0 + v1));
        let k = cell_energy(&g, (u1 - u0, v1 - v0));
        super::cell_local(mesh, c, g1, &mut slot, &mut ids, &mut local);
        let m = ids.len();
        // K L (16 × m), then Lᵀ K L (m × m)
        kl.clear();
        kl.resize(16 * m, 0.0);
        for (p, kp) in k.iter().enumerate() {
            for (q, l) in local.iter().enumerate() {
                for &(e, w) in l {
                    kl[p * m + e] += kp[q] * w;
                }
            }
        }
        block.clear();
        block.resize(m * m, 0.0);
        for (p, l) in local.iter().enumerate() {
            for &(a, w) in l {
                for e in 0..m {
                    block[a * m + e] += w * kl[p * m + e];
                }
            }
        }
        for (a, &r) in ids.iter().enumerate() {
            for (e, &q) in ids.iter().enumerate() {
                if r >= q {
                    asm.add(r, q, wc * block[a * m + e]);
                }
            }
        }
        ids.iter().for_each(|&r| slot[r as usize] = u32::MAX);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Bézier points (`4 i + j`) of `f(u, v) = Σ c[k][l] uᵏ vˡ` (degree ≤ 2 in each) on
    /// `[0, a] × [0, b]`: the Bernstein coefficients of `1, s, s²` are
    /// `[1,1,1,1]`, `[0,⅓,⅔,1]`, `[0,0,⅓,1]`.
    fn bezier(c: [[f64; 3]; 3], a: f64, b: f64) -> [f64; 16] {
        let mono = [
            [1.0, 1.0, 1.0, 1.0],
            [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0],
            [0.0, 0.0, 1.0 / 3.0, 1.0],
        ];
        let mut p = [0.0; 16];
        for (ij, x) in p.iter_mut().enumerate() {
            for k in 0..3 {
                for l in 0..3 {
                    *x += c[k][l]
                        * a.powi(k as i32)
                        * b.powi(l as i32)
                        * mono[k][ij / 4]
                        * mono[l][ij % 4];
                }
            }
        }
        p
    }

    fn energy(k: &[[f64; 16]; 16], p: &[f64; 16]) -> f64 {
        (0..16)
            .map(|i| (0..16).map(|j| p[i] * k[i][j] * p[j]).sum::<f64>())
            .sum()
    }

    /// `∫∫ f_uu² + 2 f_uv² + f_vv²` over an `a × b` cell in closed form (a quadratic's Hessian
    /// is constant): `u²` → `4ab`, `uv` → `2ab`, `v²` → `4ab`, linear functions → 0,
    /// `u² + 3uv + v²` → `(4 + 2·9 + 4) ab`; on a square, a 20 : 1 thin and a tall cell.
    #[test]
    fn cell_energy_is_the_thin_plate_integral_of_quadratics() {
        let g = gram();
        for (a, b) in [(1.0, 1.0), (0.31, 0.0155), (0.3, 2.0)] {
            let k = cell_energy(&g, (a, b));
            let cases: [([[f64; 3]; 3], f64); 5] = [
                (
                    [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
                    4.0 * a * b,
                ),
                (
                    [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]],
                    2.0 * a * b,
                ),
                (
                    [[0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]],
                    4.0 * a * b,
                ),
                ([[3.0, -2.0, 0.0], [5.0, 0.0, 0.0], [0.0, 0.0, 0.0]], 0.0),
                (
                    [[0.0, 0.0, 1.0], [0.0, 3.0, 0.0], [1.0, 0.0, 0.0]],
                    (4.0 + 18.0 + 4.0) * a * b,
                ),
            ];
            for (c, want) in cases {
                let e = energy(&k, &bezier(c, a, b));
                // roundoff: the sum's terms grow with the aspect ratio squared (`a/b³` against
                // the energy's `a b`)
                let aspect = (a / b).max(b / a);
                let scale = 4.0 * a * b * (1.0 + aspect * aspect);
                assert!(
                    (e - want).abs() <= 1e-9 * scale.max(want),
                    "{a} × {b}, {c:?}: energy {e}, closed form {want}"
                );
            }
        }
    }

    #[test]
    fn the_factor_vanishes_at_the_zeros_and_is_one_a_corner_cell_away() {
        let rc = Rect {
            cylinder: 0,
            strip: 0,
            length: 1.0,
            height: 0.5,
            m: 5,
            n: 5,
            edge_u: 0.01,
            edge_v: 0.005,
            levels: 2,
            first_cell: 0,
            base_m: 5,
            base_n: 5,
            xs: Vec::new(),
            ys: Vec::new(),
            u_fine: Vec::new(),
            v_fine: Vec::new(),
        };
        // E = 0.01 · 2² = 0.04
        assert_eq!(near_zero_factor(&rc, 0.0, 0.0), 0.0);
        assert!((near_zero_factor(&rc, 0.02, 0.0) - 0.25).abs() < 1e-12);
        assert!((near_zero_factor(&rc, 1.0 - 0.012, 0.5 - 0.016) - 0.25).abs() < 1e-12);
        assert_eq!(near_zero_factor(&rc, 0.5, 0.25), 1.0);
    }
}
