//! Genus ≥ 2, step 3: one cubic spline per cylinder of [`super::genus_domain`], fitted to the
//! data points in it, extracted to Bézier patches for export.
//!
//! **A simpler design than paper 003's** (documented in `docs/notes/wave2-s6-tsp6.md`): each
//! cylinder `[0, L) × [0, H]` carries its own tensor-product cubic B-spline, periodic and
//! uniform in `u` (`nu` spans), clamped and uniform in `v` (`nv` spans), fitted by least
//! squares plus a small fairness term (squared second differences of the control net), and
//! refined uniformly (the coarser direction doubles) until its largest error is below the
//! tolerance or a budget is spent. Inside a cylinder the surface is C²; the cylinders are
//! **not** joined along the critical trajectories (no shared control points, no T-junctions
//! continuing through the gluing translations): the jumps there are measured
//! ([`GenusFit::glued_jumps`]) from the crossings of the mesh edges with the critical levels,
//! and they are of the size of the fitting error. The zeros (extraordinary points) lie on the
//! cylinders' boundaries, so the same measure covers them.
//!
//! For export every cylinder's domain is translated to `u + offset` (offsets separate the
//! cylinders, so every Bézier patch has its own parameter rectangle).

use super::basis::cubic;
use super::bezier::{interpolate_patch, BezierPatch, Continuity};
use super::fit::bbox_scale;
use super::genus_domain::GenusDomain;
use crate::error::{Error, Result};
use crate::numeric::sparse::Cholesky;
use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;
use serde::Serialize;

/// A tensor-product cubic spline on one cylinder: `control[j * nu + i]`, `i < nu` (periodic in
/// `u`), `j < nv + 3` (clamped in `v`).
#[derive(Debug, Clone)]
pub struct CylinderSpline {
    pub circumference: f64,
    pub height: f64,
    pub nu: usize,
    pub nv: usize,
    pub control: Vec<[f64; 3]>,
}

impl CylinderSpline {
    fn hu(&self) -> f64 {
        self.circumference / self.nu as f64
    }

    fn hv(&self) -> f64 {
        self.height / self.nv as f64
    }

    /// The (at most 16) basis functions non-zero at `(u, v)`: control index and value.
    fn basis(&self, u: f64, v: f64, out: &mut Vec<(usize, f64)>) {
        out.clear();
        let (l, h) = (self.circumference, self.height);
        let (hu, hv) = (self.hu(), self.hv());
        let u = u.rem_euclid(l);
        let v = v.clamp(0.0, h * (1.0 - 1e-14));
        let su = ((u / hu).floor() as isize).clamp(0, self.nu as isize - 1);
        let sv = ((v / hv).floor() as usize).min(self.nv - 1);
        let nu = self.nu as isize;
        let vk = |k: isize| (k.clamp(0, self.nv as isize) as f64) * hv;
        for j in sv..sv + 4 {
            // clamped knots: function j uses tau[j..j + 5], tau[k] = vk(k − 3)
            let tv: [f64; 5] = std::array::from_fn(|k| vk(j as isize + k as isize - 3));
            let bv = cubic(&tv, v)[0];
            if bv == 0.0 {
                continue;
            }
            for i in su - 1..su + 3 {
                let tu: [f64; 5] = std::array::from_fn(|k| (i + k as isize - 2) as f64 * hu);
                let bu = cubic(&tu, u)[0];
                if bu != 0.0 {
                    out.push((j * self.nu + i.rem_euclid(nu) as usize, bu * bv));
                }
            }
        }
    }

    pub fn point(&self, u: f64, v: f64) -> [f64; 3] {
        let mut b = Vec::with_capacity(16);
        self.basis(u, v, &mut b);
        let mut p = [0.0; 3];
        for (k, w) in b {
            for d in 0..3 {
                p[d] += w * self.control[k][d];
            }
        }
        p
    }
}

/// One refinement step (all cylinders).
#[derive(Debug, Clone, Serialize)]
pub struct GenusStep {
    pub control_points: usize,
    pub rms_error_percent: f64,
    pub max_error_percent: f64,
}

