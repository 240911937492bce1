//! Texture coordinates on the **common subdivision** of the input mesh and the final intrinsic
//! triangulation `T` of a conformal flow (Gillespie–Springborn–Crane 2021, "Discrete
//! conformal equivalence of polyhedral surfaces" (CEPS) §5): every vertex is a point of the
//! input surface (an input vertex, or the crossing of an input edge with an edge of `T`,
//! given by its input face and barycentric coordinates there), every triangle lies in one
//! input face and one face of `T`, and its UVs are the projective interpolation of the layout
//! of `T` ([`crate::metric::common_subdivision`]). The map is exact at the vertices of `T` and
//! the pieces are convex in both charts, so — unlike the input's own faces, whose UV triangles
//! join layout points of vertices that are not adjacent in `T` — no triangle is flipped.
//!
//! * E² and H² ([`common_subdivision_uvs`]): `T` is laid out through the cut of the surface
//!   (the laid-out mesh is `T`'s simplicial refinement, cut to a disk); the three corners of
//!   every face of `T` take the layout positions of their vertices, mapped across the seams by
//!   the deck group exactly as [`super::input_uv::input_face_uvs`] does for input faces.
//! * S² ([`sphere_common_subdivision`]): `T` is the convex hull of the points of
//!   [`crate::flow::sphere::conformal_sphere`] (inscribed in the unit sphere). A point with
//!   projective weights `β` on a hull face is `Σ β_i p_i / Σ β_i` on the face's plane — the
//!   Klein model of the face's ideal triangle — and it is sent to the sphere by central
//!   projection. The origin lies inside the hull, so a piece positively oriented on its face
//!   plane stays positively oriented on the sphere (`det[p0, p1, p2] > 0`).
//!
//! **Known limitation.** The flow's flip log starts with isometric flips (to the Delaunay
//! triangulation of the input metric) and [`CommonSubdivision::from_triangulation`] maps the
//! input faces to the ideal triangles spanned by their straightened edges (a continuous,
//! piecewise projective homeomorphism, exact on every input edge the isometric flips kept),
//! not through the Euclidean triangles of that Delaunay triangulation (CEPS's three-way
//! overlay); see that function.

use super::deck::{DeckFrames, DeckGroup};
use super::input_uv::{candidate_frames, candidate_maps, face_uvs_with_lengths};
use super::isometry::Complex;
use super::place::{ExtPoint, Frame, Space};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::metric::common_subdivision::{
    disk_orientation, repair_rounded_pieces, CommonSubdivision,
};
use crate::metric::intrinsic::{length_of_lambda, IntrinsicTriangulation};
use crate::metric::{Geometry, IntrinsicMetric};
use crate::numeric::dd::Cdd;
use rayon::prelude::*;

/// The common subdivision with its UVs (see the module docs).
#[derive(Debug, Clone)]
pub struct SubdivisionUv {
    /// Per vertex: an input face that contains it and its barycentric coordinates on that
    /// face (in the order of `mesh.face(f)`). Vertices `0..V` are the input vertices.
    pub locations: Vec<(u32, [f64; 3])>,
    /// Per vertex: its point on the input surface (from `locations` and the input positions).
    pub positions: Vec<[f64; 3]>,
    /// Triangles (counter-clockwise on the input surface).
    pub triangles: Vec<[u32; 3]>,
    /// Input face of every triangle.
    pub input_face: Vec<u32>,
    /// Per triangle corner (`3t + i`): E² plane, H² Poincaré disk; on S² the point on the
    /// unit sphere is in `sphere_points` and this is empty.
    pub corner_uv: Vec<[f64; 2]>,
    /// S²: per vertex, its point on the unit sphere; empty in E² and H².
    pub sphere_points: Vec<[f64; 3]>,
    /// Triangles whose image is not positively oriented (E²: signed area; H²: signed area in
    /// the Klein model; S²: `det[p0, p1, p2]`), degenerate ones included.
    pub flipped_faces: usize,
    /// Faces of `T` whose corners needed a deck transformation (they straddle a seam).
    pub seam_faces: usize,
    /// Faces of `T` whose layout triangle is not positively oriented (then the pieces inside
    /// are not either: the layout, not the subdivision, is at fault — e.g. points too far out
    /// in the Poincaré disk for double precision).
    pub t_flipped_faces: usize,
    /// Faces of `T` written at another image under the deck group than the layout's (nearer
    /// the centre of the disk), because double precision could not resolve their pieces
    /// where the polygon puts them (H² from a double-double layout only; 0 otherwise).
    pub recentred_faces: usize,
    /// UVs moved by a few ulps so that pieces that are positively oriented in exact
    /// arithmetic but came out degenerate or flipped from rounding are positive
    /// ([`crate::metric::common_subdivision::repair_rounded_pieces`]).
    pub nudged_uvs: usize,
    /// Crossings of input edges with edges of `T`, and faces of `T`.
    pub crossings: usize,
    pub t_faces: usize,
}

