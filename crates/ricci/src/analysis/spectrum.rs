//! Geodesic length spectrum of a closed surface with its uniformization metric (paper 002
//! §6.3.3, Tables 2–4): the lengths of the closed geodesics, one per free homotopy class of
//! closed curves (unoriented: γ and γ⁻¹ are one class; powers are classes of their own, so
//! 2 × the shortest length appears as in the papers' tables), sorted with multiplicity.
//!
//! **Genus 1** ([`lattice_spectrum`]). The deck group is a lattice `ω₁Z + ω₂Z` of
//! translations; classes are the lattice vectors up to sign and the length of a class is
//! `|m ω₁ + n ω₂|`. The basis is Lagrange(Gauss)-reduced, then every vector of length ≤ L is
//! enumerated with the provable bound `|m|, |n| ≤ L/√λ_min(G)` (G the Gram matrix), L being
//! enlarged until enough vectors are found.
//!
//! **Genus ≥ 2** ([`fuchsian_spectrum`]). A class with translation length `ℓ(γ) = 2
//! acosh(|tr γ|/2)` is represented by the closed geodesic, whose lifts are the axes of the
//! conjugates of γ. Completeness: every class of length ≤ L has a conjugate whose axis
//! meets the fundamental polygon F (the axis crosses some tile hF; conjugate by h). For such
//! a γ and p on its axis in F, `d(F, γF) ≤ d(p, γp) = ℓ(γ) ≤ L`. The tiles within distance L
//! of F form a connected set under side adjacency (the L-neighbourhood of F is connected and
//! a path in it can avoid the vertices), so a breadth-first search over tiles from F through
//! the side pairings, keeping every tile whose distance to F may be ≤ L, finds all of them.
//! The test is conservative: ∂F is covered by small balls `B(c_j, r_j)` (and F by one ball
//! around a centre o), and a tile is dropped only if `d(c_j, γ c_k) − r_j − r_k > L` for all
//! pairs (distances between disjoint tiles are attained on their boundaries). Candidates are
//! the tiles γ with `ℓ(γ) ≤ L` whose axis meets F (it then crosses ∂F). They are grouped into
//! classes by tracing the closed geodesic through F: where the axis of γ crosses side s it
//! continues in the copy `S_s F`, whose piece pulled back to F lies on the axis of
//! `S_s⁻¹ γ S_s`; joining every candidate with these conjugates (and with γ⁻¹) links all the
//! pieces of one closed geodesic, and nothing else (they are conjugates). Each connected
//! group is one class. L starts at the shortest generator length and grows until at least
//! the requested number of classes have length ≤ L; every class shorter than L is then found.

use crate::analysis::teichmuller::translation_length_dd;
use crate::error::{Error, Result};
use crate::layout::dd::MobiusDd;
use crate::layout::deck::{DeckGroup, Polygon};
use crate::layout::isometry::{disk_distance, poincare_to_hyperboloid, Complex, Isometry, Mobius};
use crate::layout::place::Layout;
use std::collections::{HashMap, VecDeque};

/// The modulus `τ` of the flat torus `C/(ω₁Z + ω₂Z)`: the ratio of a reduced basis, in the
/// fundamental domain of SL(2, Z) (`Im τ > 0`, `|Re τ| ≤ 1/2`, `|τ| ≥ 1`; on the boundary
/// `Re τ ≥ 0` when `|τ| = 1` or `|Re τ| = 1/2`). Two flat tori are similar (conformally
/// equivalent) iff their moduli are equal. Returns `(Re τ, Im τ)`.
pub fn torus_modulus(w1: Complex, w2: Complex) -> Result<(f64, f64)> {
    if !(w1.norm() > 0.0 && w2.norm() > 0.0) || (w2 / w1).im.abs() < 1e-14 {
        return Err(Error::numerical(
            "the translation generators of the torus are degenerate (not a lattice)",
        ));
    }
    let mut t = w2 / w1;
    if t.im < 0.0 {
        t = -t;
    }
    for _ in 0..200 {
        t.re -= t.re.round();
        if t.norm_sqr() < 1.0 - 1e-15 {
            t = -Complex::new(1.0, 0.0) / t;
        } else {
            break;
        }
    }
    // Boundary conventions (up to rounding).
    if (t.re.abs() - 0.5).abs() < 1e-13 {
        t.re = 0.5;
    }
    if (t.norm() - 1.0).abs() < 1e-13 && t.re < 0.0 {
        t.re = -t.re;
    }
    Ok((t.re, t.im))
}

