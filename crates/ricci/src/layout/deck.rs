//! Fundamental polygons, side pairings and deck transformation generators (paper 001 §V
//! "Compute deck transformation group generators", paper 002 §4.3.3 and §6.2.2.3).
//!
//! A [`Polygon`] describes the boundary of a cut mesh (a disk) as sides in boundary order:
//! each side is a chain of cut-mesh vertices from one corner to the next, labelled by a
//! letter of the boundary word (`a1`, `b1`, `a1^-1`, …) and paired with the side that carries
//! the inverse letter. Side `s` runs from corner `P_s` to corner `P_{s+1}`; its partner `m` is
//! glued to it in reverse, vertex `t` of `s` being vertex `n − t` of `m`.
//!
//! **Side pairings.** From a layout of the cut mesh, the isometry `S_s` carrying the partner
//! side onto side `s` (`P_{m+1} ↦ P_s`, `P_m ↦ P_{s+1}`) is computed from the two end points
//! (the papers' construction, τ₁⁻¹∘τ₀ for Möbius maps), from every single edge of the side
//! (their spread around the end-point map is the accuracy measure of paper 001 Table II), and
//! by least squares over all vertices of the side (paper 001 §VI.e: average over the whole
//! cut), which is the one used downstream. `S_s(F)` is the copy of the polygon `F` across
//! side `s`, so the pairings generate the tiling.
//!
//! **Deck generators.** The fundamental group generators are the loops read along the
//! boundary: lifting the loop `x` from the base corner `P_0` gives the deck transformation
//! `D(x)`, a homomorphism from π₁ (paths concatenated left to right) to the isometries. With
//! `Q_s = D(x_1 ⋯ x_s)` (the map taking `F` to the copy whose base corner is `P_s`) the two
//! lifts of a letter `x` on side `s` (positive) and its partner `m` give
//! `S_s = Q_s Q_{m+1}⁻¹ = Q_{s+1} Q_m⁻¹`. These `2·(#pairs)` equations on the corner nodes
//! `0..n` form a tree for a canonical word and determine all `Q_s` from `Q_0 = id`; then
//! `D(x) = Q_s⁻¹ Q_{s+1}`. The group relation is the product of the generators along the
//! boundary word, `D(x_1)⋯D(x_n)` (= `α₁β₁α₁⁻¹β₁⁻¹⋯αgβgαg⁻¹βg⁻¹` for a canonical polygon),
//! which must be the identity; its distance to the identity is `relation_error`. For a flat
//! torus the generators are translations; for a flat metric with cone points rigid motions
//! (the relation holds when all cone angles are multiples of 2π); for H² the Fuchsian
//! generators.
//!
//! **Precision.** Everything runs in the working precision of the space ([`Frame`]): in H²
//! double-double on the double-double positions of the layout ([`Layout::positions_lo`]),
//! rounded to double precision only for the result. In double precision the generators of a
//! polygon reaching hyperbolic distance r are resolved to ~1e-16·e^r and the relation product
//! of 4g such maps (entries ~e^{ℓ/2}) lost every digit on fertility (2e-3) and botijo (1e7).
//! What limited the result then was the metric: the flow's curvature error κ (~5e-15 per
//! vertex at the double-precision floor of `K = 2π − Σθ`) makes the maps from different edges
//! of a side differ by rotations of size κ about the vertices between them, i.e. by ~κ·sinh r
//! in the matrix norm of [`Isometry::distance`] and ~κ·sinh d at points at distance d
//! ([`SidePairing::edge_spread`]); fertility's long sides reached 6e-9 (matrices) and 2e-7
//! (points). With the metric polished to double-double ([`crate::flow::polish`], the default
//! of the layout pipeline, [`super::pipeline`]) and laid out from double-double lengths
//! ([`super::place::layout_dd`]), measured (`tests/layout_meshes.rs`, BENCHMARKS.md): relation
//! error and edge spreads ≤ 1e-17 on eight, 3holes, genus3, fertility, cup and botijo.

use super::isometry::Isometry;
use super::place::{ext_position, ExtPoint, Frame, Layout, Space};
use crate::error::{Error, Result};