impl SubdivisionUv {
    /// Number of vertices.
    pub fn n_vertices(&self) -> usize {
        self.locations.len()
    }
}

fn locations(sub: &CommonSubdivision) -> Result<Vec<(u32, [f64; 3])>> {
    let mut loc = vec![(u32::MAX, [f64::NAN; 3]); sub.n_vertices()];
    for (t, tr) in sub.triangles.iter().enumerate() {
        for (i, &v) in tr.iter().enumerate() {
            let v = v as usize;
            if loc[v].0 == u32::MAX {
                loc[v] = (sub.input_face[t], sub.input_barycentric[3 * t + i]);
            }
        }
    }
    if let Some(v) = loc.iter().position(|l| l.0 == u32::MAX) {
        return Err(Error::numerical(format!(
            "vertex {v} of the common subdivision is in no triangle"
        )));
    }
    Ok(loc)
}

/// The subdivision, the locations of its vertices and their points on the input surface.
type Base = (CommonSubdivision, Vec<(u32, [f64; 3])>, Vec<[f64; 3]>);

fn base(
    input: &Mesh,
    input_positions: &[[f64; 3]],
    input_lengths: &[f64],
    geometry: Geometry,
    intrinsic: &IntrinsicTriangulation,
    u: &[f64],
) -> Result<Base> {
    let sub = CommonSubdivision::from_triangulation(input, geometry, input_lengths, intrinsic, u)?;
    let loc = locations(&sub)?;
    let positions = sub.positions(input, input_positions)?;
    Ok((sub, loc, positions))
}

/// The common subdivision of `input` (positions and Euclidean edge lengths — the lengths the
/// flow started from, only used to replay the flips) and the final intrinsic triangulation
/// `intrinsic` of a conformal flow in E² or H² (`FlowResult::triangulation.triangulation`,
/// with `u = FlowResult::u`), with UVs from a layout of `T`: `layout_positions` are the
/// positions of the laid-out mesh's vertices, `origin[v]` the surface vertex each is a copy
/// of (input ids first), `group` the deck group (`None` for a disk).
#[allow(clippy::too_many_arguments)]
pub fn common_subdivision_uvs<S: Space<Point = Complex>>(
    input: &Mesh,
    input_positions: &[[f64; 3]],
    input_metric: &IntrinsicMetric,
    intrinsic: &IntrinsicTriangulation,
    u: &[f64],
    layout_positions: &[Complex],
    origin: &[u32],
    group: Option<&DeckGroup<S::Iso>>,
) -> Result<SubdivisionUv>
where
    S::Iso: super::isometry::Isometry<Point = Complex>,
{
    let layout = LaidOut {
        positions: layout_positions,
        positions_lo: &[],
        origin,
    };
    common_subdivision_uvs_ext::<S>(
        input,
        input_positions,
        input_metric,
        intrinsic,
        u,
        &layout,
        group,
        None,
    )
}

/// A layout of `T`'s (cut) simplicial mesh as [`common_subdivision_uvs_ext`] takes it.
#[derive(Debug, Clone, Copy)]
pub struct LaidOut<'a> {
    /// Positions of the laid-out mesh's vertices (rounded to double precision).
    pub positions: &'a [Complex],
    /// Their low-order parts ([`super::place::Layout::positions_lo`]: H² layouts in
    /// double-double), or empty.
    pub positions_lo: &'a [Complex],
    /// The surface vertex every laid-out vertex is a copy of (input ids first).
    pub origin: &'a [u32],
}

