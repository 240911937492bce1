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
use super::bezier::{interpolate_patch, BezierPatch};
use super::fit::bbox_scale;
use super::genus_domain::{CylinderChart, GenusDomain};
use super::glue::{gluing, Gluing, RigidLayout};
use crate::error::{Error, Result};
use crate::numeric::sparse::Cholesky;
use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;
use serde::Serialize;

/// A tensor-product cubic spline on one cylinder, in the sheared coordinate
/// `u' = (u − shift − shear · v / H) mod L` of [`super::glue::RigidLayout`]:
/// `control[j * ncu + i]`, `j < nv + 3` (clamped uniform knots in `v`). In `u'`: without knot
/// lines, periodic uniform knots (`nu` spans, `ncu = nu`); with knot lines, every strip
/// between two lines carries clamped uniform knots (`spans[s]` spans, triple knots on the
/// lines), consecutive strips share the control column on their common line
/// (`ncu = Σ (spans[s] + 2)`), so the surface is C⁰ across the lines and C² elsewhere.
#[derive(Debug, Clone)]
pub struct CylinderSpline {
    pub circumference: f64,
    pub height: f64,
    pub shift: f64,
    pub shear: f64,
    /// Knot lines `u'` (sorted, the first at 0); empty: uniform periodic.
    pub lines: Vec<f64>,
    /// Spans per strip (one entry per knot line; `[nu]` without lines).
    pub spans: Vec<usize>,
    pub nu: usize,
    pub nv: usize,
    pub control: Vec<[f64; 3]>,
}

impl CylinderSpline {
    fn new(c: &CylinderChart, layout: Option<&RigidLayout>, spans: Vec<usize>, nv: usize) -> Self {
        let (shift, shear, lines) = layout.map_or((0.0, 0.0, Vec::new()), |y| {
            (y.shift, y.shear, y.lines.clone())
        });
        let nu = spans.iter().sum();
        let mut s = CylinderSpline {
            circumference: c.circumference,
            height: c.height,
            shift,
            shear,
            lines,
            spans,
            nu,
            nv,
            control: Vec::new(),
        };
        s.control = vec![[0.0; 3]; s.ncu() * (nv + 3)];
        s
    }

    /// Control points per row.
    pub fn ncu(&self) -> usize {
        if self.lines.is_empty() {
            self.nu
        } else {
            self.spans.iter().map(|m| m + 2).sum()
        }
    }

    pub(crate) fn hv(&self) -> f64 {
        self.height / self.nv as f64
    }

    /// `u'` of the cylinder point `(u, v)`.
    pub fn param(&self, u: f64, v: f64) -> f64 {
        (u - self.shift - self.shear * v / self.height).rem_euclid(self.circumference)
    }

    fn strip_length(&self, s: usize) -> f64 {
        self.lines.get(s + 1).copied().unwrap_or(self.circumference) - self.lines[s]
    }

    /// First control column of strip `s`.
    pub fn strip_start(&self, s: usize) -> usize {
        self.spans[..s].iter().map(|m| m + 2).sum()
    }

    /// The `nu + 1` span boundaries in `u'` (from 0 to `L`), and whether each is a knot line.
    pub fn breaks(&self) -> Vec<(f64, bool)> {
        if self.lines.is_empty() {
            let h = self.circumference / self.nu as f64;
            return (0..=self.nu).map(|i| (i as f64 * h, false)).collect();
        }
        let mut out = Vec::with_capacity(self.nu + 1);
        for (s, &m) in self.spans.iter().enumerate() {
            let (a, h) = (self.lines[s], self.strip_length(s) / m as f64);
            for i in 0..m {
                out.push((a + i as f64 * h, i == 0));
            }
        }
        out.push((self.circumference, true));
        out
    }

