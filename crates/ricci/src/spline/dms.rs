//! Triangular B-splines of Dahmen–Micchelli–Seidel (DMS) over a planar triangulation.
//!
//! Follows Dahmen, Micchelli, Seidel, "Blossoming begets B-spline bases built better by
//! B-patches" (Math. Comp. 1992) and Fong–Seidel (1993); used by paper 000 §5.
//!
//! **Knots.** Every domain vertex `v` carries a knot cloud `t_{v,0} = v, t_{v,1}, …, t_{v,n}`.
//! For a domain triangle `I = (v_0, v_1, v_2)` (counter-clockwise) and `β = (β_0, β_1, β_2)`,
//! `|β| = n`, the knot set is `V_β^I = {t_{0,0..β_0}, t_{1,0..β_1}, t_{2,0..β_2}}` (`β_m + 1`
//! knots of cloud `m`, `n + 3` in all) and the normalised basis function is
//! `N_{I,β} = |d_β^I| M(· | V_β^I)`, `d_β^I = det(t_{0,β_0}, t_{1,β_1}, t_{2,β_2})` (twice the
//! signed area; [`crate::spline::simplex`] fixes the normalisation of `M`).
//!
//! **Admissibility** (checked by [`DmsSpace::new`]): every triangle `Δ_β^I = [t_{0,β_0},
//! t_{1,β_1}, t_{2,β_2}]`, `|β| ≤ n`, is positively oriented and their interiors share a point
//! (`Ω_I ≠ ∅`); no three knots of a triangle's knot array are collinear (then every basis
//! function is `C^{n−1}`); on a boundary edge `(v, w)` every knot of the clouds of `v` and `w`
//! other than `v` and `w` lies strictly outside the domain's side of the edge line. Under these
//! conditions the spline space contains every polynomial of degree `≤ n` on the domain, with
//! control points given by blossoming ([`DmsSpace::control_points_of_polynomial`]):
//! `c_{I,β} = f(t_{0,0..β_0−1}, t_{1,0..β_1−1}, t_{2,0..β_2−1})`. (Sketch of why: the
//! recurrence on `V_β^I` with `W = Δ_β^I` telescopes over `β` by the affinity of the blossom;
//! the terms that lose a vertex knot cancel between the two triangles of an interior edge,
//! which see the same knots with opposite orientation; on a boundary edge they live outside the
//! domain.) In particular the basis is a partition of unity on the whole closed domain.
//!
//! **Evaluation.** A point of the domain is given with the face it belongs to; every value and
//! derivative is the limit from inside that face (the half-open convention of
//! [`crate::spline::simplex`] with the direction towards the face's centroid). So points on
//! edges and vertices are handled exactly, and derivatives of order `n` (piecewise constant)
//! are one-sided. A chart of a manifold spline can build the same basis from knots in its own
//! coordinates with [`TriangleBasis::new`].
//!
//! **B-patch polynomial.** The control points of one triangle also define a polynomial `P^I`
//! of degree `n`, the unique one whose blossom at `t_{0,0..β_0−1}, t_{1,0..β_1−1},
//! t_{2,0..β_2−1}` is `c_{I,β}` for all `|β| = n` (the DMS B-patch). Its blossom at any
//! arguments is a fixed linear combination of the control points ([`TriangleBasis::blossom_weights`],
//! a generalised de Casteljau algorithm over the triangles `Δ_γ^I`, `|γ| < n`); the fairing of
//! paper 000 (eq. 14, Fig. 13) constrains control points by it.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::numeric::dd::Dd;

use super::poly::Polynomial;
use super::simplex::{det3, n_partials, Point, SimplexFamily};

/// Largest supported degree.
pub const MAX_DEGREE: usize = 6;

/// Multi-indices `β` with `|β| = n`, in the order used for control points of a triangle:
/// `β_0` descending, then `β_1` descending (`(n,0,0), (n−1,1,0), (n−1,0,1), …, (0,0,n)`).
pub fn multi_indices(n: usize) -> Vec<[usize; 3]> {
    let mut v = Vec::with_capacity((n + 1) * (n + 2) / 2);
    for b0 in (0..=n).rev() {
        for b1 in (0..=n - b0).rev() {
            v.push([b0, b1, n - b0 - b1]);
        }
    }
    v
}

/// Position of `β` in [`multi_indices`]`(n)`.
pub fn multi_index_position(n: usize, beta: [usize; 3]) -> usize {
    let k = n - beta[0]; // rows with larger β_0 come first: 1 + 2 + … + k entries
    k * (k + 1) / 2 + (k - beta[1])
}

/// Number of control points per triangle, `(n+1)(n+2)/2`.
pub const fn per_triangle(n: usize) -> usize {
    (n + 1) * (n + 2) / 2
}

