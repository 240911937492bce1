//! Genus ≥ 2, step 3b: continuity of the exported patches of [`super::cylinder_fit`],
//! measured by sampling both sides of every patch side:
//!
//! * inside a cylinder, across the simple knots: the jumps of the partials of orders 0..=3
//!   (C² expected: orders 0..2 vanish, order 3 does not);
//! * inside a cylinder, across the knot lines (triple knots through the zero copies): the
//!   position gap and the angle between the two sides' normals (C⁰ expected);
//! * across the critical trajectories: the position gap and the normal angle, at the crossing
//!   points of mesh edges with the critical levels (from [`GenusDomain::crossings`], found
//!   independently of the gluing), at the midpoints of consecutive crossings glued by the
//!   same translation, and, when the boundary rows are shared, at points along every glued
//!   strip; crossings and midpoints within [`NEAR_ZERO`] of the circumference from a copy of
//!   a zero are reported apart ([`GluedSeams::near_zeros`]);
//! * at the zeros themselves ([`GenusFit::at_zeros`]): every copy of a zero is a corner of two
//!   strips (the knot line through it), so a simple zero of a genus-2 form (cone angle 4π) is
//!   the common corner of eight patches; the spread of their eight corner points (C⁰ at the
//!   zero) and the largest angle between their normals there (the G¹ defect at the zero). The two sides' parameters differ by a translation and a shear, which keep the
//!   normal's direction, so the normals compare directly.

use super::bezier::{BezierPatch, Continuity};
use super::cylinder_fit::GenusFit;
use super::genus_domain::GenusDomain;
use serde::Serialize;

/// Position gap and normal angle across a family of patch sides.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Seam {
    /// Largest distance between the two sides' points.
    pub max_gap: f64,
    /// Largest angle between the two sides' normals `∂u × ∂v`, degrees.
    pub max_angle_degrees: f64,
    /// Side points compared.
    pub comparisons: usize,
}

/// The seams across the critical trajectories.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct GluedSeams {
    /// At the mesh edges' crossings of the critical levels.
    pub crossings: Seam,
    /// At the midpoints of consecutive crossings glued by the same translation.
    pub midpoints: Seam,
    /// Along every glued strip (empty without shared boundary rows).
    pub strips: Seam,
    /// Crossings and midpoints closer than [`NEAR_ZERO`] (of the circumference) to a copy of a
    /// zero: there the piecewise-linear development of a mesh edge passing by the cone point
    /// can glue it to the wrong side of the zero, so they are kept apart.
    pub near_zeros: Seam,
}

/// See [`GluedSeams::near_zeros`].
pub const NEAR_ZERO: f64 = 2e-3;

impl GluedSeams {
    pub fn max_gap(&self) -> f64 {
        self.crossings
            .max_gap
            .max(self.midpoints.max_gap)
            .max(self.strips.max_gap)
    }

    pub fn max_angle_degrees(&self) -> f64 {
        self.crossings
            .max_angle_degrees
            .max(self.midpoints.max_angle_degrees)
            .max(self.strips.max_angle_degrees)
    }
}

pub(super) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(super) fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm([a[0] - b[0], a[1] - b[1], a[2] - b[2]])
}

fn normal(p: &BezierPatch, u: f64, v: f64) -> [f64; 3] {
    cross(p.partial(u, v, 1, 0), p.partial(u, v, 0, 1))
}

impl Seam {
    fn add(&mut self, p: &BezierPatch, a: (f64, f64), q: &BezierPatch, b: (f64, f64)) {
        self.comparisons += 1;
        self.max_gap = self.max_gap.max(dist(p.point(a.0, a.1), q.point(b.0, b.1)));
        let (n, m) = (normal(p, a.0, a.1), normal(q, b.0, b.1));
        let dot = n[0] * m[0] + n[1] * m[1] + n[2] * m[2];
        let angle = norm(cross(n, m)).atan2(dot).to_degrees();
        self.max_angle_degrees = self.max_angle_degrees.max(angle);
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
            c.magnitudes[order] = c.magnitudes[order].max(norm(x));
        }
    }
}

impl GenusFit {
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