    /// The (at most 4) `u` functions non-zero at `u' ∈ [0, L)`: column, value, derivative.
    fn ubasis(&self, u: f64, out: &mut Vec<(usize, [f64; 2])>) {
        out.clear();
        let l = self.circumference;
        if self.lines.is_empty() {
            let (hu, nu) = (l / self.nu as f64, self.nu as isize);
            let su = ((u / hu).floor() as isize).clamp(0, nu - 1);
            for i in su - 1..su + 3 {
                let tu: [f64; 5] = std::array::from_fn(|k| (i + k as isize - 2) as f64 * hu);
                let b = cubic(&tu, u);
                if b[0] != 0.0 || b[1] != 0.0 {
                    out.push((i.rem_euclid(nu) as usize, [b[0], b[1]]));
                }
            }
            return;
        }
        let s = self.lines.partition_point(|&x| x <= u).saturating_sub(1);
        let (a, len, m) = (self.lines[s], self.strip_length(s), self.spans[s]);
        let x = u.clamp(a, a + len * (1.0 - 1e-14));
        let h = len / m as f64;
        let q = (((x - a) / h).floor() as usize).min(m - 1);
        let (start, ncu) = (self.strip_start(s), self.ncu());
        let tau = |k: usize| a + (k.clamp(3, m + 3) - 3) as f64 * h;
        for k in q..q + 4 {
            let t: [f64; 5] = std::array::from_fn(|r| tau(k + r));
            let b = cubic(&t, x);
            if b[0] != 0.0 || b[1] != 0.0 {
                out.push(((start + k) % ncu, [b[0], b[1]]));
            }
        }
    }

    /// The (at most 16) basis functions non-zero at `(u', v)`: control index and
    /// `[N, ∂N/∂u', ∂N/∂v]`.
    fn basis_d(&self, u: f64, v: f64, out: &mut Vec<(usize, [f64; 3])>) {
        let mut bu = Vec::with_capacity(4);
        self.ubasis(u.rem_euclid(self.circumference), &mut bu);
        out.clear();
        let (h, hv, ncu) = (self.height, self.hv(), self.ncu());
        let v = v.clamp(0.0, h * (1.0 - 1e-14));
        let sv = ((v / hv).floor() as usize).min(self.nv - 1);
        let vk = |k: isize| (k.clamp(0, self.nv as isize) as f64) * hv;
        for j in sv..sv + 4 {
            // clamped knots: function j uses tau[j..j + 5], tau[k] = vk(k − 3)
            let tv: [f64; 5] = std::array::from_fn(|k| vk(j as isize + k as isize - 3));
            let bv = cubic(&tv, v);
            if bv[0] == 0.0 && bv[1] == 0.0 {
                continue;
            }
            for &(i, b) in &bu {
                out.push((j * ncu + i, [b[0] * bv[0], b[1] * bv[0], b[0] * bv[1]]));
            }
        }
    }

    /// The (at most 16) basis functions non-zero at `(u', v)`: control index and value.
    fn basis(&self, u: f64, v: f64, out: &mut Vec<(usize, f64)>) {
        let mut d = Vec::with_capacity(16);
        self.basis_d(u, v, &mut d);
        out.clear();
        out.extend(d.iter().filter(|x| x.1[0] != 0.0).map(|&(k, x)| (k, x[0])));
    }

    /// The point at the spline's own parameters `(u', v)`.
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
    /// `u'` offset of each cylinder's domain in the exported parameter space.
    pub offsets: Vec<f64>,
    /// Error per data point (`GenusDomain::points` order), in the units of the positions.
    pub errors: Vec<f64>,
    pub steps: Vec<GenusStep>,
    pub converged: bool,
    /// Longest bounding-box side (errors in percent are relative to it).
    pub scale: f64,
    /// The strips and their glues when the boundary rows are shared (C⁰ across the critical
    /// trajectories); `Err(why)` when the fit fell back to the gluing penalty.
    pub gluing: std::result::Result<Gluing, String>,
    /// Distinct unknowns (control points after sharing the glued boundary rows).
    pub unknowns: usize,
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
    /// 1), used only when the boundary rows cannot be shared ([`super::glue::gluing`]).
    pub glue: f64,
    /// Share the glued boundary rows (exact C⁰); `false` forces the penalty.
    pub share: bool,
    /// With shared rows: weight of the tangent penalty `w h² |∂_v S_lower − ∂_v S_upper|²`
    /// (developed `v`, span width `h`) at three points per span of every glued strip, pulling
    /// the two sides towards C¹ (0: off).
    pub tangent: f64,
    /// With shared rows: weight of the knot-line tangent penalty
    /// `w h² |∂_u' S_left − ∂_u' S_right|²` (span width `h`) at three points per `v` span of
    /// every knot line (through the zero copies; C⁰ by the triple knots), pulling the strips
    /// on either side towards C¹ (0: off). Without it the strips fold along the knot lines
    /// (normals up to ~175° apart on eight); with 3 (the default) the knot lines are within a
    /// few degrees of G¹ and so are the corners at the zeros (test
    /// `genus_two_zeros_are_c0_and_their_normal_jump_shrinks_under_refinement`), at the cost
    /// of a higher L∞ for the same control points near the zeros.
    pub line_tangent: f64,
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
            share: true,
            tangent: 1.0,
            line_tangent: 3.0,
        }
    }
}

