//! Genus ≥ 2, step 3a: how the cylinders of [`super::genus_domain`] are glued along the
//! critical trajectories, cut into **strips** whose sides are glued whole, so that one mesh of
//! knot intervals covers the closed surface ([`super::domain_mesh`], issue 18).
//!
//! **Interfaces.** The copies of the zeros cut every cylinder's top circle into intervals; each
//! is a horizontal saddle connection (or a whole circle where a cylinder meets the next band
//! without a zero on it), and its other side is an interval between consecutive zero copies on
//! the bottom circle of one cylinder above, glued by a translation in `u`. Which one, and the
//! translation, are read off the mesh edges' [`GenusDomain::crossings`] (the cylinder, interval
//! and offset most crossings agree on; the others, next to a zero where the piecewise-linear
//! development is not that of the flat surface, are counted as outliers).
//!
//! **Lines.** A cylinder is cut into strips by segments from a point of its bottom circle to a
//! point of its top circle (straight in `(u, v)`), one per zero copy. A cylinder has as many
//! copies on top as on the bottom only in special cases (eight.off; in general a cylinder of
//! genus ≥ 3 can have one copy below and two above, or none on a circle that is a regular level
//! of another band's critical value), so **points are added** in the middle of interfaces: an
//! added point lies on the top of one cylinder and the bottom of the next, so it balances one
//! cylinder and unbalances the next; the points are routed along the directed graph
//! "cylinder → cylinder above" from cylinders with more points below to cylinders with more
//! above (shortest paths, preferring the longest intervals: a flow, which exists because the
//! circumferences are a positive circulation on that graph), and every whole-circle interface
//! gets at least one. Every cylinder then has `k` points on each circle; line `i` joins bottom
//! point `i` to top point `i + r`, the rotation `r` (and the number of turns) chosen to make the
//! lines as vertical as possible (least `Σ (u_top − u_bottom)²`). Added points are regular
//! vertices of the mesh (valence 4); only the zero copies are its extraordinary points.
//!
//! **Strips and glues.** Strip `s` of a cylinder lies between lines `s` and `s + 1`; its top is
//! glued whole to the bottom of one strip of the cylinder above (a [`Glue`]): the same two
//! points seen from both sides. Following the glues upward, the strips form closed **chains**;
//! every strip of a chain gets one knot length, the mean width of the chain's strips (a strip
//! whose bottom and top widths differ is parametrized affinely on every level `v`), so glued
//! sides carry the same knot intervals. When every cylinder's lines are parallel and the knot
//! lengths are the widths (genus 2 with one zero per critical level, e.g. eight.off), the
//! layout is a shear of the cylinder ([`CylinderLayout::rigid`], what the per-cylinder fit of
//! [`super::cylinder_fit`] needs to share its boundary rows).

use super::genus_domain::GenusDomain;
use serde::Serialize;
use std::collections::VecDeque;

/// How one cylinder is cut into strips.
#[derive(Debug, Clone, Serialize)]
pub struct CylinderLayout {
    /// `u` of line `i` on the bottom circle (`v = 0`): increasing, within one circumference.
    pub bottom: Vec<f64>,
    /// `u` of line `i` on the top circle (`v = H`), unwrapped so that line `i` is the segment
    /// from `(bottom[i], 0)` to `(top[i], H)`: increasing, `top[k − 1] < top[0] + L`.
    pub top: Vec<f64>,
    /// Knot length of strip `s` (between lines `s` and `s + 1`, the last one wraps around).
    pub lengths: Vec<f64>,
    /// Whether line `i` ends at a zero copy on the bottom and on the top circle (else at an
    /// added point).
    pub zero_ends: Vec<[bool; 2]>,
}

/// A cylinder layout that is a shear: `u' = (u − shift − shear · v / H) mod L`, knot lines
/// `u' = lines[s]` (`lines[0] = 0`), knot lengths equal to the widths.
#[derive(Debug, Clone, Serialize)]
pub struct RigidLayout {
    pub shift: f64,
    pub shear: f64,
    pub lines: Vec<f64>,
}