/// The first `count` lengths of the spectrum of the flat torus `C/(ω₁Z + ω₂Z)` (lattice
/// vectors up to sign, including non-primitive ones), sorted.
pub fn lattice_spectrum(w1: Complex, w2: Complex, count: usize) -> Result<Vec<f64>> {
    if !(w1.norm() > 0.0 && w2.norm() > 0.0) || (w2 / w1).im.abs() < 1e-14 {
        return Err(Error::numerical(
            "the translation generators of the torus are degenerate (not a lattice)",
        ));
    }
    let (mut a, mut b) = (w1, w2);
    // Lagrange reduction: |a| ≤ |b|, |Re(b ā)| ≤ |a|²/2.
    for _ in 0..200 {
        if b.norm_sqr() < a.norm_sqr() {
            std::mem::swap(&mut a, &mut b);
        }
        let mu = ((b * a.conj()).re / a.norm_sqr()).round();
        if mu == 0.0 {
            break;
        }
        b -= a * mu;
    }
    if b.norm_sqr() < a.norm_sqr() {
        std::mem::swap(&mut a, &mut b);
    }
    // Enumerate m·a + n·b (n ≥ 0, m > 0 when n = 0) with norm ≤ l, row by row: row n lies at
    // distance n·h from the line through a (h = |a ∧ b| / |a|), and |m·a + n·b| ≤ l exactly
    // for m in an interval around −n (a·b)/|a|² of half-width √(l² − n²h²)/|a|. So the work
    // is the number of vectors found plus the rows, however long and thin the torus (the old
    // square of side l/√λ_min did ~10¹³ steps for τ = 10⁶ i).
    let (g11, g12) = (a.norm_sqr(), (a * b.conj()).re);
    let h = (a.re * b.im - a.im * b.re).abs() / a.norm();
    if !(h > 0.0 && h.is_finite() && g11.is_finite()) {
        return Err(Error::numerical("degenerate translation lattice"));
    }
    let mut l = b.norm() * 2.0;
    // Each round multiplies l by 1.5, so the count within l by 2.25: a budget of rounds far
    // beyond any `count` (the CLI allows 10 000).
    for _ in 0..200 {
        let mut out = Vec::new();
        let rows = (l / h).floor() as i64;
        for n in 0..=rows {
            let w = (l * l - (n as f64 * h).powi(2)).max(0.0).sqrt();
            let c = -(n as f64) * g12 / g11;
            let r = w / g11.sqrt();
            let lo = if n == 0 { 1 } else { (c - r).floor() as i64 };
            for m in lo..=(c + r).ceil() as i64 {
                let v = (a * m as f64 + b * n as f64).norm();
                if v <= l {
                    out.push(v);
                }
            }
        }
        if out.len() >= count {
            out.sort_by(f64::total_cmp);
            out.truncate(count);
            return Ok(out);
        }
        l *= 1.5;
    }
    Err(Error::numerical(format!(
        "the lattice enumeration found fewer than {count} vectors within 200 rounds"
    )))
}

/// One free homotopy class of closed geodesics on a hyperbolic surface.
#[derive(Debug, Clone)]
pub struct GeodesicClass {
    pub length: f64,
    /// A deck transformation in the class whose axis meets the fundamental polygon.
    pub representative: Mobius,
    /// Number of conjugates (counting γ and γ⁻¹) whose axis meets the polygon.
    pub pieces: usize,
}

/// Result of [`fuchsian_spectrum`].
#[derive(Debug, Clone)]
pub struct HyperbolicSpectrum {
    /// Classes sorted by length (ties by nothing in particular), the first `count`.
    pub classes: Vec<GeodesicClass>,
    /// Every class of length ≤ `complete_up_to` is in the enumeration that produced `classes`.
    pub complete_up_to: f64,
    /// Tiles of the universal cover visited by the last search.
    pub tiles: usize,
    /// Links from a candidate to a conjugate whose tile was not enumerated (should be 0; a
    /// positive number means the classes may be over-counted).
    pub unmatched_links: usize,
}