/// One side of a fundamental polygon.
#[derive(Debug, Clone, PartialEq)]
pub struct Side {
    /// Letter of the boundary word as written (`"a1"`, `"b2^-1"`, `"c1"`, …).
    pub label: String,
    /// Index of the letter in [`Polygon::letters`], `None` for a piece of original boundary.
    pub letter: Option<usize>,
    /// Whether the side reads the letter inverted.
    pub inverse: bool,
    /// Cut-mesh vertices along the side, from its start corner to its end corner.
    pub vertices: Vec<u32>,
    /// Index of the partner side (carrying the inverse letter), if paired.
    pub partner: Option<usize>,
}

/// The boundary of a cut mesh as a polygon with paired sides.
#[derive(Debug, Clone, PartialEq)]
pub struct Polygon {
    /// Names of the letters (fundamental group generators), e.g. `["a1", "b1", "a2", "b2"]`.
    pub letters: Vec<String>,
    /// Sides in boundary order (counter-clockwise, the surface on the left).
    pub sides: Vec<Side>,
}

impl Polygon {
    /// The boundary word, e.g. `"a1 b1 a1^-1 b1^-1"`.
    pub fn word(&self) -> String {
        self.sides
            .iter()
            .map(|s| s.label.clone())
            .collect::<Vec<_>>()
            .join(" ")
    }

    /// Build the sides from labelled vertex chains, pairing each letter with its inverse.
    /// Labels are `"x"` or `"x^-1"`; a label that occurs once (no partner) is an unpaired side.
    pub fn from_labelled(sides: Vec<(String, Vec<u32>)>) -> Result<Polygon> {
        let mut letters: Vec<String> = Vec::new();
        let mut out = Vec::with_capacity(sides.len());
        for (label, vertices) in sides {
            let (name, inverse) = match label.strip_suffix("^-1") {
                Some(n) => (n.to_string(), true),
                None => (label.clone(), false),
            };
            let letter = match letters.iter().position(|l| *l == name) {
                Some(i) => i,
                None => {
                    letters.push(name);
                    letters.len() - 1
                }
            };
            out.push(Side {
                label,
                letter: Some(letter),
                inverse,
                vertices,
                partner: None,
            });
        }
        for s in 0..out.len() {
            let l = out[s].letter;
            let partners: Vec<usize> = (0..out.len())
                .filter(|&m| m != s && out[m].letter == l && out[m].inverse != out[s].inverse)
                .collect();
            match partners.len() {
                0 => out[s].letter = None,
                1 => out[s].partner = Some(partners[0]),
                _ => {
                    return Err(Error::input(format!(
                        "letter {} occurs more than twice in the boundary word",
                        out[s].label
                    )))
                }
            }
        }
        let poly = Polygon {
            letters,
            sides: out,
        };
        poly.check()?;
        Ok(poly)
    }

    /// Sides must be chained (each ends where the next starts) and partners must have the
    /// same number of vertices.
    pub fn check(&self) -> Result<()> {
        let n = self.sides.len();
        if n == 0 {
            return Err(Error::input("the polygon has no sides"));
        }
        for (s, side) in self.sides.iter().enumerate() {
            if side.vertices.len() < 2 {
                return Err(Error::input(format!(
                    "side {s} ({}) has fewer than two vertices",
                    side.label
                )));
            }
            let next = &self.sides[(s + 1) % n];
            if side.vertices.last() != next.vertices.first() {
                return Err(Error::input(format!(
                    "side {s} ({}) ends at vertex {:?} but side {} ({}) starts at vertex {:?}",
                    side.label,
                    side.vertices.last(),
                    (s + 1) % n,
                    next.label,
                    next.vertices.first()
                )));
            }
            if let Some(m) = side.partner {
                if self.sides[m].vertices.len() != side.vertices.len() {
                    return Err(Error::input(format!(
                        "side {s} ({}) has {} vertices but its partner {m} ({}) has {}",
                        side.label,
                        side.vertices.len(),
                        self.sides[m].label,
                        self.sides[m].vertices.len()
                    )));
                }
            }
        }
        Ok(())
    }

    /// True if every side is paired (a closed surface cut along loops through one point).
    pub fn is_closed(&self) -> bool {
        self.sides.iter().all(|s| s.partner.is_some())
    }
}

