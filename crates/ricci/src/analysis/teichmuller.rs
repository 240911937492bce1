//! Teichmüller coordinates of a closed hyperbolic surface of genus g ≥ 2 (paper 002 §6.3.4,
//! Fig. 42–44, Tables 5–8): Fenchel–Nielsen coordinates (3g − 3 lengths and 3g − 3 twists of
//! a pants decomposition) and, for genus 2, the paper's 7 length coordinates (Luo's
//! coordinates, 6g − 5 geodesic lengths), all computed from the Fuchsian group of the
//! uniformization metric given by its canonical generators `α_k = D(a_k)`, `β_k = D(b_k)`
//! (the deck generators of the canonical cut, [`crate::layout::deck`]), with
//! `[α₁, β₁] ⋯ [α_g, β_g] = id` and `[x, y] = x y x⁻¹ y⁻¹` (paths concatenated left to
//! right, as the boundary word `a1 b1 a1^-1 b1^-1 ⋯` reads them).
//!
//! **Lengths.** The closed geodesic in the free homotopy class of a word `w` has length
//! `ℓ(w) = 2 acosh(|tr D(w)|/2)` (trace of the normalized SU(1,1) matrix; the sign of the
//! lift does not matter).
//!
//! **The pants decomposition** (3g − 3 curves, as words in the canonical generators):
//! * `a_k`, k = 1…g (non-separating);
//! * `s_k = [a₁,b₁]⋯[a_k,b_k]`, k = 1…g − 1: separates handles 1…k from the rest
//!   (`s₁` bounds the first handle, `s_{g−1}⁻¹ = [a_g, b_g]` the last);
//! * `t_k = [a_k, b_k]`, k = 2…g − 1: bounds handle k alone.
//!
//! Every word is a run of consecutive letters of the boundary word, i.e. a chord of the
//! fundamental polygon between two corners (all corners are the base point), hence a simple
//! closed curve; the runs are nested or disjoint, so the curves are disjoint (after pushing
//! them off the base point). For g = 2 these are `a₁, a₂, s₁` (the separating curve of the
//! two building blocks I of Fig. 44). The 2g − 2 pairs of pants and the groups of their lifts:
//! the handle pants `P_k = ⟨a_k, X_k⟩`, `X_k = b_k a_k⁻¹ b_k⁻¹`, with boundaries `a_k`, `X_k`
//! (the other side of `a_k`) and `a_k X_k = [a_k, b_k]`; the middle pants
//! `M_k = ⟨s_{k−1}, t_k⟩` (k = 2…g − 1) with boundaries `s_{k−1}`, `t_k`, `s_k⁻¹`.
//!
//! **Twists** (Fenchel–Nielsen, marked by these words). For a pants curve with element `G`
//! (axis `A`, oriented in the direction `G` translates), take the two pants lifts adjacent to
//! `A` — subgroups that contain `G` itself — and in each one chosen other boundary element
//! `H` (below). The common perpendicular of `A` and the axis of `H` (the seam) meets `A` at a
//! foot; the twist is the signed distance along `A` from the foot of the first side to the
//! foot of the second. The choices (first side; second side):
//! * `a_k`: `P_k`, `H = [a_k, b_k]`; `b_k⁻¹ P_k b_k` (which contains `a_k⁻¹`),
//!   `H = b_k⁻¹ [a_k, b_k] b_k`;
//! * `s_k`: the handles-1…k side (`P₁` with `H = a₁` for k = 1, else `M_k` with
//!   `H = s_{k−1}`); the other side (`P_g` with `H = a_g` for k = g − 1, else `M_{k+1}` with
//!   `H = t_{k+1}`);
//! * `t_k`: `P_k` with `H = a_k`; `M_k` with `H = s_{k−1}`.
//!
//! Normalisation: `twist` is the raw real number of this marking: a Dehn twist about a pants
//! curve (e.g. `b_k ↦ b_k a_k`) changes it by exactly ± the curve's length and nothing else,
//! which the tests check. Zero twist means the two seams meet. The coordinate vector uses the
//! `reduced_twist`, the twist modulo its period in `(−p/2, p/2]`: `p = ℓ` (Dehn twist), or
//! `p = ℓ/2` for a curve bounding a one-holed torus (`s₁`, `s_{g−1}`, `t_k`): the seams from
//! it to the two sides of the handle's `a_k` are half its length apart (a pair of pants is
//! two congruent right-angled hexagons), and the handle's half-turn exchanges them. The
//! reduced twists are functions on the moduli of the pants decomposition's marking up to
//! these twists, so a different cut that picks the same curves gives the same numbers. The coordinates are those of the *marked* surface: another canonical basis (a
//! different base vertex or cut) differs by a mapping class and can give other numbers for
//! the same surface; the lengths of the pants curves are the lengths of those classes, which
//! all occur in the geodesic spectrum ([`crate::analysis::spectrum`]).
//!
//! **Length coordinates** (genus 2, paper 002 §6.3.4: "two building blocks I and one block
//! II", 6g − 5 = 7 lengths; Fig. 44 did not survive the text extraction, so this is our choice
//! of curves, all chords of the polygon hence simple): the one-holed tori of the two handles
//! are each determined by `ℓ(a_k), ℓ(b_k), ℓ(a_k b_k)` (Fricke: `tr a, tr b, tr ab` determine
//! the pair up to conjugacy, including the boundary `[a_k, b_k]`), and the seventh curve
//! `b₁⁻¹ a₂` crosses the separating curve `s₁` and so depends on the twist about it; we take
//! the shortest of its images under Dehn twists about `s₁` ([`seventh_length`]), which does
//! not depend on that part of the marking. The vector is
//! `(ℓ(a₁), ℓ(b₁), ℓ(a₁b₁), ℓ(a₂), ℓ(b₂), ℓ(a₂b₂), min_n ℓ(b₁⁻¹ s₁ⁿ a₂ s₁⁻ⁿ))`.
//!
//! **Marking used by [`surface_teichmuller`]**: the canonical basis of the cut, each handle's
//! `(a_k, b_k)` reduced within its one-holed torus to the shortest simple curve and the
//! shortest one crossing it once ([`MarkedGroup::reduce_handles`]; this keeps every
//! `[a_k, b_k]`, hence `s_k`, `t_k`), and the handles renumbered cyclically so that `(ℓ(a₁), …, ℓ(a_g))` is lexicographically smallest
//! (a cyclic renumbering is again canonical). This removes the cut's arbitrary choices within
//! each handle (a generated genus-2 surface gave `a₁` = the long or the short curve of a
//! handle depending on the triangulation) and of the first handle (eight.off through two base
//! vertices numbers its handles either way), not the rest of the mapping class group: which
//! separating curves `s_k` the cut's handles define is not normalised, and equal lengths
//! (symmetric surfaces) leave the choice among them to the cut.
//!
//! **Distance** ([`coordinate_distance`]): the paper (Tables 6–8) approximates the distance in
//! Teichmüller space by the Euclidean distance between coordinate vectors; we do the same on
//! the length coordinates (genus 2) or the Fenchel–Nielsen vectors (genus ≥ 3). It is not
//! the Teichmüller or Weil–Petersson metric, and between two different meshes it compares
//! markings chosen independently by their cuts.