/// [`common_subdivision_uvs`] from a layout given in the working precision of its space: in
/// H² with `positions_lo` the corners of `T`'s faces are formed in double-double (copy
/// positions and deck maps, [`super::input_uv::face_uvs`]'s choices) and the pieces are
/// interpolated and rounded once ([`CommonSubdivision::uv_hyperbolic_dd`]); `t_flipped_faces`
/// is then measured in double-double too. `frames` are the deck group's maps in double-double
/// ([`super::deck::deck_group_ext`]; without them the rounded maps of `group` are used, which
/// far out in the disk misplace the corners of faces that straddle a seam).
#[allow(clippy::too_many_arguments)]
pub fn common_subdivision_uvs_ext<S: Space<Point = Complex>>(
    input: &Mesh,
    input_positions: &[[f64; 3]],
    input_metric: &IntrinsicMetric,
    intrinsic: &IntrinsicTriangulation,
    u: &[f64],
    layout: &LaidOut<'_>,
    group: Option<&DeckGroup<S::Iso>>,
    frames: Option<&DeckFrames<S::Frame>>,
) -> Result<SubdivisionUv>
where
    S::Iso: super::isometry::Isometry<Point = Complex>,
{
    input_metric.require(Geometry::Euclidean, "the common subdivision's input metric")?;
    let input_lengths = input_metric.lengths();
    let (layout_positions, origin) = (layout.positions, layout.origin);
    let lo = layout.positions_lo;
    if !lo.is_empty() && lo.len() != layout_positions.len() {
        return Err(Error::input(format!(
            "{} low parts for {} layout positions",
            lo.len(),
            layout_positions.len()
        )));
    }
    if S::KIND == Geometry::Spherical {
        return Err(Error::input(
            "common_subdivision_uvs lays out E² and H²; use sphere_common_subdivision on S²",
        ));
    }
    let (sub, loc, positions) = base(input, input_positions, input_lengths, S::KIND, intrinsic, u)?;
    let tri = &sub.triangulation;
    let faces: Vec<[u32; 3]> = (0..tri.n_faces() as u32).map(|f| tri.face(f)).collect();
    let mut used = vec![false; tri.n_vertices];
    for t in &faces {
        for &v in t {
            used[v as usize] = true;
        }
    }
    // T's faces are congruent to their images: their side lengths pick the right deck images.
    let side_lengths: Vec<[f64; 3]> = (0..tri.n_faces())
        .map(|f| {
            [0, 1, 2].map(|i| {
                let e = intrinsic.edge[3 * f + i] as usize;
                length_of_lambda(S::KIND, intrinsic.lambda[e])
            })
        })
        .collect();
    let corners = face_uvs_with_lengths::<S>(
        &used,
        &faces,
        Some(&side_lengths),
        layout_positions,
        origin,
        group,
    )?;
    let corner: Vec<[f64; 2]> = corners.corner.iter().map(|z| [z.re, z.im]).collect();
    let mut t_flipped_faces = corners.flipped_faces.len();
    let mut recentred_faces = 0;
    let uv = if S::KIND == Geometry::Hyperbolic && !lo.is_empty() {
        let dd = hyperbolic_uv_dd::<S>(&sub, u, &corners.source, layout, group, frames)?;
        t_flipped_faces = dd.t_flipped_faces;
        recentred_faces = dd.recentred_faces;
        dd.uv
    } else {
        sub.uv(S::KIND, u, &corner)?
    };
    let mut uv = uv;
    let t_flipped: std::collections::HashSet<u32> = corners.flipped_faces.iter().copied().collect();
    let nudged_uvs = repair_rounded_pieces(
        S::KIND,
        &sub.triangles,
        &mut uv,
        sub.n_input_vertices as u32,
        |t| {
            !t_flipped.contains(&sub.t_face[t])
                && sub.barycentric_orientation(t, u) > BARYCENTRIC_MARGIN
        },
    );
    let flipped_faces = sub.flipped_triangles(S::KIND, &uv);
    Ok(SubdivisionUv {
        nudged_uvs,
        locations: loc,
        positions,
        triangles: sub.triangles.clone(),
        input_face: sub.input_face.clone(),
        corner_uv: uv,
        sphere_points: Vec::new(),
        flipped_faces,
        seam_faces: corners.seam_faces,
        t_flipped_faces,
        recentred_faces,
        crossings: sub.crossings.len(),
        t_faces: tri.n_faces(),
    })
}

/// A piece whose barycentric orientation on its face of `T` exceeds this is positively
/// oriented in exact arithmetic (the determinant of normalised weights is computed to a few
/// ulps of 1); only such pieces have their rounded UVs repaired.
const BARYCENTRIC_MARGIN: f64 = 1e-13;

/// What [`hyperbolic_uv_dd`] computed.
struct DdUv {
    uv: Vec<[f64; 2]>,
    t_flipped_faces: usize,
    recentred_faces: usize,
}