impl RigidLayout {
    /// Length of strip `s` in a cylinder of circumference `l`.
    pub fn strip_length(&self, s: usize, l: f64) -> f64 {
        self.lines.get(s + 1).copied().unwrap_or(l) - self.lines[s]
    }
}

impl CylinderLayout {
    /// Number of strips (= lines).
    pub fn strips(&self) -> usize {
        self.bottom.len()
    }

    /// Knot length of strip `s`.
    pub fn strip_length(&self, s: usize) -> f64 {
        self.lengths[s]
    }

    /// `u` of line `i` (`i ≤ k`; line `k` is line 0 one turn on) at height fraction `t = v / H`.
    fn line_at(&self, i: usize, t: f64, l: f64) -> f64 {
        let k = self.bottom.len();
        let (j, turn) = if i >= k { (i - k, l) } else { (i, 0.0) };
        turn + self.bottom[j] + (self.top[j] - self.bottom[j]) * t
    }

    /// The strip holding the point `(u, v)` of a cylinder of height `h` and circumference `l`,
    /// and the knot coordinate in it (`0 ≤ x ≤` [`Self::strip_length`]).
    pub fn locate(&self, u: f64, v: f64, h: f64, l: f64) -> (usize, f64) {
        let t = (v / h).clamp(0.0, 1.0);
        let k = self.bottom.len();
        let x0 = self.line_at(0, t, l);
        let u = x0 + (u - x0).rem_euclid(l);
        let s = (1..k)
            .take_while(|&i| self.line_at(i, t, l) <= u)
            .last()
            .unwrap_or(0);
        let (a, b) = (self.line_at(s, t, l), self.line_at(s + 1, t, l));
        let x = ((u - a) / (b - a)).clamp(0.0, 1.0) * self.lengths[s];
        (s, x)
    }

    /// `u mod l` of the point of strip `s` with knot coordinate `x` at height `v` (the inverse
    /// of [`Self::locate`]).
    pub fn u_of(&self, s: usize, x: f64, v: f64, h: f64, l: f64) -> f64 {
        let t = (v / h).clamp(0.0, 1.0);
        let (a, b) = (self.line_at(s, t, l), self.line_at(s + 1, t, l));
        (a + (b - a) * x / self.lengths[s]).rem_euclid(l)
    }

    /// The layout as a shear of the cylinder, when it is one (all lines parallel, knot
    /// lengths equal to the widths, within `1e-6 l`).
    pub fn rigid(&self, l: f64) -> Option<RigidLayout> {
        let k = self.bottom.len();
        let shear = self.top[0] - self.bottom[0];
        let tol = TOL * l;
        let parallel = (0..k).all(|i| (self.top[i] - self.bottom[i] - shear).abs() <= tol);
        let widths = (0..k).all(|s| {
            (self.line_at(s + 1, 0.0, l) - self.line_at(s, 0.0, l) - self.lengths[s]).abs() <= tol
        });
        (parallel && widths).then(|| RigidLayout {
            shift: self.bottom[0],
            shear,
            lines: self.bottom.iter().map(|b| b - self.bottom[0]).collect(),
        })
    }
}

/// The top of strip `lower_strip` of cylinder `lower` is the bottom of strip `upper_strip` of
/// cylinder `upper`, knot coordinates equal.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Glue {
    pub lower: usize,
    pub lower_strip: usize,
    pub upper: usize,
    pub upper_strip: usize,
    /// The knot length of both strips.
    pub length: f64,
    /// Mesh-edge crossings of the interface this glue lies on.
    pub crossings: usize,
}