use crate::error::{Error, Result};
use crate::layout::dd::MobiusDd;
use crate::layout::deck::{DeckGroup, Polygon};
use crate::layout::isometry::{Complex, Mobius};
use crate::metric::IntrinsicMetric;
use crate::numeric::dd::Cdd;

/// A word in the canonical generators: `(letter, inverse)` with letter `2(k−1)` for `a_k` and
/// `2(k−1) + 1` for `b_k`.
pub type Word = Vec<(usize, bool)>;

/// A marked Fuchsian group: the canonical generators `α_k`, `β_k` (normalized SU(1,1)), kept
/// in double-double: products of the 4(g − 1) generators of `s_{g−1}` lose every digit in
/// double precision on surfaces whose polygon reaches far (a generated genus-3 surface: the
/// relation `[α₁,β₁]⋯` off by 4e-3 in double, 1e-12 in double-double from the same rounded
/// generators).
#[derive(Debug, Clone)]
pub struct MarkedGroup {
    pub a: Vec<MobiusDd>,
    pub b: Vec<MobiusDd>,
}

/// Translation length `2 acosh(|tr|/2)` of a double-double element (0 if not hyperbolic).
pub fn translation_length_dd(m: &MobiusDd) -> f64 {
    let h = m.a.re.f64().abs();
    if h > 1.0 {
        2.0 * h.acosh()
    } else {
        0.0
    }
}

