//! Parameter correction of a fit (Hoschek, "Intrinsic parametrization for approximation",
//! CAGD 1988; the standard companion of least-squares surface fitting): each data point's
//! parameter `u_k` moves to the foot of the perpendicular from `p_k` to the current surface, so
//! that `|S(u_k) − p_k|` measures the distance to the surface rather than also the tangential
//! slip of the fixed conformal parameters (paper 003 §3.3 fits at the parameters `u_k ∈ M`
//! without saying how they are chosen; the conformal net gives the start).
//!
//! Newton on `|S(u) − p|²/2`: `δ = −H⁻¹ Jᵀ r` with `J = [S_u S_v]`, `r = S(u) − p` and
//! `H = JᵀJ + [r·S_uu r·S_uv; r·S_uv r·S_vv]` (the closest point, not its linearisation), or
//! the Gauss–Newton `H = JᵀJ` where that `H` is not positive definite;
//! a step is at most half the smaller side of the T-mesh face holding `u` and is halved (at
//! most `HALVINGS` times) until the distance decreases; otherwise the parameter stays.

use super::surface::TSpline;
use rayon::prelude::*;

const HALVINGS: usize = 4;

/// `steps` Newton steps per point; returns the corrected parameters (canonical
/// representatives) and how many of them moved.
pub fn correct_parameters(
    ts: &TSpline,
    points: &[[f64; 3]],
    params: &[[f64; 2]],
    steps: usize,
) -> (Vec<[f64; 2]>, usize) {
    let mesh = &ts.basis.mesh;
    let lattice = mesh.lattice;
    let faces = mesh.faces();
    let grid = mesh.face_grid();
    // every point on its own: in parallel, collected in order (the same for any thread count)
    let out: Vec<([f64; 2], bool)> = points
        .par_iter()
        .zip(params)
        .map(|(p, &uv)| {
            let mut uv = uv;
            let mut changed = false;
            for _ in 0..steps {
                let Some(f) = grid.locate(uv[0], uv[1]) else {
                    break;
                };
                let face = &faces[f];
                let limit = 0.5 * (face.u1 - face.u0).min(face.v1 - face.v0);
                let jet = ts.jet(uv[0], uv[1]);
                let r = sub(&jet[0], p);
                let (su, sv) = (jet[1], jet[2]);
                let (a0, b0, c0) = (dot(&su, &su), dot(&su, &sv), dot(&sv, &sv));
                // Newton: the Hessian of |S − p|²/2 adds r·S_uu, r·S_uv, r·S_vv to JᵀJ; kept
                // when it stays positive definite, else the Gauss–Newton matrix JᵀJ
                let (a1, b1, c1) = (
                    a0 + dot(&r, &jet[3]),
                    b0 + dot(&r, &jet[4]),
                    c0 + dot(&r, &jet[5]),
                );
                let newton = a1 > 0.0 && a1 * c1 - b1 * b1 > 1e-3 * (a0 * c0 - b0 * b0);
                let (a, b, c) = if newton { (a1, b1, c1) } else { (a0, b0, c0) };
                let det = a * c - b * b;
                if !(det > 1e-300) {
                    break;
                }
                let (gu, gv) = (dot(&su, &r), dot(&sv, &r));
                let mut d = [-(c * gu - b * gv) / det, -(a * gv - b * gu) / det];
                let len = d[0].hypot(d[1]);
                if !len.is_finite() || len == 0.0 {
                    break;
                }
                if len > limit {
                    d = [d[0] * limit / len, d[1] * limit / len];
                }
                let before = dot(&r, &r);
                let mut accepted = false;
                for _ in 0..=HALVINGS {
                    let (u, v) = lattice.canonical(uv[0] + d[0], uv[1] + d[1]);
                    let q = sub(&ts.point(u, v), p);
                    if dot(&q, &q) < before {
                        uv = [u, v];
                        accepted = true;
                        break;
                    }
                    d = [0.5 * d[0], 0.5 * d[1]];
                }
                if !accepted {
                    break;
                }
                changed = true;
            }
            (uv, changed)
        })
        .collect();
    let moved = out.iter().filter(|x| x.1).count();
    (out.into_iter().map(|x| x.0).collect(), moved)
}

fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