#[inline]
fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1]]
}
#[inline]
fn norm(a: Point) -> f64 {
    a[0].hypot(a[1])
}

/// A planar triangulation: the parameter domain of a DMS spline.
#[derive(Debug, Clone)]
pub struct Domain {
    points: Vec<Point>,
    mesh: Mesh,
}

impl Domain {
    /// Validate and build. Triangles must be counter-clockwise with positive area and form an
    /// oriented manifold (disk-like or with holes).
    pub fn new(points: Vec<Point>, triangles: Vec<[u32; 3]>) -> Result<Domain> {
        if let Some(v) = points
            .iter()
            .position(|p| !p[0].is_finite() || !p[1].is_finite())
        {
            return Err(Error::input(format!(
                "spline domain: vertex {v} has a non-finite coordinate"
            )));
        }
        let mesh = Mesh::from_triangles(points.len(), triangles)?;
        for (f, t) in mesh.faces().iter().enumerate() {
            let [a, b, c] = t.map(|v| points[v as usize]);
            let area2 = det3(a, b, c);
            let scale = norm(sub(b, a)).max(norm(sub(c, a))).max(norm(sub(c, b)));
            if !(area2 > 1e-12 * scale * scale) {
                return Err(Error::input(format!(
                    "spline domain: face {f} ({}, {}, {}) is not counter-clockwise with positive area (signed area {:.3e})",
                    t[0],
                    t[1],
                    t[2],
                    area2 / 2.0
                )));
            }
        }
        if let Some(v) = (0..mesh.n_vertices() as u32).find(|&v| mesh.is_isolated(v)) {
            return Err(Error::input(format!(
                "spline domain: vertex {v} belongs to no triangle"
            )));
        }
        Ok(Domain { points, mesh })
    }
    pub fn points(&self) -> &[Point] {
        &self.points
    }
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }
    pub fn triangles(&self) -> &[[u32; 3]] {
        self.mesh.faces()
    }
    pub fn n_faces(&self) -> usize {
        self.mesh.n_faces()
    }
    /// The corners of face `f`.
    pub fn face_points(&self, f: u32) -> [Point; 3] {
        self.mesh.face(f).map(|v| self.points[v as usize])
    }
    /// Centroid of face `f`.
    pub fn centroid(&self, f: u32) -> Point {
        let [a, b, c] = self.face_points(f);
        [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0]
    }
    /// The point with barycentric coordinates `bary` in face `f`.
    pub fn point_in_face(&self, f: u32, bary: [f64; 3]) -> Point {
        let [a, b, c] = self.face_points(f);
        [
            bary[0] * a[0] + bary[1] * b[0] + bary[2] * c[0],
            bary[0] * a[1] + bary[1] * b[1] + bary[2] * c[1],
        ]
    }
}

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
            return Err(Error::input(format!(
                "DMS spline degree {degree} is not supported (1..={MAX_DEGREE})"
            )));
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
            return Err(Error::input(format!(
                "DMS spline degree {degree} is not supported (1..={MAX_DEGREE})"
            )));
        }
        if !(opts.spread > 0.0 && opts.spread <= 0.45) {
            return Err(Error::input(format!(
                "knot spread {} is outside (0, 0.45]",
                opts.spread
            )));
        }
        let mesh = domain.mesh();
        let nv = mesh.n_vertices();
        let n = degree;
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

