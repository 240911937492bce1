//! Texture coordinates on the **input's own faces** from a layout of another triangulation of
//! the same surface (the cut's refinement, or the intrinsic Delaunay triangulation of
//! `--scheme conformal`), whose vertices include the input's with the same ids.
//!
//! Every input vertex has one or more positions in the layout (several along the seams: one
//! per copy in the cut mesh). An input face `(a, b, c)` gets, for `a`, one of its copies
//! `p_a`, and for `b` and `c` the images `g(p_b)`, `g(p_c)` of their copies under deck
//! transformations `g` that bring them nearest to `p_a` (geodesic distance of the model
//! space). Faces away from the seams take the identity; a face whose edges cross a cut loop
//! of the laid-out triangulation gets its far vertices mapped across the loop by the side
//! pairing of that loop (at the polygon's corners, where seams meet, by a product of two, or
//! by `Q_s Q_t⁻¹` for corner maps `Q`). The UVs are exact at the vertices; inside a face they interpolate linearly,
//! which is a valid map of the face when its UV triangle is positively oriented. The result
//! lists the faces that are not (`flipped_faces`): where a map exact inside the faces is
//! needed, the common subdivision of the two triangulations is.

use super::deck::{DeckFrames, DeckGroup};
use super::isometry::Isometry;
use super::place::{Frame, Space};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use rayon::prelude::*;

/// UVs per corner of the input faces (three per face, in face order).
#[derive(Debug, Clone)]
pub struct InputUvs<P> {
    /// `corner[3f + i]`: the layout position of corner `i` of input face `f`.
    pub corner: Vec<P>,
    /// Input faces whose UV triangle is not positively oriented.
    pub flipped_faces: Vec<u32>,
    /// Input faces that needed a deck transformation (they straddle a seam).
    pub seam_faces: usize,
    /// Per corner: the laid-out vertex whose position it took and the index, in
    /// [`candidate_maps`], of the deck transformation applied to it (0: the identity), so
    /// that the corner can be recomputed in another precision.
    pub source: Vec<(u32, u32)>,
}

/// The deck transformations [`face_uvs`] tries, in its order: the identity; the side
/// pairings in both directions (a face straddling one seam); products of two of them (not
/// `x x⁻¹`) and `Q_s Q_t⁻¹` (`s ≠ t`) for corner maps `Q` (faces at the polygon's corners,
/// where several seams meet). The second value ends the three levels (identity; pairings;
/// products).
pub fn candidate_maps<I: Isometry>(group: Option<&DeckGroup<I>>) -> (Vec<I>, [usize; 3]) {
    match group {
        None => (vec![I::identity()], [1, 1, 1]),
        Some(g) => {
            let pairs: Vec<I> = g.pairings.iter().map(|p| p.map).collect();
            let corners: Vec<I> = g.corner_maps.iter().flatten().copied().collect();
            candidates(&pairs, &corners, I::identity(), I::compose, I::inverse)
        }
    }
}

/// [`candidate_maps`] (same order) in the working precision of the space, from the deck
/// group's unrounded maps ([`DeckFrames`]).
pub fn candidate_frames<F: Frame>(frames: &DeckFrames<F>) -> Vec<F> {
    let corners: Vec<F> = frames.corner_maps.iter().flatten().copied().collect();
    candidates(
        &frames.pairings,
        &corners,
        F::identity(),
        F::compose,
        F::inverse,
    )
    .0
}

fn candidates<T: Copy>(
    pairings: &[T],
    corner_maps: &[T],
    identity: T,
    compose: impl Fn(&T, &T) -> T,
    inverse: impl Fn(&T) -> T,
) -> (Vec<T>, [usize; 3]) {
    let mut cands = vec![identity];
    let pairs: Vec<T> = pairings.iter().flat_map(|p| [*p, inverse(p)]).collect();
    let mut prods = Vec::new();
    // `pairs[2k + 1]` is `pairs[2k]⁻¹`: the products `x x⁻¹` and `Q_s Q_s⁻¹` are the identity
    // (candidate 0) up to rounding and are left out — same list in every precision.
    for (a, x) in pairs.iter().enumerate() {
        for (b, y) in pairs.iter().enumerate() {
            if b != a ^ 1 {
                prods.push(compose(x, y));
            }
        }
    }
    // Around the polygon's corners (copies of the base vertex) the sectors are related by
    // Q_s Q_t⁻¹ (corner maps: P_0 ↦ P_s), which can be long products of pairings.
    for (s, qs) in corner_maps.iter().enumerate() {
        for (t, qt) in corner_maps.iter().enumerate() {
            if s != t {
                prods.push(compose(qs, &inverse(qt)));
            }
        }
    }
    cands.extend(pairs);
    let l1 = cands.len();
    cands.extend(prods);
    let l2 = cands.len();
    (cands, [1, l1, l2])
}