/// The isometry pairing a side with its partner, and how consistent its estimates are.
#[derive(Debug, Clone)]
pub struct SidePairing<I> {
    pub side: usize,
    pub partner: usize,
    /// From the two end points of the sides (the papers' construction).
    pub endpoints: I,
    /// Least squares over all vertices of the side (used for the deck group).
    pub map: I,
    /// How far a map computed from one edge of the side can be from the end-point map (paper
    /// 001 Table II): the largest geodesic distance, over all edges, between the images of the
    /// partner side's first, middle and last vertices under the two maps. (A distance between
    /// the matrices would grow with the distance of the side from the origin of the model.)
    pub edge_spread: f64,
    /// The same comparison as matrices: the largest [`Isometry::distance`] (Frobenius norm
    /// of the difference of the normalized SU(1,1) matrices in H², the norm of
    /// `relation_error`) between a map computed from one edge and the end-point map. It
    /// measures the disagreement as seen from the centre of the layout, the paper's
    /// Table 10 compares the parameters (θ, z₀) of the same maps, which is less strict.
    pub edge_spread_matrix: f64,
    /// Largest distance, in the model space, between `map(partner vertex)` and the vertex.
    pub max_vertex_error: f64,
}

/// Side pairings and deck transformation generators of a laid-out fundamental polygon.
#[derive(Debug, Clone)]
pub struct DeckGroup<I> {
    /// One entry per side that has a partner, in side order.
    pub pairings: Vec<SidePairing<I>>,
    /// For every side, the index into `pairings` (`None` for unpaired sides).
    pub side_pairing: Vec<Option<usize>>,
    /// Letter names (from the polygon).
    pub letters: Vec<String>,
    /// `D(x)` per letter (`None` if it could not be determined, e.g. unpaired sides).
    pub generators: Vec<Option<I>>,
    /// `Q_s` per corner `s = 0..=n` (deck map taking corner `P_0` of `F` to corner `P_s`).
    pub corner_maps: Vec<Option<I>>,
    /// Distance of `D(x_1)⋯D(x_n)` from the identity, when all sides are paired.
    pub relation_error: Option<f64>,
    /// Product of the sizes of the factors of the relation ([`Isometry::size`]): in double
    /// precision the rounding of the product alone could reach machine epsilon times this
    /// (long generators on surfaces with far-apart handles make it huge); the product is
    /// formed in the working precision of the space (double-double in H², see the module
    /// docs), where the rounding is ~1e-32 times it.
    pub relation_condition: f64,
    /// Largest edge spread over all sides.
    pub max_edge_spread: f64,
    /// Largest matrix edge spread ([`SidePairing::edge_spread_matrix`]) over all sides.
    pub max_edge_spread_matrix: f64,
    /// Largest vertex error of the least-squares side maps.
    pub max_vertex_error: f64,
}

impl<I: Isometry> DeckGroup<I> {
    /// The isometry carrying the partner of side `s` onto side `s` (the copy of the polygon
    /// across side `s` is `side_map(s)(F)`).
    pub fn side_map(&self, s: usize) -> Option<I> {
        self.side_pairing[s].map(|p| {
            if self.pairings[p].side == s {
                self.pairings[p].map
            } else {
                self.pairings[p].map.inverse()
            }
        })
    }
    /// The generators that could be determined, with their letters.
    pub fn named_generators(&self) -> Vec<(String, I)> {
        self.letters
            .iter()
            .zip(&self.generators)
            .filter_map(|(l, g)| g.map(|g| (l.clone(), g)))
            .collect()
    }
    /// `D(w)` of a word given as (letter, inverse) pairs.
    pub fn word(&self, w: &[(usize, bool)]) -> Option<I> {
        let mut m = I::identity();
        for &(l, inv) in w {
            let g = (*self.generators.get(l)?)?;
            m = m.compose(&if inv { g.inverse() } else { g });
        }
        Some(m.normalized())
    }
}

/// Side pairings and deck generators of the polygon `poly` laid out as `layout` (positions
/// indexed by cut-mesh vertex).
pub fn deck_group<S: Space>(
    layout: &Layout<S::Point>,
    poly: &Polygon,
) -> Result<DeckGroup<S::Iso>> {
    Ok(deck_group_ext::<S>(layout, poly)?.0)
}

