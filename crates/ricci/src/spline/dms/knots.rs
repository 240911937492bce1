//! The knot clouds of a DMS spline space (module docs of [`super`]): their placement
//! ([`KnotClouds::place`]) and the quality measures of knot arrays that it optimizes
//! (general position, thin `Δ_β`, small `Ω_I`).

use super::*;
use crate::spline::error::SplineError;

/// How [`KnotClouds::place`] puts the knots.
#[derive(Debug, Clone, Copy)]
pub struct KnotOptions {
    /// Cloud radius as a fraction of the smallest altitude at the vertex over its triangles
    /// (the distance from the vertex to the opposite edge). Must be in (0, 0.45]; clouds of
    /// triangles whose `Δ_β` come out too thin are shrunk automatically.
    pub spread: f64,
    /// Seed of the deterministic pseudo-random angles.
    pub seed: u64,
}

impl Default for KnotOptions {
    fn default() -> Self {
        KnotOptions {
            spread: 0.3,
            seed: 0x5eed,
        }
    }
}

/// Knot clouds `t_{v,0..n}` of every domain vertex, `t_{v,0} = v`.
#[derive(Debug, Clone)]
pub struct KnotClouds {
    degree: usize,
    /// `knots[v * (n+1) + k] = t_{v,k}`.
    knots: Vec<Point>,
}

pub(crate) fn hash64(mut x: u64) -> u64 {
    // splitmix64
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}
pub(crate) fn unit(x: u64) -> f64 {
    (hash64(x) >> 11) as f64 / (1u64 << 53) as f64
}

impl KnotClouds {
    /// Use knot clouds given by the caller: `knots[v * (degree+1) + k] = t_{v,k}`; `t_{v,0}`
    /// must be the vertex itself (checked by [`DmsSpace::new`]).
    pub fn new(degree: usize, knots: Vec<Point>) -> Result<KnotClouds> {
        if !(1..=MAX_DEGREE).contains(&degree) {
            return Err(SplineError::DegreeUnsupported {
                spline: "DMS",
                degree,
                min: 1,
                max: MAX_DEGREE,
            }
            .into());
        }
        if !knots.len().is_multiple_of(degree + 1) {
            return Err(Error::input(format!(
                "knot clouds: {} knots is not a multiple of degree + 1 = {}",
                knots.len(),
                degree + 1
            )));
        }
        Ok(KnotClouds { degree, knots })
    }