    /// The patch of cylinder `k` holding `(u', v)` (`v` at the top or bottom goes to the top or
    /// bottom row), and the exported `u`.
    fn locate(&self, first: &[usize], k: usize, u: f64, v: f64) -> (usize, f64) {
        let s = &self.splines[k];
        let u = u.rem_euclid(s.circumference);
        let breaks = s.breaks();
        let i = breaks
            .partition_point(|b| b.0 <= u)
            .saturating_sub(1)
            .min(s.nu - 1);
        let j = ((v / s.hv()).floor().max(0.0) as usize).min(s.nv - 1);
        (first[k] + j * s.nu + i, u + self.offsets[k])
    }

    /// Jumps of the partials of orders 0..=3 across every side shared by two patches of the
    /// same cylinder that is not a knot line (including the periodic seam), and the seam
    /// (gap, normal angle) across the knot lines; `samples` points per side.
    pub fn interior_jumps(&self, patches: &[BezierPatch], samples: usize) -> (Continuity, Seam) {
        let first = self.first_patch();
        let mut c = Continuity {
            jumps: [0.0; 4],
            magnitudes: [0.0; 4],
            comparisons: 0,
        };
        let mut lines = Seam::default();
        for (k, s) in self.splines.iter().enumerate() {
            let breaks = s.breaks();
            for j in 0..s.nv {
                for i in 0..s.nu {
                    let q = &patches[first[k] + j * s.nu + i];
                    let right = &patches[first[k] + j * s.nu + (i + 1) % s.nu];
                    let line = breaks[i + 1].1;
                    for m in 0..samples {
                        let t = (m as f64 + 0.5) / samples as f64;
                        let v = q.v0 + t * (q.v1 - q.v0);
                        if line {
                            lines.add(q, (q.u1, v), right, (right.u0, v));
                        } else {
                            compare(&mut c, q, (q.u1, v), right, (right.u0, v), 3);
                        }
                        if j + 1 < s.nv {
                            let up = &patches[first[k] + (j + 1) * s.nu + i];
                            let u = q.u0 + t * (q.u1 - q.u0);
                            compare(&mut c, q, (u, q.v1), up, (u, up.v0), 3);
                        }
                    }
                }
            }
        }
        (c, lines)
    }

    /// Gap and normal angle across the critical trajectories (see the module's note);
    /// `samples` points per span of every glued strip.
    pub fn glued_seams(
        &self,
        patches: &[BezierPatch],
        domain: &GenusDomain,
        samples: usize,
    ) -> GluedSeams {
        let first = self.first_patch();
        let mut out = GluedSeams::default();
        // one point seen from both sides, in developed coordinates (u on the top of `lower`,
        // u' on the bottom of `upper`)
        let near = |k: usize, top: bool, u: f64| {
            let l = self.splines[k].circumference;
            domain.zero_copies.iter().any(|z| {
                let d = (z.u - u).rem_euclid(l);
                z.cylinder == k && z.top == top && d.min(l - d) < NEAR_ZERO * l
            })
        };
        let mut probe = |which: usize, lower: usize, ul: f64, upper: usize, uu: f64| {
            let seam = if near(lower, true, ul) || near(upper, false, uu) {
                &mut out.near_zeros
            } else if which == 0 {
                &mut out.crossings
            } else {
                &mut out.midpoints
            };
            let (a, b) = (&self.splines[lower], &self.splines[upper]);
            let (p, u) = self.locate(&first, lower, a.param(ul, a.height), a.height);
            let (q, w) = self.locate(&first, upper, b.param(uu, 0.0), 0.0);
            seam.add(&patches[p], (u, a.height), &patches[q], (w, 0.0));
        };
        let mut pts: Vec<(usize, f64, usize, f64)> = domain
            .crossings
            .iter()
            .map(|x| (x.lower, x.u_lower, x.upper, x.u_upper))
            .collect();
        for &(a, ul, b, uu) in &pts {
            probe(0, a, ul, b, uu);
        }
        // midpoints of consecutive crossings glued by the same translation
        pts.sort_by(|a, b| (a.0, a.2).cmp(&(b.0, b.2)).then(a.1.total_cmp(&b.1)));
        for w in pts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let lu = self.splines[a.2].circumference;
            let shift = |x: (usize, f64, usize, f64)| (x.3 - x.1).rem_euclid(lu);
            let ds = (shift(a) - shift(b)).abs();
            let close = b.1 - a.1 < 0.1 * self.splines[a.0].circumference;
            if a.0 == b.0 && a.2 == b.2 && close && ds.min(lu - ds) < 1e-9 * lu {
                let m = 0.5 * (a.1 + b.1);
                probe(1, a.0, m, a.2, (m + shift(a)).rem_euclid(lu));
            }
        }
        // along every glued strip, in the splines' own parameters
        if let Ok(g) = &self.gluing {
            for x in &g.glues {
                let (a, b) = (&self.splines[x.lower], &self.splines[x.upper]);
                let m = a.spans[x.lower_strip];
                let h = x.length / m as f64;
                for i in 0..m * samples {
                    let off = (i as f64 + 0.5) / samples as f64 * h;
                    let (p, u) =
                        self.locate(&first, x.lower, a.lines[x.lower_strip] + off, a.height);
                    let (q, w) = self.locate(&first, x.upper, b.lines[x.upper_strip] + off, 0.0);
                    out.strips
                        .add(&patches[p], (u, a.height), &patches[q], (w, 0.0));
                }
            }
        }
        out
    }
}