impl MarkedGroup {
    /// The genus.
    pub fn genus(&self) -> usize {
        self.a.len()
    }
    /// From double-precision generators.
    pub fn new(a: &[Mobius], b: &[Mobius]) -> MarkedGroup {
        MarkedGroup {
            a: a.iter().map(|&m| m.into()).collect(),
            b: b.iter().map(|&m| m.into()).collect(),
        }
    }
    /// `D(w)`, normalized, in double-double.
    pub fn eval(&self, w: &[(usize, bool)]) -> Result<MobiusDd> {
        let mut m = MobiusDd::IDENTITY;
        for &(l, inv) in w {
            let k = l / 2;
            let g = if l % 2 == 0 {
                self.a.get(k)
            } else {
                self.b.get(k)
            }
            .ok_or_else(|| {
                Error::input(format!(
                    "letter {l} of a word does not exist in a genus-{} group",
                    self.genus()
                ))
            })?;
            m = m.compose(&if inv { g.inverse() } else { *g });
        }
        Ok(m.normalized())
    }
    /// Distance of `[α₁, β₁] ⋯ [α_g, β_g]` from the identity ([`MobiusDd::distance`]).
    pub fn relation_error(&self) -> f64 {
        let mut m = MobiusDd::IDENTITY;
        for k in 0..self.genus() {
            let (a, b) = (self.a[k], self.b[k]);
            m = m
                .compose(&a)
                .compose(&b)
                .compose(&a.inverse())
                .compose(&b.inverse());
        }
        m.normalized().distance(&MobiusDd::IDENTITY)
    }
    /// The marked group of a canonical fundamental polygon (boundary word
    /// `a1 b1 a1^-1 b1^-1 ⋯ ag bg ag^-1 bg^-1`) and its deck group.
    pub fn from_deck_group(poly: &Polygon, group: &DeckGroup<Mobius>) -> Result<MarkedGroup> {
        let n = poly.sides.len();
        if n < 8 || !n.is_multiple_of(4) || !poly.is_closed() {
            return Err(Error::topology(format!(
                "Teichmüller coordinates need the canonical polygon of a closed surface of genus \
                 ≥ 2; this polygon has {n} sides (word {})",
                poly.word()
            )));
        }
        let g = n / 4;
        let mut a = Vec::with_capacity(g);
        let mut b = Vec::with_capacity(g);
        for k in 1..=g {
            let want = [
                format!("a{k}"),
                format!("b{k}"),
                format!("a{k}^-1"),
                format!("b{k}^-1"),
            ];
            for (j, w) in want.iter().enumerate() {
                if poly.sides[4 * (k - 1) + j].label != *w {
                    return Err(Error::topology(format!(
                        "the boundary word {} is not the canonical a1 b1 a1^-1 b1^-1 ⋯ (side {} \
                         is {}, expected {w})",
                        poly.word(),
                        4 * (k - 1) + j,
                        poly.sides[4 * (k - 1) + j].label
                    )));
                }
            }
            let gen = |name: &str| -> Result<Mobius> {
                let i = group
                    .letters
                    .iter()
                    .position(|l| l == name)
                    .ok_or_else(|| Error::input(format!("the deck group has no letter {name}")))?;
                group.generators[i].ok_or_else(|| {
                    Error::numerical(format!("the deck generator {name} was not determined"))
                })
            };
            a.push(gen(&format!("a{k}"))?);
            b.push(gen(&format!("b{k}"))?);
        }
        Ok(MarkedGroup::new(&a, &b))
    }
    /// The same surface with the marking changed by a Dehn twist about `a_k` (`b_k ↦ b_k a_k`,
    /// still a canonical basis: `[a_k, b_k a_k] = [a_k, b_k]`).
    pub fn dehn_twist_a(&self, k: usize) -> MarkedGroup {
        let mut m = self.clone();
        m.b[k] = m.b[k].compose(&m.a[k]).normalized();
        m
    }
    /// The handles renumbered cyclically, `(a_{r+1}, b_{r+1}, …, a_g, b_g, a_1, b_1, …)`: still
    /// a canonical basis (the relation is conjugated), the same marked surface read from
    /// another corner of the polygon.
    pub fn rotate_handles(&self, r: usize) -> MarkedGroup {
        let g = self.genus();
        let mut m = self.clone();
        for k in 0..g {
            m.a[k] = self.a[(k + r) % g];
            m.b[k] = self.b[(k + r) % g];
        }
        m
    }
    /// Of the g cyclic renumberings of the handles ([`MarkedGroup::rotate_handles`]), the one
    /// whose lengths `(ℓ(a₁), …, ℓ(a_g))` are lexicographically smallest (ties within a
    /// relative 1e-9 count as equal and go to the smaller rotation): a choice that does not
    /// depend on which handle the cut numbered first.
    pub fn with_canonical_handle_order(&self) -> MarkedGroup {
        let g = self.genus();
        let lens: Vec<f64> = self.a.iter().map(translation_length_dd).collect();
        let key = |r: usize| -> Vec<f64> { (0..g).map(|k| lens[(k + r) % g]).collect() };
        let mut best = 0;
        for r in 1..g {
            let (x, y) = (key(r), key(best));
            for (u, v) in x.iter().zip(&y) {
                if (u - v).abs() > 1e-9 * v.abs().max(1.0) {
                    if u < v {
                        best = r;
                    }
                    break;
                }
            }
        }
        self.rotate_handles(best)
    }
    /// Each handle's basis reduced in its one-holed torus by Dehn twists about `a_k` and
    /// `b_k` (`b_k ↦ b_k a_k^{±1}`, `a_k ↦ a_k b_k^{±1}`) and the swap
    /// `(a_k, b_k) ↦ (a_k b_k a_k⁻¹, a_k⁻¹)` — all of which keep `[a_k, b_k]` as an element,
    /// so the curves `s_k`, `t_k` and the relation do not change: the longer of the two is
    /// replaced by the shorter of `a_k b_k`, `a_k b_k⁻¹` while that is shorter (descent in
    /// the Farey tree of the handle's simple curves, where lengths are convex along each
    /// line), then `a_k` is made the shorter. On exit `a_k` is the shortest simple closed
    /// curve of the handle and `b_k` the shortest crossing it once (ties within a relative
    /// 1e-9 keep the cut's choice). At most 200 moves per handle; returns the number of moves.
    pub fn reduce_handles(&mut self) -> usize {
        let len = translation_length_dd;
        let shorter = |x: f64, y: f64| x < y * (1.0 - 1e-9);
        let mut moves = 0;
        for k in 0..self.genus() {
            let (mut a, mut b) = (self.a[k], self.b[k]);
            for _ in 0..200 {
                let (la, lb) = (len(&a), len(&b));
                let ab = a.compose(&b).normalized();
                let abi = a.compose(&b.inverse()).normalized();
                let (lab, labi) = (len(&ab), len(&abi));
                let best = lab.min(labi);
                if la >= lb && shorter(best, la) {
                    // a ↦ a b^{±1} (Dehn twist about b).
                    a = if lab <= labi { ab } else { abi };
                } else if lb > la && shorter(best, lb) {
                    // b ↦ b a^{±1} (Dehn twist about a); ℓ(b a^{±1}) = ℓ(a b^{±1}) up to
                    // inversion and conjugation.
                    let ba = b.compose(&a).normalized();
                    let bai = b.compose(&a.inverse()).normalized();
                    b = if len(&ba) <= len(&bai) { ba } else { bai };
                } else {
                    break;
                }
                moves += 1;
            }
            if shorter(len(&b), len(&a)) {
                let na = a.compose(&b).compose(&a.inverse()).normalized();
                b = a.inverse();
                a = na;
                moves += 1;
            }
            self.a[k] = a;
            self.b[k] = b;
        }
        moves
    }
    /// The marking changed by a Dehn twist about `s_k` (`k` ≥ 1, 1-based as the curve's
    /// name): the generators of handles k+1…g conjugated by `s_k`, still canonical.
    pub fn dehn_twist_s(&self, k: usize) -> Result<MarkedGroup> {
        let s = self.eval(&separating_word(k))?;
        let mut m = self.clone();
        for j in k..self.genus() {
            m.a[j] = s.compose(&m.a[j]).compose(&s.inverse()).normalized();
            m.b[j] = s.compose(&m.b[j]).compose(&s.inverse()).normalized();
        }
        Ok(m)
    }
}

