//! The cylinder decomposition of a closed surface of genus `g ≥ 1` by the critical horizontal
//! trajectories of a holomorphic 1-form (paper 003 §2, "high genus closed surfaces", Fig. 2):
//! the first step of the domain manifold for genus ≥ 2.
//!
//! Horizontal trajectories are the curves along which `Im ω = 0`, i.e. the level sets of
//! `v = Im ∫ω`. For a general form they do not close; they do when `Im ω` has integer
//! periods, for then `v mod 1` is a circle-valued harmonic function ([`integral_form`] finds
//! the holomorphic form whose imaginary part is the harmonic form `ζ_k` dual to loop `k`).
//! Its critical points are the zeros of `ω` (`2g − 2` with multiplicity); the level sets
//! through them — the critical horizontal trajectories — cut the surface into bands between
//! consecutive critical values, and every band is a union of flat cylinders
//! `[0, L) × [v_a, v_b]` (`u = Re ∫ω` around, `v` up): the rectangles of the domain manifold,
//! glued along the critical trajectories by translations.
//!
//! [`cylinders`] computes, on the cut mesh of the forms (the conformal net), each band's
//! height and, at its middle level, the components of the level set (one per cylinder) and
//! their circumferences `L = ∮ du` (signed: a face whose uv image is reversed, near a zero,
//! counts negatively). Checks that do not come from the decomposition: the coarea formula
//! `Σ_cylinders L·H = ∫ du∧dv` (the signed uv area of the net), and the circumferences at a
//! second level of each band (homologous curves: the same `∮ du`).
//!
//! A level curve is also **developed** ([`LevelCurve::crossings`]): walking it face by face,
//! `u` at each crossed edge is the sum of the face segments' `Δu` before it (on a face the form
//! is affine, so `Δu` is the flat length; the net's jumps across the cut do not enter), and
//! the walk's total is `±∮ du`. [`super::genus_domain`] gives a thin band's cylinders (no
//! vertex inside) their `u` this way.

use crate::analysis::forms::cochain::period;
use crate::analysis::forms::small::solve;
use crate::analysis::forms::{HolomorphicForm, HolomorphicForms, Zero};
use crate::error::{Error, Result};
use crate::layout::isometry::Complex;
use serde::Serialize;

/// One cylinder of the decomposition.
#[derive(Debug, Clone, Serialize)]
pub struct Cylinder {
    /// Index of its band (between critical levels `levels[band]` and the next one).
    pub band: usize,
    /// `v` of its bottom (mod 1) and its height.
    pub bottom: f64,
    pub height: f64,
    /// `∮ du` around it at the band's middle level, and at a second level (one third).
    pub circumference: f64,
    pub circumference_check: f64,
    /// Faces of the cut mesh its middle level curve crosses.
    pub faces_crossed: usize,
}

/// The decomposition and its checks.
#[derive(Debug, Clone, Serialize)]
pub struct CylinderDecomposition {
    /// The loop whose dual harmonic form is `Im ω` (`∫_{γ_l} Im ω = δ_kl`).
    pub class: usize,
    /// `max_l |∫_{γ_l} Im ω − δ_kl|` (0 up to the solve's rounding).
    pub period_defect: f64,
    pub zeros: Vec<Zero>,
    /// Critical values `v mod 1` of the zeros, sorted, merged within 1e-9.
    pub levels: Vec<f64>,
    pub cylinders: Vec<Cylinder>,
    /// `∫ du∧dv` over the net (signed uv area of the cut mesh).
    pub area: f64,
    /// `Σ L·H` over the cylinders.
    pub cylinder_area: f64,
}