/// What the spline does at one zero (an extraordinary point): see [`GenusFit::at_zeros`].
#[derive(Debug, Clone, Copy, Serialize)]
pub struct AtZero {
    /// The zero's vertex (of the cut mesh, as in [`GenusDomain::zero_copies`]).
    pub saddle: u32,
    /// Its copies on the cylinders' circles, and the patch corners evaluated there.
    pub copies: usize,
    pub corners: usize,
    /// Largest distance between two corner points (0 up to rounding: C⁰ at the zero).
    pub max_gap: f64,
    /// Largest angle between two corner normals `∂u × ∂v`, degrees (0 would be G¹).
    pub max_normal_angle_degrees: f64,
}

impl GenusFit {
    /// At every zero: the corners of the patches meeting at its copies — on each copy's knot
    /// line, the patch on either side (left: the strip ending there, right: the one starting
    /// there), on the cylinder's top or bottom row — evaluated at the copy, compared point by
    /// point (gap) and normal by normal (angle). The copies are snapped to their cylinder's
    /// nearest knot line (they are its ends, up to the gluing's mismatch). Empty without
    /// shared boundary rows (no knot lines).
    pub fn at_zeros(&self, patches: &[BezierPatch], domain: &GenusDomain) -> Vec<AtZero> {
        if self.gluing.is_err() {
            return Vec::new();
        }
        let first = self.first_patch();
        let mut saddles: Vec<u32> = domain.zero_copies.iter().map(|z| z.saddle).collect();
        saddles.sort_unstable();
        saddles.dedup();
        saddles
            .into_iter()
            .map(|saddle| {
                let mut corners: Vec<([f64; 3], [f64; 3])> = Vec::new();
                let mut copies = 0;
                for z in domain.zero_copies.iter().filter(|z| z.saddle == saddle) {
                    let s = &self.splines[z.cylinder];
                    if s.lines.is_empty() {
                        continue;
                    }
                    copies += 1;
                    let l = s.circumference;
                    let v = if z.top { s.height } else { 0.0 };
                    let u = s.param(z.u, v);
                    let line = s
                        .lines
                        .iter()
                        .chain(std::iter::once(&l))
                        .copied()
                        .min_by(|a, b| (a - u).abs().total_cmp(&(b - u).abs()))
                        .unwrap_or(0.0)
                        .rem_euclid(l);
                    // right of the line: the strip starting there; left: the one ending there
                    let (right, ur) = self.locate(&first, z.cylinder, line, v);
                    let (left, _) = self.locate(&first, z.cylinder, line - 1e-9 * l, v);
                    let ul = patches[left].u1;
                    for (p, u) in [(right, ur), (left, ul)] {
                        let q = &patches[p];
                        corners.push((q.point(u, v), normal(q, u, v)));
                    }
                }
                let (mut gap, mut angle) = (0.0f64, 0.0f64);
                for (i, a) in corners.iter().enumerate() {
                    for b in &corners[..i] {
                        gap = gap.max(dist(a.0, b.0));
                        let dot = a.1[0] * b.1[0] + a.1[1] * b.1[1] + a.1[2] * b.1[2];
                        angle = angle.max(norm(cross(a.1, b.1)).atan2(dot).to_degrees());
                    }
                }
                AtZero {
                    saddle,
                    copies,
                    corners: corners.len(),
                    max_gap: gap,
                    max_normal_angle_degrees: angle,
                }
            })
            .collect()
    }
}