    /// Place admissible knot clouds for a domain (see module docs). Around an interior vertex
    /// the knots lie in the annulus `[0.6, 1] × spread × (smallest altitude at the vertex)`; at
    /// a boundary vertex in the central 75 % of the wedge that lies outside both boundary
    /// edges (so the boundary condition holds). Positions are pseudo-random (reproducible from
    /// `seed`); every vertex keeps the best of 32 candidates for the measure
    /// [`general_position`] over its triangles (a second sweep for clouds still below 0.05),
    /// because nearly collinear knots amplify rounding errors of the recurrence. Clouds of
    /// triangles whose `Δ_β` come out thin (relative area below `min(0.05, ½ ×` the
    /// triangle's own, see `needs_shrink`) or whose `Ω_I` is small (< 10 % of the triangle)
    /// are shrunk by 0.7 and re-optimised.
    pub fn place(domain: &Domain, degree: usize, opts: &KnotOptions) -> Result<KnotClouds> {
        if !(1..=MAX_DEGREE).contains(&degree) {
            return Err(SplineError::DegreeUnsupported {
                spline: "DMS",
                degree,
                min: 1,
                max: MAX_DEGREE,
            }
            .into());
        }
        if !(opts.spread > 0.0 && opts.spread <= 0.45) {
            return Err(SplineError::KnotSpread {
                spread: opts.spread,
            }
            .into());
        }
        let mesh = domain.mesh();
        let nv = mesh.n_vertices();
        let n = degree;
        let (mut radius, wedge) = cloud_shapes(domain, opts)?;
        // Candidate clouds are pseudo-random (reproducible from the seed); each vertex keeps the
        // candidate whose worst knot triple (over its triangles) is least collinear.
        let candidate = |v: usize, r: f64, attempt: u64, out: &mut [Point]| {
            let p = domain.points[v];
            let (center, half) = wedge[v];
            let key =
                hash64(opts.seed ^ hash64(v as u64) ^ attempt.wrapping_mul(0xA24B_AED4_963E_E407));
            out[0] = p;
            for k in 1..=n {
                let rr = r * (0.6 + 0.4 * unit(key.wrapping_add(2 * k as u64)));
                let t = unit(key.wrapping_add(2 * k as u64 + 1));
                let ang = if half >= std::f64::consts::PI {
                    2.0 * std::f64::consts::PI * t
                } else {
                    center + 0.75 * half * (2.0 * t - 1.0)
                };
                out[k] = [p[0] + rr * ang.cos(), p[1] + rr * ang.sin()];
            }
        };
        let mut knots = vec![[0.0; 2]; nv * (n + 1)];
        for v in 0..nv {
            candidate(v, radius[v], 0, &mut knots[v * (n + 1)..(v + 1) * (n + 1)]);
        }
        let faces_of: Vec<Vec<u32>> = (0..nv as u32)
            .map(|v| mesh.vertex_faces(v).collect())
            .collect();
        // Quality of vertex v's cloud: worst triple with at least one knot of v.
        // Stops early once the quality drops to `floor` (the candidate is then rejected).
        let local_quality = |v: usize, knots: &[Point], floor: f64| -> f64 {
            let mut q = f64::INFINITY;
            let mut arr = Vec::with_capacity(3 * (n + 1));
            for &f in &faces_of[v] {
                let t = mesh.face(f);
                arr.clear();
                // This vertex's moving knots first.
                let m = t.iter().position(|&w| w as usize == v).unwrap_or(0);
                arr.extend_from_slice(&knots[v * (n + 1) + 1..(v + 1) * (n + 1)]);
                for (mm, &w) in t.iter().enumerate() {
                    if mm == m {
                        arr.push(knots[v * (n + 1)]);
                    } else {
                        arr.extend_from_slice(
                            &knots[w as usize * (n + 1)..(w as usize + 1) * (n + 1)],
                        );
                    }
                }
                q = q.min(general_position_involving(&arr, n, floor));
                if q <= floor {
                    return q;
                }
            }
            q
        };
        const CANDIDATES: u64 = 32;
        let mut trial = vec![[0.0; 2]; n + 1];
        let mut dirty = vec![true; nv];
        let mut counter = 0u64;
        for round in 0..12 {
            // Optimise the clouds of dirty vertices (two sweeps).
            for sweep in 0..2 {
                for v in 0..nv {
                    if !dirty[v] {
                        continue;
                    }
                    let range = v * (n + 1)..(v + 1) * (n + 1);
                    let mut best_q = local_quality(v, &knots, 0.0);
                    if sweep > 0 && best_q > 0.05 {
                        continue; // good enough: only poor clouds get a second sweep
                    }
                    let mut best = knots[range.clone()].to_vec();
                    for _ in 0..CANDIDATES {
                        counter += 1;
                        candidate(v, radius[v], counter, &mut trial);
                        knots[range.clone()].copy_from_slice(&trial);
                        let q = local_quality(v, &knots, best_q);
                        if q > best_q {
                            best_q = q;
                            best.copy_from_slice(&trial);
                        }
                    }
                    knots[range].copy_from_slice(&best);
                }
            }
            // Shrink the clouds of triangles whose Δ_β are too thin or whose Ω_I is small.
            dirty.fill(false);
            let mut any = false;
            for t in mesh.faces() {
                let arr = triangle_knots(&knots, n, *t);
                if needs_shrink(n, &arr) {
                    for &v in t {
                        dirty[v as usize] = true;
                    }
                    any = true;
                }
            }
            if !any || round == 11 {
                break;
            }
            for v in 0..nv {
                if dirty[v] {
                    radius[v] *= 0.7;
                    let p = domain.points[v];
                    for k in 1..=n {
                        let t = &mut knots[v * (n + 1) + k];
                        *t = [p[0] + 0.7 * (t[0] - p[0]), p[1] + 0.7 * (t[1] - p[1])];
                    }
                }
            }
        }
        Ok(KnotClouds { degree, knots })
    }

    pub fn degree(&self) -> usize {
        self.degree
    }
    pub fn n_vertices(&self) -> usize {
        self.knots.len() / (self.degree + 1)
    }
    /// The cloud `t_{v,0..n}`.
    pub fn cloud(&self, v: u32) -> &[Point] {
        let m = self.degree + 1;
        &self.knots[v as usize * m..(v as usize + 1) * m]
    }
    /// All knots, `[v * (n+1) + k] = t_{v,k}`.
    pub fn knots(&self) -> &[Point] {
        &self.knots
    }
}

pub(crate) fn triangle_knots(knots: &[Point], n: usize, t: [u32; 3]) -> Vec<Point> {
    let mut arr = Vec::with_capacity(3 * (n + 1));
    for v in t {
        arr.extend_from_slice(&knots[v as usize * (n + 1)..(v as usize + 1) * (n + 1)]);
    }
    arr
}

