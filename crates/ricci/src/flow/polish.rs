//! Polishing a converged hyperbolic metric beyond double precision (iterative refinement of
//! the Newton solve of paper 001 §V Step 3 with a double-double residual).
//!
//! The flow ([`super::newton`]) stops at max |K − K̄| ≈ 5e-15: `K = 2π − Σθ` evaluated in
//! double precision cannot resolve less. The hyperbolic layout and deck group run in
//! double-double ([`crate::numeric::dd`]), and on surfaces with long canonical loops the
//! remaining curvature error, amplified by ~sinh of the distance from the centre of the
//! Poincaré disk, is what limits the agreement of deck maps computed from different edges.
//!
//! [`polish_metric`] keeps the variables `u` in double-double and iterates
//!
//! ```text
//! r = K̄ − K(u)   (double-double),   H δ = r   (H = ∂K/∂u in double precision, faer LLᵀ),   u += δ
//! ```
//!
//! with the Hessian of the flow assembled and factored once at the starting point. Because
//! `H` is accurate to ~1e-16 relative, every step multiplies the residual by ~1e-16·cond(H)
//! (two or three steps go from 5e-15 to the double-double floor ~1e-30).
//!
//! The double-double residual uses the scheme's own formulas: circle packing (Thurston,
//! tangential, inversive) `γ = log((1 + eᵘ)/(1 − eᵘ))`,
//! `sinh²(l/2) = sinh²((γi − γj)/2) + ½ sinh γi sinh γj (1 + η)` (as
//! [`crate::metric::Background::circle_packing_length`]); vertex scaling
//! `sinh(l/2) = e^{(ui+uj)/2} η` with `η = sinh(l⁰/2)` (given with a low part, so a
//! double-double metric can be polished in place). Corner angles are never formed: the
//! half-angle tangents `t = tan(θ/2)` of the cosine law (as in [`crate::metric::kernel`]) give
//! the unit numbers `e^{iθ} = (1 − t² + 2it)/(1 + t²)`, their product around a vertex is
//! `e^{iΣθ}`, and the residual `Σθ − (2π or π)` is its argument, a small angle whose `atan2`
//! is exact in double precision. So only targets `K̄ = 0` are supported (the uniform target
//! of closed surfaces and the geodesic-boundary target, i.e. the hyperbolic uniformization
//! metrics); others are refused. Geometry: H² only.
//!
//! The result reports the double-double residual before and after, the steps taken and
//! whether it reached the tolerance (default 1e-26).

// `!(x > 0.0)` is used on purpose: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::metric::{ConformalStructure, Evaluator, Geometry, HessianPattern, IntrinsicMetric};
use crate::numeric::dd::{Cdd, Dd};
use crate::numeric::sparse::SymmetricSolver;

/// Settings of [`polish_metric`].
#[derive(Debug, Clone, Copy)]
pub struct PolishSettings {
    /// Stop when the double-double max |K − K̄| is at most this.
    pub tolerance: f64,
    /// At most this many refinement steps.
    pub max_steps: usize,
}

impl Default for PolishSettings {
    fn default() -> Self {
        PolishSettings {
            tolerance: 1e-26,
            max_steps: 4,
        }
    }
}

/// A metric polished to double-double.
#[derive(Debug, Clone)]
pub struct PolishedMetric {
    /// Variables `u` (leading parts) and their low parts.
    pub u: Vec<f64>,
    pub u_lo: Vec<f64>,
    /// The polished metric (H²): edge `e` has length `lengths[e] + lengths_lo[e]` to ~32
    /// digits (the low parts are always present).
    pub metric: IntrinsicMetric,
    /// Refinement steps taken.
    pub steps: usize,
    /// Max |K − K̄| over the free vertices in double-double at the start.
    pub residual_start: f64,
    /// The same at the end.
    pub residual_dd: f64,
    /// The residual after every step (first entry: the start).
    pub history: Vec<f64>,
    /// Whether `residual_dd ≤ tolerance`.
    pub converged: bool,
}