/// Layouts of all cylinders and the glues of all their strips.
#[derive(Debug, Clone, Serialize)]
pub struct Gluing {
    pub layouts: Vec<CylinderLayout>,
    pub glues: Vec<Glue>,
    /// Largest disagreement (relative to the circumference) between the two sides' lengths of
    /// an interface and of a glued strip side.
    pub mismatch: f64,
    /// Crossings that disagree with the glue of their interface, and their largest distance
    /// to a zero copy (relative to the circumference).
    pub outliers: usize,
    pub outlier_distance: f64,
    /// Points added on the interfaces (lines not through a zero), and interfaces.
    pub added_points: usize,
    pub interfaces: usize,
    /// Largest `|u_top − u_bottom| / H` of a line (its slope against the vertical).
    pub max_slope: f64,
}

impl Gluing {
    /// The layouts as shears of the cylinders when every one is ([`CylinderLayout::rigid`]).
    pub fn rigid(&self, domain: &GenusDomain) -> Option<Vec<RigidLayout>> {
        self.layouts
            .iter()
            .zip(&domain.cylinders)
            .map(|(y, c)| y.rigid(c.circumference))
            .collect()
    }
}

const TOL: f64 = 1e-6;

fn wrap_dist(a: f64, b: f64, l: f64) -> f64 {
    let d = (a - b).rem_euclid(l);
    d.min(l - d)
}

/// The intervals of a circle of circumference `l` cut at `copies` (sorted): `(start, length)`;
/// one closed interval `(0, l)` without copies.
fn intervals(copies: &[f64], l: f64) -> Vec<(f64, f64)> {
    let k = copies.len();
    if k == 0 {
        return vec![(0.0, l)];
    }
    (0..k)
        .map(|i| {
            let end = if i + 1 < k {
                copies[i + 1]
            } else {
                copies[0] + l
            };
            (copies[i], end - copies[i])
        })
        .collect()
}

/// The interval of `iv` holding `u`, and the offset of `u` from its start.
fn interval_of(iv: &[(f64, f64)], u: f64, l: f64) -> (usize, f64) {
    let i = iv
        .iter()
        .rposition(|&(s, _)| s <= u)
        .unwrap_or(iv.len() - 1);
    (i, (u - iv[i].0).rem_euclid(l))
}

/// One side of an interface: a top interval of `lower` glued to a bottom interval of `upper`,
/// `offset_upper = offset_lower − rotation` (`rotation ≠ 0` only on whole circles).
#[derive(Debug, Clone, Copy)]
struct Interface {
    lower: usize,
    upper: usize,
    lower_start: f64,
    upper_start: f64,
    length: f64,
    rotation: f64,
    closed: bool,
    crossings: usize,
}

/// A point on a circle: `u`, the interface it lies on and its index there (0: the interval's
/// start, a zero copy; on a whole circle the added points are numbered from 0).
type Labelled = (f64, (usize, usize), bool);

/// The zero copies of every cylinder's circles and the intervals they cut them into.
struct Circles {
    circ: Vec<f64>,
    /// Zero copies (sorted `u`) on the bottom and top circles.
    zb: Vec<Vec<f64>>,
    zt: Vec<Vec<f64>>,
    /// Intervals `(start, length)` of the bottom and top circles, and the first index of each
    /// cylinder's in the concatenation.
    ib: Vec<Vec<(f64, f64)>>,
    it: Vec<Vec<(f64, f64)>>,
    fb: Vec<usize>,
    ft: Vec<usize>,
}

fn firsts<T>(per: &[Vec<T>]) -> Vec<usize> {
    per.iter()
        .scan(0, |at, v| {
            let f = *at;
            *at += v.len();
            Some(f)
        })
        .collect()
}