/// The maps of a [`DeckGroup`] in the working precision of the space (double-double in H²),
/// before [`deck_group`] rounds them: far out in the Poincaré disk a rounded map with entries
/// ~e^{ℓ/2} moves points by ~1e-16·e^ℓ relative to the exact one.
#[derive(Debug, Clone)]
pub struct DeckFrames<F> {
    /// Per entry of [`DeckGroup::pairings`]: its `map`.
    pub pairings: Vec<F>,
    /// Per corner: [`DeckGroup::corner_maps`].
    pub corner_maps: Vec<Option<F>>,
}

/// A deck group with its maps in the working precision.
pub type DeckGroupExt<S> = (
    DeckGroup<<S as Space>::Iso>,
    DeckFrames<<S as Space>::Frame>,
);

/// [`deck_group`] and its maps in the working precision ([`DeckFrames`]).
pub fn deck_group_ext<S: Space>(
    layout: &Layout<S::Point>,
    poly: &Polygon,
) -> Result<DeckGroupExt<S>> {
    poly.check()?;
    let pos = &layout.positions;
    if !layout.positions_lo.is_empty() && layout.positions_lo.len() != pos.len() {
        return Err(Error::input(
            "the layout's low-order position parts do not match its positions",
        ));
    }
    let n = poly.sides.len();
    for side in &poly.sides {
        if let Some(&v) = side.vertices.iter().find(|&&v| v as usize >= pos.len()) {
            return Err(Error::input(format!(
                "side {} refers to vertex {v}, but the layout has {} vertices",
                side.label,
                pos.len()
            )));
        }
    }
    // Everything below runs in the working precision of the space (double-double in H²,
    // see [`Frame`]) and is rounded to double precision for the result.
    type F<S> = <S as Space>::Frame;
    let mut pairings = Vec::new();
    let mut precise_maps: Vec<F<S>> = Vec::new();
    let mut side_pairing = vec![None; n];
    for (s, side) in poly.sides.iter().enumerate() {
        let Some(m) = side.partner else { continue };
        if side.inverse || side_pairing[s].is_some() {
            continue;
        }
        let (pairing, map) = pair_sides::<S>(layout, poly, s, m)?;
        side_pairing[s] = Some(pairings.len());
        side_pairing[m] = Some(pairings.len());
        precise_maps.push(map);
        pairings.push(pairing);
    }
    let q = corner_maps::<S>(n, &pairings, &precise_maps);
    let mut precise_generators: Vec<Option<F<S>>> = vec![None; poly.letters.len()];
    for (s, side) in poly.sides.iter().enumerate() {
        let (Some(l), Some(_)) = (side.letter, side.partner) else {
            continue;
        };
        if side.inverse {
            continue;
        }
        if let (Some(a), Some(b)) = (q[s], q[s + 1]) {
            precise_generators[l] = Some(a.inverse().compose(&b).normalized());
        }
    }
    let generators: Vec<Option<S::Iso>> = precise_generators
        .iter()
        .map(|g| g.map(|g| g.round()))
        .collect();
    let relation_condition: f64 = poly
        .sides
        .iter()
        .filter_map(|s| generators.get(s.letter?).copied().flatten())
        .map(|g| g.size())
        .product();
    let relation_error = relation_error::<S>(poly, &precise_generators);
    let max_edge_spread = pairings.iter().map(|p| p.edge_spread).fold(0.0, f64::max);
    let max_edge_spread_matrix = pairings
        .iter()
        .map(|p| p.edge_spread_matrix)
        .fold(0.0, f64::max);
    let max_vertex_error = pairings
        .iter()
        .map(|p| p.max_vertex_error)
        .fold(0.0, f64::max);
    let group = DeckGroup {
        pairings,
        side_pairing,
        letters: poly.letters.clone(),
        generators,
        corner_maps: q.iter().map(|m| m.map(|m| m.round())).collect(),
        relation_error,
        relation_condition,
        max_edge_spread,
        max_edge_spread_matrix,
        max_vertex_error,
    };
    let frames = DeckFrames {
        pairings: precise_maps,
        corner_maps: q,
    };
    Ok((group, frames))
}

/// Working-precision isometries of the space `S`.
type WorkingFrame<S> = <S as Space>::Frame;