impl HyperbolicSpectrum {
    pub fn lengths(&self) -> Vec<f64> {
        self.classes.iter().map(|c| c.length).collect()
    }
}

/// Orbit points of tiles, found again by position (hyperbolic distance below 1e-7). Points are
/// filed in cells of width `BAND` in the distance `r` from the origin and about `BAND` in arc
/// length (at the cell's inner radius) in the angle. (Cells in `r` alone crowd at large `r`,
/// where the tiles of a search are: with the rejected tiles of seahorse2_100K also filed,
/// lookups made the search 10× slower.) A point within 1e-7 of `x` is at most `1e-4` of a
/// cell away from `x` in `r` and (beyond the first `SMALL` bands) in the angle, so a lookup
/// probes the cell of `x` and a neighbour only when `x` lies within `MARGIN` (a hundredth of
/// a cell, 100× the need) of that side: one cell for almost every lookup. Cells hold the
/// head of a chain through `next` (no allocation per cell) and are hashed with a multiply.
struct TileIndex {
    cells: HashMap<(i64, i64), u32, std::hash::BuildHasherDefault<CellHasher>>,
    /// Next point of the same cell (`u32::MAX`: none).
    next: Vec<u32>,
    points: Vec<([f64; 3], Complex)>,
}

/// Multiplicative hashing of the two integers of a cell key (SipHash was a tenth of the
/// search's time).
#[derive(Default, Clone, Copy)]
struct CellHasher(u64);

impl std::hash::Hasher for CellHasher {
    #[inline]
    fn finish(&self) -> u64 {
        self.0 ^ (self.0 >> 29)
    }
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x100000001b3);
        }
    }
    #[inline]
    fn write_i64(&mut self, x: i64) {
        self.0 = (self.0.rotate_left(29) ^ x as u64).wrapping_mul(0x9e3779b97f4a7c15);
    }
}

impl TileIndex {
    const BAND: f64 = 1e-3;
    /// Bands (r < 0.064) where the angular cells are probed three at a time: near the
    /// origin the arc of a cell's inner circle is much shorter than the outer one's.
    const SMALL: i64 = 64;
    const MARGIN: f64 = 1e-2;
    /// `sinh(1e-7 / 2)²`: two entries are the same point when `|p − q|² (1 + X₀)(1 + Y₀)/4`
    /// is below it (hyperbolic distance below 1e-7, without the `asinh`).
    const SAME: f64 = 5e-8 * 5e-8;
    fn new() -> Self {
        TileIndex {
            cells: HashMap::default(),
            next: Vec::new(),
            points: Vec::new(),
        }
    }
    /// `r / BAND` of a hyperboloid point.
    fn band_coordinate(x: &[f64; 3]) -> f64 {
        x[2].max(1.0).acosh() / Self::BAND
    }
    /// Number of angular cells of band `k`: its inner circle's length over `BAND`.
    fn sectors(k: i64) -> i64 {
        let r = k.max(0) as f64 * Self::BAND;
        ((2.0 * std::f64::consts::PI * r.sinh() / Self::BAND).ceil() as i64).clamp(1, 1 << 52)
    }
    /// The angle of a point as a fraction of the full turn, in [0, 1].
    fn turn(x: &[f64; 3]) -> f64 {
        (x[1].atan2(x[0]) / (2.0 * std::f64::consts::PI)).rem_euclid(1.0)
    }
    /// Disk point with 1 − |p|² = 2/(1 + X₀) known exactly.
    fn entry(x: [f64; 3]) -> ([f64; 3], Complex) {
        (x, Complex::new(x[0], x[1]) / (1.0 + x[2]))
    }
    fn same(a: &([f64; 3], Complex), b: &([f64; 3], Complex)) -> bool {
        (a.1 - b.1).norm_sqr() * ((1.0 + a.0[2]) * (1.0 + b.0[2])) * 0.25 < Self::SAME
    }
    fn probe(&self, cell: (i64, i64), e: &([f64; 3], Complex)) -> Option<usize> {
        let mut i = *self.cells.get(&cell)?;
        while i != u32::MAX {
            if Self::same(&self.points[i as usize], e) {
                return Some(i as usize);
            }
            i = self.next[i as usize];
        }
        None
    }
    fn find(&self, x: [f64; 3]) -> Option<usize> {
        let e = Self::entry(x);
        let t = Self::band_coordinate(&x);
        let k = t.floor() as i64;
        let ft = t - k as f64;
        let u = Self::turn(&x);
        let first = if ft < Self::MARGIN || k < Self::SMALL {
            k - 1
        } else {
            k
        };
        let last = if ft > 1.0 - Self::MARGIN || k < Self::SMALL {
            k + 1
        } else {
            k
        };
        for kk in first..=last {
            let n = Self::sectors(kk);
            let s = u * n as f64;
            let a = s.floor() as i64;
            let fs = s - a as f64;
            if n <= 3 {
                for aa in 0..n {
                    if let Some(i) = self.probe((kk, aa), &e) {
                        return Some(i);
                    }
                }
                continue;
            }
            let wide = kk < Self::SMALL;
            let lo = if wide || fs < Self::MARGIN { a - 1 } else { a };
            let hi = if wide || fs > 1.0 - Self::MARGIN {
                a + 1
            } else {
                a
            };
            for aa in lo..=hi {
                if let Some(i) = self.probe((kk, aa.rem_euclid(n)), &e) {
                    return Some(i);
                }
            }
        }
        None
    }
    fn insert(&mut self, x: [f64; 3]) -> usize {
        let i = self.points.len();
        self.points.push(Self::entry(x));
        let k = Self::band_coordinate(&x).floor() as i64;
        let n = Self::sectors(k);
        let cell = (
            k,
            ((Self::turn(&x) * n as f64).floor() as i64).rem_euclid(n),
        );
        let head = self.cells.entry(cell).or_insert(u32::MAX);
        self.next.push(*head);
        *head = i as u32;
        i
    }
}