impl Circles {
    fn new(domain: &GenusDomain) -> Self {
        let nc = domain.cylinders.len();
        let circ: Vec<f64> = domain.cylinders.iter().map(|c| c.circumference).collect();
        let copies = |c: usize, top: bool| {
            let mut u: Vec<f64> = domain
                .zero_copies
                .iter()
                .filter(|z| z.cylinder == c && z.top == top)
                .map(|z| z.u)
                .collect();
            u.sort_by(f64::total_cmp);
            u
        };
        let zb: Vec<Vec<f64>> = (0..nc).map(|c| copies(c, false)).collect();
        let zt: Vec<Vec<f64>> = (0..nc).map(|c| copies(c, true)).collect();
        let ib: Vec<Vec<(f64, f64)>> = (0..nc).map(|c| intervals(&zb[c], circ[c])).collect();
        let it: Vec<Vec<(f64, f64)>> = (0..nc).map(|c| intervals(&zt[c], circ[c])).collect();
        let (fb, ft) = (firsts(&ib), firsts(&it));
        Circles {
            circ,
            zb,
            zt,
            ib,
            it,
            fb,
            ft,
        }
    }
}

/// A crossing seen from a top interval: the upper cylinder, its bottom interval, the
/// difference of the offsets from the two intervals' starts, the distance to a zero copy / L.
type Vote = (usize, usize, f64, f64);

/// The interfaces (one per top interval, in the order of the cylinders and their intervals)
/// from the crossings' votes, and the crossings that disagree: `(interfaces, outliers, their
/// largest distance to a zero copy, largest length mismatch)`.
fn interfaces(
    domain: &GenusDomain,
    k: &Circles,
) -> Result<(Vec<Interface>, usize, f64, f64), String> {
    let ntop: usize = k.it.iter().map(Vec::len).sum();
    let nbottom: usize = k.ib.iter().map(Vec::len).sum();
    if ntop != nbottom {
        return Err(format!(
            "the cylinders' top circles have {ntop} intervals between zero copies and their bottom circles {nbottom}"
        ));
    }
    let near = |z: &[f64], u: f64, l: f64| {
        z.iter()
            .map(|&x| wrap_dist(u, x, l) / l)
            .fold(0.5f64, f64::min)
    };
    let mut votes: Vec<Vec<Vote>> = vec![Vec::new(); ntop];
    for x in &domain.crossings {
        let (a, b) = (x.lower, x.upper);
        let (ua, ub) = (
            x.u_lower.rem_euclid(k.circ[a]),
            x.u_upper.rem_euclid(k.circ[b]),
        );
        let (j, oa) = interval_of(&k.it[a], ua, k.circ[a]);
        let (i, ob) = interval_of(&k.ib[b], ub, k.circ[b]);
        let d = near(&k.zt[a], ua, k.circ[a]).min(near(&k.zb[b], ub, k.circ[b]));
        votes[k.ft[a] + j].push((b, i, oa - ob, d));
    }
    // per top interval: the (cylinder, interval, offset) most crossings agree on; the offset
    // difference must vanish unless both sides are whole circles
    let mut faces: Vec<Interface> = Vec::with_capacity(ntop);
    let mut bottom_of = vec![usize::MAX; nbottom];
    let (mut outliers, mut outlier_distance, mut mismatch) = (0usize, 0.0f64, 0.0f64);
    for c in 0..k.circ.len() {
        let l = k.circ[c];
        let closed = k.zt[c].is_empty();
        let agree =
            |p: &Vote, q: &Vote| (p.0, p.1) == (q.0, q.1) && wrap_dist(p.2, q.2, l) <= TOL * l;
        let admissible = |p: &Vote| {
            closed == k.zb[p.0].is_empty() && (closed || wrap_dist(p.2, 0.0, l) <= TOL * l)
        };
        for (j, &(start, length)) in k.it[c].iter().enumerate() {
            let v = &votes[k.ft[c] + j];
            let best = v
                .iter()
                .filter(|p| admissible(p))
                .map(|p| (p, v.iter().filter(|q| agree(p, q)).count()))
                .fold(None, |best: Option<(&Vote, usize)>, (p, n)| match best {
                    Some((_, m)) if m >= n => best,
                    _ => Some((p, n)),
                });
            let Some((&p, n)) = best else {
                return Err(format!(
                    "no mesh edge crosses the top of cylinder {c} consistently (interval {j} of {})",
                    k.it[c].len()
                ));
            };
            for q in v.iter().filter(|q| !agree(&p, q)) {
                outliers += 1;
                outlier_distance = outlier_distance.max(q.3);
            }
            let (b, i) = (p.0, p.1);
            let (ustart, ulen) = k.ib[b][i];
            mismatch = mismatch.max((length - ulen).abs() / l);
            if (length - ulen).abs() > TOL * l.max(k.circ[b]) {
                return Err(format!(
                    "interval {j} on the top of cylinder {c} (length {length}) is glued to interval {i} on the bottom of cylinder {b} (length {ulen})"
                ));
            }
            if bottom_of[k.fb[b] + i] != usize::MAX {
                return Err(format!(
                    "interval {i} on the bottom of cylinder {b} is glued twice"
                ));
            }
            bottom_of[k.fb[b] + i] = faces.len();
            faces.push(Interface {
                lower: c,
                upper: b,
                lower_start: start,
                upper_start: ustart,
                length,
                rotation: if closed { p.2.rem_euclid(l) } else { 0.0 },
                closed,
                crossings: n,
            });
        }
    }
    Ok((faces, outliers, outlier_distance, mismatch))
}