/// Per-vertex double-double data of the length law: circle packing `[sinh γ, γ]`, vertex
/// scaling `[e^{u/2}, 0]`.
fn vertex_data(circle_packing: bool, u: Dd) -> Result<[Dd; 2]> {
    if circle_packing {
        if !(u.hi < 0.0) {
            return Err(Error::numerical(format!(
                "hyperbolic circle-packing variable u = {:e} is not negative",
                u.hi
            )));
        }
        let t = u.exp();
        let g = ((Dd::ONE + t) / (Dd::ONE - t)).ln();
        Ok([g.sinh(), g])
    } else {
        Ok([(u * Dd::new(0.5)).exp(), Dd::ZERO])
    }
}

/// Double-double edge lengths of the structure at variables `u` (+ `u_lo`).
fn lengths_dd(
    mesh: &Mesh,
    structure: &ConformalStructure,
    eta_lo: Option<&[f64]>,
    u: &[Dd],
) -> Result<Vec<Dd>> {
    use rayon::prelude::*;
    let cp = structure.scheme.is_circle_packing();
    // Per vertex, then per edge, in parallel (rayon): each value depends on its own inputs
    // only, and the first error in index order is the one reported, as in one loop.
    let vd: Vec<Result<[Dd; 2]>> = u
        .par_iter()
        .with_min_len(2048)
        .map(|&x| vertex_data(cp, x))
        .collect();
    let vd: Vec<[Dd; 2]> = vd.into_iter().collect::<Result<_>>()?;
    let half = Dd::new(0.5);
    let out: Vec<Result<Dd>> = (0..mesh.n_edges())
        .into_par_iter()
        .with_min_len(2048)
        .map(|e| {
            let [a, b] = mesh.edge_vertices(e as u32);
            let eta = Dd::new(structure.eta[e]) + Dd::new(eta_lo.map_or(0.0, |l| l[e]));
            let (va, vb) = (vd[a as usize], vd[b as usize]);
            let x = if cp {
                let d = ((va[1] - vb[1]) * half).sinh();
                let x2 = d.sqr() + half * va[0] * vb[0] * (Dd::ONE + eta);
                if !(x2.hi > 0.0) {
                    return Err(Error::numerical(format!(
                        "edge {e} ({a}, {b}) has no length at the polished variables"
                    )));
                }
                x2.sqrt()
            } else {
                va[0] * vb[0] * eta
            };
            Ok(Dd::new(2.0) * x.asinh())
        })
        .collect();
    out.into_iter().collect()
}