/// H² from a double-double layout (see [`common_subdivision_uvs_ext`]): the corners of `T`'s
/// faces in double-double from `face_uvs`'s choices (`source`), the pieces interpolated and
/// rounded once. A face of `T` that still has a piece whose rounded UV triangle is not
/// positively oriented lies too far out in the disk for double precision to resolve it
/// there (at distance r the written coordinates resolve ~1e-16·e^r); it is written at the
/// image under the deck group nearest the centre instead (greedily over the candidate maps
/// of [`candidate_maps`]), when all its pieces are positively oriented there: one more seam
/// around that face, counted in `recentred_faces`.
fn hyperbolic_uv_dd<S: Space<Point = Complex>>(
    sub: &CommonSubdivision,
    u: &[f64],
    source: &[(u32, u32)],
    layout: &LaidOut<'_>,
    group: Option<&DeckGroup<S::Iso>>,
    deck_frames: Option<&DeckFrames<S::Frame>>,
) -> Result<DdUv>
where
    S::Iso: super::isometry::Isometry<Point = Complex>,
{
    let (maps, _) = candidate_maps(group);
    let frames: Vec<S::Frame> = match deck_frames.map(candidate_frames) {
        Some(f) if f.len() == maps.len() => f,
        _ => maps.iter().map(S::Frame::from_iso).collect(),
    };
    let ext: Vec<ExtPoint<S>> = source
        .par_iter()
        .map(|&(c, k)| {
            let c = c as usize;
            let p = S::Frame::ext(layout.positions[c], Some(layout.positions_lo[c]));
            frames[k as usize].apply(p)
        })
        .collect();
    let cdd = |p: ExtPoint<S>| {
        let (hi, lo) = S::Frame::split(p);
        Cdd::from_parts(hi, lo.unwrap_or(Complex::new(0.0, 0.0)))
    };
    let nf = ext.len() / 3;
    let t_flipped_faces = (0..nf)
        .filter(|&f| {
            let o = S::Frame::orientation(ext[3 * f], ext[3 * f + 1], ext[3 * f + 2]);
            o.is_nan() || o <= 0.0
        })
        .count();
    let (hi, lo): (Vec<[f64; 2]>, Vec<[f64; 2]>) = ext
        .iter()
        .map(|&p| {
            let z = cdd(p);
            ([z.re.hi, z.im.hi], [z.re.lo, z.im.lo])
        })
        .unzip();
    let mut uv = sub.uv_hyperbolic_dd(u, &hi, &lo)?;
    let piece_flipped = |uv: &[[f64; 2]], t: usize| {
        let o = disk_orientation(uv[3 * t], uv[3 * t + 1], uv[3 * t + 2]);
        o.is_nan() || o <= 0.0
    };
    let mut pieces: Vec<Vec<usize>> = vec![Vec::new(); nf];
    let mut bad = vec![false; nf];
    for (t, &f) in sub.t_face.iter().enumerate() {
        pieces[f as usize].push(t);
        if piece_flipped(&uv, t) {
            bad[f as usize] = true;
        }
    }
    let origin = S::Frame::ext(S::base_point(), None);
    let radius = |p: &[ExtPoint<S>; 3]| {
        p.iter()
            .map(|&q| S::Frame::point_distance(q, origin))
            .fold(0.0, f64::max)
    };
    let mut recentred_faces = 0;
    for f in (0..nf).filter(|&f| bad[f]) {
        // Greedy descent over the candidate maps towards the centre (at most 32 steps).
        let start = [ext[3 * f], ext[3 * f + 1], ext[3 * f + 2]];
        let (mut p, mut r) = (start, radius(&start));
        for _ in 0..32 {
            let best = frames[1..]
                .iter()
                .map(|h| {
                    let q = p.map(|x| h.apply(x));
                    (radius(&q), q)
                })
                .min_by(|a, b| a.0.total_cmp(&b.0));
            match best {
                Some((rq, q)) if rq < r - 1e-6 => (p, r) = (q, rq),
                _ => break,
            }
        }
        if r >= radius(&start) {
            continue;
        }
        let p = p.map(cdd);
        let mut moved = Vec::with_capacity(3 * pieces[f].len());
        for &t in &pieces[f] {
            for c in 0..3 {
                moved.push(sub.piece_uv_hyperbolic_dd(t, c, u, &p)?);
            }
        }
        if (0..pieces[f].len()).all(|k| !piece_flipped(&moved, k)) {
            for (k, &t) in pieces[f].iter().enumerate() {
                uv[3 * t..3 * t + 3].copy_from_slice(&moved[3 * k..3 * k + 3]);
            }
            recentred_faces += 1;
        }
    }
    Ok(DdUv {
        uv,
        t_flipped_faces,
        recentred_faces,
    })
}

