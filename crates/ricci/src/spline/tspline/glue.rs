//! Genus ≥ 2, step 3a: how the cylinders of [`super::genus_domain`] are glued along the
//! critical trajectories, in a form that lets the cylinders' splines share their boundary
//! control points (C⁰ across the critical trajectories by construction, issue 18).
//!
//! Every cylinder's circles are cut by the copies of the zeros into **segments**; a top
//! segment of one cylinder is a bottom segment of the next, up to a translation in `u`. Each
//! cylinder gets a **sheared** coordinate `u' = u − shift − shear · v / H` (an affine change
//! of its parameters, the surface is unchanged) such that the zero copies on its top and
//! bottom circles lie on the same vertical lines `u' = lines[s]` (the **knot lines**, triple
//! knots in the fit). The cylinder is then a cycle of vertical **strips** `[lines[s],
//! lines[s + 1]]`; the top of strip `s` of cylinder `c` is glued, point for point with the
//! same offset from the strip's left line, to the bottom of strip `s'` of another cylinder
//! (a [`Glue`]). Both are read off the data: the copies from
//! [`GenusDomain::zero_copies`], the glues from the mesh edges' [`GenusDomain::crossings`].
//!
//! This needs, per cylinder, as many zero copies on top as on the bottom with the same cyclic
//! gaps (true for the pants decompositions of genus 2 with one zero per critical level, e.g.
//! eight.off); otherwise [`gluing`] says why not and the fit falls back to the penalty.

use super::genus_domain::GenusDomain;
use serde::Serialize;

/// The sheared coordinate and the knot lines of one cylinder.
#[derive(Debug, Clone, Serialize)]
pub struct CylinderLayout {
    /// `u' = (u − shift − shear · v / H) mod L`.
    pub shift: f64,
    pub shear: f64,
    /// Knot lines `u'` (sorted, `lines[0] = 0`): strip `s` is `[lines[s], lines[s + 1]]`,
    /// the last one ends at `L`.
    pub lines: Vec<f64>,
}

impl CylinderLayout {
    /// Length of strip `s` in a cylinder of circumference `l`.
    pub fn strip_length(&self, s: usize, l: f64) -> f64 {
        self.lines.get(s + 1).copied().unwrap_or(l) - self.lines[s]
    }

    /// The strip holding `u' ∈ [0, L)`.
    pub fn strip(&self, u: f64) -> usize {
        self.lines.partition_point(|&x| x <= u).saturating_sub(1)
    }
}

/// The top of strip `lower_strip` of cylinder `lower` is the bottom of strip `upper_strip` of
/// cylinder `upper`, offsets from the strips' left lines equal.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Glue {
    pub lower: usize,
    pub lower_strip: usize,
    pub upper: usize,
    pub upper_strip: usize,
    pub length: f64,
    /// Mesh-edge crossings that gave this glue.
    pub crossings: usize,
}

/// Layouts of all cylinders and the glues of all their strips.
#[derive(Debug, Clone, Serialize)]
pub struct Gluing {
    pub layouts: Vec<CylinderLayout>,
    pub glues: Vec<Glue>,
    /// Largest disagreement (relative to the circumference) between the zero copies on a
    /// cylinder's top and bottom after the shear, between glued strips' lengths, and between
    /// the crossings' offsets on the two sides.
    pub mismatch: f64,
    /// Crossings that disagree with the glue of their strip, and their largest distance to a
    /// knot line (relative to the circumference).
    pub outliers: usize,
    pub outlier_distance: f64,
}

const TOL: f64 = 1e-6;

/// A crossing seen from a top strip: upper cylinder and strip, the offsets from the strips'
/// left lines on both sides, the distance to the nearest knot line (relative to `L`).
type Vote = (usize, usize, f64, f64, f64);

fn wrap_dist(a: f64, b: f64, l: f64) -> f64 {
    let d = (a - b).rem_euclid(l);
    d.min(l - d)
}

fn layout(domain: &GenusDomain, c: usize) -> Result<(CylinderLayout, f64), String> {
    let l = domain.cylinders[c].circumference;
    let copies = |top: bool| {
        let mut u: Vec<f64> = domain
            .zero_copies
            .iter()
            .filter(|z| z.cylinder == c && z.top == top)
            .map(|z| z.u)
            .collect();
        u.sort_by(f64::total_cmp);
        u
    };
    let (bottom, top) = (copies(false), copies(true));
    if bottom.is_empty() || bottom.len() != top.len() {
        return Err(format!(
            "cylinder {c} has {} zero copies on its bottom circle and {} on its top circle",
            bottom.len(),
            top.len()
        ));
    }
    let shift = bottom[0];
    let b: Vec<f64> = bottom.iter().map(|x| x - shift).collect();
    let mut t: Vec<f64> = top.iter().map(|x| (x - shift).rem_euclid(l)).collect();
    t.sort_by(f64::total_cmp);
    let k = b.len();
    let mut best: Option<(f64, f64)> = None; // (shear, mismatch)
    for r in 0..k {
        let mut shear = t[r].rem_euclid(l);
        if shear > 0.5 * l {
            shear -= l;
        }
        let worst = (0..k)
            .map(|i| wrap_dist(t[(r + i) % k] - shear, b[i], l))
            .fold(0.0, f64::max);
        if worst < TOL * l && best.is_none_or(|(s, _)| shear.abs() < s.abs()) {
            best = Some((shear, worst / l));
        }
    }
    let Some((shear, mismatch)) = best else {
        return Err(format!(
            "the zero copies on the top of cylinder {c} are not a shear of those on its bottom"
        ));
    };
    Ok((
        CylinderLayout {
            shift,
            shear,
            lines: b,
        },
        mismatch,
    ))
}