fn a_(k: usize) -> (usize, bool) {
    (2 * (k - 1), false)
}
fn b_(k: usize) -> (usize, bool) {
    (2 * (k - 1) + 1, false)
}
fn inv(w: &[(usize, bool)]) -> Word {
    w.iter().rev().map(|&(l, i)| (l, !i)).collect()
}
fn cat(parts: &[&[(usize, bool)]]) -> Word {
    parts.iter().flat_map(|p| p.iter().copied()).collect()
}
/// `[a_k, b_k]`.
pub fn commutator_word(k: usize) -> Word {
    let (a, b) = (a_(k), b_(k));
    vec![a, b, (a.0, true), (b.0, true)]
}
/// `s_k = [a₁,b₁]⋯[a_k,b_k]`.
pub fn separating_word(k: usize) -> Word {
    (1..=k).flat_map(commutator_word).collect()
}

/// Homology class of a word: exponent sums `(a₁, b₁, …, a_g, b_g)`.
pub fn homology(w: &[(usize, bool)], genus: usize) -> Vec<i64> {
    let mut h = vec![0; 2 * genus];
    for &(l, i) in w {
        if l < h.len() {
            h[l] += if i { -1 } else { 1 };
        }
    }
    h
}

/// Algebraic intersection number of two homology classes in the canonical basis
/// (`a_k · b_k = 1`, `b_k · a_k = −1`, all others 0).
pub fn intersection_number(x: &[i64], y: &[i64]) -> i64 {
    (0..x.len() / 2)
        .map(|k| x[2 * k] * y[2 * k + 1] - x[2 * k + 1] * y[2 * k])
        .sum()
}