/// The pairing of the positive side `s` with its partner `m`: end-point map, per-edge spreads
/// and the least-squares map (also returned in the working precision).
fn pair_sides<S: Space>(
    layout: &Layout<S::Point>,
    poly: &Polygon,
    s: usize,
    m: usize,
) -> Result<(SidePairing<S::Iso>, WorkingFrame<S>)> {
    type F<S> = WorkingFrame<S>;
    let side = &poly.sides[s];
    let v: Vec<ExtPoint<S>> = side
        .vertices
        .iter()
        .map(|&x| ext_position::<S>(layout, x as usize))
        .collect();
    let w: Vec<ExtPoint<S>> = poly.sides[m]
        .vertices
        .iter()
        .rev()
        .map(|&x| ext_position::<S>(layout, x as usize))
        .collect();
    // Now w[t] ↔ v[t].
    let k = v.len() - 1;
    let endpoints = F::<S>::from_pairs(w[0], w[k], v[0], v[k]);
    let mut spread = 0.0f64;
    let mut spread_matrix = 0.0f64;
    let probes = [w[0], w[k / 2], w[k]].map(|p| (p, endpoints.apply(p)));
    for t in 0..k {
        let e = F::<S>::from_pairs(w[t], w[t + 1], v[t], v[t + 1]);
        spread_matrix = spread_matrix.max(e.distance(&endpoints));
        for &(p, q) in &probes {
            spread = spread.max(F::<S>::point_distance(e.apply(p), q));
        }
    }
    let pairs: Vec<(ExtPoint<S>, ExtPoint<S>)> = w.iter().copied().zip(v.iter().copied()).collect();
    let map = F::<S>::fit(&pairs)
        .map_err(|e| Error::numerical(format!("side {} ({}): {e}", s, side.label)))?;
    let verr = pairs
        .iter()
        .map(|&(x, y)| F::<S>::point_distance(map.apply(x), y))
        .fold(0.0, f64::max);
    let pairing = SidePairing {
        side: s,
        partner: m,
        endpoints: endpoints.round(),
        map: map.round(),
        edge_spread: spread,
        edge_spread_matrix: spread_matrix,
        max_vertex_error: verr,
    };
    Ok((pairing, map))
}

/// Corner maps `Q_0 = id, …, Q_n` from the pairings: `Q_s = S_s Q_{m+1}`,
/// `Q_{s+1} = S_s Q_m` for a positive side `s` with partner `m` (a search over the corners).
fn corner_maps<S: Space>(
    n: usize,
    pairings: &[SidePairing<S::Iso>],
    precise_maps: &[WorkingFrame<S>],
) -> Vec<Option<WorkingFrame<S>>> {
    type F<S> = WorkingFrame<S>;
    let mut adj: Vec<Vec<(usize, F<S>)>> = vec![Vec::new(); n + 1];
    for (p, &t) in pairings.iter().zip(precise_maps) {
        let (s, m) = (p.side, p.partner);
        let ti = t.inverse();
        // Q_u = T Q_v  ⇒ edge u → v with Q_v = T⁻¹ Q_u, and v → u with Q_u = T Q_v.
        for (u, v) in [(s, m + 1), (s + 1, m)] {
            adj[u].push((v, ti));
            adj[v].push((u, t));
        }
    }
    let mut q: Vec<Option<F<S>>> = vec![None; n + 1];
    q[0] = Some(F::<S>::identity());
    let mut stack = vec![0usize];
    while let Some(u) = stack.pop() {
        let qu = q[u].expect("visited nodes have maps");
        for &(v, t) in &adj[u] {
            if q[v].is_none() {
                q[v] = Some(t.compose(&qu).normalized());
                stack.push(v);
            }
        }
    }
    q
}

/// Distance of the product of the generators along the boundary word from the identity,
/// when the polygon is closed and every generator is known.
fn relation_error<S: Space>(
    poly: &Polygon,
    precise_generators: &[Option<WorkingFrame<S>>],
) -> Option<f64> {
    type F<S> = WorkingFrame<S>;
    if poly.is_closed() && precise_generators.iter().all(|g| g.is_some()) {
        let mut prod = F::<S>::identity();
        for side in &poly.sides {
            let g = precise_generators[side.letter.unwrap_or(0)].unwrap_or_else(F::<S>::identity);
            prod = prod
                .compose(&if side.inverse { g.inverse() } else { g })
                .normalized();
        }
        Some(prod.distance(&F::<S>::identity()))
    } else {
        None
    }
}