/// See the module docs. `positions` are the layout positions of the laid-out mesh's vertices,
/// `origin[v]` the vertex of the surface (input ids first) each of them is a copy of; `group`
/// the deck group of the layout (`None` for a disk: no seams).
pub fn input_face_uvs<S: Space>(
    input: &Mesh,
    positions: &[S::Point],
    origin: &[u32],
    group: Option<&DeckGroup<S::Iso>>,
) -> Result<InputUvs<S::Point>>
where
    S::Iso: Isometry<Point = S::Point>,
{
    let used: Vec<bool> = (0..input.n_vertices() as u32)
        .map(|v| !input.is_isolated(v))
        .collect();
    face_uvs::<S>(&used, input.faces(), positions, origin, group)
}

/// [`input_face_uvs`] for any list of triangles on the surface's vertices (`used[v]`: vertex
/// `v` is a corner of some triangle) — e.g. the faces of an intrinsic triangulation, which
/// may be a Δ-complex (self-loops, multi-edges) and so not a [`Mesh`].
pub fn face_uvs<S: Space>(
    used: &[bool],
    faces: &[[u32; 3]],
    positions: &[S::Point],
    origin: &[u32],
    group: Option<&DeckGroup<S::Iso>>,
) -> Result<InputUvs<S::Point>>
where
    S::Iso: Isometry<Point = S::Point>,
{
    face_uvs_with_lengths::<S>(used, faces, None, positions, origin, group)
}

