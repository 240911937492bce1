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

use super::deck::DeckGroup;
use super::isometry::Isometry;
use super::place::Space;
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// UVs per corner of the input faces (three per face, in face order).
#[derive(Debug, Clone)]
pub struct InputUvs<P> {
    /// `corner[3f + i]`: the layout position of corner `i` of input face `f`.
    pub corner: Vec<P>,
    /// Input faces whose UV triangle is not positively oriented.
    pub flipped_faces: Vec<u32>,
    /// Input faces that needed a deck transformation (they straddle a seam).
    pub seam_faces: usize,
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
    // Candidate deck transformations: identity; the side pairings (each maps the partner
    // side onto its side: a face straddling that seam) — both directions; products of two
    // (faces at the polygon's corners, where several seams meet).
    // Searched in three levels (identity; pairings; products), the next only when the
    // previous leaves the face spread out or flipped.
    let mut cands: Vec<S::Iso> = vec![S::Iso::identity()];
    let mut level_end = [1usize, 1, 1];
    if let Some(g) = group {
        let pairs: Vec<S::Iso> = g
            .pairings
            .iter()
            .flat_map(|p| [p.map, p.map.inverse()])
            .collect();
        let mut prods = Vec::new();
        for x in &pairs {
            for y in &pairs {
                prods.push(x.compose(y));
            }
        }
        // Around the polygon's corners (copies of the base vertex) the sectors are related
        // by Q_s Q_t⁻¹ (corner maps: P_0 ↦ P_s), which can be long products of pairings.
        let corners: Vec<S::Iso> = g.corner_maps.iter().flatten().copied().collect();
        for qs in &corners {
            for qt in &corners {
                prods.push(qs.compose(&qt.inverse()));
            }
        }
        cands.extend(pairs);
        level_end[1] = cands.len();
        cands.extend(prods);
        level_end[2] = cands.len();
    }
    // Nearest image of vertex `w` to point `p`: (distance, point).
    let nearest = |w: u32, p: S::Point, n: usize| -> (f64, S::Point) {
        let mut best = (f64::INFINITY, p);
        for &c in &copies[w as usize] {
            let q = positions[c as usize];
            for g in &cands[..n] {
                let gq = g.apply(q);
                let d = S::distance(gq, p);
                if d < best.0 {
                    best = (d, gq);
                }
            }
        }
        best
    };
    // First pass with the identity only: the typical size of a face in the layout.
    let mut spread = vec![0.0f64; faces.len()];
    let mut corner = Vec::with_capacity(3 * faces.len());
    for (f, t) in faces.iter().enumerate() {
        let pa = positions[copies[t[0] as usize][0] as usize];
        let (db, pb) = nearest(t[1], pa, 1);
        let (dc, pc) = nearest(t[2], pa, 1);
        spread[f] = db.max(dc).max(S::distance(pb, pc));
        corner.extend([pa, pb, pc]);
    }
    let mut sorted: Vec<f64> = spread.iter().copied().filter(|x| x.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let mut seam_faces = 0;
    for (f, t) in faces.iter().enumerate() {
        let orient = S::orientation(corner[3 * f], corner[3 * f + 1], corner[3 * f + 2]);
        let suspicious = spread[f] > 4.0 * median || orient <= 0.0;
        if !suspicious || group.is_none() {
            continue;
        }
        // Every copy of `a`, the candidate maps of one level after the other for `b`, `c`.
        let mut best = (
            f64::INFINITY,
            [corner[3 * f], corner[3 * f + 1], corner[3 * f + 2]],
        );
        for &n in &level_end[1..] {
            for &ca in &copies[t[0] as usize] {
                let pa = positions[ca as usize];
                let (db, pb) = nearest(t[1], pa, n);
                let (dc, pc) = nearest(t[2], pa, n);
                let total = db.max(dc).max(S::distance(pb, pc));
                if total < best.0 {
                    best = (total, [pa, pb, pc]);
                }
            }
            let [pa, pb, pc] = best.1;
            if best.0 <= 4.0 * median && S::orientation(pa, pb, pc) > 0.0 {
                break;
            }
        }
        if best.0 < spread[f] {
            seam_faces += 1;
            corner[3 * f..3 * f + 3].copy_from_slice(&best.1);
        }
    }
    let flipped_faces = (0..faces.len())
        .filter(|&f| S::orientation(corner[3 * f], corner[3 * f + 1], corner[3 * f + 2]) <= 0.0)
        .map(|f| f as u32)
        .collect();
    Ok(InputUvs {
        corner,
        flipped_faces,
        seam_faces,
    })
}