fn triangle_knots(knots: &[Point], n: usize, t: [u32; 3]) -> Vec<Point> {
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
fn convex_hull(points: &[Point]) -> Vec<Point> {
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
fn clip_left(poly: &[Point], a: Point, b: Point) -> Vec<Point> {
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
fn polygon_area(poly: &[Point]) -> f64 {
    let Some(&o) = poly.first() else {
        return 0.0;
    };
    let mut s = 0.0;
    for i in 1..poly.len().saturating_sub(1) {
        s += det3(o, poly[i], poly[i + 1]);
    }
    0.5 * s
}

/// The DMS basis functions `N_{I,β}`, `|β| = n`, of one triangle, built from the knot clouds
/// of its three vertices (counter-clockwise) in any coordinate system — a chart of a manifold
/// spline supplies them in its own coordinates.
#[derive(Debug, Clone)]
pub struct TriangleBasis {
    degree: usize,
    /// Clouds of the three vertices, `[m * (n+1) + k] = t_{m,k}`.
    knots: Vec<Point>,
    family: SimplexFamily,
    /// `|d_β|` per β (in [`multi_indices`] order).
    scale: Vec<f64>,
    /// Bounding box of all knots (contains every support).
    bbox: [Point; 2],
    /// Convex hull of all knots, counter-clockwise (contains every support).
    hull: Vec<Point>,
    /// Affine barycentric maps of `Δ_γ`, `|γ| < n`, for the blossom: per γ (ordered by `|γ|`,
    /// then [`multi_indices`]) `[a, bx, by]` for each of the three coordinates.
    patch: Vec<[[f64; 3]; 3]>,
    /// Smallest `det Δ_β / (longest side)²` over `|β| ≤ n`.
    min_orientation: f64,
    /// Area of `Ω_I = ∩ Δ_β` relative to the area of `Δ_0` (the domain triangle).
    omega_ratio: f64,
    /// [`general_position`] of the knot array.
    general_position: f64,
}

impl TriangleBasis {
    /// Build the basis of a triangle whose vertices carry the clouds `clouds[m] = t_{m,0..n}`
    /// (vertices counter-clockwise). Fails if the knots violate the DMS conditions that can be
    /// checked on one triangle: a triangle `Δ_β` that is not positively oriented, an empty
    /// `Ω_I`, or three collinear knots.
    pub fn new(degree: usize, clouds: [&[Point]; 3]) -> Result<TriangleBasis> {
        let n = degree;
        if !(1..=MAX_DEGREE).contains(&n) || clouds.iter().any(|c| c.len() != n + 1) {
            return Err(Error::input(format!(
                "DMS triangle: degree {n} needs clouds of {} knots each (degree 1..={MAX_DEGREE})",
                n + 1
            )));
        }
        let mut knots = Vec::with_capacity(3 * (n + 1));
        for c in clouds {
            knots.extend_from_slice(c);
        }
        let t = |m: usize, k: usize| knots[m * (n + 1) + k];
        let (min_orientation, omega_ratio) = patch_quality(n, &knots);
        if !(min_orientation > 1e-9) {
            return Err(Error::input(format!(
                "DMS knots: a triangle Δ_β is not positively oriented (relative signed area {min_orientation:.2e}); move the knots closer to their vertices"
            )));
        }
        if !(omega_ratio > 1e-9) {
            return Err(Error::input(
                "DMS knots: the triangles Δ_β of a domain triangle have no common interior point (Ω_I is empty); move the knots closer to their vertices",
            ));
        }
        let gp = general_position(&knots);
        if !(gp > 1e-9) {
            return Err(Error::input(format!(
                "DMS knots: three knots of a triangle are collinear (relative area {gp:.1e}); the basis would lose smoothness"
            )));
        }
        let groups: Vec<u8> = (0..3 * (n + 1)).map(|i| (i / (n + 1)) as u8).collect();
        let betas = multi_indices(n);
        let mut sets = Vec::with_capacity(betas.len());
        let mut scale = Vec::with_capacity(betas.len());
        for beta in &betas {
            let mut mask = 0u64;
            for m in 0..3 {
                for k in 0..=beta[m] {
                    mask |= 1 << (m * (n + 1) + k);
                }
            }
            sets.push(mask);
            scale.push(det3(t(0, beta[0]), t(1, beta[1]), t(2, beta[2])));
        }
        let family = SimplexFamily::new(&knots, &groups, &sets)?;
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for k in &knots {
            for c in 0..2 {
                lo[c] = lo[c].min(k[c]);
                hi[c] = hi[c].max(k[c]);
            }
        }
        let mut patch = Vec::new();
        for total in 0..n {
            for g in multi_indices(total) {
                let w = [t(0, g[0]), t(1, g[1]), t(2, g[2])];
                let det = det3(w[0], w[1], w[2]);
                let mut maps = [[0.0; 3]; 3];
                for j in 0..3 {
                    let (q, r) = (w[(j + 1) % 3], w[(j + 2) % 3]);
                    maps[j] = [
                        (q[0] * r[1] - q[1] * r[0]) / det,
                        (q[1] - r[1]) / det,
                        (r[0] - q[0]) / det,
                    ];
                }
                patch.push(maps);
            }
        }
        let hull = convex_hull(&knots);
        Ok(TriangleBasis {
            degree: n,
            general_position: gp,
            hull,
            knots,
            family,
            scale,
            bbox: [lo, hi],
            patch,
            min_orientation,
            omega_ratio,
        })
    }

    pub fn degree(&self) -> usize {
        self.degree
    }
    /// Number of basis functions, `(n+1)(n+2)/2`.
    pub fn len(&self) -> usize {
        self.scale.len()
    }
    pub fn is_empty(&self) -> bool {
        self.scale.is_empty()
    }
    /// Knot `t_{m,k}` (vertex `m` of the triangle).
    pub fn knot(&self, m: usize, k: usize) -> Point {
        self.knots[m * (self.degree + 1) + k]
    }
    /// Bounding box of the knots, which contains the support of every basis function.
    pub fn bbox(&self) -> [Point; 2] {
        self.bbox
    }
    /// Could `u` be in the support of a basis function (inside or on the convex hull of the
    /// knots, with a small tolerance)?
    #[inline]
    pub fn may_contain(&self, u: Point) -> bool {
        if !(u[0] >= self.bbox[0][0]
            && u[0] <= self.bbox[1][0]
            && u[1] >= self.bbox[0][1]
            && u[1] <= self.bbox[1][1])
        {
            return false;
        }
        let k = self.hull.len();
        let diam = (self.bbox[1][0] - self.bbox[0][0]).max(self.bbox[1][1] - self.bbox[0][1]);
        for i in 0..k {
            let (a, b) = (self.hull[i], self.hull[(i + 1) % k]);
            let len = norm(sub(b, a));
            if det3(a, b, u) < -1e-9 * len * diam {
                return false;
            }
        }
        true
    }
    /// Smallest relative signed area of the triangles `Δ_β`, `|β| ≤ n`.
    pub fn min_orientation(&self) -> f64 {
        self.min_orientation
    }
    /// Area of `Ω_I` over the area of the triangle.
    pub fn omega_ratio(&self) -> f64 {
        self.omega_ratio
    }
    /// How far the knots are from having three on a line ([`general_position`]).
    pub fn general_position(&self) -> f64 {
        self.general_position
    }
    /// Smallest relative determinant of the recurrence triangles.
    pub fn min_relative_det(&self) -> f64 {
        self.family.min_relative_det()
    }
    /// Number of simplex-spline nodes one evaluation computes.
    pub fn n_nodes(&self) -> usize {
        self.family.n_nodes()
    }
    /// Scratch length for [`Self::eval`] with derivatives up to `order`.
    pub fn workspace_len(&self, order: usize) -> usize {
        self.family.workspace_len(order)
    }

    /// Evaluate all `N_{I,β}` and their partials up to `order` at `u` as limits from direction
    /// `dir`: `out[b * n_partials(order) + partial_index(a, c)]` for β number `b`.
    pub fn eval(&self, u: Point, dir: Point, order: usize, work: &mut Vec<f64>, out: &mut [f64]) {
        self.family.eval(u, dir, order, work, out);
        self.apply_scale(order, out);
    }

    /// The centroid of the knots: the origin of [`Self::eval_offset`].
    pub fn origin(&self) -> Point {
        self.family.origin()
    }

    /// Simplex splines → `N_{I,β} = |d_β| M(· | V_β)` (values and partials, in place).
    fn apply_scale(&self, order: usize, out: &mut [f64]) {
        let np = n_partials(order);
        for (b, s) in self.scale.iter().enumerate() {
            for v in &mut out[b * np..(b + 1) * np] {
                *v *= s;
            }
        }
    }

    /// [`Self::eval`] at `origin() + x`, the point given by its offset from the knots'
    /// centroid (see [`SimplexFamily::eval_offset`]).
    pub fn eval_offset(
        &self,
        x: Point,
        dir: Point,
        order: usize,
        work: &mut Vec<f64>,
        out: &mut [f64],
    ) {
        self.family.eval_offset(x, dir, order, work, out);
        self.apply_scale(order, out);
    }

    /// [`Self::eval_offset`] with the recurrence in double-double
    /// ([`SimplexFamily::eval_offset_extended`]).
    pub fn eval_offset_extended(
        &self,
        x: [Dd; 2],
        dir: Point,
        order: usize,
        work: &mut Vec<Dd>,
        out: &mut [f64],
    ) {
        self.family.eval_offset_extended(x, dir, order, work, out);
        self.apply_scale(order, out);
    }

    /// The arguments `t_{0,0..β_0−1}, t_{1,0..β_1−1}, t_{2,0..β_2−1}` at which the blossom gives
    /// the control point of β.
    pub fn blossom_args(&self, beta: [usize; 3]) -> Vec<Point> {
        let mut a = Vec::with_capacity(self.degree);
        for (m, &bm) in beta.iter().enumerate() {
            for k in 0..bm {
                a.push(self.knot(m, k));
            }
        }
        a
    }

    /// Weights `w_β` with `blossom of P^I at args = Σ_β w_β c_{I,β}`, where `P^I` is the B-patch
    /// polynomial of this triangle's control points (module docs); `args.len()` must be `n`.
    /// Generalised de Casteljau: start from weight 1 on `γ = 0` and, for each argument in
    /// turn, split the weight of every `γ` among `γ + e_m` by the barycentric coordinates of
    /// the argument in `Δ_γ = [t_{0,γ_0}, t_{1,γ_1}, t_{2,γ_2}]`.
    pub fn blossom_weights(&self, args: &[Point], out: &mut [f64]) {
        let n = self.degree;
        assert_eq!(args.len(), n);
        // weights per level in a dense (n+1)² array indexed by (γ_0, γ_1).
        let w = n + 1;
        let mut cur = vec![0.0; w * w];
        let mut next = vec![0.0; w * w];
        cur[0] = 1.0;
        let mut pidx = 0;
        for (s, x) in args.iter().enumerate() {
            next.fill(0.0);
            for g in multi_indices(s) {
                let maps = &self.patch[pidx];
                pidx += 1;
                let wt = cur[g[0] * w + g[1]];
                if wt == 0.0 {
                    continue;
                }
                let lam = maps.map(|m| m[0] + m[1] * x[0] + m[2] * x[1]);
                next[(g[0] + 1) * w + g[1]] += wt * lam[0];
                next[g[0] * w + g[1] + 1] += wt * lam[1];
                next[g[0] * w + g[1]] += wt * lam[2];
            }
            std::mem::swap(&mut cur, &mut next);
        }
        for (b, beta) in multi_indices(n).iter().enumerate() {
            out[b] = cur[beta[0] * w + beta[1]];
        }
    }
}

/// [`TriangleBasis::blossom_weights`] for the knot array `knots` (`[m * (n+1) + k] = t_{m,k}`)
/// given directly, in any coordinate system: the barycentric coordinates of each argument in
/// `Δ_γ` are formed from differences to the argument, so a frame local to the triangle keeps
/// them to rounding of the triangle's size.
pub(crate) fn blossom_weights_of(n: usize, knots: &[Point], args: &[Point], out: &mut [f64]) {
    let t = |m: usize, k: usize| knots[m * (n + 1) + k];
    let w = n + 1;
    let mut cur = vec![0.0; w * w];
    let mut next = vec![0.0; w * w];
    cur[0] = 1.0;
    for (s, x) in args.iter().enumerate() {
        next.fill(0.0);
        for g in multi_indices(s) {
            let wt = cur[g[0] * w + g[1]];
            if wt == 0.0 {
                continue;
            }
            let d = [
                sub(t(0, g[0]), *x),
                sub(t(1, g[1]), *x),
                sub(t(2, g[2]), *x),
            ];
            let det = det3(t(0, g[0]), t(1, g[1]), t(2, g[2]));
            let cr = |a: Point, b: Point| a[0] * b[1] - a[1] * b[0];
            let lam = [
                cr(d[1], d[2]) / det,
                cr(d[2], d[0]) / det,
                cr(d[0], d[1]) / det,
            ];
            next[(g[0] + 1) * w + g[1]] += wt * lam[0];
            next[g[0] * w + g[1] + 1] += wt * lam[1];
            next[g[0] * w + g[1]] += wt * lam[2];
        }
        std::mem::swap(&mut cur, &mut next);
    }
    for (b, beta) in multi_indices(n).iter().enumerate() {
        out[b] = cur[beta[0] * w + beta[1]];
    }
}

/// Uniform grid of the triangles' support boxes, for finding the basis functions that may be
/// non-zero at a point.
#[derive(Debug, Clone)]
struct Grid {
    lo: Point,
    cell: f64,
    nx: usize,
    ny: usize,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Grid {
    fn new(boxes: &[[Point; 2]]) -> Grid {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        let mut mean = 0.0;
        for b in boxes {
            for c in 0..2 {
                lo[c] = lo[c].min(b[0][c]);
                hi[c] = hi[c].max(b[1][c]);
            }
            mean += (b[1][0] - b[0][0]).max(b[1][1] - b[0][1]);
        }
        mean /= boxes.len().max(1) as f64;
        let ext = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-300);
        let mut cell = mean.max(ext / 2048.0);
        if !(cell > 0.0) {
            cell = 1.0;
        }
        let nx = (((hi[0] - lo[0]) / cell).floor() as usize + 1).min(4096);
        let ny = (((hi[1] - lo[1]) / cell).floor() as usize + 1).min(4096);
        let idx =
            |x: f64, n: usize, o: f64| (((x - o) / cell).floor().max(0.0) as usize).min(n - 1);
        let mut count = vec![0u32; nx * ny + 1];
        let ranges: Vec<[usize; 4]> = boxes
            .iter()
            .map(|b| {
                [
                    idx(b[0][0], nx, lo[0]),
                    idx(b[1][0], nx, lo[0]),
                    idx(b[0][1], ny, lo[1]),
                    idx(b[1][1], ny, lo[1]),
                ]
            })
            .collect();
        for r in &ranges {
            for j in r[2]..=r[3] {
                for i in r[0]..=r[1] {
                    count[j * nx + i + 1] += 1;
                }
            }
        }
        for k in 1..count.len() {
            count[k] += count[k - 1];
        }
        let mut fillp = count.clone();
        let mut items = vec![0u32; count[nx * ny] as usize];
        for (t, r) in ranges.iter().enumerate() {
            for j in r[2]..=r[3] {
                for i in r[0]..=r[1] {
                    items[fillp[j * nx + i] as usize] = t as u32;
                    fillp[j * nx + i] += 1;
                }
            }
        }
        Grid {
            lo,
            cell,
            nx,
            ny,
            start: count,
            items,
        }
    }
    fn query(&self, u: Point) -> &[u32] {
        let fx = ((u[0] - self.lo[0]) / self.cell).floor();
        let fy = ((u[1] - self.lo[1]) / self.cell).floor();
        if !(fx >= 0.0 && fy >= 0.0) || fx as usize >= self.nx || fy as usize >= self.ny {
            return &[];
        }
        let c = fy as usize * self.nx + fx as usize;
        &self.items[self.start[c] as usize..self.start[c + 1] as usize]
    }
}

/// Arithmetic of the simplex-spline recurrence in an evaluation.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    /// Double-double recurrence ([`SimplexFamily::eval_offset_extended`]) whenever partials
    /// are asked for (values alone use the double recurrence, which is accurate for them):
    /// partials agree between charts and between nearby points to ~1e-12 of their size. The
    /// default.
    #[default]
    Extended,
    /// Double precision (~8× faster): values to 1e-15, but an order-`k` partial carries
    /// rounding noise `~ε (D/r)^k` (`D/r` the ratio of a basis function's support to its
    /// thinnest knot cloud), up to 1e-8–1e-6 of the partial at edges and vertices of graded
    /// meshes. Enough for quadrature (the fit's Gram matrix) and tessellation.
    Double,
}

/// Scratch space for evaluations (reuse it: evaluation does not allocate once it is warm).
/// `precision` chooses the arithmetic of the manifold spline's basis evaluations
/// ([`crate::spline::manifold::ManifoldSpace`]).
#[derive(Debug, Default, Clone)]
pub struct Workspace {
    pub precision: Precision,
    pub(crate) simplex: Vec<f64>,
    pub(crate) simplex_dd: Vec<Dd>,
    pub(crate) local: Vec<f64>,
    /// Global control-point indices of the basis functions found by [`DmsSpace::basis_at`].
    pub indices: Vec<u32>,
    /// Their values and partials, `n_partials(order)` per function.
    pub values: Vec<f64>,
}

impl Workspace {
    /// An empty workspace whose evaluations use `precision`.
    pub fn with_precision(precision: Precision) -> Workspace {
        Workspace {
            precision,
            ..Workspace::default()
        }
    }
}

/// Quality of the knot configuration, as measured by [`DmsSpace::new`].
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct KnotReport {
    /// Smallest relative signed area of a `Δ_β^I` (> 0 required).
    pub min_orientation: f64,
    /// Smallest `|Ω_I| / |I|` (> 0 required).
    pub min_omega_ratio: f64,
    /// Smallest sine-like measure of collinearity of three knots of one triangle.
    pub min_general_position: f64,
    /// Largest number of simplex-spline nodes of one triangle.
    pub max_nodes: usize,
}

/// The DMS spline space of a planar triangulation: domain, knots and the basis of every
/// triangle. Control points are indexed `face * (n+1)(n+2)/2 + position of β`.
#[derive(Debug, Clone)]
pub struct DmsSpace {
    domain: Domain,
    clouds: KnotClouds,
    bases: Vec<TriangleBasis>,
    grid: Grid,
    report: KnotReport,
}

impl DmsSpace {
    /// Build the space and check the DMS conditions (module docs); the error names the face
    /// or vertex at fault.
    pub fn new(domain: Domain, clouds: KnotClouds) -> Result<DmsSpace> {
        let n = clouds.degree();
        let mesh = domain.mesh();
        if clouds.n_vertices() != mesh.n_vertices() {
            return Err(Error::input(format!(
                "knot clouds for {} vertices, domain has {}",
                clouds.n_vertices(),
                mesh.n_vertices()
            )));
        }
        for v in 0..mesh.n_vertices() as u32 {
            if clouds.cloud(v)[0] != domain.points[v as usize] {
                return Err(Error::input(format!(
                    "knot t_(v,0) of vertex {v} is not the vertex itself"
                )));
            }
        }
        // Boundary condition: knots of boundary vertices outside their boundary edges.
        for h in mesh.n_corners() as u32..mesh.n_halfedges() as u32 {
            // interior twin a → b has the domain on its left
            let hi = mesh.he_twin(h);
            let (a, b) = (mesh.he_origin(hi), mesh.he_tip(hi));
            let (pa, pb) = (domain.points[a as usize], domain.points[b as usize]);
            for &v in &[a, b] {
                for (k, t) in clouds.cloud(v).iter().enumerate().skip(1) {
                    if !(det3(pa, pb, *t) < 0.0) {
                        return Err(Error::input(format!(
                            "DMS knots: knot {k} of boundary vertex {v} is not outside the boundary edge ({a}, {b}); polynomial reproduction would fail near it"
                        )));
                    }
                }
            }
        }
        use rayon::prelude::*;
        let bases: Vec<TriangleBasis> = mesh
            .faces()
            .par_iter()
            .enumerate()
            .map(|(f, t)| {
                TriangleBasis::new(n, t.map(|v| clouds.cloud(v)))
                    .map_err(|e| Error::input(format!("face {f}: {e}")))
            })
            .collect::<Result<_>>()?;
        let mut report = KnotReport {
            min_orientation: f64::INFINITY,
            min_omega_ratio: f64::INFINITY,
            min_general_position: f64::INFINITY,
            max_nodes: 0,
        };
        for b in &bases {
            report.min_orientation = report.min_orientation.min(b.min_orientation);
            report.min_omega_ratio = report.min_omega_ratio.min(b.omega_ratio);
            report.min_general_position = report.min_general_position.min(b.general_position);
            report.max_nodes = report.max_nodes.max(b.n_nodes());
        }
        let boxes: Vec<[Point; 2]> = bases.iter().map(|b| b.bbox).collect();
        let grid = Grid::new(&boxes);
        Ok(DmsSpace {
            domain,
            clouds,
            bases,
            grid,
            report,
        })
    }

    /// Convenience: place knots with [`KnotClouds::place`] and build the space.
    pub fn with_placed_knots(
        domain: Domain,
        degree: usize,
        opts: &KnotOptions,
    ) -> Result<DmsSpace> {
        let clouds = KnotClouds::place(&domain, degree, opts)?;
        DmsSpace::new(domain, clouds)
    }

    pub fn degree(&self) -> usize {
        self.clouds.degree()
    }
    pub fn domain(&self) -> &Domain {
        &self.domain
    }
    pub fn clouds(&self) -> &KnotClouds {
        &self.clouds
    }
    pub fn report(&self) -> KnotReport {
        self.report
    }
    /// The basis of face `f`.
    pub fn triangle(&self, f: u32) -> &TriangleBasis {
        &self.bases[f as usize]
    }
    /// Control points per triangle.
    pub fn per_triangle(&self) -> usize {
        per_triangle(self.degree())
    }
    /// Total number of control points (basis functions).
    pub fn n_control_points(&self) -> usize {
        self.bases.len() * self.per_triangle()
    }
    /// Global index of control point `β` of face `f`.
    pub fn control_index(&self, f: u32, beta: [usize; 3]) -> usize {
        f as usize * self.per_triangle() + multi_index_position(self.degree(), beta)
    }

    /// Find a face containing `u` (closed triangles; `None` outside the domain).
    pub fn locate(&self, u: Point) -> Option<u32> {
        let mut best: Option<(f64, u32)> = None;
        for &f in self.grid.query(u) {
            let [a, b, c] = self.domain.face_points(f);
            let area = det3(a, b, c);
            let m = det3(u, b, c).min(det3(a, u, c)).min(det3(a, b, u)) / area;
            if m >= -1e-12 && best.is_none_or(|(s, _)| m > s) {
                best = Some((m, f));
            }
        }
        best.map(|(_, f)| f)
    }

    /// All basis functions that may be non-zero at `u` in face `face` (values and partials up
    /// to `order`, as limits from inside `face`), written to `ws.indices` / `ws.values`.
    /// Returns the number of functions.
    pub fn basis_at(&self, face: u32, u: Point, order: usize, ws: &mut Workspace) -> Result<usize> {
        if face as usize >= self.bases.len() || !u[0].is_finite() || !u[1].is_finite() {
            return Err(Error::input(format!(
                "spline evaluation at ({}, {}) in face {face}: the domain has {} faces and the point must be finite",
                u[0],
                u[1],
                self.bases.len()
            )));
        }
        let np = n_partials(order);
        let nb = self.per_triangle();
        let c = self.domain.centroid(face);
        let mut dir = sub(c, u);
        if dir[0] == 0.0 && dir[1] == 0.0 {
            dir = [1.0, 0.0];
        }
        ws.indices.clear();
        ws.values.clear();
        if ws.local.len() < nb * np {
            ws.local.resize(nb * np, 0.0);
        }
        for &t in self.grid.query(u) {
            let basis = &self.bases[t as usize];
            if !basis.may_contain(u) {
                continue;
            }
            match ws.precision {
                Precision::Extended if order > 0 => {
                    // `u − origin` is exact in double-double.
                    let o = basis.origin();
                    let x = [Dd::new(u[0]) - Dd::new(o[0]), Dd::new(u[1]) - Dd::new(o[1])];
                    basis.eval_offset_extended(x, dir, order, &mut ws.simplex_dd, &mut ws.local)
                }
                _ => basis.eval(u, dir, order, &mut ws.simplex, &mut ws.local),
            }
            for b in 0..nb {
                ws.indices.push((t as usize * nb + b) as u32);
            }
            ws.values.extend_from_slice(&ws.local[..nb * np]);
        }
        Ok(ws.indices.len())
    }

    /// Evaluate `F = Σ c N` and its partials up to `order` at `u` in `face`:
    /// `out[k * dim + d]` is partial `k` (layout of [`crate::spline::simplex::partial_index`])
    /// of coordinate `d`. `control` holds `dim` numbers per control point.
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate(
        &self,
        control: &[f64],
        dim: usize,
        face: u32,
        u: Point,
        order: usize,
        ws: &mut Workspace,
        out: &mut [f64],
    ) -> Result<()> {
        let n = self.domain().n_faces() * per_triangle(self.degree());
        evaluate_with(control, dim, n, order, ws, out, |ws| {
            self.basis_at(face, u, order, ws)
        })
    }

    /// Control points (`dim` = 1) of a polynomial of degree `≤ n` by blossoming: the spline
    /// with these control points equals the polynomial on the whole domain.
    pub fn control_points_of_polynomial(&self, p: &Polynomial) -> Result<Vec<f64>> {
        let n = self.degree();
        if p.degree() > n {
            return Err(Error::input(format!(
                "a polynomial of degree {} is not in the spline space of degree {n}",
                p.degree()
            )));
        }
        let mut c = Vec::with_capacity(self.n_control_points());
        for basis in &self.bases {
            for beta in multi_indices(n) {
                c.push(p.blossom(&basis.blossom_args(beta)));
            }
        }
        Ok(c)
    }

    /// Initial control points of paper 000 §5 step (i): the degree-`n` uniform subdivision of
    /// every domain triangle mapped by its own linear interpolation of `positions` (one point of
    /// dimension `dim` per domain vertex): `c_{I,β} = Σ_m β_m P_{v_m} / n`.
    pub fn subdivision_control_points(&self, positions: &[f64], dim: usize) -> Result<Vec<f64>> {
        let n = self.degree();
        let nv = self.domain.mesh().n_vertices();
        if positions.len() != nv * dim {
            return Err(Error::input(format!(
                "{} coordinates given for {nv} domain vertices of dimension {dim}",
                positions.len()
            )));
        }
        let mut c = Vec::with_capacity(self.n_control_points() * dim);
        for t in self.domain.triangles() {
            for beta in multi_indices(n) {
                for d in 0..dim {
                    let mut s = 0.0;
                    for m in 0..3 {
                        s += beta[m] as f64 * positions[t[m] as usize * dim + d];
                    }
                    c.push(s / n as f64);
                }
            }
        }
        Ok(c)
    }
}

/// `F = Σ c N` and its partials up to `order` (`out[k * dim + d]`) for a spline space with
/// `n_control_points` control points, `basis` filling `ws` with the basis functions at the
/// point ([`DmsSpace::evaluate`], [`super::space::evaluate`]).
pub(crate) fn evaluate_with(
    control: &[f64],
    dim: usize,
    n_control_points: usize,
    order: usize,
    ws: &mut Workspace,
    out: &mut [f64],
    basis: impl FnOnce(&mut Workspace) -> Result<usize>,
) -> Result<()> {
    let np = n_partials(order);
    if control.len() != n_control_points * dim || out.len() < np * dim {
        return Err(Error::input(format!(
            "spline evaluation: {} control numbers for {} control points of dimension {dim}, output of {} for {} numbers",
            control.len(),
            n_control_points,
            out.len(),
            np * dim
        )));
    }
    let m = basis(ws)?;
    combine(control, dim, m, np, ws, out);
    Ok(())
}

/// `out = Σ_i c_{indices[i]} values[i]` over the first `m` basis functions of `ws`, summed as
/// `c_0 + Σ_i (c_i − c_0) values[i]` (partials: without the `c_0` term), `c_0` the first
/// function's control point: equal by the partition of unity (`Σ N = 1`, `Σ ∂^α N = 0`), but
/// the terms are of the size of the spline's support instead of its distance from the origin.
/// A face's second partials are sums of terms up to 10⁶ × their result; in the plain form
/// their rounding (`ε |c|`) alone reached 1e-10 of `∂²F`.
pub(crate) fn combine(
    control: &[f64],
    dim: usize,
    m: usize,
    np: usize,
    ws: &Workspace,
    out: &mut [f64],
) {
    out[..np * dim].fill(0.0);
    if m == 0 {
        return;
    }
    let g0 = ws.indices[0] as usize;
    let c0 = &control[g0 * dim..(g0 + 1) * dim];
    for i in 0..m {
        let g = ws.indices[i] as usize;
        let vals = &ws.values[i * np..(i + 1) * np];
        let c = &control[g * dim..(g + 1) * dim];
        for k in 0..np {
            let v = vals[k];
            if v != 0.0 {
                for d in 0..dim {
                    out[k * dim + d] += v * (c[d] - c0[d]);
                }
            }
        }
    }
    for d in 0..dim {
        out[d] += c0[d];
    }
}