/// `g o` on the hyperboloid for the centre `o_h`. When the centre is the origin (the compact
/// domain is laid out so), `g 0 = b/ā`, i.e. `(2ab, |a|² + |b|²)`, straight from the leading
/// parts of the coefficients (`|a|² − |b|² = 1` to double-double precision for a product of
/// normalized words), without rounding, normalizing or forming the Lorentz matrix.
#[inline]
fn orbit_point(g: &MobiusDd, o_h: [f64; 3]) -> [f64; 3] {
    if o_h == [0.0, 0.0, 1.0] {
        let (a, b) = (g.a.hi(), g.b.hi());
        let ab = a * b;
        [2.0 * ab.re, 2.0 * ab.im, a.norm_sqr() + b.norm_sqr()]
    } else {
        apply_h(&g.round().klein_matrix(), o_h)
    }
}

fn apply_h(m: &[[f64; 3]; 3], x: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * x[0] + m[0][1] * x[1] + m[0][2] * x[2],
        m[1][0] * x[0] + m[1][1] * x[1] + m[1][2] * x[2],
        m[2][0] * x[0] + m[2][1] * x[1] + m[2][2] * x[2],
    ]
}

/// The sides of a domain, given as its boundary points each tagged with the side that starts
/// there, that the real diameter of the frame `fr` (an axis, see [`axis_frame`]) crosses or
/// touches (within `tol`), each once, in the order of the boundary; only the boundary edges
/// `edges` (edge `e` joins points `e` and `e + 1`, increasing) are tested.
fn sides_crossed(
    fr: &Mobius,
    bnd: &[(Complex, usize)],
    edges: impl IntoIterator<Item = usize>,
    tol: f64,
) -> Vec<usize> {
    let nb = bnd.len();
    let im = |e: usize| fr.apply(bnd[e % nb].0).im;
    let mut sides = Vec::new();
    for e in edges {
        let (a, b) = (im(e), im(e + 1));
        if a * b <= 0.0 || a.abs() < tol || b.abs() < tol {
            let s = bnd[e].1;
            if !sides.contains(&s) {
                sides.push(s);
            }
        }
    }
    sides
}