/// `det[a, b, c]`, computed as `((b − a) × (c − a)) · a` (small triangles on the unit sphere
/// keep their relative accuracy).
pub fn sphere_orientation(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let d1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let d2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        d1[1] * d2[2] - d1[2] * d2[1],
        d1[2] * d2[0] - d1[0] * d2[2],
        d1[0] * d2[1] - d1[1] * d2[0],
    ];
    n[0] * a[0] + n[1] * a[1] + n[2] * a[2]
}

/// Faces of `faces` whose points (on the unit sphere) are not positively oriented
/// (`det ≤ 0`, or not finite).
pub fn sphere_flipped_faces(points: &[[f64; 3]], faces: &[[u32; 3]]) -> Vec<u32> {
    faces
        .iter()
        .enumerate()
        .filter(|(_, t)| {
            let d = sphere_orientation(
                points[t[0] as usize],
                points[t[1] as usize],
                points[t[2] as usize],
            );
            d.is_nan() || d <= 0.0
        })
        .map(|(f, _)| f as u32)
        .collect()
}

/// The common subdivision of `input` and the final triangulation of the conformal map to the
/// sphere (`FlowResult::triangulation`: `intrinsic` its Δ-complex, `points` its vertices on
/// the unit sphere, `u = FlowResult::u`), each vertex sent to the sphere by projective
/// interpolation on its hull face and central projection (see the module docs).
pub fn sphere_common_subdivision(
    input: &Mesh,
    input_positions: &[[f64; 3]],
    input_metric: &IntrinsicMetric,
    intrinsic: &IntrinsicTriangulation,
    u: &[f64],
    points: &[[f64; 3]],
) -> Result<SubdivisionUv> {
    input_metric.require(Geometry::Euclidean, "the common subdivision's input metric")?;
    let input_lengths = input_metric.lengths();
    if points.len() != intrinsic.n_vertices {
        return Err(Error::input(format!(
            "{} points on the sphere for a triangulation with {} vertices",
            points.len(),
            intrinsic.n_vertices
        )));
    }
    let (sub, loc, positions) = base(
        input,
        input_positions,
        input_lengths,
        Geometry::Euclidean,
        intrinsic,
        u,
    )?;
    let tri = &sub.triangulation;
    let mut sphere = vec![[f64::NAN; 3]; sub.n_vertices()];
    for (t, (tr, &f)) in sub.triangles.iter().zip(&sub.t_face).enumerate() {
        let verts = tri.face(f);
        for (c, &v) in tr.iter().enumerate() {
            let v = v as usize;
            if !sphere[v][0].is_nan() {
                continue;
            }
            // β_i = w_i e^{−u_i}, normalised in log space (as CommonSubdivision::uv).
            let w = sub.t_weights[3 * t + c];
            let logs: [f64; 3] = [0, 1, 2].map(|i| {
                if w[i] > 0.0 {
                    w[i].ln() - u.get(verts[i] as usize).copied().unwrap_or(0.0)
                } else {
                    f64::NEG_INFINITY
                }
            });
            let m = logs.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            let beta = logs.map(|l| if l.is_finite() { (l - m).exp() } else { 0.0 });
            let mut x = [0.0f64; 3];
            for i in 0..3 {
                let p = points[verts[i] as usize];
                for k in 0..3 {
                    x[k] += beta[i] * p[k];
                }
            }
            let r = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
            if r.is_nan() || r <= 0.0 {
                return Err(Error::numerical(format!(
                    "vertex {v} of the common subdivision is at the centre of the sphere \
                     (the origin is not inside the hull of the points)"
                )));
            }
            sphere[v] = x.map(|c| c / r);
        }
    }
    let flipped_faces = sphere_flipped_faces(&sphere, &sub.triangles).len();
    Ok(SubdivisionUv {
        locations: loc,
        positions,
        triangles: sub.triangles.clone(),
        input_face: sub.input_face.clone(),
        corner_uv: Vec::new(),
        sphere_points: sphere,
        flipped_faces,
        seam_faces: 0,
        recentred_faces: 0,
        nudged_uvs: 0,
        t_flipped_faces: sphere_flipped_faces(
            points,
            &(0..tri.n_faces() as u32)
                .map(|f| tri.face(f))
                .collect::<Vec<_>>(),
        )
        .len(),
        crossings: sub.crossings.len(),
        t_faces: tri.n_faces(),
    })
}