/// The holomorphic form `ω` with `Im ω = ζ_k` (the harmonic form with periods `δ_kl` on the
/// loops `a₁, b₁, …`), and `max_l |∫_{γ_l} Im ω − δ_kl|`.
pub fn integral_form(h: &HolomorphicForms, k: usize) -> Result<(HolomorphicForm, f64)> {
    let g = h.genus;
    let n = 2 * g;
    if k >= n {
        return Err(Error::input(format!(
            "loop {k} does not exist: a genus-{g} surface has {n} loops"
        )));
    }
    let mesh = h.mesh();
    let periods = |w: &[f64]| -> Vec<f64> {
        h.cut
            .loops
            .iter()
            .take(n)
            .map(|lp| period(mesh, w, &lp.halfedges))
            .collect()
    };
    // Im(Σ (x_j + i y_j) ω_j) = Σ x_j Im ω_j + y_j Re ω_j: columns x_1 … x_g, y_1 … y_g
    let mut cols: Vec<Vec<f64>> = h.basis.iter().map(|w| periods(&w.im)).collect();
    cols.extend(h.basis.iter().map(|w| periods(&w.re)));
    let a: Vec<Vec<f64>> = (0..n)
        .map(|l| (0..n).map(|j| cols[j][l]).collect())
        .collect();
    let mut e = vec![0.0; n];
    e[k] = 1.0;
    let x = solve(&a, &e);
    if x.iter().any(|t| !t.is_finite()) {
        return Err(Error::numerical(
            "the periods of the holomorphic basis are singular: no form with integer imaginary periods",
        ));
    }
    let c: Vec<Complex> = (0..g).map(|j| Complex::new(x[j], x[g + j])).collect();
    let form = h.combination(&c);
    let got = periods(&form.im);
    let defect = got
        .iter()
        .enumerate()
        .map(|(l, p)| (p - if l == k { 1.0 } else { 0.0 }).abs())
        .fold(0.0, f64::max);
    Ok((form, defect))
}

/// The cylinders of `form` (whose imaginary part must have integer periods, e.g. from
/// [`integral_form`]; `class` is recorded only).
pub fn cylinders(
    h: &HolomorphicForms,
    form: &HolomorphicForm,
    class: usize,
    period_defect: f64,
) -> Result<CylinderDecomposition> {
    let zeros = h.zeros(form)?.zeros;
    let net = h.net(form)?;
    let cut = &h.cut;
    let cm = &cut.cut_mesh;
    let uv = &net.uv;
    // the critical values, from any cut copy of each zero's vertex
    let mut levels: Vec<f64> = Vec::new();
    for z in &zeros {
        let Some(c) = cut.cut_vertex_origin.iter().position(|&o| o == z.vertex) else {
            return Err(Error::topology(format!(
                "zero at vertex {} has no copy in the cut mesh",
                z.vertex
            )));
        };
        levels.push(uv[c][1].rem_euclid(1.0));
    }
    levels.sort_by(f64::total_cmp);
    levels.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    let bands: Vec<(f64, f64)> = if levels.is_empty() {
        vec![(0.0, 1.0)]
    } else {
        (0..levels.len())
            .map(|i| {
                let lo = levels[i];
                let hi = if i + 1 < levels.len() {
                    levels[i + 1]
                } else {
                    levels[0] + 1.0
                };
                (lo, hi - lo)
            })
            .collect()
    };
    let mut area = 0.0;
    for f in 0..cm.n_faces() as u32 {
        let [a, b, c] = cm.face(f).map(|v| uv[v as usize]);
        area += 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
    }
    let mut out = Vec::new();
    for (band, &(bottom, height)) in bands.iter().enumerate() {
        let mid = level_curves(h, uv, (bottom + 0.5 * height).rem_euclid(1.0))?;
        let third = level_curves(h, uv, (bottom + height / 3.0).rem_euclid(1.0))?;
        let mut check: Vec<f64> = third.iter().map(|c| c.circumference).collect();
        for LevelCurve {
            circumference: length,
            faces,
            ..
        } in mid
        {
            // the homologous curve at the other level: the closest circumference
            let j = check
                .iter()
                .enumerate()
                .min_by(|x, y| (x.1 - length).abs().total_cmp(&(y.1 - length).abs()))
                .map(|(j, _)| j);
            let other = j.map_or(f64::NAN, |j| check.swap_remove(j));
            out.push(Cylinder {
                band,
                bottom,
                height,
                circumference: length,
                circumference_check: other,
                faces_crossed: faces,
            });
        }
    }
    let cylinder_area = out.iter().map(|c| c.circumference * c.height).sum();
    Ok(CylinderDecomposition {
        class,
        period_defect,
        zeros,
        levels,
        cylinders: out,
        area,
        cylinder_area,
    })
}

/// One closed component of a level set `v ≡ t (mod 1)`, developed along itself.
#[derive(Debug, Clone)]
pub struct LevelCurve {
    /// Signed `∮ du` (a face whose uv image is reversed counts negatively).
    pub circumference: f64,
    /// Faces of the cut mesh it crosses.
    pub faces: usize,
    /// The refined-mesh edges it crosses: the half-edge along which `v` increases, the
    /// parameter `s ∈ (0, 1)` of the crossing point from that half-edge's origin, and its `u`
    /// developed along the curve (the sum of the face segments `Δu` from the first crossing;
    /// defined mod `|circumference|`).
    pub crossings: Vec<(u32, f64, f64)>,
}