/// The Möbius map taking the axis of a hyperbolic element to the real diameter, its
/// attracting fixed point to +1.
fn axis_frame(g: &Mobius) -> Option<Mobius> {
    let (rep, att) = g.fixed_points()?;
    // Closest point of the geodesic to 0: along u = (e₁ + e₂)/|e₁ + e₂| at distance
    // (1 − sin θ)/cos θ = cos θ/(1 + sin θ), θ the half angle between the end points, with
    // cos θ = |e₁ + e₂|/2 and sin θ = |e₁ − e₂|/2; hence c = (e₁ + e₂)/(2 + |e₁ − e₂|), which
    // is also right for diameters (c = 0).
    let c = (rep + att) / (2.0 + (att - rep).norm());
    let t = Mobius::to_origin(c);
    let a = t.apply(att);
    Some(Mobius::rotation(-a.arg()).compose(&t))
}

/// The tiles `gF` kept by a breadth-first search from `F` through the side pairings `maps`
/// (words composed in double-double: products of side pairings that move the centre far lose
/// in double the 1e-7 that tells two tiles apart). A tile is found again by the position of
/// `g o` (`o_h`: the centre on the hyperboloid); `keep(g, g o)` decides whether a new tile is
/// kept (a tile already found is not tested again; a rejected one is, from each neighbour:
/// remembering the millions of rejected tiles of seahorse2_100K cost more than testing them
/// again, 61 s instead of 15 s and 1.4 GB). The search can be **grown**:
/// [`TileSearch::grow`] with a weaker `keep` (a larger length bound) continues from the kept
/// tiles that had a rejected neighbour — every tile kept under the smaller bound is kept
/// under the larger one, so the grown search is the search that the larger bound alone would
/// have made, without redoing its inside.
struct TileSearch {
    elems_dd: Vec<MobiusDd>,
    elems: Vec<Mobius>,
    index: TileIndex,
    /// Kept tiles with a neighbour that the last `keep` rejected.
    frontier: Vec<usize>,
    queue: VecDeque<usize>,
}

impl TileSearch {
    fn new(o_h: [f64; 3]) -> TileSearch {
        let mut index = TileIndex::new();
        index.insert(o_h);
        TileSearch {
            elems_dd: vec![MobiusDd::IDENTITY],
            elems: vec![Mobius::identity()],
            index,
            frontier: Vec::new(),
            queue: VecDeque::from([0usize]),
        }
    }

    /// Grow the search under a new `keep` (weaker than the previous ones); false when more
    /// than `max_tiles` tiles are kept.
    fn grow(
        &mut self,
        o_h: [f64; 3],
        maps: &[MobiusDd],
        max_tiles: usize,
        mut keep: impl FnMut(&Mobius, [f64; 3]) -> bool,
    ) -> bool {
        self.queue.extend(std::mem::take(&mut self.frontier));
        while let Some(t) = self.queue.pop_front() {
            if self.elems.len() > max_tiles {
                return false;
            }
            let mut rejected = false;
            for sm in maps {
                // Normalized only when kept: the product of two normalized words is
                // normalized to double-double precision, more than the lookup needs.
                let gd = self.elems_dd[t].compose(sm);
                let go = orbit_point(&gd, o_h);
                if self.index.find(go).is_some() {
                    continue;
                }
                let g = gd.round();
                if keep(&g, go) {
                    self.index.insert(go);
                    self.elems.push(g);
                    self.elems_dd.push(gd.normalized());
                    self.queue.push_back(self.elems.len() - 1);
                } else {
                    rejected = true;
                }
            }
            if rejected {
                self.frontier.push(t);
            }
        }
        self.elems.len() <= max_tiles
    }

    fn run(
        o_h: [f64; 3],
        maps: &[MobiusDd],
        max_tiles: usize,
        keep: impl FnMut(&Mobius, [f64; 3]) -> bool,
    ) -> Option<TileSearch> {
        let mut s = TileSearch::new(o_h);
        s.grow(o_h, maps, max_tiles, keep).then_some(s)
    }

