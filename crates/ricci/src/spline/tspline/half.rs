//! The surface's half of the genus-0 torus ([`super::genus0`]): the strip between the two
//! seams (the two cut loops at the poles, closed geodesics of the rectangular torus, half a
//! period apart) that holds the input vertices. The other half is the mirror copy of the
//! double, with no data.
//!
//! Used to count the control points that influence the surface (those whose blending
//! function's support meets the strip) and to export only the surface (the Bézier patches
//! clipped to the strip).

use super::bezier::{interpolate_patch, BezierPatch};
use super::tmesh::Anchor;
use serde::Serialize;

/// The strip `from ≤ x_axis ≤ from + width` (mod `period`) of the torus, `axis` 0 (`u`) or
/// 1 (`v`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Half {
    pub axis: usize,
    pub from: f64,
    pub width: f64,
    pub period: f64,
}

impl Half {
    /// Whether the open interval `(a, b)` of the axis (any representative, `b − a` less than a
    /// period) meets the open strip.
    pub fn meets(&self, a: f64, b: f64) -> bool {
        if b - a >= self.period {
            return true;
        }
        let t = (a - self.from).rem_euclid(self.period);
        t < self.width || t + (b - a) > self.period
    }

    /// The anchors whose blending function's support meets the strip.
    pub fn anchors_on(&self, anchors: &[Anchor]) -> usize {
        anchors
            .iter()
            .filter(|a| {
                let k = if self.axis == 0 {
                    &a.knots_u
                } else {
                    &a.knots_v
                };
                self.meets(k[0], k[4])
            })
            .count()
    }

    /// The pieces of `[a, b]` (any representative) inside the strip, in the same
    /// representative as `[a, b]`.
    fn pieces(&self, a: f64, b: f64) -> Vec<(f64, f64)> {
        let p = self.period;
        // the strip's copies near [a, b]
        let k0 = ((a - self.from - self.width) / p).floor() as i64;
        let k1 = ((b - self.from) / p).ceil() as i64;
        (k0..=k1)
            .filter_map(|k| {
                let (s0, s1) = (
                    self.from + k as f64 * p,
                    self.from + k as f64 * p + self.width,
                );
                let (x0, x1) = (a.max(s0), b.min(s1));
                (x1 - x0 > 1e-12 * p).then_some((x0, x1))
            })
            .collect()
    }

    /// The patches restricted to the strip: a patch inside is kept, one across a seam is cut
    /// there (the same polynomial over the smaller rectangle), one outside is dropped.
    pub fn clip(&self, patches: &[BezierPatch]) -> Vec<BezierPatch> {
        let mut out = Vec::with_capacity(patches.len() / 2 + 8);
        for q in patches {
            let (a, b) = if self.axis == 0 {
                (q.u0, q.u1)
            } else {
                (q.v0, q.v1)
            };
            for (x0, x1) in self.pieces(a, b) {
                if x0 == a && x1 == b {
                    out.push(*q);
                } else if self.axis == 0 {
                    out.push(interpolate_patch(x0, x1, q.v0, q.v1, |u, v| q.point(u, v)));
                } else {
                    out.push(interpolate_patch(q.u0, q.u1, x0, x1, |u, v| q.point(u, v)));
                }
            }
        }
        out
    }
}
