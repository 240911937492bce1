//! Normal coordinates of the input edges in an intrinsic triangulation (Gillespie–Sharp–Crane
//! 2021, "Integer coordinates for intrinsic geometry processing" §§3–4): the arcs inside one
//! triangle, their update under a flip, and the replay of a flip log (see the parent module).

use super::Tri;
use crate::error::{Error, Result};
use crate::mesh::{Mesh, NONE};
use crate::metric::intrinsic::IntrinsicTriangulation;
use crate::metric::Geometry;

/// The input edges inside one triangle, from the crossing counts `x_j ≥ 0` of its three
/// sides (side `j` runs from corner `j` to corner `j+1`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TriangleArcs {
    /// Arcs cutting off corner `m` (joining sides `m` and `m+2`), nearest the corner first.
    pub corner: [u32; 3],
    /// Arcs through side `j` that leave the opposite corner `j+2` (nonzero for one side at most).
    pub through: [u32; 3],
}

impl TriangleArcs {
    /// Decompose the crossing counts; `None` if they are not the counts of disjoint arcs
    /// (a parity or sign violation).
    pub fn new(x: [i64; 3]) -> Option<TriangleArcs> {
        let x = x.map(|v| v.max(0));
        let mut through = [0i64; 3];
        for j in 0..3 {
            through[j] = (x[j] - x[(j + 1) % 3] - x[(j + 2) % 3]).max(0);
        }
        let mut corner = [0u32; 3];
        for m in 0..3 {
            let twice = x[m] + x[(m + 2) % 3] - x[(m + 1) % 3] - through[m] - through[(m + 2) % 3]
                + through[(m + 1) % 3];
            if twice < 0 || twice % 2 != 0 {
                return None;
            }
            corner[m] = (twice / 2) as u32;
        }
        Some(TriangleArcs {
            corner,
            through: through.map(|t| t as u32),
        })
    }
}

/// Where the arc crossing side `j` at position `p` (counted from corner `j`) goes inside the
/// triangle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum ArcEnd {
    /// Crosses side `.0` at position `.1` (counted from that side's first corner).
    Side(usize, u32),
    /// Ends at corner `.0`.
    Corner(usize),
}

#[inline]
pub(super) fn arc_end(arcs: &TriangleArcs, x: [u32; 3], j: usize, p: u32) -> ArcEnd {
    let c = arcs.corner[j];
    if p < c {
        let k = (j + 2) % 3;
        ArcEnd::Side(k, x[k] - 1 - p)
    } else if p < c + arcs.through[j] {
        ArcEnd::Corner((j + 2) % 3)
    } else {
        ArcEnd::Side((j + 1) % 3, x[j] - 1 - p)
    }
}

/// Crossing counts of the three sides of face `f`, as signed normal coordinates.
#[inline]
pub(super) fn face_counts(tri: &Tri, normal: &[i32], f: u32) -> [i64; 3] {
    let b = 3 * f as usize;
    [0, 1, 2].map(|j| normal[tri.edge[b + j] as usize] as i64)
}

/// Normal coordinate of the edge `kl` that replaces `ij = edge_he[e]` under a flip, from the
/// coordinates of the quadrilateral (see the module docs). `Err` names the edge when the
/// coordinates are inconsistent.
pub fn flipped_normal_coordinate(tri: &Tri, normal: &[i32], e: u32) -> Result<i32> {
    let h = tri.edge_he[e as usize];
    let t = tri.twin[h as usize];
    if t == NONE {
        return Err(Error::input(format!(
            "edge {e} is a boundary edge and cannot flip"
        )));
    }
    let bad = || {
        Error::numerical(format!(
            "normal coordinates around edge {e} are not those of disjoint input edges"
        ))
    };
    let arcs_a = TriangleArcs::new(face_counts(tri, normal, h / 3)).ok_or_else(bad)?;
    let arcs_b = TriangleArcs::new(face_counts(tri, normal, t / 3)).ok_or_else(bad)?;
    let (jh, jt) = ((h % 3) as usize, (t % 3) as usize);
    // Triangle A = (i, j, k) with h = i→j; triangle B = (j, i, l) with t = j→i.
    let ci_a = arcs_a.corner[jh] as i64;
    let ck_a = arcs_a.corner[(jh + 2) % 3] as i64;
    let through_h = arcs_a.through[jh] as i64; // leave k through ij
    let leave_i_a = arcs_a.through[(jh + 1) % 3] as i64; // i → jk
    let leave_j_a = arcs_a.through[(jh + 2) % 3] as i64; // j → ki
    let ci_b = arcs_b.corner[(jt + 1) % 3] as i64;
    let cl_b = arcs_b.corner[(jt + 2) % 3] as i64;
    let through_t = arcs_b.through[jt] as i64; // leave l through ij
    let leave_j_b = arcs_b.through[(jt + 1) % 3] as i64; // j → il
    let leave_i_b = arcs_b.through[(jt + 2) % 3] as i64; // i → lj
                                                         // Along ij from i: side A has [0, ci_a) i-side, [ci_a, ci_a + through_h) from k, rest j-side;
                                                         // side B has [0, ci_b) i-side, [ci_b, ci_b + through_t) from l, rest j-side.
    let lo = ci_a.max(ci_b);
    let hi = (ci_a + through_h).min(ci_b + through_t);
    let crossing = (ci_a - ci_b - through_t).max(0) + (ci_b - ci_a - through_h).max(0);
    let others = ck_a + leave_i_a + leave_j_a + cl_b + leave_i_b + leave_j_b + crossing;
    if hi > lo {
        // An input edge runs from k to l through ij: it becomes the new edge.
        if hi - lo != 1 || others != 0 || normal[e as usize] < 0 {
            return Err(bad());
        }
        return Ok(-1);
    }
    let n = others + i64::from(normal[e as usize] == -1);
    i32::try_from(n).map_err(|_| Error::numerical(format!("edge {e}: {n} crossings overflow")))
}

/// Replay `flip_log` on the input triangulation with normal coordinates.
pub(super) fn replay(
    mesh: &Mesh,
    geometry: Geometry,
    lengths: &[f64],
    flip_log: &[u32],
) -> Result<(Tri, Vec<i32>)> {
    let tri = IntrinsicTriangulation::from_mesh(mesh, geometry, lengths)?;
    replay_on(tri, flip_log)
}

/// [`replay`] from a given start: `tri` must be the input triangulation (the input mesh's
/// half-edges and edge ids), whose `edge_he` choices the flips follow.
pub(super) fn replay_on(mut tri: Tri, flip_log: &[u32]) -> Result<(Tri, Vec<i32>)> {
    let mut normal = vec![-1i32; tri.n_edges()];
    for (step, &e) in flip_log.iter().enumerate() {
        if e as usize >= tri.n_edges() {
            return Err(Error::input(format!(
                "flip log entry {step} names edge {e}, but the mesh has {} edges",
                tri.n_edges()
            )));
        }
        if !tri.is_flippable(e) {
            return Err(Error::input(format!(
                "flip log entry {step}: edge {e} cannot be flipped (boundary, or one face on \
                 both sides)"
            )));
        }
        let n = flipped_normal_coordinate(&tri, &normal, e)?;
        tri.flip(e);
        normal[e as usize] = n;
    }
    tri.flip_log.clear();
    Ok((tri, normal))
}