/// A power of two within a factor 2 of `1/x` (`x > 0` finite; 1 otherwise): multiplying by
/// it is exact.
#[inline]
fn power_of_two_near_inverse(x: f64) -> f64 {
    if !(x > 0.0) || !x.is_finite() {
        return 1.0;
    }
    let e = ((x.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    2f64.powi((-e).clamp(-1022, 1023))
}

/// `K̄ − K` in double-double for target 0 (see the module docs), as doubles.
///
/// The three unit factors of each face are computed in parallel (rayon; the four double-double
/// `sinh` per face are most of the cost) and multiplied into the vertex products in face
/// order, as one loop would: the same numbers whatever the number of threads.
fn residual_dd(mesh: &Mesh, lengths: &[Dd], residual: &mut [f64]) -> Result<()> {
    use rayon::prelude::*;
    let nv = mesh.n_vertices();
    let mut prod = vec![Cdd::ONE; nv];
    let half = Dd::new(0.5);
    let factors: Vec<Option<[Cdd; 3]>> = (0..mesh.n_faces() as u32)
        .into_par_iter()
        .with_min_len(2048)
        .map(|f| {
            let l = mesh.face_edges_opposite(f).map(|e| lengths[e as usize]);
            let sig = (l[0] + l[1] + l[2]) * half;
            let d = [sig - l[0], sig - l[1], sig - l[2]];
            if d.iter().any(|x| !(x.hi > 0.0)) {
                return None;
            }
            let s0 = sig.sinh();
            let sd = d.map(|x| x.sinh());
            // tan²(θ_i/2) = A/B with A = sinh d_j sinh d_k, B = sinh σ sinh d_i, so
            // e^{iθ_i} = (1 − t² + 2it)/(1 + t²) is a positive multiple of (B − A) + 2i√(AB),
            // and AB = sinh σ sinh d₀ sinh d₁ sinh d₂ is the same for the three corners: one
            // square root per face and no division.
            let p2 = Dd::new(2.0) * (s0 * sd[0] * sd[1] * sd[2]).sqrt();
            Some([0, 1, 2].map(|i| {
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                Cdd {
                    re: s0 * sd[i] - sd[j] * sd[k],
                    im: p2,
                }
            }))
        })
        .collect();
    for (f, w) in factors.iter().enumerate() {
        let Some(w) = w else {
            return Err(Error::numerical(format!(
                "face {f} violates the triangle inequality in the polished metric"
            )));
        };
        // The products around a vertex are rescaled by powers of two (exact) to stay near 1;
        // only their argument is used.
        let fv = mesh.face(f as u32);
        for i in 0..3 {
            let z = prod[fv[i] as usize] * w[i];
            let scale = Dd::new(power_of_two_near_inverse(z.re.hi.abs() + z.im.hi.abs()));
            prod[fv[i] as usize] = z.scale(scale);
        }
    }
    for v in 0..nv {
        if mesh.is_isolated(v as u32) {
            residual[v] = 0.0;
            continue;
        }
        // e^{iΣθ} · e^{−i·base}: base 2π inside, π on the boundary.
        let z = if mesh.is_boundary_vertex(v as u32) {
            -prod[v]
        } else {
            prod[v]
        };
        let r = z.im.f64().atan2(z.re.f64());
        if !(r.abs() < 1e-3) {
            return Err(Error::numerical(format!(
                "vertex {v}: curvature error {r:.3e} is too large to polish (the metric must \
                 be converged first)"
            )));
        }
        // K̄ − K = 0 − (base − Σθ) = Σθ − base.
        residual[v] = r;
    }
    Ok(())
}

/// The curvature `K_v = 2π − Σθ` (`π − Σθ` on the boundary) of the H² metric of `structure`
/// at the double-double variables `u + u_lo`, evaluated in double-double (see the module
/// docs) and rounded. Only curvatures below 1e-3 in magnitude can be evaluated this way (the
/// argument of `e^{iΣθ}` is taken near 0); larger ones are an error naming the vertex.
pub fn curvature_dd(
    mesh: &Mesh,
    structure: &ConformalStructure,
    eta_lo: Option<&[f64]>,
    u: &[f64],
    u_lo: &[f64],
) -> Result<Vec<f64>> {
    let nv = mesh.n_vertices();
    if u.len() != nv || u_lo.len() != nv || structure.eta.len() != mesh.n_edges() {
        return Err(Error::input(
            "curvature_dd: the variables or the structure do not match the mesh",
        ));
    }
    let ud: Vec<Dd> = u
        .iter()
        .zip(u_lo)
        .map(|(&a, &b)| Dd::new(a) + Dd::new(b))
        .collect();
    let l = lengths_dd(mesh, structure, eta_lo, &ud)?;
    let mut r = vec![0.0; nv];
    residual_dd(mesh, &l, &mut r)?;
    Ok(r.iter().map(|x| -x).collect())
}

/// The max |K| over the vertices of a hyperbolic metric given by its edge lengths (with low
/// parts when double-double), evaluated in double-double from the lengths themselves (see the
/// module docs): what a polish to target 0 would start from, at the cost of one residual.
/// Errors: not H², a length count other than the mesh's edges, a face violating the triangle
/// inequality, a curvature of 1e-3 or more somewhere.
pub fn max_curvature_dd(mesh: &Mesh, metric: &IntrinsicMetric) -> Result<f64> {
    metric.require(Geometry::Hyperbolic, "the double-double curvature")?;
    if metric.len() != mesh.n_edges() {
        return Err(Error::input(format!(
            "{} edge lengths for a mesh with {} edges",
            metric.len(),
            mesh.n_edges()
        )));
    }
    let lengths: Vec<Dd> = (0..mesh.n_edges()).map(|e| metric.length_dd(e)).collect();
    let mut r = vec![0.0; mesh.n_vertices()];
    residual_dd(mesh, &lengths, &mut r)?;
    Ok(r.iter().fold(0.0, |m: f64, x| m.max(x.abs())))
}

/// Polish the hyperbolic metric of `structure` at variables `u` (a converged flow's) to
/// double-double, for the target `K̄ = 0` on every vertex not `fixed` (see the module docs).
/// `eta_lo` optionally gives low parts of the per-edge coefficients (vertex scaling of a
/// double-double metric).
///
/// Errors: not H², a nonzero target on a free vertex, wrong array sizes, a metric that is
/// not converged (curvature error ≥ 1e-3 somewhere), a Hessian that cannot be factored.
pub fn polish_metric(
    mesh: &Mesh,
    structure: &ConformalStructure,
    eta_lo: Option<&[f64]>,
    u: &[f64],
    target: &[f64],
    fixed: &[bool],
    settings: &PolishSettings,
) -> Result<PolishedMetric> {
    if structure.geometry != Geometry::Hyperbolic {
        return Err(Error::input(format!(
            "the double-double polish is implemented for hyperbolic metrics only, not {}",
            structure.geometry
        )));
    }
    let nv = mesh.n_vertices();
    if u.len() != nv || target.len() != nv || fixed.len() != nv {
        return Err(Error::input(format!(
            "polish: {} variables, {} targets and {} fixed flags for {nv} vertices",
            u.len(),
            target.len(),
            fixed.len()
        )));
    }
    if structure.eta.len() != mesh.n_edges() || eta_lo.is_some_and(|l| l.len() != mesh.n_edges()) {
        return Err(Error::input(
            "polish: the conformal structure does not match the mesh's edges",
        ));
    }
    if let Some(v) = (0..nv).find(|&v| !fixed[v] && target[v] != 0.0 && !mesh.is_isolated(v as u32))
    {
        return Err(Error::input(format!(
            "the double-double polish supports the target curvature 0 only (uniform or \
             geodesic-boundary hyperbolic metrics); vertex {v} has target {:e}",
            target[v]
        )));
    }
    let mut ev = Evaluator::new(mesh, structure.clone());
    let pattern = HessianPattern::new(&ev.data, fixed);
    let mut values = vec![0.0; pattern.nnz()];
    if !ev.evaluate_with_hessian(u, &pattern, &mut values) {
        return Err(Error::numerical(
            "polish: the metric lies outside the domain of the scheme",
        ));
    }
    let mut solver = SymmetricSolver::new(&pattern)?;
    if !solver.factor_llt(&values) {
        return Err(Error::numerical(
            "polish: the Hessian is not positive definite",
        ));
    }
    let mut ud: Vec<Dd> = u.iter().map(|&x| Dd::new(x)).collect();
    let mut r = vec![0.0; nv];
    let mut rhs = vec![0.0; pattern.n()];
    let max_free = |r: &[f64]| {
        (0..nv)
            .filter(|&v| !fixed[v])
            .map(|v| r[v].abs())
            .fold(0.0, f64::max)
    };
    let mut lengths = lengths_dd(mesh, structure, eta_lo, &ud)?;
    residual_dd(mesh, &lengths, &mut r)?;
    let mut err = max_free(&r);
    let residual_start = err;
    let mut history = vec![err];
    let mut steps = 0;
    while err > settings.tolerance && steps < settings.max_steps {
        for (c, &v) in pattern.free_vertex.iter().enumerate() {
            rhs[c] = r[v as usize];
        }
        solver.solve(&mut rhs);
        let mut trial = ud.clone();
        for (c, &v) in pattern.free_vertex.iter().enumerate() {
            trial[v as usize] = trial[v as usize] + Dd::new(rhs[c]);
        }
        let l = lengths_dd(mesh, structure, eta_lo, &trial)?;
        let mut rt = vec![0.0; nv];
        residual_dd(mesh, &l, &mut rt)?;
        let e = max_free(&rt);
        steps += 1;
        history.push(e);
        if !(e < err) {
            // At the floor of the double-double evaluation: keep the better point.
            break;
        }
        ud = trial;
        lengths = l;
        r = rt;
        err = e;
    }
    Ok(PolishedMetric {
        u: ud.iter().map(|x| x.hi).collect(),
        u_lo: ud.iter().map(|x| x.lo).collect(),
        metric: IntrinsicMetric::with_low_parts(
            Geometry::Hyperbolic,
            lengths.iter().map(|x| x.hi).collect(),
            lengths.iter().map(|x| x.lo).collect(),
        )?,
        steps,
        residual_start,
        residual_dd: err,
        history,
        converged: err <= settings.tolerance,
    })
}