    /// The next length bound after a bound `l` that gave fewer than `count` classes: the
    /// `count`-th distinct length among the candidates up to `1.25 l` when there are that
    /// many (each distinct length is at least one class, so a search up to it is certain to
    /// find `count` classes), else `1.25 l`.
    fn next_bound(&self, l: f64, count: usize, cross: impl Fn(&Mobius) -> Vec<usize>) -> f64 {
        let cap = 1.25 * l;
        let (cand, _) = self.candidates(cap, cross);
        let mut lens: Vec<f64> = cand
            .iter()
            .map(|&i| translation_length_dd(&self.elems_dd[i]))
            .collect();
        lens.sort_by(f64::total_cmp);
        lens.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * b.abs());
        match lens.get(count.saturating_sub(1)) {
            Some(&x) if x > l => (x * (1.0 + 1e-9) + 1e-12).min(cap),
            _ => cap,
        }
    }

    /// Candidates of the class search: the hyperbolic tiles with `ℓ ≤ l` (`ℓ` from the
    /// double-double word) whose axis crosses the domain's boundary, with the sides it crosses
    /// (`cross` of the axis' frame, see [`axis_frame`]; empty when the axis misses the domain).
    fn candidates(
        &self,
        l: f64,
        cross: impl Fn(&Mobius) -> Vec<usize>,
    ) -> (Vec<usize>, Vec<Vec<usize>>) {
        let mut cand: Vec<usize> = Vec::new();
        let mut crossings: Vec<Vec<usize>> = Vec::new();
        for (i, g) in self.elems.iter().enumerate().skip(1) {
            let len = translation_length_dd(&self.elems_dd[i]);
            if !(len > 0.0 && len <= l) {
                continue;
            }
            let Some(fr) = axis_frame(g) else { continue };
            let sides = cross(&fr);
            if !sides.is_empty() {
                cand.push(i);
                crossings.push(sides);
            }
        }
        (cand, crossings)
    }

    /// The classes of the candidates; `Some` when at least `count` were found.
    fn spectrum(
        &self,
        l: f64,
        maps: &[MobiusDd],
        o_h: [f64; 3],
        count: usize,
        cross: impl Fn(&Mobius) -> Vec<usize>,
    ) -> Option<HyperbolicSpectrum> {
        let (cand, crossings) = self.candidates(l, cross);
        let (mut classes, unmatched) =
            group_classes(&self.elems_dd, &cand, &crossings, maps, &self.index, o_h);
        classes.sort_by(|a, b| a.length.total_cmp(&b.length));
        if classes.len() < count {
            return None;
        }
        classes.truncate(count);
        Some(HyperbolicSpectrum {
            classes,
            complete_up_to: l,
            tiles: self.elems.len(),
            unmatched_links: unmatched,
        })
    }
}

/// Centre of a finite set of disk points (Badoiu–Clarkson iterations towards the minimax
/// centre) and the largest distance from it to one of them.
fn minimax_centre(points: &[Complex]) -> (Complex, f64) {
    let mut o = points[0];
    for it in 1..200 {
        let far = points
            .iter()
            .copied()
            .max_by(|p, q| disk_distance(o, *p).total_cmp(&disk_distance(o, *q)))
            .unwrap_or(o);
        let t = Mobius::to_origin(o);
        let w = t.apply(far);
        let d = disk_distance(o, far);
        let step = Complex::from_polar((0.5 * d / (it as f64 + 1.0)).tanh(), w.arg());
        o = t.inverse().apply(step);
    }
    let rho = points
        .iter()
        .map(|&p| disk_distance(o, p))
        .fold(0.0, f64::max);
    (o, rho)
}

/// Cover of a closed boundary cycle by balls of radius about 0.2 (greedy along the cycle):
/// (centre, radius) such that every point of the cycle's edges is in a ball (edges shorter
/// than the gaps are covered by the ball of their first end point widened by the edge).
fn cycle_balls(bnd: &[(Complex, usize)]) -> Vec<(Complex, f64)> {
    let nb = bnd.len();
    let mut balls: Vec<(Complex, f64)> = Vec::new();
    let mut i = 0;
    while i < nb {
        let c = bnd[i].0;
        let mut r: f64 = 0.0;
        let mut j = i;
        loop {
            let nxt = bnd[(j + 1) % nb].0;
            let d = disk_distance(c, nxt);
            if d > 0.2 && j > i {
                break;
            }
            r = r.max(d);
            j += 1;
            if j >= nb {
                break;
            }
        }
        balls.push((c, r));
        i = j.max(i + 1);
    }
    balls
}