/// Which curve of the decomposition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PantsCurve {
    /// `a_k` (1-based).
    A(usize),
    /// `s_k = [a₁,b₁]⋯[a_k,b_k]`.
    S(usize),
    /// `t_k = [a_k, b_k]`.
    T(usize),
}

impl PantsCurve {
    pub fn name(self) -> String {
        match self {
            PantsCurve::A(k) => format!("a{k}"),
            PantsCurve::S(k) => format!("s{k}"),
            PantsCurve::T(k) => format!("t{k}"),
        }
    }
    /// The word of the curve.
    pub fn word(self) -> Word {
        match self {
            PantsCurve::A(k) => vec![a_(k)],
            PantsCurve::S(k) => separating_word(k),
            PantsCurve::T(k) => commutator_word(k),
        }
    }
}

/// The 3g − 3 curves of the pants decomposition, in the order of the coordinates:
/// `a₁…a_g, s₁…s_{g−1}, t₂…t_{g−1}`.
pub fn pants_curves(genus: usize) -> Vec<PantsCurve> {
    let mut c: Vec<PantsCurve> = (1..=genus).map(PantsCurve::A).collect();
    c.extend((1..genus).map(PantsCurve::S));
    c.extend((2..genus).map(PantsCurve::T));
    c
}

/// The two seam choices of a pants curve (see the module docs): for each side, a word `H`
/// whose axis bounds the pants lift on that side.
pub fn seam_words(curve: PantsCurve, genus: usize) -> (Word, Word) {
    match curve {
        PantsCurve::A(k) => {
            let c = commutator_word(k);
            let bk = [b_(k)];
            (c.clone(), cat(&[&inv(&bk), &c, &bk]))
        }
        PantsCurve::S(k) => {
            let first = if k == 1 {
                vec![a_(1)]
            } else {
                separating_word(k - 1)
            };
            let second = if k + 1 == genus {
                vec![a_(genus)]
            } else {
                commutator_word(k + 1)
            };
            (first, second)
        }
        PantsCurve::T(k) => (vec![a_(k)], separating_word(k - 1)),
    }
}

/// The genus-2 length coordinates' words (module docs).
pub fn length_coordinate_words() -> Vec<(String, Word)> {
    vec![
        ("a1".into(), vec![a_(1)]),
        ("b1".into(), vec![b_(1)]),
        ("a1 b1".into(), vec![a_(1), b_(1)]),
        ("a2".into(), vec![a_(2)]),
        ("b2".into(), vec![b_(2)]),
        ("a2 b2".into(), vec![a_(2), b_(2)]),
        ("b1^-1 a2".into(), vec![(b_(1).0, true), a_(2)]),
    ]
}

/// The seventh length coordinate: `min_n ℓ(b₁⁻¹ s₁ⁿ a₂ s₁⁻ⁿ)`, the shortest of the curves
/// `b₁⁻¹ a₂` moved by Dehn twists about `s₁` (lengths are convex in n; |n| ≤ 16), so that it
/// does not depend on the marking's twist about `s₁`. Returns (length, n).
pub fn seventh_length(group: &MarkedGroup) -> Result<(f64, i32)> {
    let s = group.eval(&separating_word(1))?;
    let b1i = group.eval(&[(b_(1).0, true)])?;
    let a2 = group.eval(&[a_(2)])?;
    let at = |n: i32| -> Result<f64> {
        let mut c = MobiusDd::IDENTITY;
        let p = if n >= 0 { s } else { s.inverse() };
        for _ in 0..n.abs() {
            c = c.compose(&p);
        }
        let w = b1i
            .compose(&c)
            .compose(&a2)
            .compose(&c.inverse())
            .normalized();
        geodesic_length(&w, "b1^-1 s1^n a2 s1^-n")
    };
    let (mut best, mut bn) = (at(0)?, 0);
    for dir in [1i32, -1] {
        let mut n = dir;
        while n.abs() <= 16 {
            let l = at(n)?;
            if l >= best {
                break;
            }
            best = l;
            bn = n;
            n += dir;
        }
    }
    Ok((best, bn))
}