/// How far three points are from a line: the sine of the largest angle of the triangle,
/// `|det| / (product of the two shorter sides)` (0 for collinear points, 1 for a right angle
/// or better).
#[inline]
pub fn triple_quality(a: Point, b: Point, c: Point) -> f64 {
    let (x, y, z) = (norm(sub(b, a)), norm(sub(c, b)), norm(sub(a, c)));
    let longest = x.max(y).max(z);
    let prod = x * y * z / longest;
    if prod == 0.0 {
        return 0.0;
    }
    (det3(a, b, c).abs() / prod).min(1.0)
}

/// Smallest [`triple_quality`] over all triples of knots: a scale-free measure of how far the
/// knots are from having three on a line.
pub fn general_position(knots: &[Point]) -> f64 {
    general_position_involving(knots, knots.len(), 0.0)
}

/// Smallest [`triple_quality`] over the triples with at least one knot in `range`.
/// Smallest [`triple_quality`] over the triples whose first knot is in `0..prefix` (i.e. all
/// triples with at least one knot there). Stops as soon as the result is known to be
/// `≤ floor`. Works with squared qualities (no square roots in the loop).
pub(crate) fn general_position_involving(knots: &[Point], prefix: usize, floor: f64) -> f64 {
    let floor2 = floor * floor;
    let mut worst2 = f64::INFINITY;
    let k = knots.len();
    for i in 0..prefix.min(k) {
        for j in i + 1..k {
            let dij = sub(knots[j], knots[i]);
            let x2 = dij[0] * dij[0] + dij[1] * dij[1];
            for l in j + 1..k {
                let dil = sub(knots[l], knots[i]);
                let djl = sub(knots[l], knots[j]);
                let z2 = dil[0] * dil[0] + dil[1] * dil[1];
                let y2 = djl[0] * djl[0] + djl[1] * djl[1];
                let det = dij[0] * dil[1] - dij[1] * dil[0];
                let prod = x2 * y2 * z2;
                let q2 = if prod == 0.0 {
                    0.0
                } else {
                    (det * det * x2.max(y2).max(z2) / prod).min(1.0)
                };
                if q2 < worst2 {
                    worst2 = q2;
                    if worst2 <= floor2 {
                        return worst2.sqrt();
                    }
                }
            }
        }
    }
    worst2.sqrt()
}

/// For the knot array of one triangle (`[m * (n+1) + k] = t_{m,k}`): the smallest relative
/// signed area `det Δ_β / (longest side)²` over `|β| ≤ n`, and the area of
/// `Ω_I = ∩ Δ_β` relative to the triangle `Δ_0`.
pub fn patch_quality(n: usize, knots: &[Point]) -> (f64, f64) {
    let t = |m: usize, k: usize| knots[m * (n + 1) + k];
    let mut min_orientation = f64::INFINITY;
    let mut omega: Vec<Point> = vec![t(0, 0), t(1, 0), t(2, 0)];
    for total in 0..=n {
        for beta in multi_indices(total) {
            let (a, b, c) = (t(0, beta[0]), t(1, beta[1]), t(2, beta[2]));
            let s = norm(sub(b, a)).max(norm(sub(c, a))).max(norm(sub(c, b)));
            min_orientation = min_orientation.min(det3(a, b, c) / (s * s));
            omega = clip_left(&omega, a, b);
            omega = clip_left(&omega, b, c);
            omega = clip_left(&omega, c, a);
        }
    }
    let omega_ratio = if omega.len() < 3 {
        0.0
    } else {
        polygon_area(&omega) / (0.5 * det3(t(0, 0), t(1, 0), t(2, 0)))
    };
    (min_orientation, omega_ratio)
}

/// Should the clouds of a triangle (knot array as in [`patch_quality`]) shrink: are its
/// `Δ_β` too thin or its `Ω_I` too small? "Too thin" is relative to the triangle itself:
/// relative area below `min(0.05, ½ · relative area of Δ_0)`. Against a fixed 0.05 a thin
/// triangle (a 176° cap on rocker-arm.off, relative area 0.018) fails whatever its clouds —
/// `Δ_0` is the triangle — and its vertices' clouds were shrunk in every round, to 2% of the
/// already small radius (10⁻⁴ of the face), where the basis's derivatives lose 6–7 digits.
pub(crate) fn needs_shrink(n: usize, knots: &[Point]) -> bool {
    let (o, w) = patch_quality(n, knots);
    let (a, b, c) = (knots[0], knots[n + 1], knots[2 * (n + 1)]);
    let s = norm(sub(b, a)).max(norm(sub(c, a))).max(norm(sub(c, b)));
    let o0 = det3(a, b, c) / (s * s);
    o < 0.05f64.min(0.5 * o0) || w < 0.1
}