/// Length spectrum of a closed hyperbolic surface from the layout of its fundamental polygon
/// (Poincaré disk) and its deck group: at least the `count` shortest classes (see the module
/// documentation for the completeness argument). `max_tiles` bounds the search.
pub fn fuchsian_spectrum(
    layout: &Layout<Complex>,
    poly: &Polygon,
    group: &DeckGroup<Mobius>,
    count: usize,
    max_tiles: usize,
) -> Result<HyperbolicSpectrum> {
    if !poly.is_closed() {
        return Err(Error::topology(
            "the length spectrum needs a closed surface (every polygon side paired)",
        ));
    }
    let n_sides = poly.sides.len();
    let mut side_maps: Vec<Mobius> = Vec::with_capacity(n_sides);
    for s in 0..n_sides {
        side_maps.push(group.side_map(s).ok_or_else(|| {
            Error::topology(format!(
                "side {s} of the fundamental polygon has no pairing"
            ))
        })?);
    }
    // Boundary cycle: (position, side of the edge starting there).
    let mut bnd: Vec<(Complex, usize)> = Vec::new();
    for (s, side) in poly.sides.iter().enumerate() {
        for &v in &side.vertices[..side.vertices.len() - 1] {
            bnd.push((layout.positions[v as usize], s));
        }
    }
    let points: Vec<Complex> = bnd.iter().map(|b| b.0).collect();
    let (o, rho) = minimax_centre(&points);
    let balls = cycle_balls(&bnd);
    let ball_h: Vec<[f64; 3]> = balls.iter().map(|b| poincare_to_hyperboloid(b.0)).collect();
    let o_h = poincare_to_hyperboloid(o);
    let mut l = group
        .named_generators()
        .iter()
        .map(|(_, g)| g.translation_length())
        .filter(|x| *x > 0.0)
        .fold(f64::INFINITY, f64::min);
    if !l.is_finite() {
        return Err(Error::numerical(
            "the deck generators are not hyperbolic isometries (is the metric hyperbolic?)",
        ));
    }
    // cosh of the hyperbolic distance from the Lorentz product (X₀ is the last coordinate).
    let cosh_d = |x: [f64; 3], y: [f64; 3]| x[2] * y[2] - x[0] * y[0] - x[1] * y[1];
    let nballs = balls.len();
    let r_max = balls.iter().map(|b| b.1).fold(0.0, f64::max);
    // Thresholds are widened by a relative 1e-9 so that rounding can only keep a tile more.
    let widen = |x: f64| x.cosh() * (1.0 + 1e-9) + 1e-9;
    let maps_dd: Vec<MobiusDd> = side_maps.iter().map(|&g| g.into()).collect();
    for _round in 0..12 {
        let pair_limit: Vec<f64> = (0..nballs * nballs)
            .map(|i| widen(l + balls[i / nballs].1 + balls[i % nballs].1))
            .collect();
        let reach: Vec<f64> = balls.iter().map(|b| widen(l + b.1 + rho + r_max)).collect();
        let coarse = widen(l + 2.0 * rho);
        // Conservative distance test between F and gF: F lies in B(o, ρ), and ∂F in the
        // balls; in cosh form (no acosh per pair): d(c_j, g c_k) ≤ L + r_j + r_k. Balls c_j
        // farther than L + r_j + ρ + r_max from g o cannot be near any ball of gF (which lies
        // in the ball of radius ρ + r_max around g o) and are skipped.
        let keep = |g: &Mobius, go: [f64; 3]| {
            if cosh_d(o_h, go) > coarse {
                return false;
            }
            let k = g.klein_matrix();
            let gb: Vec<[f64; 3]> = ball_h.iter().map(|&b| apply_h(&k, b)).collect();
            ball_h.iter().enumerate().any(|(j, &cj)| {
                cosh_d(cj, go) <= reach[j] && {
                    let row = &pair_limit[j * nballs..(j + 1) * nballs];
                    gb.iter().zip(row).any(|(&gk, &lim)| cosh_d(cj, gk) <= lim)
                }
            })
        };
        let Some(search) = TileSearch::run(o_h, &maps_dd, max_tiles, keep) else {
            return Err(Error::numerical(format!(
                "the spectrum search exceeded {max_tiles} tiles of the universal cover at \
                 length bound {l:.3} (the fundamental polygon is very distorted)"
            )));
        };
        let cross = |fr: &Mobius| sides_crossed(fr, &bnd, 0..bnd.len(), 1e-8);
        if let Some(sp) = search.spectrum(l, &maps_dd, o_h, count, cross) {
            return Ok(sp);
        }
        l *= 1.25;
    }
    Err(Error::numerical(
        "the spectrum search did not find enough classes within 12 enlargements of its length bound",
    ))
}