/// Where the level enters or leaves a face of the net: the half-edge of that side along which
/// `v` increases, the parameter from its origin, and the crossing's `u` in the face's uv image.
type FaceCrossing = (u32, f64, f64);

/// The components of the level set `v ≡ t (mod 1)` on the net (`uv`: the net's coordinates),
/// each developed ([`LevelCurve`]). Every crossed edge must be crossed once and meet two
/// crossed faces (a closed 1-manifold), else an error naming the edge.
pub(crate) fn level_curves(
    h: &HolomorphicForms,
    uv: &[[f64; 2]],
    t: f64,
) -> Result<Vec<LevelCurve>> {
    let cm = &h.cut.cut_mesh;
    let refined = h.mesh();
    let ne = refined.n_edges();
    // per refined edge, the faces whose level segment ends on it
    let mut ends: Vec<Vec<u32>> = vec![Vec::new(); ne];
    let mut segment = vec![0.0f64; cm.n_faces()];
    let mut at: Vec<[FaceCrossing; 2]> = vec![[(0, 0.0, 0.0); 2]; cm.n_faces()];
    let mut crossed = vec![false; cm.n_faces()];
    for f in 0..cm.n_faces() as u32 {
        let corners = cm.face(f).map(|v| uv[v as usize]);
        let lo = corners.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
        let hi = corners
            .iter()
            .map(|p| p[1])
            .fold(f64::NEG_INFINITY, f64::max);
        let k0 = (lo - t).ceil();
        if !(k0 + t < hi) {
            continue;
        }
        if k0 + 1.0 + t < hi {
            return Err(Error::numerical(format!(
                "face {f} spans more than one period of Im ω (refine the mesh)"
            )));
        }
        let level = k0 + t;
        let mut us = Vec::with_capacity(2);
        for i in 0..3 {
            let (p, q) = (corners[i], corners[(i + 1) % 3]);
            if (p[1] - level) * (q[1] - level) < 0.0 {
                let s = (level - p[1]) / (q[1] - p[1]);
                let u = p[0] + s * (q[0] - p[0]);
                let hh = 3 * f + i as u32;
                if us.len() < 2 {
                    at[f as usize][us.len()] = if q[1] > p[1] {
                        (hh, s, u)
                    } else {
                        (refined.he_twin(hh), 1.0 - s, u)
                    };
                }
                us.push(u);
                ends[refined.he_edge(3 * f + i as u32) as usize].push(f);
            }
        }
        if us.len() != 2 {
            return Err(Error::numerical(format!(
                "the level {t:.6} passes through a vertex of face {f}"
            )));
        }
        let [a, b, c] = corners;
        let det = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        segment[f as usize] = det.signum() * (us[1] - us[0]).abs();
        crossed[f as usize] = true;
    }
    for (e, fs) in ends.iter().enumerate() {
        if !(fs.is_empty() || fs.len() == 2) {
            return Err(Error::numerical(format!(
                "the level {t:.6} crosses edge {e} {} time(s) from its faces (not a closed curve there)",
                fs.len()
            )));
        }
    }
    // walk every curve face by face: the face across the exit edge is the next one
    let mut seen = vec![false; cm.n_faces()];
    let mut curves = Vec::new();
    for f0 in 0..cm.n_faces() {
        if !crossed[f0] || seen[f0] {
            continue;
        }
        let mut curve = LevelCurve {
            circumference: 0.0,
            faces: 0,
            crossings: Vec::new(),
        };
        let (mut f, mut entry, mut u) = (f0, 0usize, 0.0);
        while !seen[f] {
            seen[f] = true;
            curve.circumference += segment[f];
            curve.faces += 1;
            let (hh, s, u_in) = at[f][entry];
            let (exit, s_out, u_out) = at[f][1 - entry];
            if f == f0 {
                curve.crossings.push((hh, s, u));
            }
            u += u_out - u_in;
            let e = refined.he_edge(exit) as usize;
            let next = ends[e].iter().copied().find(|&g| g as usize != f);
            let Some(g) = next else { break };
            let g = g as usize;
            if g != f0 {
                curve.crossings.push((exit, s_out, u));
            }
            entry = usize::from(refined.he_edge(at[g][0].0) as usize != e);
            f = g;
        }
        curves.push(curve);
    }
    Ok(curves)
}