/// The fitted splines of all cylinders.
#[derive(Debug, Clone)]
pub struct GenusFit {
    pub splines: Vec<CylinderSpline>,
    /// `u` offset of each cylinder's domain in the exported parameter space.
    pub offsets: Vec<f64>,
    /// Error per data point (`GenusDomain::points` order), in the units of the positions.
    pub errors: Vec<f64>,
    pub steps: Vec<GenusStep>,
    pub converged: bool,
    /// Longest bounding-box side (errors in percent are relative to it).
    pub scale: f64,
}

/// Options of [`fit_cylinders`].
#[derive(Debug, Clone, Copy)]
pub struct GenusFitOptions {
    /// L∞ tolerance as a fraction of the longest bounding-box side.
    pub tolerance: f64,
    /// Weight of the fairness term (relative to the data term per control point).
    pub smoothing: f64,
    /// Data points per span of the initial grid (about).
    pub points_per_span: usize,
    pub max_iterations: usize,
    pub max_control_points: usize,
    /// Weight of the gluing penalty at each crossing of a critical level (a data point weighs
    /// 1); 0 fits the cylinders independently.
    pub glue: f64,
}

impl Default for GenusFitOptions {
    fn default() -> Self {
        GenusFitOptions {
            tolerance: 0.005,
            smoothing: 1e-4,
            points_per_span: 20,
            max_iterations: 12,
            max_control_points: 20_000,
            glue: 100.0,
        }
    }
}

/// Data and fairness terms of one cylinder (unknowns `base..base + nu (nv + 3)`).
fn assemble_one(
    s: &CylinderSpline,
    base: usize,
    data: &[([f64; 2], [f64; 3])],
    smoothing: f64,
    trip: &mut Vec<Triplet<usize, usize, f64>>,
    rhs: &mut Mat<f64>,
) {
    let (nu, nv) = (s.nu, s.nv);
    let n = nu * (nv + 3);
    let mut b = Vec::with_capacity(16);
    for (uv, p) in data {
        s.basis(uv[0], uv[1], &mut b);
        for &(r, x) in &b {
            for &(c, y) in &b {
                trip.push(Triplet::new(base + r, base + c, x * y));
            }
            for d in 0..3 {
                rhs[(base + r, d)] += x * p[d];
            }
        }
    }
    // fairness: second differences along u (periodic), v, and the mixed difference
    let w = smoothing * (data.len() as f64 / n as f64).max(1.0);
    let idx = |i: usize, j: usize| base + j * nu + i % nu;
    let mut push = |row: &[(usize, f64)]| {
        for &(r, x) in row {
            for &(c, y) in row {
                trip.push(Triplet::new(r, c, w * x * y));
            }
        }
    };
    for j in 0..nv + 3 {
        for i in 0..nu {
            push(&[
                (idx(i + nu - 1, j), 1.0),
                (idx(i, j), -2.0),
                (idx(i + 1, j), 1.0),
            ]);
            if j + 2 < nv + 3 {
                push(&[
                    (idx(i, j), 1.0),
                    (idx(i, j + 1), -2.0),
                    (idx(i, j + 2), 1.0),
                ]);
            }
            if j + 1 < nv + 3 {
                push(&[
                    (idx(i, j), 1.0),
                    (idx(i + 1, j), -1.0),
                    (idx(i, j + 1), -1.0),
                    (idx(i + 1, j + 1), 1.0),
                ]);
            }
        }
    }
}