/// `ℓ = 2 acosh(|tr|/2)`; an error if the element is not hyperbolic.
pub fn geodesic_length(m: &MobiusDd, what: &str) -> Result<f64> {
    let h = m.a.re.f64().abs();
    // Also refuses NaN.
    if h.partial_cmp(&1.0) != Some(std::cmp::Ordering::Greater) || !h.is_finite() {
        return Err(Error::numerical(format!(
            "the deck element of {what} is not hyperbolic (|tr|/2 = {h:.6}); is the metric \
             hyperbolic and converged?"
        )));
    }
    Ok(2.0 * h.acosh())
}

/// Position along the axis of `g` (towards its attracting fixed point, up to a constant) of
/// the foot of the common perpendicular to the geodesic with end points `p`, `q`, and
/// whether `p, q` lie on the left of the oriented axis. With `w(z) = (z − r)/(z − f)` (r, f
/// the repelling and attracting fixed points) the disk goes to a half-plane, the axis to a
/// ray from 0 on which arclength is `log |w|`, and the perpendicular from the geodesic
/// between boundary points `w(p)`, `w(q)` (same side of 0) meets it at `|w| = √(|w(p)||w(q)|)`.
fn foot(r: Complex, f: Complex, p: Complex, q: Complex) -> (f64, bool, bool) {
    let w = |z: Complex| (z - r) / (z - f);
    let (wp, wq) = (w(p), w(q));
    let pos = 0.5 * (wp.norm().ln() + wq.norm().ln());
    // Side: sign of the orientation of (r, f, z) on the circle.
    let side = |z: Complex| {
        let u = f - r;
        let v = z - r;
        u.re * v.im - u.im * v.re > 0.0
    };
    let (sp, sq) = (side(p), side(q));
    (pos, sp, sp == sq)
}

/// One curve's coordinates.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CurveCoordinates {
    pub name: String,
    /// The word, e.g. `"a1 b1 a1^-1 b1^-1"`.
    pub word: String,
    pub length: f64,
    /// The raw twist of the marking (module docs).
    pub twist: f64,
    /// The twist modulo its period ([`CurveCoordinates::twist_period`]), in `(−p/2, p/2]`.
    pub reduced_twist: f64,
    /// `ℓ` (a Dehn twist about the curve), or `ℓ/2` when the curve bounds a one-holed torus
    /// (`s₁`, `s_{g−1}`, `t_k`: the torus's half-turn moves the seams by half the boundary).
    pub twist_period: f64,
}

/// Fenchel–Nielsen and length coordinates of a marked group.
#[derive(Debug, Clone, serde::Serialize)]
pub struct TeichmullerCoordinates {
    pub genus: usize,
    /// The 3g − 3 pants curves with length and twist.
    pub curves: Vec<CurveCoordinates>,
    /// `(ℓ₁…ℓ_{3g−3}, τ₁…τ_{3g−3})` with the reduced twists.
    pub fenchel_nielsen: Vec<f64>,
    /// Genus 2: the 7 length coordinates (module docs); empty otherwise.
    pub length_coordinates: Vec<f64>,
    /// Names of the length-coordinate curves.
    pub length_curves: Vec<String>,
    /// Distance of the group relation from the identity (double-double product of the
    /// generators as given).
    pub relation_error: f64,
    /// Seams not where a pants decomposition puts them: a seam element's axis not on one side
    /// of its curve's axis, or both seams of a curve on the same side (0 expected).
    pub misplaced_seams: usize,
}

impl TeichmullerCoordinates {
    /// The vector used by [`coordinate_distance`]: the length coordinates for genus 2, the
    /// Fenchel–Nielsen vector otherwise.
    pub fn distance_vector(&self) -> &[f64] {
        if self.length_coordinates.is_empty() {
            &self.fenchel_nielsen
        } else {
            &self.length_coordinates
        }
    }
}