/// [`face_uvs`] for triangles whose side lengths in the laid-out metric are known
/// (`side_lengths[f] = [l₀₁, l₁₂, l₂₀]`; the faces of the intrinsic triangulation the layout
/// refines, which are congruent to their images): a face whose nearest images are flipped or
/// do not have these side lengths — around the polygon's corners, where the sectors of many
/// seams meet, the nearest image of a vertex can be the wrong one — takes the images, over all
/// copies and candidate maps, whose distances match the side lengths best among the
/// positively oriented ones.
pub fn face_uvs_with_lengths<S: Space>(
    used: &[bool],
    faces: &[[u32; 3]],
    side_lengths: Option<&[[f64; 3]]>,
    positions: &[S::Point],
    origin: &[u32],
    group: Option<&DeckGroup<S::Iso>>,
) -> Result<InputUvs<S::Point>>
where
    S::Iso: Isometry<Point = S::Point>,
{
    if let Some(l) = side_lengths {
        if l.len() != faces.len() {
            return Err(Error::input(format!(
                "{} side-length triples for {} faces",
                l.len(),
                faces.len()
            )));
        }
    }
    if positions.len() != origin.len() {
        return Err(Error::input(format!(
            "{} layout positions for {} vertex origins",
            positions.len(),
            origin.len()
        )));
    }
    let nv = used.len();
    if let Some(f) = faces
        .iter()
        .position(|t| t.iter().any(|&v| v as usize >= nv))
    {
        return Err(Error::input(format!(
            "face {f} names a vertex beyond the surface's {nv}"
        )));
    }
    let mut copies: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for (c, &v) in origin.iter().enumerate() {
        if (v as usize) < nv {
            copies[v as usize].push(c as u32);
        }
    }
    if let Some(v) = (0..nv).find(|&v| copies[v].is_empty() && used[v]) {
        return Err(Error::input(format!(
            "input vertex {v} has no position in the layout"
        )));
    }
    // Searched in three levels (identity; pairings; products), the next only when the
    // previous leaves the face spread out or flipped. Every face's search reads only the
    // layout, so the faces are searched in parallel (rayon) with the same results.
    let (cands, level_end) = candidate_maps(group);
    let images = Images::<S>::new(positions, &copies, &cands, &level_end);
    // First pass with the identity only: the typical size of a face in the layout.
    let first: Vec<Choice<S::Point>> = faces
        .par_iter()
        .map_init(Vec::new, |buf, t| {
            let ca = copies[t[0] as usize][0];
            let pa = positions[ca as usize];
            let (db, pb, sb) = images.nearest(t[1], pa, 1, f64::INFINITY, buf);
            let (dc, pc, sc) = images.nearest(t[2], pa, 1, f64::INFINITY, buf);
            let spread = db.max(dc).max(S::distance(pb, pc));
            (spread, [pa, pb, pc], [(ca, 0), sb, sc])
        })
        .collect();
    let mut sorted: Vec<f64> = first
        .iter()
        .map(|c| c.0)
        .filter(|x| x.is_finite())
        .collect();
    // The element at the middle of the sorted spreads (a selection, not a sort).
    let mid = sorted.len() / 2;
    let median = if sorted.is_empty() {
        0.0
    } else {
        *sorted.select_nth_unstable_by(mid, f64::total_cmp).1
    };
    let across: Vec<Option<Choice<S::Point>>> = match group {
        None => Vec::new(),
        Some(_) => faces
            .par_iter()
            .zip(first.par_iter())
            .map_init(Vec::new, |buf, (t, now)| {
                images.across_seams(t, now, median, &level_end, buf)
            })
            .collect(),
    };
    let mut corner = Vec::with_capacity(3 * faces.len());
    let mut source = Vec::with_capacity(3 * faces.len());
    let mut seam_faces = 0;
    for (f, mut choice) in first.into_iter().enumerate() {
        if let Some(Some(better)) = across.get(f) {
            seam_faces += 1;
            choice = *better;
        }
        corner.extend(choice.1);
        source.extend(choice.2);
    }
    if let (Some(l), Some(_)) = (side_lengths, group) {
        seam_faces += images.match_side_lengths(faces, l, &mut corner, &mut source);
    }
    let flipped_faces = (0..faces.len())
        .filter(|&f| S::orientation(corner[3 * f], corner[3 * f + 1], corner[3 * f + 2]) <= 0.0)
        .map(|f| f as u32)
        .collect();
    Ok(InputUvs {
        corner,
        flipped_faces,
        seam_faces,
        source,
    })
}

/// A face's corners with their mismatch and sources (copy, map).
type Choice<P> = (f64, [P; 3], [(u32, u32); 3]);

/// The images an [`Images::nearest`] search visited: (distance key, image, copy, map).
type Visits<P> = Vec<(f64, P, u32, u32)>;

/// The last few images whose exact distance from a search's point was measured: near the
/// identity, many candidate maps (products `x x⁻¹`, `Q_s Q_s⁻¹`, …) send a copy to the same
/// rounded point, whose distance is then measured once ([`Space::distance`] is a function of
/// the two points: the same value as measuring again).
struct Measured<P> {
    seen: [Option<(P, f64)>; 4],
    next: usize,
}

impl<P> Default for Measured<P> {
    fn default() -> Self {
        Measured {
            seen: [None, None, None, None],
            next: 0,
        }
    }
}

impl<P: Copy + PartialEq> Measured<P> {
    /// `S::distance(q, p)` for the search's point `p` (the same `p` at every call).
    fn distance<S: Space<Point = P>>(&mut self, q: P, p: P) -> f64 {
        for &(r, d) in self.seen.iter().flatten() {
            // Equal coordinates (±0 alike) give equal distances: every formula of
            // `Space::distance` reads the coordinates through differences, squares and norms.
            if r == q {
                return d;
            }
        }
        let d = S::distance(q, p);
        self.seen[self.next] = Some((q, d));
        self.next = (self.next + 1) % self.seen.len();
        d
    }
}