mod surface;
pub mod trace;
pub use surface::{surface_spectrum, CompactDomain};

/// Union of candidates into classes (see [`fuchsian_spectrum`]): each candidate is joined
/// with its inverse and with its conjugates by the side pairings of the sides its axis
/// crosses. Returns the classes and the number of links to tiles that were not enumerated.
fn group_classes(
    elems: &[MobiusDd],
    cand: &[usize],
    crossings: &[Vec<usize>],
    side_maps: &[MobiusDd],
    index: &TileIndex,
    o_h: [f64; 3],
) -> (Vec<GeodesicClass>, usize) {
    let mut pos_of: HashMap<usize, usize> = HashMap::new();
    for (c, &i) in cand.iter().enumerate() {
        pos_of.insert(i, c);
    }
    let mut parent: Vec<usize> = (0..cand.len()).collect();
    fn find(p: &mut [usize], x: usize) -> usize {
        let mut r = x;
        while p[r] != r {
            r = p[r];
        }
        let mut y = x;
        while p[y] != r {
            let nx = p[y];
            p[y] = r;
            y = nx;
        }
        r
    }
    let mut unmatched = 0;
    for (c, &i) in cand.iter().enumerate() {
        let g = elems[i];
        let mut links = vec![g.inverse()];
        for &s in &crossings[c] {
            let sm = side_maps[s];
            links.push(sm.inverse().compose(&g).compose(&sm).normalized());
        }
        for h in links {
            match index.find(orbit_point(&h, o_h)) {
                Some(i) => {
                    if let Some(&d) = pos_of.get(&i) {
                        let (a, b) = (find(&mut parent, c), find(&mut parent, d));
                        if a != b {
                            parent[a.max(b)] = a.min(b);
                        }
                    }
                }
                None => unmatched += 1,
            }
        }
    }
    let mut classes: HashMap<usize, GeodesicClass> = HashMap::new();
    for (c, &i) in cand.iter().enumerate() {
        let r = find(&mut parent, c);
        let g = elems[i].round();
        let e = classes.entry(r).or_insert(GeodesicClass {
            length: translation_length_dd(&elems[i]),
            representative: g,
            pieces: 0,
        });
        e.pieces += 1;
    }
    (classes.into_values().collect(), unmatched)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// τ does not depend on the basis: any SL(2, Z) change of basis, a rotation and a scaling
    /// of the lattice give the same reduced modulus.
    #[test]
    fn torus_modulus_is_invariant_under_change_of_basis() {
        for tau in [
            Complex::new(0.0, 1.0),
            Complex::new(0.5, 3f64.sqrt() / 2.0),
            Complex::new(0.31, 1.7),
            Complex::new(-0.2, 3.873),
        ] {
            let (w1, w2) = (Complex::new(1.0, 0.0), tau);
            let want = torus_modulus(w1, w2).unwrap();
            // |Re| ≤ 1/2, |τ| ≥ 1.
            assert!(want.0.abs() <= 0.5 + 1e-15 && want.0.hypot(want.1) >= 1.0 - 1e-15);
            let rot = Complex::from_polar(2.7, 0.83);
            for (a, b, c, d) in [
                (1, 0, 0, 1),
                (2, 1, 1, 1),
                (1, 3, 0, 1),
                (0, -1, 1, 0),
                (5, 2, 2, 1),
            ] {
                let (v1, v2) = (
                    (w1 * a as f64 + w2 * b as f64) * rot,
                    (w1 * c as f64 + w2 * d as f64) * rot,
                );
                let got = torus_modulus(v1, v2).unwrap();
                assert!(
                    (got.0 - want.0).abs() < 1e-12 && (got.1 - want.1).abs() < 1e-12,
                    "{tau}: {got:?} vs {want:?}"
                );
            }
        }
        // The rectangle of side ratio 3.873: τ = 3.873 i.
        let t = torus_modulus(Complex::new(0.0, 2.0), Complex::new(2.0 * 3.873, 0.0)).unwrap();
        assert!(t.0.abs() < 1e-15 && (t.1 - 3.873).abs() < 1e-12, "{t:?}");
    }
}