/// The layouts and glues of `domain`, or a sentence saying why the strips do not match.
pub fn gluing(domain: &GenusDomain) -> Result<Gluing, String> {
    let nc = domain.cylinders.len();
    let mut layouts = Vec::with_capacity(nc);
    let mut mismatch = 0.0f64;
    for c in 0..nc {
        let (lay, m) = layout(domain, c)?;
        mismatch = mismatch.max(m);
        layouts.push(lay);
    }
    // per (cylinder, strip): the glue on its top
    let first: Vec<usize> = layouts
        .iter()
        .scan(0, |at, lay| {
            let f = *at;
            *at += lay.lines.len();
            Some(f)
        })
        .collect();
    let strips = first.last().map_or(0, |f| f + layouts[nc - 1].lines.len());
    // per crossing: (top strip, upper cylinder, upper strip, offsets, distance to a line / L)
    let mut votes: Vec<Vec<Vote>> = vec![Vec::new(); strips];
    for x in &domain.crossings {
        let (a, b) = (x.lower, x.upper);
        let (la, lb) = (
            domain.cylinders[a].circumference,
            domain.cylinders[b].circumference,
        );
        let (ya, yb) = (&layouts[a], &layouts[b]);
        let ua = (x.u_lower - ya.shift - ya.shear).rem_euclid(la);
        let ub = (x.u_upper - yb.shift).rem_euclid(lb);
        let near = |y: &CylinderLayout, u: f64, l: f64| {
            y.lines
                .iter()
                .map(|&z| wrap_dist(u, z, l) / l)
                .fold(f64::INFINITY, f64::min)
        };
        let d = near(ya, ua, la).min(near(yb, ub, lb));
        let (sa, sb) = (ya.strip(ua), yb.strip(ub));
        votes[first[a] + sa].push((b, sb, ua - ya.lines[sa], ub - yb.lines[sb], d));
    }
    // the glue of a top strip: the (cylinder, strip) most of its crossings go to with equal
    // offsets; the others (next to a zero, where the piecewise-linear development of the
    // edges around the cone point is not that of the flat surface) are outliers
    let mut top: Vec<Option<Glue>> = vec![None; strips];
    let (mut outliers, mut outlier_distance) = (0, 0.0f64);
    for (c, lay) in layouts.iter().enumerate() {
        let lc = domain.cylinders[c].circumference;
        for s in 0..lay.lines.len() {
            let v = &votes[first[c] + s];
            let good = |t: &Vote| (t.2 - t.3).abs() <= TOL * lc;
            let mut best: Option<((usize, usize), usize)> = None;
            for t in v.iter().filter(|t| good(t)) {
                let n = v
                    .iter()
                    .filter(|o| good(o) && (o.0, o.1) == (t.0, t.1))
                    .count();
                if best.is_none_or(|(_, m)| n > m) {
                    best = Some(((t.0, t.1), n));
                }
            }
            let Some(((b, sb), n)) = best else {
                return Err(format!(
                    "no mesh edge crosses the top of strip {s} of cylinder {c} consistently"
                ));
            };
            for t in v.iter().filter(|t| !(good(t) && (t.0, t.1) == (b, sb))) {
                outliers += 1;
                outlier_distance = outlier_distance.max(t.4);
            }
            let (length, lenb) = (
                lay.strip_length(s, lc),
                layouts[b].strip_length(sb, domain.cylinders[b].circumference),
            );
            mismatch = mismatch.max((length - lenb).abs() / lc);
            if (length - lenb).abs() > TOL * lc {
                return Err(format!(
                    "strip {s} of cylinder {c} (length {length}) is glued to strip {sb} of cylinder {b} (length {lenb})"
                ));
            }
            top[first[c] + s] = Some(Glue {
                lower: c,
                lower_strip: s,
                upper: b,
                upper_strip: sb,
                length,
                crossings: n,
            });
        }
    }
    let total = domain.crossings.len();
    if 20 * outliers > total || outlier_distance > 0.05 {
        return Err(format!(
            "{outliers} of {total} crossings of the critical levels disagree with the glues of their strips (up to {outlier_distance:.2e} of the circumference from a zero)"
        ));
    }
    let mut glues = Vec::with_capacity(strips);
    let mut bottom_seen = vec![false; strips];
    for (c, lay) in layouts.iter().enumerate() {
        for s in 0..lay.lines.len() {
            let Some(g) = top[first[c] + s] else {
                return Err(format!(
                    "no mesh edge crosses the top of strip {s} of cylinder {c}"
                ));
            };
            let seen = &mut bottom_seen[first[g.upper] + g.upper_strip];
            if *seen {
                return Err(format!(
                    "the bottom of strip {} of cylinder {} is glued twice",
                    g.upper_strip, g.upper
                ));
            }
            *seen = true;
            glues.push(g);
        }
    }
    Ok(Gluing {
        layouts,
        glues,
        mismatch,
        outliers,
        outlier_distance,
    })
}