/// Data and fairness terms of one cylinder (slots `base..base + ncu (nv + 3)`).
fn assemble_one(
    s: &CylinderSpline,
    base: usize,
    data: &[([f64; 2], [f64; 3])],
    smoothing: f64,
    trip: &mut Vec<Triplet<usize, usize, f64>>,
    rhs: &mut [[f64; 3]],
) {
    let (nu, nv) = (s.ncu(), s.nv);
    let n = nu * (nv + 3);
    let mut b = Vec::with_capacity(16);
    for (uv, p) in data {
        s.basis(uv[0], uv[1], &mut b);
        for &(r, x) in &b {
            for &(c, y) in &b {
                trip.push(Triplet::new(base + r, base + c, x * y));
            }
            for d in 0..3 {
                rhs[base + r][d] += x * p[d];
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

fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

/// Unknown per control slot (all cylinders, `base[k] + local`): the top row of every glued
/// strip is the bottom row of the strip above (same columns in order), and the count.
fn shared_unknowns(
    splines: &[CylinderSpline],
    base: &[usize],
    gluing: Option<&Gluing>,
) -> (Vec<usize>, usize) {
    let n = base
        .last()
        .map_or(0, |b| b + splines[splines.len() - 1].control.len());
    let mut parent: Vec<usize> = (0..n).collect();
    for g in gluing.map_or(&[][..], |g| &g.glues[..]) {
        let (a, b) = (&splines[g.lower], &splines[g.upper]);
        let m = a.spans[g.lower_strip];
        let (sa, sb) = (a.strip_start(g.lower_strip), b.strip_start(g.upper_strip));
        let top = base[g.lower] + (a.nv + 2) * a.ncu();
        for k in 0..=m + 2 {
            let x = find(&mut parent, top + (sa + k) % a.ncu());
            let y = find(&mut parent, base[g.upper] + (sb + k) % b.ncu());
            parent[x] = y;
        }
    }
    let mut id = vec![usize::MAX; n];
    let mut map = vec![0; n];
    let mut count = 0;
    for x in 0..n {
        let r = find(&mut parent, x);
        if id[r] == usize::MAX {
            id[r] = count;
            count += 1;
        }
        map[x] = id[r];
    }
    (map, count)
}

/// All cylinders in one least-squares system: data, fairness, glued boundary rows shared
/// (`gluing`), or else the gluing penalty `glue · |S_lower(u, H) − S_upper(u', 0)|²` at every
/// crossing of a critical level. Returns the splines and the number of distinct unknowns.
fn solve_all(
    domain: &GenusDomain,
    mut splines: Vec<CylinderSpline>,
    data: &[Vec<([f64; 2], [f64; 3])>],
    smoothing: f64,
    glue: f64,
    gluing: Option<&Gluing>,
    tangent: [f64; 2],
) -> Result<(Vec<CylinderSpline>, usize)> {
    let mut base = Vec::with_capacity(splines.len());
    let mut slots = 0;
    for s in &splines {
        base.push(slots);
        slots += s.control.len();
    }
    let mut trip: Vec<Triplet<usize, usize, f64>> = Vec::new();
    let mut rhs = vec![[0.0; 3]; slots];
    for (k, s) in splines.iter().enumerate() {
        assemble_one(s, base[k], &data[k], smoothing, &mut trip, &mut rhs);
    }
    if gluing.is_none() {
        let (mut ba, mut bb) = (Vec::new(), Vec::new());
        for x in &domain.crossings {
            let (a, b) = (&splines[x.lower], &splines[x.upper]);
            a.basis(a.param(x.u_lower, a.height), a.height, &mut ba);
            b.basis(b.param(x.u_upper, 0.0), 0.0, &mut bb);
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
    }
    if let Some(g) = gluing.filter(|_| tangent[0] > 0.0) {
        tangent_penalty(&splines, &base, g, tangent[0], &mut trip);
    }
    if gluing.is_some() && tangent[1] > 0.0 {
        line_tangent_penalty(&splines, &base, tangent[1], &mut trip);
    }
    let (map, n) = shared_unknowns(&splines, &base, gluing);
    for t in trip.iter_mut() {
        *t = Triplet::new(map[t.row], map[t.col], t.val);
    }
    let mut b = Mat::<f64>::zeros(n, 3);
    for (x, r) in rhs.iter().enumerate() {
        for d in 0..3 {
            b[(map[x], d)] += r[d];
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
    chol.solve_in_place(b.as_mut());
    for (k, s) in splines.iter_mut().enumerate() {
        for i in 0..s.control.len() {
            let r = map[base[k] + i];
            s.control[i] = [b[(r, 0)], b[(r, 1)], b[(r, 2)]];
            if s.control[i].iter().any(|x| !x.is_finite()) {
                return Err(Error::numerical(
                    "cylinder fit: the solve gave non-finite control points",
                ));
            }
        }
    }
    Ok((splines, n))
}

/// `w h² |∂_v S_lower − ∂_v S_upper|²` at three points per span of every glued strip, with
/// `∂_v` at fixed developed `u` (`∂_v − (shear / H) ∂_u'` in a spline's own parameters).
fn tangent_penalty(
    splines: &[CylinderSpline],
    base: &[usize],
    g: &Gluing,
    w: f64,
    trip: &mut Vec<Triplet<usize, usize, f64>>,
) {
    let (mut ba, mut bb) = (Vec::new(), Vec::new());
    for x in &g.glues {
        let (a, b) = (&splines[x.lower], &splines[x.upper]);
        let m = a.spans[x.lower_strip];
        let h = x.length / m as f64;
        let (ka, kb) = (a.shear / a.height, b.shear / b.height);
        for i in 0..3 * m {
            let off = (i as f64 + 0.5) / 3.0 * h;
            a.basis_d(a.lines[x.lower_strip] + off, a.height, &mut ba);
            b.basis_d(b.lines[x.upper_strip] + off, 0.0, &mut bb);
            let row: Vec<(usize, f64)> = ba
                .iter()
                .map(|&(k, d)| (base[x.lower] + k, d[2] - ka * d[1]))
                .chain(
                    bb.iter()
                        .map(|&(k, d)| (base[x.upper] + k, kb * d[1] - d[2])),
                )
                .collect();
            for &(r, p) in &row {
                for &(c, q) in &row {
                    trip.push(Triplet::new(r, c, w * h * h * p * q));
                }
            }
        }
    }
}

/// `w h² |∂_u' S_left − ∂_u' S_right|²` at three points per `v` span of every knot line of
/// every cylinder (`h`: the mean span width of the two strips meeting there).
fn line_tangent_penalty(
    splines: &[CylinderSpline],
    base: &[usize],
    w: f64,
    trip: &mut Vec<Triplet<usize, usize, f64>>,
) {
    let (mut bl, mut br) = (Vec::new(), Vec::new());
    for (k, s) in splines.iter().enumerate() {
        let n = s.lines.len();
        for (i, &line) in s.lines.iter().enumerate() {
            let left = (i + n - 1) % n;
            let h = 0.5
                * (s.strip_length(i) / s.spans[i] as f64
                    + s.strip_length(left) / s.spans[left] as f64);
            let before = (line - 1e-9 * s.circumference).rem_euclid(s.circumference);
            for j in 0..3 * s.nv {
                let v = (j as f64 + 0.5) / 3.0 * s.hv();
                s.basis_d(before, v, &mut bl);
                s.basis_d(line, v, &mut br);
                let row: Vec<(usize, f64)> = bl
                    .iter()
                    .map(|&(c, d)| (base[k] + c, d[1]))
                    .chain(br.iter().map(|&(c, d)| (base[k] + c, -d[1])))
                    .collect();
                for &(r, p) in &row {
                    for &(c, q) in &row {
                        trip.push(Triplet::new(r, c, w * h * h * p * q));
                    }
                }
            }
        }
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Strip classes: strips glued top to bottom have the same spans. Per cylinder, per strip,
/// the class; and the number of classes.
fn strip_classes(nstrips: &[usize], gluing: Option<&Gluing>) -> (Vec<Vec<usize>>, usize) {
    let first: Vec<usize> = nstrips
        .iter()
        .scan(0, |at, &k| {
            let f = *at;
            *at += k;
            Some(f)
        })
        .collect();
    let n: usize = nstrips.iter().sum();
    let mut parent: Vec<usize> = (0..n).collect();
    for g in gluing.map_or(&[][..], |g| &g.glues[..]) {
        let x = find(&mut parent, first[g.lower] + g.lower_strip);
        let y = find(&mut parent, first[g.upper] + g.upper_strip);
        parent[x] = y;
    }
    let mut id = vec![usize::MAX; n];
    let mut count = 0;
    let classes = nstrips
        .iter()
        .enumerate()
        .map(|(c, &k)| {
            (0..k)
                .map(|s| {
                    let r = find(&mut parent, first[c] + s);
                    if id[r] == usize::MAX {
                        id[r] = count;
                        count += 1;
                    }
                    id[r]
                })
                .collect()
        })
        .collect();
    (classes, count)
}

/// One refinement: where a point is above the tolerance `tol`, its strip's class doubles its
/// spans if they are at least as wide as the cylinder's rows are high, else the cylinder's
/// rows double. Returns the new spans per class and rows per cylinder.
fn refine(
    splines: &[CylinderSpline],
    data: &[Vec<([f64; 2], [f64; 3])>],
    errors: &[Vec<f64>],
    tol: f64,
    classes: &[Vec<usize>],
    spans: &[usize],
    nv: &[usize],
) -> (Vec<usize>, Vec<usize>) {
    let (mut next_spans, mut next_nv) = (spans.to_vec(), nv.to_vec());
    let mut doubled = vec![false; spans.len()];
    for (c, s) in splines.iter().enumerate() {
        for ((uv, _), &e) in data[c].iter().zip(&errors[c]) {
            if e <= tol {
                continue;
            }
            let (k, len) = if s.lines.is_empty() {
                (0, s.circumference)
            } else {
                let k = s.lines.partition_point(|&x| x <= uv[0]).saturating_sub(1);
                (k, s.strip_length(k))
            };
            let class = classes[c][k];
            if len / spans[class] as f64 >= s.hv() {
                if !doubled[class] {
                    doubled[class] = true;
                    next_spans[class] *= 2;
                }
            } else {
                next_nv[c] = 2 * nv[c];
            }
        }
    }
    (next_spans, next_nv)
}

/// The gluing of `domain` when every cylinder's layout is a shear (what sharing the boundary
/// rows of tensor-product splines in sheared coordinates needs), or why not.
fn sheared_gluing(domain: &GenusDomain) -> std::result::Result<Gluing, String> {
    gluing(domain).and_then(|g| match g.rigid(domain) {
        Some(_) => Ok(g),
        None => Err(
            "the strips are not a shear of every cylinder (their lines are not parallel)"
                .to_string(),
        ),
    })
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
    let gluing = if opts.share {
        sheared_gluing(domain)
    } else {
        Err("sharing the boundary rows was switched off".to_string())
    };
    let glued = gluing.as_ref().ok();
    let rigid: Option<Vec<RigidLayout>> = glued.and_then(|g| g.rigid(domain));
    let layout = |c: usize| rigid.as_ref().map(|r| &r[c]);
    let nstrips: Vec<usize> = (0..nc)
        .map(|c| layout(c).map_or(1, |y| y.lines.len()))
        .collect();
    let (classes, nclasses) = strip_classes(&nstrips, glued);
    let strip_len = |c: usize, s: usize| {
        let l = domain.cylinders[c].circumference;
        layout(c).map_or(l, |y| y.strip_length(s, l))
    };
    // data in each spline's own parameters (u', v)
    let mut data: Vec<Vec<([f64; 2], [f64; 3])>> = vec![Vec::new(); nc];
    let probe: Vec<CylinderSpline> = (0..nc)
        .map(|c| CylinderSpline::new(&domain.cylinders[c], layout(c), vec![1; nstrips[c]], 1))
        .collect();
    for p in &domain.points {
        let Some(x) = positions.get(p.vertex as usize) else {
            return Err(Error::input(format!(
                "data point {} has no position ({} given)",
                p.vertex,
                positions.len()
            )));
        };
        data[p.cylinder].push(([probe[p.cylinder].param(p.u, p.v), p.v], *x));
    }
    // initial grids: about `points_per_span` data points per span, square-ish spans; a
    // class of glued strips takes the finest span width wanted by its cylinders
    let mut nv: Vec<usize> = Vec::with_capacity(nc);
    let mut width = vec![f64::INFINITY; nclasses];
    for (c, cyl) in domain.cylinders.iter().enumerate() {
        let spans = (data[c].len() / opts.points_per_span.max(1)).max(4) as f64;
        let nu = ((spans * cyl.circumference / cyl.height).sqrt().round() as usize).max(4);
        nv.push(((spans / nu as f64).round() as usize).max(1));
        for &k in &classes[c] {
            width[k] = width[k].min(cyl.circumference / nu as f64);
        }
    }
    let mut spans: Vec<usize> = vec![1; nclasses];
    for (c, cl) in classes.iter().enumerate() {
        for (s, &k) in cl.iter().enumerate() {
            let want = (strip_len(c, s) / width[k]).round() as usize;
            spans[k] = spans[k].max(want.max(if glued.is_some() { 1 } else { 4 }));
        }
    }
    let mut steps = Vec::new();
    let mut converged = false;
    let mut splines: Vec<CylinderSpline> = Vec::new();
    let mut errors: Vec<Vec<f64>> = Vec::new();
    let mut unknowns = 0;
    for _ in 0..opts.max_iterations.max(1) {
        let fresh: Vec<CylinderSpline> = (0..nc)
            .map(|c| {
                let m = classes[c].iter().map(|&k| spans[k]).collect();
                CylinderSpline::new(&domain.cylinders[c], layout(c), m, nv[c])
            })
            .collect();
        (splines, unknowns) = solve_all(
            domain,
            fresh,
            &data,
            opts.smoothing,
            opts.glue,
            glued,
            [opts.tangent, opts.line_tangent],
        )?;
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
        steps.push(GenusStep {
            control_points: unknowns,
            rms_error_percent: 100.0 * rms / scale,
            max_error_percent: 100.0 * max / scale,
        });
        if max <= tol {
            converged = true;
            break;
        }
        let (next_spans, next_nv) = refine(&splines, &data, &errors, tol, &classes, &spans, &nv);
        let total: usize = (0..nc)
            .map(|c| {
                let ncu: usize = classes[c]
                    .iter()
                    .map(|&k| next_spans[k] + if glued.is_some() { 2 } else { 0 })
                    .sum();
                ncu * (next_nv[c] + 3)
            })
            .sum();
        if total > opts.max_control_points {
            break;
        }
        (spans, nv) = (next_spans, next_nv);
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
        gluing,
        unknowns,
    })
}

impl GenusFit {
    /// Distinct control points (the glued boundary rows counted once).
    pub fn control_points(&self) -> usize {
        self.unknowns
    }

    /// Bézier patches, cylinder by cylinder, row by row (`v` span `j`, then `u'` span `i`), in
    /// the exported parameter space (`u' + offset`).
    pub fn patches(&self) -> Vec<BezierPatch> {
        let mut out = Vec::new();
        for (s, &off) in self.splines.iter().zip(&self.offsets) {
            let hv = s.hv();
            let breaks = s.breaks();
            for j in 0..s.nv {
                for i in 0..s.nu {
                    let (u0, u1, v0) = (breaks[i].0, breaks[i + 1].0, j as f64 * hv);
                    let p = interpolate_patch(u0, u1, v0, v0 + hv, |u, v| s.point(u, v));
                    out.push(shift(p, off));
                }
            }
        }
        out
    }

    /// A point of cylinder `k` at its developed coordinates `(u, v)` (not sheared, not offset).
    pub fn point(&self, k: usize, u: f64, v: f64) -> [f64; 3] {
        let s = &self.splines[k];
        s.point(s.param(u, v), v)
    }

    /// The exported parameter `u' + offset` of the point `(u, v)` of cylinder `k`.
    pub fn exported_u(&self, k: usize, u: f64, v: f64) -> f64 {
        self.splines[k].param(u, v) + self.offsets[k]
    }
}

fn shift(mut p: BezierPatch, off: f64) -> BezierPatch {
    p.u0 += off;
    p.u1 += off;
    p
}