/// The labelled points on every cylinder's bottom and top circles: the zero copies that start
/// the interfaces and `added[e]` points evenly spaced inside interface `e`.
#[allow(clippy::type_complexity)]
fn labelled_points(
    faces: &[Interface],
    added: &[usize],
    circ: &[f64],
) -> (Vec<Vec<Labelled>>, Vec<Vec<Labelled>>) {
    let nc = circ.len();
    let mut bottom: Vec<Vec<Labelled>> = vec![Vec::new(); nc];
    let mut top: Vec<Vec<Labelled>> = vec![Vec::new(); nc];
    for (e, f) in faces.iter().enumerate() {
        let x = added[e];
        let (lo, up) = (circ[f.lower], circ[f.upper]);
        // on a whole circle `x ≥ 1` points from offset 0; else the zero copy and `x` inside
        let offsets: Vec<f64> = if f.closed {
            (0..x).map(|k| f.length * k as f64 / x as f64).collect()
        } else {
            (0..=x)
                .map(|k| f.length * k as f64 / (x + 1) as f64)
                .collect()
        };
        for (k, o) in offsets.into_iter().enumerate() {
            let zero = !f.closed && k == 0;
            top[f.lower].push(((f.lower_start + o).rem_euclid(lo), (e, k), zero));
            let u = (f.upper_start + o - f.rotation).rem_euclid(up);
            bottom[f.upper].push((u, (e, k), zero));
        }
    }
    for p in bottom.iter_mut().chain(top.iter_mut()) {
        p.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    (bottom, top)
}

/// The lines of cylinder `c` (circumference `l`, height `h`) from its sorted bottom and top
/// points: bottom point `i` to top point `i + r`, `r` (with the number of turns) minimizing
/// `Σ (u_top − u_bottom)²`; the layout (knot lengths still 0) and the top labels of its lines.
fn cylinder_lines(
    c: usize,
    bp: &[Labelled],
    tp: &[Labelled],
    l: f64,
) -> Result<(CylinderLayout, Vec<(usize, usize)>), String> {
    let k = bp.len();
    if k == 0 || k != tp.len() {
        return Err(format!(
            "cylinder {c} has {k} points on its bottom circle and {} on its top after balancing",
            tp.len()
        ));
    }
    let unwrapped = |j: isize| {
        let (q, r) = (j.div_euclid(k as isize), j.rem_euclid(k as isize) as usize);
        tp[r].0 + q as f64 * l
    };
    let cost = |r: isize| -> f64 {
        (0..k)
            .map(|i| (unwrapped(i as isize + r) - bp[i].0).powi(2))
            .sum()
    };
    let r = (-(k as isize)..2 * k as isize)
        .min_by(|&a, &b| cost(a).total_cmp(&cost(b)))
        .unwrap_or(0);
    let tl: Vec<Labelled> = (0..k)
        .map(|i| tp[(i as isize + r).rem_euclid(k as isize) as usize])
        .collect();
    let layout = CylinderLayout {
        bottom: bp.iter().map(|p| p.0).collect(),
        top: (0..k).map(|i| unwrapped(i as isize + r)).collect(),
        lengths: vec![0.0; k],
        zero_ends: (0..k).map(|i| [bp[i].2, tl[i].2]).collect(),
    };
    Ok((layout, tl.iter().map(|p| p.1).collect()))
}

/// Width of strip `s` of `y` at height fraction `t`.
fn width(y: &CylinderLayout, s: usize, t: f64, l: f64) -> f64 {
    y.line_at(s + 1, t, l) - y.line_at(s, t, l)
}

/// Sets one knot length per chain of strips glued top to bottom (`up_of`, over the strips
/// numbered cylinder by cylinder): the mean width of the chain's strips.
fn chain_lengths(
    layouts: &mut [CylinderLayout],
    circ: &[f64],
    up_of: &[usize],
) -> Result<(), String> {
    let owner: Vec<(usize, usize)> = (0..layouts.len())
        .flat_map(|c| (0..layouts[c].strips()).map(move |s| (c, s)))
        .collect();
    let strips = owner.len();
    let mut done = vec![false; strips];
    for r0 in 0..strips {
        if done[r0] {
            continue;
        }
        let mut chain = vec![r0];
        let mut r = up_of[r0];
        while r != r0 {
            if chain.len() > strips || done[r] {
                return Err("the glues of the strips' tops are not a permutation".into());
            }
            chain.push(r);
            r = up_of[r];
        }
        let widths = chain.iter().map(|&r| {
            let (c, s) = owner[r];
            0.5 * (width(&layouts[c], s, 0.0, circ[c]) + width(&layouts[c], s, 1.0, circ[c]))
        });
        let mean = widths.sum::<f64>() / chain.len() as f64;
        for &r in &chain {
            let (c, s) = owner[r];
            layouts[c].lengths[s] = mean;
            done[r] = true;
        }
    }
    Ok(())
}

/// The layouts and glues of `domain`, or a sentence saying why the strips do not match.
pub fn gluing(domain: &GenusDomain) -> Result<Gluing, String> {
    let nc = domain.cylinders.len();
    let k = Circles::new(domain);
    let (faces, outliers, outlier_distance, mut mismatch) = interfaces(domain, &k)?;
    let total = domain.crossings.len();
    if 20 * outliers > total || outlier_distance > 0.05 {
        return Err(format!(
            "{outliers} of {total} crossings of the critical levels disagree with the glues of their intervals (up to {outlier_distance:.2e} of the circumference from a zero)"
        ));
    }
    let added = balance(&faces, nc)?;
    let (pts_bottom, pts_top) = labelled_points(&faces, &added, &k.circ);
    let mut layouts = Vec::with_capacity(nc);
    let mut labels_top = Vec::with_capacity(nc);
    let mut max_slope = 0.0f64;
    for c in 0..nc {
        let (y, tl) = cylinder_lines(c, &pts_bottom[c], &pts_top[c], k.circ[c])?;
        let h = domain.cylinders[c].height;
        for (b, t) in y.bottom.iter().zip(&y.top) {
            max_slope = max_slope.max((t - b).abs() / h);
        }
        layouts.push(y);
        labels_top.push(tl);
    }
    // glues: the top of strip s starts at the label of line s's top end; the strip above
    // starts at the same label on its bottom
    let first = firsts(&labels_top);
    let mut up_of = Vec::with_capacity(first.last().map_or(0, |f| f + labels_top[nc - 1].len()));
    let mut glues = Vec::with_capacity(up_of.capacity());
    for c in 0..nc {
        for (s, label) in labels_top[c].iter().enumerate() {
            let b = faces[label.0].upper;
            let Some(m) = pts_bottom[b].iter().position(|p| p.1 == *label) else {
                return Err(format!(
                    "the top of strip {s} of cylinder {c} starts at a point missing on the bottom of cylinder {b}"
                ));
            };
            let (wt, wb) = (
                width(&layouts[c], s, 1.0, k.circ[c]),
                width(&layouts[b], m, 0.0, k.circ[b]),
            );
            mismatch = mismatch.max((wt - wb).abs() / k.circ[c]);
            if (wt - wb).abs() > TOL * k.circ[c].max(k.circ[b]) {
                return Err(format!(
                    "the top of strip {s} of cylinder {c} (width {wt}) is glued to the bottom of strip {m} of cylinder {b} (width {wb})"
                ));
            }
            up_of.push(first[b] + m);
            glues.push(Glue {
                lower: c,
                lower_strip: s,
                upper: b,
                upper_strip: m,
                length: 0.0,
                crossings: faces[label.0].crossings,
            });
        }
    }
    chain_lengths(&mut layouts, &k.circ, &up_of)?;
    for g in &mut glues {
        g.length = layouts[g.lower].lengths[g.lower_strip];
    }
    Ok(Gluing {
        layouts,
        glues,
        mismatch,
        outliers,
        outlier_distance,
        added_points: added.iter().sum(),
        interfaces: faces.len(),
        max_slope,
    })
}

/// Points to add per interface so that every cylinder has as many points on its bottom circle
/// as on its top (the module doc): at least one on a whole circle, then units of flow from
/// cylinders with more points below to cylinders with more above along shortest directed
/// paths, each step over the interface with the longest gaps.
fn balance(faces: &[Interface], nc: usize) -> Result<Vec<usize>, String> {
    let mut x: Vec<usize> = faces.iter().map(|f| usize::from(f.closed)).collect();
    // points below minus points above, per cylinder
    let mut excess = vec![0isize; nc];
    for (f, &n) in faces.iter().zip(&x) {
        let pts = n as isize + isize::from(!f.closed);
        excess[f.upper] += pts;
        excess[f.lower] -= pts;
    }
    let mut out: Vec<Vec<usize>> = vec![Vec::new(); nc];
    for (e, f) in faces.iter().enumerate() {
        out[f.lower].push(e);
    }
    let budget = faces.len() * nc + nc;
    for _ in 0..budget {
        let Some(src) = excess.iter().position(|&d| d > 0) else {
            return Ok(x);
        };
        // breadth-first search upward to a cylinder with more points above
        let mut via = vec![usize::MAX; nc];
        let mut seen = vec![false; nc];
        seen[src] = true;
        let mut queue = VecDeque::from([src]);
        let mut sink = None;
        while let Some(c) = queue.pop_front() {
            if excess[c] < 0 {
                sink = Some(c);
                break;
            }
            let mut edges = out[c].clone();
            let gap = |e: usize| faces[e].length / (x[e] + 2) as f64;
            edges.sort_by(|&a, &b| gap(b).total_cmp(&gap(a)));
            for e in edges {
                let u = faces[e].upper;
                if !seen[u] {
                    seen[u] = true;
                    via[u] = e;
                    queue.push_back(u);
                }
            }
        }
        let Some(mut c) = sink else {
            return Err(format!(
                "cylinder {src} has more zero copies on its bottom circle than on its top and no cylinder above it has fewer"
            ));
        };
        excess[c] += 1;
        excess[src] -= 1;
        while c != src {
            let e = via[c];
            x[e] += 1;
            c = faces[e].lower;
        }
    }
    Err("balancing the points on the cylinders' circles did not finish".into())
}