/// `x` modulo `p` in `(−p/2, p/2]`.
pub fn reduce(x: f64, p: f64) -> f64 {
    let r = x - p * (x / p).round();
    if r <= -0.5 * p {
        r + p
    } else {
        r
    }
}

/// Word as text.
pub fn word_text(w: &[(usize, bool)]) -> String {
    w.iter()
        .map(|&(l, i)| {
            format!(
                "{}{}{}",
                if l % 2 == 0 { "a" } else { "b" },
                l / 2 + 1,
                if i { "^-1" } else { "" }
            )
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// Fenchel–Nielsen coordinates (and length coordinates for genus 2) of a marked Fuchsian group
/// of genus ≥ 2 (module docs for the curves and conventions).
pub fn fenchel_nielsen(group: &MarkedGroup) -> Result<TeichmullerCoordinates> {
    let g = group.genus();
    if g < 2 || group.b.len() != g {
        return Err(Error::topology(format!(
            "Fenchel–Nielsen coordinates need genus ≥ 2 ({} a- and {} b-generators given)",
            g,
            group.b.len()
        )));
    }
    let mut curves = Vec::new();
    let mut misplaced = 0;
    for c in pants_curves(g) {
        let w = c.word();
        let m = group.eval(&w)?;
        let len = geodesic_length(&m, &format!("curve {}", c.name()))?;
        // Work in a frame where the axis passes near the origin (conjugation in double-double,
        // then double precision): the entries of the curve's and the seams' matrices are then
        // ~cosh of the lengths involved instead of ~e^{distance of the axis from 0}.
        let (r0, f0) = m
            .round()
            .fixed_points()
            .ok_or_else(|| Error::numerical(format!("curve {} has no axis", c.name())))?;
        let centre = (r0 + f0) / (2.0 + (f0 - r0).norm());
        let t = MobiusDd::to_origin(Cdd::from(centre));
        let frame = |x: &MobiusDd| t.compose(x).compose(&t.inverse()).normalized().round();
        let (r, f) = frame(&m)
            .fixed_points()
            .ok_or_else(|| Error::numerical(format!("curve {} has no axis", c.name())))?;
        let (w1, w2) = seam_words(c, g);
        let mut feet = [0.0; 2];
        let mut sides = [false; 2];
        for (i, sw) in [w1, w2].iter().enumerate() {
            let h = frame(&group.eval(sw)?);
            let (p, q) = h.fixed_points().ok_or_else(|| {
                Error::numerical(format!(
                    "the seam element {} of curve {} is not hyperbolic",
                    word_text(sw),
                    c.name()
                ))
            })?;
            let (pos, side, same) = foot(r, f, p, q);
            if !same {
                misplaced += 1;
            }
            feet[i] = pos;
            sides[i] = side;
        }
        if sides[0] == sides[1] {
            misplaced += 1;
        }
        let twist = feet[1] - feet[0];
        let period = match c {
            PantsCurve::A(_) => len,
            PantsCurve::S(k) if k != 1 && k + 1 != g => len,
            _ => 0.5 * len,
        };
        curves.push(CurveCoordinates {
            name: c.name(),
            word: word_text(&w),
            length: len,
            twist,
            reduced_twist: reduce(twist, period),
            twist_period: period,
        });
    }
    let mut fnv: Vec<f64> = curves.iter().map(|c| c.length).collect();
    fnv.extend(curves.iter().map(|c| c.reduced_twist));
    let (mut lc, mut names) = (Vec::new(), Vec::new());
    if g == 2 {
        for (name, w) in length_coordinate_words().into_iter().take(6) {
            lc.push(geodesic_length(&group.eval(&w)?, &name)?);
            names.push(name);
        }
        let (l7, n7) = seventh_length(group)?;
        lc.push(l7);
        names.push(if n7 == 0 {
            "b1^-1 a2".to_string()
        } else {
            format!("b1^-1 s1^{n7} a2 s1^{}", -n7)
        });
    }
    Ok(TeichmullerCoordinates {
        genus: g,
        curves,
        fenchel_nielsen: fnv,
        length_coordinates: lc,
        length_curves: names,
        relation_error: group.relation_error(),
        misplaced_seams: misplaced,
    })
}

/// The distance of paper 002 Tables 6–8: the Euclidean distance of the coordinate vectors
/// ([`TeichmullerCoordinates::distance_vector`]); `None` for different genera.
pub fn coordinate_distance(x: &TeichmullerCoordinates, y: &TeichmullerCoordinates) -> Option<f64> {
    if x.genus != y.genus {
        return None;
    }
    let (u, v) = (x.distance_vector(), y.distance_vector());
    Some(
        u.iter()
            .zip(v)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt(),
    )
}

/// Options of [`surface_teichmuller`].
#[derive(Debug, Clone)]
pub struct TeichmullerOptions {
    /// Base vertex of the canonical cut (`None`: the cut's choice).
    pub base: Option<u32>,
    /// Curvature tolerance of the uniformization flow.
    pub tolerance: f64,
}

impl Default for TeichmullerOptions {
    fn default() -> Self {
        TeichmullerOptions {
            base: None,
            tolerance: 1e-12,
        }
    }
}

/// Coordinates of a surface with what the pipeline measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SurfaceTeichmuller {
    pub coordinates: TeichmullerCoordinates,
    /// Max |K − K̄| of the flow.
    pub max_curvature_error: f64,
    /// Flipped faces of the layout (0).
    pub flipped_faces: usize,
    /// The deck group's relation error (double-double product, rounded).
    pub deck_relation_error: f64,
    /// Base vertex the cut used.
    pub base: u32,
    /// Moves of [`MarkedGroup::reduce_handles`] applied to the cut's basis.
    pub handle_moves: usize,
    pub seconds: f64,
}

/// The whole chain for a closed surface of genus ≥ 2 with Euclidean edge `lengths`: hyperbolic
/// uniformization (conformal flow with intrinsic Delaunay flips), double-double polish,
/// canonical cut, double-double layout, deck group ([`crate::layout::pipeline`]), then
/// [`fenchel_nielsen`] of the marking with reduced handles ([`MarkedGroup::reduce_handles`])
/// in the canonical handle order ([`MarkedGroup::with_canonical_handle_order`]). A flow that did not converge is an error.
pub fn surface_teichmuller(
    mesh: &crate::mesh::Mesh,
    metric: &IntrinsicMetric,
    opts: &TeichmullerOptions,
    progress: &mut dyn crate::progress::Progress,
) -> Result<SurfaceTeichmuller> {
    use crate::layout::pipeline::{
        cut_disk_polished, polish_uniformization, uniformization_metric,
    };
    use crate::metric::{Geometry, Hyperbolic, Scheme};
    let t0 = std::time::Instant::now();
    let topo = crate::mesh::topology(mesh);
    if topo.components.len() != 1 || mesh.has_boundary() || topo.genus() < 2 {
        return Err(Error::topology(format!(
            "Teichmüller coordinates need one closed surface of genus ≥ 2; this mesh has {} \
             component(s), genus {} and {}",
            topo.components.len(),
            topo.genus(),
            if mesh.has_boundary() {
                "a boundary"
            } else {
                "no boundary"
            }
        )));
    }
    let flow = uniformization_metric(
        mesh,
        metric,
        Geometry::Hyperbolic,
        Scheme::Conformal,
        opts.tolerance,
        progress,
    )?;
    if !flow.converged {
        return Err(Error::numerical(format!(
            "the hyperbolic uniformization flow did not converge (max |K − K̄| = {:.1e} after {} \
             iterations); no coordinates computed",
            flow.max_curvature_error, flow.iterations
        )));
    }
    let polished = polish_uniformization(mesh, metric, &flow)?;
    let work = flow
        .triangulation
        .as_ref()
        .map(|t| &t.simplicial.mesh)
        .unwrap_or(mesh);
    progress.report("cut", None, "cutting along canonical loops");
    let disk = cut_disk_polished(work, &polished.metric, None, opts.base, progress)?;
    progress.report("layout", None, "layout and deck group");
    let lay = crate::layout::place::layout_dd::<Hyperbolic>(&disk.mesh, &disk.metric, None)?;
    let deck = crate::layout::deck::deck_group::<Hyperbolic>(&lay, &disk.polygon)?;
    let mut marked = MarkedGroup::from_deck_group(&disk.polygon, &deck)?;
    let handle_moves = marked.reduce_handles();
    let marked = marked.with_canonical_handle_order();
    let coordinates = fenchel_nielsen(&marked)?;
    Ok(SurfaceTeichmuller {
        coordinates,
        max_curvature_error: flow.max_curvature_error,
        flipped_faces: lay.flipped_faces.len(),
        deck_relation_error: deck.relation_error.unwrap_or(f64::NAN),
        base: disk.cut.base,
        handle_moves,
        seconds: t0.elapsed().as_secs_f64(),
    })
}
