//! Genus ≥ 2: the continuity of the domain-mesh spline ([`super::domain_mesh`]) measured across
//! every cell side (issue 18: "C² away from extraordinary points and the stated continuity at
//! the zeros, measured across every patch boundary (derivative jumps per order)").
//!
//! The sides fall into three classes by the distance of their ends to the zeros (paper 003
//! §2's extraordinary points, the mesh's only irregular vertices): sides with a zero at an end
//! (C⁰ for a general net; C¹ in the translation chart, hence G¹, for a net that satisfies the
//! mesh's conditions at the zeros, as every fitted one does: [`super::domain_mesh`]), sides with an end one knot interval
//! from a zero (a corner of a cell that has a zero as a corner: C² since the cells near the
//! zeros have one size, see [`super::domain_mesh`]), and all the other sides (C²). Both patches of a side are evaluated at the same
//! surface points in their own cells' coordinates: the neighbour across a side is a
//! translation away (the gluing), so its partial derivatives are those of the same chart.
//! Tangent-plane continuity at the zeros is measured directly: the angle between the two
//! patches' normals `∂u × ∂v` along every side at a zero, its ends included.

use super::bezier::{BezierPatch, Continuity};
use super::cylinder_jumps::{cross, norm};
use super::domain_mesh::DomainMesh;

/// Jumps per order (0..=3) across the cell sides, per class.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct SideContinuity {
    /// Sides with a zero at an end.
    pub at_zeros: Continuity,
    /// Sides with an end one knot interval from a zero (and none at a zero).
    pub one_interval_from_zeros: Continuity,
    /// All other sides (both ends at least two knot intervals from every zero).
    pub elsewhere: Continuity,
    /// Sides per class, in the order above.
    pub sides: [usize; 3],
    /// Largest angle (degrees) between the two patches' normals along the sides at a zero (0:
    /// G¹ there), over the sampled points and both ends of every such side.
    pub normal_angle_at_zeros: f64,
    /// Points where that angle was measured (points where a normal vanishes are skipped).
    pub normal_comparisons: usize,
}

/// The angle in degrees between the normals `∂u × ∂v` of `a` at `pa` and of `b` at `pb`, or
/// `None` where either normal is degenerate (relative to its partials).
pub fn normal_angle(
    a: &BezierPatch,
    pa: (f64, f64),
    b: &BezierPatch,
    pb: (f64, f64),
) -> Option<f64> {
    let normal = |p: &BezierPatch, (u, v): (f64, f64)| {
        let (x, y) = (p.partial(u, v, 1, 0), p.partial(u, v, 0, 1));
        let n = cross(x, y);
        (norm(n) > 1e-12 * norm(x) * norm(y)).then_some(n)
    };
    let (na, nb) = (normal(a, pa)?, normal(b, pb)?);
    let (s, c) = (
        norm(cross(na, nb)),
        na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2],
    );
    Some(s.atan2(c).to_degrees())
}

/// The same point of a side in both patches' parameters at `t ∈ [0, 1]` along it: right side,
/// `a`'s right edge is `b`'s left edge; top side, `a`'s top is `b`'s bottom.
fn side_point(a: &BezierPatch, b: &BezierPatch, side: usize, t: f64) -> ((f64, f64), (f64, f64)) {
    if side == 0 {
        (
            (a.u1, a.v0 + t * (a.v1 - a.v0)),
            (b.u0, b.v0 + t * (b.v1 - b.v0)),
        )
    } else {
        (
            (a.u0 + t * (a.u1 - a.u0), a.v1),
            (b.u0 + t * (b.u1 - b.u0), b.v0),
        )
    }
}

impl SideContinuity {
    /// Every side: the largest jump and magnitude per order over the three classes.
    pub fn all(&self) -> Continuity {
        let mut out = Continuity::default();
        for c in [
            &self.at_zeros,
            &self.one_interval_from_zeros,
            &self.elsewhere,
        ] {
            for k in 0..4 {
                out.jumps[k] = out.jumps[k].max(c.jumps[k]);
                out.magnitudes[k] = out.magnitudes[k].max(c.magnitudes[k]);
            }
            out.comparisons += c.comparisons;
        }
        out
    }
}

/// The class of every side of `mesh` (0 at a zero, 1 one interval from one, 2 farther), in
/// the order of [`DomainMesh::sides`].
pub fn side_classes(mesh: &DomainMesh) -> Vec<usize> {
    let mut ring = vec![false; mesh.n_vertices()];
    for q in &mesh.corners {
        if q.iter().any(|&v| mesh.is_zero(v)) {
            for &v in q {
                ring[v as usize] = true;
            }
        }
    }
    mesh.sides()
        .into_iter()
        .map(|(c, side, at_zero)| {
            let q = mesh.corners[c as usize];
            let ends = if side == 0 {
                [q[1], q[2]]
            } else {
                [q[2], q[3]]
            };
            if at_zero {
                0
            } else if ends.iter().any(|&v| ring[v as usize]) {
                1
            } else {
                2
            }
        })
        .collect()
}

/// Jumps of all partials of orders 0..=3 at `samples` points of every cell side of the spline
/// with control points `control`, per class.
pub fn side_continuity(mesh: &DomainMesh, control: &[[f64; 3]], samples: usize) -> SideContinuity {
    let patches: Vec<BezierPatch> = (0..mesh.n_cells() as u32)
        .map(|c| mesh.patch(c, control, 0.0, 0.0))
        .collect();
    let mut out = SideContinuity::default();
    let samples = samples.max(1);
    for ((c, side, _), class) in mesh.sides().into_iter().zip(side_classes(mesh)) {
        let a = &patches[c as usize];
        let b = &patches[mesh.across(c, side) as usize];
        out.sides[class] += 1;
        let acc = match class {
            0 => &mut out.at_zeros,
            1 => &mut out.one_interval_from_zeros,
            _ => &mut out.elsewhere,
        };
        for k in 0..samples {
            let (pa, pb) = side_point(a, b, side, (k as f64 + 0.5) / samples as f64);
            acc.compare(a, pa, b, pb);
        }
        if class == 0 {
            for k in 0..=samples {
                let (pa, pb) = side_point(a, b, side, k as f64 / samples as f64);
                if let Some(angle) = normal_angle(a, pa, b, pb) {
                    out.normal_angle_at_zeros = out.normal_angle_at_zeros.max(angle);
                    out.normal_comparisons += 1;
                }
            }
        }
    }
    out
}