/// All cylinders in one least-squares system: data, fairness, and the gluing penalty
/// `glue · |S_lower(u, H) − S_upper(u', 0)|²` at every crossing of a critical level.
fn solve_all(
    domain: &GenusDomain,
    grids: &[(usize, usize)],
    data: &[Vec<([f64; 2], [f64; 3])>],
    smoothing: f64,
    glue: f64,
) -> Result<Vec<CylinderSpline>> {
    let mut splines: Vec<CylinderSpline> = domain
        .cylinders
        .iter()
        .zip(grids)
        .map(|(c, &(nu, nv))| CylinderSpline {
            circumference: c.circumference,
            height: c.height,
            nu,
            nv,
            control: vec![[0.0; 3]; nu * (nv + 3)],
        })
        .collect();
    let mut base = Vec::with_capacity(splines.len());
    let mut n = 0;
    for s in &splines {
        base.push(n);
        n += s.control.len();
    }
    let mut trip: Vec<Triplet<usize, usize, f64>> = Vec::new();
    let mut rhs = Mat::<f64>::zeros(n, 3);
    for (k, s) in splines.iter().enumerate() {
        assemble_one(s, base[k], &data[k], smoothing, &mut trip, &mut rhs);
    }
    let (mut ba, mut bb) = (Vec::new(), Vec::new());
    for x in &domain.crossings {
        let (a, b) = (&splines[x.lower], &splines[x.upper]);
        a.basis(x.u_lower, a.height, &mut ba);
        b.basis(x.u_upper, 0.0, &mut bb);
        let row: Vec<(usize, f64)> = ba
            .iter()
            .map(|&(i, w)| (base[x.lower] + i, w))
            .chain(bb.iter().map(|&(i, w)| (base[x.upper] + i, -w)))
            .collect();
        for &(r, p) in &row {
            for &(c, q) in &row {
                trip.push(Triplet::new(r, c, glue * p * q));
            }
        }
    }
    let points: usize = data.iter().map(|d| d.len()).sum();
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &trip).map_err(|e| {
        Error::numerical(format!(
            "cylinder fit: the normal equations ({n} unknowns) cannot be assembled: {e:?}"
        ))
    })?;
    let chol = Cholesky::factor(a.as_ref()).map_err(|e| {
        Error::numerical(format!(
            "cylinder fit: the normal equations ({n} unknowns, {points} points) are not positive definite: {e:?}"
        ))
    })?;
    chol.solve_in_place(rhs.as_mut());
    for (k, s) in splines.iter_mut().enumerate() {
        for i in 0..s.control.len() {
            let r = base[k] + i;
            s.control[i] = [rhs[(r, 0)], rhs[(r, 1)], rhs[(r, 2)]];
            if s.control[i].iter().any(|x| !x.is_finite()) {
                return Err(Error::numerical(
                    "cylinder fit: the solve gave non-finite control points",
                ));
            }
        }
    }
    Ok(splines)
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Fit every cylinder of `domain` to `positions` (indexed by the points' `vertex`).
pub fn fit_cylinders(
    domain: &GenusDomain,
    positions: &[[f64; 3]],
    opts: &GenusFitOptions,
) -> Result<GenusFit> {
    if !(opts.tolerance > 0.0 && opts.smoothing >= 0.0) {
        return Err(Error::input(format!(
            "cylinder fit: tolerance {} must be > 0 and smoothing {} ≥ 0",
            opts.tolerance, opts.smoothing
        )));
    }
    let scale = bbox_scale(positions);
    let tol = opts.tolerance * scale;
    let nc = domain.cylinders.len();
    let mut data: Vec<Vec<([f64; 2], [f64; 3])>> = vec![Vec::new(); nc];
    for p in &domain.points {
        let Some(x) = positions.get(p.vertex as usize) else {
            return Err(Error::input(format!(
                "data point {} has no position ({} given)",
                p.vertex,
                positions.len()
            )));
        };
        data[p.cylinder].push(([p.u, p.v], *x));
    }
    // initial grids: about `points_per_span` data points per span, square-ish spans
    let mut grids: Vec<(usize, usize)> = domain
        .cylinders
        .iter()
        .zip(&data)
        .map(|(c, d)| {
            let spans = (d.len() / opts.points_per_span.max(1)).max(4) as f64;
            let nu = (spans * c.circumference / c.height).sqrt().round() as usize;
            let nu = nu.max(4);
            let nv = ((spans / nu as f64).round() as usize).max(1);
            (nu, nv)
        })
        .collect();
    let mut steps = Vec::new();
    let mut converged = false;
    let mut splines: Vec<CylinderSpline> = Vec::new();
    let mut errors: Vec<Vec<f64>> = Vec::new();
    for _ in 0..opts.max_iterations.max(1) {
        splines = solve_all(domain, &grids, &data, opts.smoothing, opts.glue)?;
        errors = splines
            .iter()
            .zip(&data)
            .map(|(s, d)| {
                d.iter()
                    .map(|(uv, p)| dist(s.point(uv[0], uv[1]), *p))
                    .collect()
            })
            .collect();
        let all: Vec<f64> = errors.iter().flatten().copied().collect();
        let max = all.iter().copied().fold(0.0, f64::max);
        let rms = (all.iter().map(|e| e * e).sum::<f64>() / all.len().max(1) as f64).sqrt();
        let count: usize = splines.iter().map(|s| s.control.len()).sum();
        steps.push(GenusStep {
            control_points: count,
            rms_error_percent: 100.0 * rms / scale,
            max_error_percent: 100.0 * max / scale,
        });
        if max <= tol {
            converged = true;
            break;
        }
        // refine the cylinders above the tolerance: the coarser direction doubles
        let mut next = grids.clone();
        for c in 0..nc {
            if errors[c].iter().any(|&e| e > tol) {
                let (nu, nv) = grids[c];
                let s = &splines[c];
                next[c] = if s.hu() >= s.hv() {
                    (2 * nu, nv)
                } else {
                    (nu, 2 * nv)
                };
            }
        }
        let total: usize = next.iter().map(|&(nu, nv)| nu * (nv + 3)).sum();
        if total > opts.max_control_points {
            break;
        }
        grids = next;
    }
    // per-point errors in the order of domain.points
    let mut cursor = vec![0usize; nc];
    let flat: Vec<f64> = domain
        .points
        .iter()
        .map(|p| {
            let e = errors[p.cylinder][cursor[p.cylinder]];
            cursor[p.cylinder] += 1;
            e
        })
        .collect();
    let gap = splines.iter().map(|s| s.circumference).fold(0.0, f64::max) * 0.25;
    let mut offsets = Vec::with_capacity(nc);
    let mut at = 0.0;
    for s in &splines {
        offsets.push(at);
        at += s.circumference + gap;
    }
    Ok(GenusFit {
        splines,
        offsets,
        errors: flat,
        steps,
        converged,
        scale,
    })
}

impl GenusFit {
    pub fn control_points(&self) -> usize {
        self.splines.iter().map(|s| s.control.len()).sum()
    }

    /// Bézier patches, cylinder by cylinder, row by row (`v` span `j`, then `u` span `i`), in
    /// the exported parameter space (`u + offset`).
    pub fn patches(&self) -> Vec<BezierPatch> {
        let mut out = Vec::new();
        for (s, &off) in self.splines.iter().zip(&self.offsets) {
            let (hu, hv) = (s.hu(), s.hv());
            for j in 0..s.nv {
                for i in 0..s.nu {
                    let (u0, v0) = (i as f64 * hu, j as f64 * hv);
                    let p = interpolate_patch(u0, u0 + hu, v0, v0 + hv, |u, v| s.point(u, v));
                    out.push(shift(p, off));
                }
            }
        }
        out
    }

    /// Index of the first patch of each cylinder in [`GenusFit::patches`].
    fn first_patch(&self) -> Vec<usize> {
        let mut at = 0;
        self.splines
            .iter()
            .map(|s| {
                let f = at;
                at += s.nu * s.nv;
                f
            })
            .collect()
    }

    /// Jumps of the partials of orders 0..=3 across every side shared by two patches of the
    /// same cylinder (including the periodic seam), `samples` points per side.
    pub fn interior_jumps(&self, patches: &[BezierPatch], samples: usize) -> Continuity {
        let first = self.first_patch();
        let mut c = empty();
        for (k, s) in self.splines.iter().enumerate() {
            for j in 0..s.nv {
                for i in 0..s.nu {
                    let q = &patches[first[k] + j * s.nu + i];
                    let right = &patches[first[k] + j * s.nu + (i + 1) % s.nu];
                    for m in 0..samples {
                        let t = (m as f64 + 0.5) / samples as f64;
                        let v = q.v0 + t * (q.v1 - q.v0);
                        compare(&mut c, q, (q.u1, v), right, (right.u0, v), 3);
                        if j + 1 < s.nv {
                            let up = &patches[first[k] + (j + 1) * s.nu + i];
                            let u = q.u0 + t * (q.u1 - q.u0);
                            compare(&mut c, q, (u, q.v1), up, (u, up.v0), 3);
                        }
                    }
                }
            }
        }
        c
    }

    /// Jumps of the partials of orders 0..=2 across the critical trajectories, at the
    /// crossings of mesh edges with the critical levels (top of the cylinder below against
    /// the bottom of the cylinder above; the flat coordinates of the two sides differ by a
    /// translation, so partials compare directly), and at the midpoints of consecutive
    /// crossings glued by the same translation (not penalized by the fit; their count is
    /// returned). Order 3 is not compared (zero entry).
    pub fn glued_jumps(
        &self,
        patches: &[BezierPatch],
        domain: &GenusDomain,
    ) -> (Continuity, usize) {
        let first = self.first_patch();
        let mut c = empty();
        let locate = |k: usize, u: f64, top: bool| -> (usize, f64) {
            let s = &self.splines[k];
            let i = ((u / s.hu()).floor() as usize).min(s.nu - 1);
            let j = if top { s.nv - 1 } else { 0 };
            (first[k] + j * s.nu + i, u + self.offsets[k])
        };
        let mut pts: Vec<(usize, f64, usize, f64)> = domain
            .crossings
            .iter()
            .map(|x| (x.lower, x.u_lower, x.upper, x.u_upper))
            .collect();
        // midpoints of consecutive crossings glued by the same translation: points where the
        // gluing penalty of the fit was not applied
        pts.sort_by(|a, b| (a.0, a.2).cmp(&(b.0, b.2)).then(a.1.total_cmp(&b.1)));
        let mut mids = Vec::new();
        for w in pts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let lu = self.splines[a.2].circumference;
            let shift = |x: (usize, f64, usize, f64)| (x.3 - x.1).rem_euclid(lu);
            let ds = (shift(a) - shift(b)).abs();
            let close = b.1 - a.1 < 0.1 * self.splines[a.0].circumference;
            if a.0 == b.0 && a.2 == b.2 && close && ds.min(lu - ds) < 1e-9 * lu {
                let m = 0.5 * (a.1 + b.1);
                mids.push((a.0, m, a.2, (m + shift(a)).rem_euclid(lu)));
            }
        }
        let n_mids = mids.len();
        pts.extend(mids);
        for (lower, ul, upper, uu) in pts {
            let (p, u) = locate(lower, ul, true);
            let (q, w) = locate(upper, uu, false);
            let h = self.splines[lower].height;
            compare(&mut c, &patches[p], (u, h), &patches[q], (w, 0.0), 2);
        }
        (c, n_mids)
    }

    /// A point of cylinder `k` at its own `(u, v)` (not the exported offset).
    pub fn point(&self, k: usize, u: f64, v: f64) -> [f64; 3] {
        self.splines[k].point(u, v)
    }
}

fn shift(mut p: BezierPatch, off: f64) -> BezierPatch {
    p.u0 += off;
    p.u1 += off;
    p
}

fn empty() -> Continuity {
    Continuity {
        jumps: [0.0; 4],
        magnitudes: [0.0; 4],
        comparisons: 0,
    }
}

fn compare(
    c: &mut Continuity,
    p: &BezierPatch,
    a: (f64, f64),
    q: &BezierPatch,
    b: (f64, f64),
    orders: usize,
) {
    c.comparisons += 1;
    for order in 0..=orders {
        for i in 0..=order {
            let x = p.partial(a.0, a.1, i, order - i);
            let y = q.partial(b.0, b.1, i, order - i);
            c.jumps[order] = c.jumps[order].max(dist(x, y));
            c.magnitudes[order] = c.magnitudes[order].max(dist(x, [0.0; 3]));
        }
    }
}