/// The images of the surface's vertices under the candidate deck maps.
///
/// Both searches return what an exhaustive search over (copy, map) in that order with
/// [`Space::distance`] returns, but skip work: candidates are ranked by
/// [`Space::distance_key`] and only those within 1e-9 (relative) of the best are measured
/// exactly; where distances are accurate ([`Space::resolved`]), the maps are visited by
/// increasing displacement bound `ℓ_g` and the visit stops where `d(g q, p) ≥ ℓ_g − d(q, p)`
/// exceeds the best found (plus 1e-6).
struct Images<'a, S: Space> {
    positions: &'a [S::Point],
    copies: &'a [Vec<u32>],
    cands: &'a [S::Iso],
    /// Per candidate map: [`Isometry::displacement_bound`].
    disp: Vec<f64>,
    /// The candidate maps but the first, by increasing `disp` (ties by index).
    by_disp: Vec<u32>,
    /// Per level end `n` of [`candidate_maps`]: the maps of `by_disp` below `n`, in its order.
    by_disp_below: Vec<(usize, Vec<u32>)>,
}

/// Rounding allowance of the pruning bounds of [`Images`].
fn slack(x: f64) -> f64 {
    1e-6 * (1.0 + x)
}

impl<'a, S: Space> Images<'a, S>
where
    S::Iso: Isometry<Point = S::Point>,
{
    fn new(
        positions: &'a [S::Point],
        copies: &'a [Vec<u32>],
        cands: &'a [S::Iso],
        level_end: &[usize],
    ) -> Self {
        let disp: Vec<f64> = cands.iter().map(|g| g.displacement_bound()).collect();
        let mut by_disp: Vec<u32> = (1..cands.len() as u32).collect();
        by_disp.sort_by(|&a, &b| disp[a as usize].total_cmp(&disp[b as usize]));
        let below = |n: usize| -> Vec<u32> {
            let maps = by_disp.iter().copied();
            maps.filter(|&k| (k as usize) < n).collect()
        };
        let by_disp_below = level_end.iter().map(|&n| (n, below(n))).collect();
        Images {
            positions,
            copies,
            cands,
            disp,
            by_disp,
            by_disp_below,
        }
    }

    /// Nearest image of vertex `w` to `p` under the first `n` candidate maps: (distance,
    /// point, (copy, map)), the first in (copy, map) order among equal distances. `upper`:
    /// the distance from `p` of some image among these (∞ if none is known), a bound to prune
    /// with from the start. `buf`: scratch space.
    fn nearest(
        &self,
        w: u32,
        p: S::Point,
        n: usize,
        upper: f64,
        buf: &mut Visits<S::Point>,
    ) -> (f64, S::Point, (u32, u32)) {
        buf.clear();
        let (mut kmin, mut upper) = (f64::INFINITY, upper);
        let prune_p = n > 1 && S::resolved(p);
        for &c in &self.copies[w as usize] {
            let q = self.positions[c as usize];
            let mut visit = |k: usize, buf: &mut Visits<S::Point>| {
                let gq = self.cands[k].apply(q);
                let key = S::distance_key(gq, p);
                if key < kmin {
                    kmin = key;
                }
                buf.push((key, gq, c, k as u32));
                gq
            };
            if n == 0 {
                continue;
            }
            let gq = visit(0, buf);
            if !prune_p {
                // No bound is used: every map is visited.
                for k in 1..n {
                    visit(k, buf);
                }
                continue;
            }
            let dq = S::resolved(q).then(|| S::distance(q, p));
            // The first map is the identity: its image is `q` itself, measured once.
            let d0 = match dq {
                Some(d) if gq == q => d,
                _ => S::distance(gq, p),
            };
            upper = upper.min(d0);
            if let Some(dq) = dq {
                // The maps below `n` in `by_disp`'s order (the same visits as filtering it).
                let order = match self.by_disp_below.iter().find(|(m, _)| *m == n) {
                    Some((_, below)) => &below[..],
                    None => &self.by_disp[..],
                };
                for &k in order {
                    if self.disp[k as usize] - dq > upper + slack(upper + dq) {
                        break;
                    }
                    if (k as usize) < n {
                        visit(k as usize, buf);
                    }
                }
            } else {
                for k in 1..n {
                    visit(k, buf);
                }
            }
        }
        let band = kmin + 1e-9 * kmin + 1e-200;
        let mut best = (f64::INFINITY, p, (u32::MAX, 0));
        let mut measured = Measured::default();
        // `buf` holds the maps of a copy in the order visited (by displacement when pruned):
        // ties are broken by (copy, map) explicitly, as the exhaustive search meets them.
        for &(key, gq, c, k) in buf.iter() {
            if key <= band {
                let d = measured.distance::<S>(gq, p);
                let found = best.2 .0 != u32::MAX;
                if d < best.0 || (found && d == best.0 && (c, k) < best.2) {
                    best = (d, gq, (c, k));
                }
            }
        }
        best
    }

    /// The second and third levels of [`face_uvs_with_lengths`]' search for face `t`, whose
    /// identity-only choice is `now` (spread, corners, sources), when it is spread out (over
    /// 4× the `median` spread) or flipped: every copy of `a`, the candidate maps of one level
    /// after the other for `b`, `c`. `Some` when that finds a smaller spread.
    fn across_seams(
        &self,
        t: &[u32; 3],
        now: &Choice<S::Point>,
        median: f64,
        level_end: &[usize; 3],
        buf: &mut Visits<S::Point>,
    ) -> Option<Choice<S::Point>> {
        let (spread, p, src) = *now;
        let suspicious = spread > 4.0 * median || S::orientation(p[0], p[1], p[2]) <= 0.0;
        if !suspicious {
            return None;
        }
        let mut best = (f64::INFINITY, p, src);
        let copies_a = &self.copies[t[0] as usize];
        // Per copy of `a`: the distances of `b`'s and `c`'s nearest images at the last level,
        // images under maps the next level has too — its pruning bounds from the start.
        let mut seeds = vec![(f64::INFINITY, f64::INFINITY); copies_a.len()];
        for &n in &level_end[1..] {
            for (&ca, seed) in copies_a.iter().zip(seeds.iter_mut()) {
                let pa = self.positions[ca as usize];
                let (db, pb, sb) = self.nearest(t[1], pa, n, seed.0, buf);
                let (dc, pc, sc) = self.nearest(t[2], pa, n, seed.1, buf);
                *seed = (db, dc);
                let total = db.max(dc).max(S::distance(pb, pc));
                if total < best.0 {
                    best = (total, [pa, pb, pc], [(ca, 0), sb, sc]);
                }
            }
            let [pa, pb, pc] = best.1;
            if best.0 <= 4.0 * median && S::orientation(pa, pb, pc) > 0.0 {
                break;
            }
        }
        (best.0 < spread).then_some(best)
    }

    /// The `keep` images of vertex `w` whose distance from `p` is nearest to `want`:
    /// (mismatch, point, (copy, map)), sorted by mismatch, ties in (copy, map) order.
    ///
    /// Once `keep` images are found, an image whose mismatch is surely above the `keep`-th
    /// smallest so far cannot be among the result: it is ruled out by its
    /// [`Space::distance_key`] against the keys of the distances `want ∓ worst` (1e-9
    /// relative slack, far above the few ulps between key and distance), without its exact
    /// distance.
    fn matching(
        &self,
        w: u32,
        p: S::Point,
        want: f64,
        keep: usize,
    ) -> Vec<(f64, S::Point, (u32, u32))> {
        type Found<P> = (f64, P, (u32, u32));
        let before = |a: &Found<S::Point>, b: &Found<S::Point>| {
            a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)).is_lt()
        };
        if keep == 0 {
            return Vec::new();
        }
        // The `keep` first images so far in (mismatch, copy, map) order, in that order.
        let mut v: Vec<Found<S::Point>> = Vec::with_capacity(keep + 1);
        // The `keep` smallest mismatches so far (ascending), and the key interval outside
        // which an image's mismatch is surely above the largest of them.
        let mut top: Vec<f64> = Vec::with_capacity(keep + 1);
        let mut keys = (f64::NEG_INFINITY, f64::INFINITY);
        let prune_p = S::resolved(p);
        let mut measured = Measured::default();
        for &c in &self.copies[w as usize] {
            let q = self.positions[c as usize];
            let prune = prune_p && S::resolved(q);
            let dq = if prune { S::distance(q, p) } else { 0.0 };
            let order = std::iter::once(0).chain(self.by_disp.iter().copied());
            for k in order.take(self.cands.len()) {
                let k = k as usize;
                if prune && top.len() == keep {
                    let worst = top[keep - 1];
                    if self.disp[k] - dq - want > worst + slack(worst + want + dq) {
                        break;
                    }
                }
                let gq = self.cands[k].apply(q);
                let key = S::distance_key(gq, p);
                // Infinite keys (overflow) and NaN are measured.
                if key.is_finite() && (key < keys.0 || key > keys.1) {
                    continue;
                }
                let m = (measured.distance::<S>(gq, p) - want).abs();
                let found = (m, gq, (c, k as u32));
                if v.len() < keep || before(&found, &v[keep - 1]) {
                    let at = v.partition_point(|x| before(x, &found));
                    v.insert(at, found);
                    v.truncate(keep);
                }
                if top.len() < keep || m < top[keep - 1] {
                    let at = top.partition_point(|&x| x <= m);
                    top.insert(at, m);
                    top.truncate(keep);
                    if top.len() == keep && !top.iter().any(|x| x.is_nan()) {
                        keys = Self::mismatch_keys(want, top[keep - 1]);
                    }
                }
            }
        }
        v
    }

    /// Keys `(lo, hi)` such that an image whose [`Space::distance_key`] lies outside
    /// `[lo, hi]` has a distance `d` with `|d − want| > worst` (see [`Images::matching`]);
    /// the whole line when that cannot be told: NaN or infinite bounds, and keys below 1e-280,
    /// where an underflowing key loses its relative accuracy.
    fn mismatch_keys(want: f64, worst: f64) -> (f64, f64) {
        const REL: f64 = 1e-9;
        const SMALLEST: f64 = 1e-280;
        let far = want + worst;
        let hi = S::key_of_distance(far * (1.0 + REL)) * (1.0 + REL);
        let near = want - worst;
        let lo = S::key_of_distance(near * (1.0 - REL)) * (1.0 - REL);
        // `!(x >= y)` is also true for NaN.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        let (lo_unknown, hi_unknown) = (
            !(near > 0.0) || !(lo >= SMALLEST) || !lo.is_finite(),
            !(hi >= SMALLEST) || !hi.is_finite(),
        );
        (
            if lo_unknown { f64::NEG_INFINITY } else { lo },
            if hi_unknown { f64::INFINITY } else { hi },
        )
    }

    /// See [`face_uvs_with_lengths`]; returns the number of faces changed.
    fn match_side_lengths(
        &self,
        faces: &[[u32; 3]],
        side_lengths: &[[f64; 3]],
        corner: &mut [S::Point],
        source: &mut [(u32, u32)],
    ) -> usize {
        let mismatch = |p: [S::Point; 3], l: [f64; 3]| {
            (S::distance(p[0], p[1]) - l[0])
                .abs()
                .max((S::distance(p[1], p[2]) - l[1]).abs())
                .max((S::distance(p[2], p[0]) - l[2]).abs())
        };
        // Per face in parallel (rayon): a face's choice reads only its own corners.
        let better: Vec<(usize, Choice<S::Point>)> = faces
            .par_iter()
            .enumerate()
            .filter_map(|(f, t)| {
                let l = side_lengths[f];
                let now = [corner[3 * f], corner[3 * f + 1], corner[3 * f + 2]];
                let tol = 1e-6 * l[0].max(l[1]).max(l[2]);
                let m0 = mismatch(now, l);
                if S::orientation(now[0], now[1], now[2]) > 0.0 && m0 <= tol {
                    return None;
                }
                let mut best: Option<Choice<S::Point>> = None;
                for &ca in &self.copies[t[0] as usize] {
                    let pa = self.positions[ca as usize];
                    let bs = self.matching(t[1], pa, l[0], 6);
                    let cs = self.matching(t[2], pa, l[2], 6);
                    for &(_, pb, sb) in &bs {
                        for &(_, pc, sc) in &cs {
                            if S::orientation(pa, pb, pc) <= 0.0 {
                                continue;
                            }
                            let m = mismatch([pa, pb, pc], l);
                            if best.as_ref().is_none_or(|b| m < b.0) {
                                best = Some((m, [pa, pb, pc], [(ca, 0), sb, sc]));
                            }
                        }
                    }
                }
                let (m, p, src) = best?;
                let take = m < m0 || S::orientation(now[0], now[1], now[2]) <= 0.0;
                take.then_some((f, (m, p, src)))
            })
            .collect();
        for (f, (_, p, src)) in &better {
            corner[3 * f..3 * f + 3].copy_from_slice(p);
            source[3 * f..3 * f + 3].copy_from_slice(src);
        }
        better.len()
    }
}