/// Convex hull (Andrew's monotone chain), counter-clockwise, without collinear points.
pub(crate) fn convex_hull(points: &[Point]) -> Vec<Point> {
    let mut p = points.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let mut h: Vec<Point> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = h.len();
        let iter: Box<dyn Iterator<Item = &Point>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while h.len() >= start + 2 && det3(h[h.len() - 2], h[h.len() - 1], q) <= 0.0 {
                h.pop();
            }
            h.push(q);
        }
        h.pop();
    }
    h
}

/// Polygon clipping of a convex polygon by the half-plane on the left of `a → b`.
pub(crate) fn clip_left(poly: &[Point], a: Point, b: Point) -> Vec<Point> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    let side = |p: Point| det3(a, b, p);
    for i in 0..poly.len() {
        let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
        let (sp, sq) = (side(p), side(q));
        if sp >= 0.0 {
            out.push(p);
        }
        if (sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0) {
            let t = sp / (sp - sq);
            out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
        }
    }
    out
}

/// Signed area of a polygon, by the shoelace formula relative to its first vertex: in
/// absolute coordinates the terms are `|x|²` and a polygon of size `h ≪ |x|` loses its area
/// to cancellation (a 1e-8 face in a unit-size affine-atlas chart of 3holes.off measured
/// `Ω_I` empty, 0 against 0.25 in a local frame).
pub(crate) fn polygon_area(poly: &[Point]) -> f64 {
    let Some(&o) = poly.first() else {
        return 0.0;
    };
    let mut s = 0.0;
    for i in 1..poly.len().saturating_sub(1) {
        s += det3(o, poly[i], poly[i + 1]);
    }
    0.5 * s
}

/// Per domain vertex: the cloud radius (`spread ×` the smallest altitude at the vertex) and
/// the wedge `(central angle, half-aperture)` its knots go in — the full circle inside, the
/// outside of both boundary edges on the boundary (the DMS boundary condition).
#[allow(clippy::type_complexity)]
fn cloud_shapes(domain: &Domain, opts: &KnotOptions) -> Result<(Vec<f64>, Vec<(f64, f64)>)> {
    let mesh = domain.mesh();
    let nv = mesh.n_vertices();
    // Radius per vertex.
    let mut radius = vec![f64::INFINITY; nv];
    for t in mesh.faces() {
        let p = t.map(|v| domain.points[v as usize]);
        let area2 = det3(p[0], p[1], p[2]);
        for m in 0..3 {
            let opp = norm(sub(p[(m + 2) % 3], p[(m + 1) % 3]));
            let h = area2 / opp;
            let v = t[m] as usize;
            radius[v] = radius[v].min(opts.spread * h);
        }
    }
    // Wedge per vertex: (central angle, half-aperture). Interior vertices: full circle.
    let mut wedge = vec![(0.0, std::f64::consts::PI); nv];
    for v in 0..nv as u32 {
        if !mesh.is_boundary_vertex(v) {
            continue;
        }
        let hs: Vec<u32> = mesh.outgoing(v).collect();
        let (first, last) = (hs[0], hs[hs.len() - 1]);
        // first: interior v → a with the domain on its left; last: boundary v → b, so the
        // domain runs b → v → a.
        let pv = domain.points[v as usize];
        let a = domain.points[mesh.he_tip(first) as usize];
        let b = domain.points[mesh.he_tip(last) as usize];
        let d1 = sub(a, pv);
        let d0 = sub(pv, b);
        let n1 = [d1[1] / norm(d1), -d1[0] / norm(d1)];
        let n0 = [d0[1] / norm(d0), -d0[0] / norm(d0)];
        let bis = [n0[0] + n1[0], n0[1] + n1[1]];
        if norm(bis) < 1e-9 {
            return Err(Error::input(format!(
                "spline domain: the boundary folds back on itself at vertex {v} (angle 0 or 2π)"
            )));
        }
        let cos_nn = (n0[0] * n1[0] + n0[1] * n1[1]).clamp(-1.0, 1.0);
        let aperture = std::f64::consts::PI - cos_nn.acos();
        wedge[v as usize] = (bis[1].atan2(bis[0]), 0.5 * aperture);
    }
    Ok((radius, wedge))
}
