//! Isometric placement of a simply connected mesh with a given metric (paper 001 §V Step 4,
//! "Flatten a seed face" and "Flatten a fundamental domain"; paper 002 §4.3.2 and §6.2.2.2).
//!
//! The three model spaces implement [`Space`] (on the background types of
//! [`crate::metric::geometry`]): the plane (points are complex numbers), the Poincaré disk
//! (complex numbers of modulus < 1) and the unit sphere (unit vectors of R³).
//!
//! Placement of the third vertex `k` of a face `(i, j, k)` (counter-clockwise) whose edge
//! `i → j` is placed: the isometry that moves `p_i` to a base point and `p_j` onto a reference
//! direction is applied, the triangle is put in its canonical position there, and the inverse
//! isometry brings `p_k` back. This is the circle intersection with the orientation check of
//! the papers, written so that every face is computed at the centre of the model: for H² each
//! face is moved to the centre of the disk by a Möbius map before placing (paper 001 §VI.b),
//! which avoids the unstable computations near the unit circle; for S² the frame
//! `(p_i, t, p_i × t)` solves `p·p_i = cos l_ik`, `p·p_j = cos l_jk`, `|p| = 1`,
//! `det[p_i, p_j, p] > 0` without cancellation. The angle at `i` comes from the half-angle
//! form of the cosine law ([`Background::angle`]), accurate for needle triangles; the papers'
//! sphere seed formula (which takes chord lengths) is not used: lengths are geodesic (docs/DESIGN.md §3).
//!
//! **Precision.** Face frames are composed in the working precision of the space ([`Frame`]):
//! double precision in E² and S², double-double in H² ([`super::dd`]), where a frame at
//! distance r from the centre has entries ~e^{r/2} and a double-precision composition would
//! perturb each step by ~1e-16·e^r. In E² and S² the relative placement of a face on its
//! parent is computed at the base point in double precision; in H² the canonical triangles
//! come from the lengths in double-double ([`Space::seed_ext`]: `tanh(l/2)` and the half-angle
//! tangent of the cosine law) and the relative placement maps the shared edge of two
//! canonical triangles onto each other in double-double ([`Space::relative`]). Lengths can be
//! given to double-double precision ([`layout_dd`], an [`IntrinsicMetric`]; the metric polished by
//! [`crate::flow::polish`]); [`layout`] is `layout_dd` with zero low parts. Positions are kept
//! in double-double ([`Layout::positions_lo`]), and the measurements (orientation, length
//! error, radius) use them. With the flow's metric
//! at tolerance 1e-12, layouts from different seed faces agree to ≤ 2e-11 on the shared
//! genus-2…5 meshes (fertility reaches r ≈ 25 from an off-centre seed), against 5e-5 in double
//! precision.
//!
//! [`layout`] places a seed face (by default the face farthest from the boundary, or a
//! centre of a closed mesh, to keep the breadth-first depth — along which rounding errors
//! accumulate — small) and then walks the faces breadth first. Each vertex is placed once, by
//! the first face that reaches it; faces reached when all three vertices are placed are only
//! checked. The result reports flipped faces (negative orientation), degenerate faces and the
//! largest disagreement between laid-out distances and the metric, which measures how far the
//! metric is from being exactly flat / hyperbolic / spherical (curvature error).

use super::dd::MobiusDd;
use super::error::LayoutError;
pub use super::frame::{Frame, IsoPoint};
use super::isometry::{
    cross3, det3, disk_distance, disk_distance_key, dot3, normalize3, sphere_distance, Complex,
    Isometry, Mobius, RigidMotion, Rotation,
};
use crate::error::{Error, Result};
use crate::mesh::{topology, Mesh, NONE};
use crate::metric::{Background, Euclidean, Geometry, Hyperbolic, IntrinsicMetric, Spherical};
use crate::numeric::dd::Cdd;
use rayon::prelude::*;
use std::collections::VecDeque;

mod walk;
use walk::walk;

/// The working-precision point of a space.
pub type ExtPoint<S> = <<S as Space>::Frame as Frame>::Ext;

/// A model space to lay out in: points, isometries and the placement of one triangle.
pub trait Space: Background {
    type Point: Copy + PartialEq + std::fmt::Debug + Send + Sync + 'static;
    type Iso: Isometry<Point = Self::Point>;
    /// The working precision of face frames and deck groups (see [`Frame`]).
    type Frame: Frame<Iso = Self::Iso>;
    /// The counter-clockwise triangle with side lengths `l01 = |p0 p1|`, `l12`, `l20` in its
    /// canonical position: `p0` at the base point, `p1` on the reference direction.
    fn seed(l01: f64, l12: f64, l20: f64) -> [Self::Point; 3] {
        let p0 = Self::base_point();
        let p1 = Self::along_reference(l01);
        let p2 = Self::third(p0, p1, l01, l12, l20);
        [p0, p1, p2]
    }
    /// The base point (origin of the plane / centre of the disk / north pole).
    fn base_point() -> Self::Point;
    /// The point at distance `d` from the base point along the reference direction.
    fn along_reference(d: f64) -> Self::Point;
    /// The vertex `p_k` of the counter-clockwise triangle `(p_i, p_j, p_k)` with metric side
    /// lengths `l_ij`, `l_jk`, `l_ki`, placed relative to `p_i` and the direction towards `p_j`.
    fn third(pi: Self::Point, pj: Self::Point, lij: f64, ljk: f64, lki: f64) -> Self::Point;
    /// Positive for counter-clockwise triangles, negative for clockwise ones.
    fn orientation(a: Self::Point, b: Self::Point, c: Self::Point) -> f64;
    /// Geodesic distance.
    fn distance(a: Self::Point, b: Self::Point) -> f64;
    /// A cheaper key that increases with [`Space::distance`] (to a few ulps, relative).
    #[inline]
    fn distance_key(a: Self::Point, b: Self::Point) -> f64 {
        Self::distance(a, b)
    }
    /// The [`Space::distance_key`] of two points at distance `d` (to the same few ulps): a
    /// search can rule a point out by its key alone, without its exact distance.
    #[inline]
    fn key_of_distance(d: f64) -> f64 {
        d
    }
    /// Whether [`Space::distance`] from `p` is accurate to 1e-9, so that searches may be
    /// pruned there with [`Isometry::displacement_bound`].
    #[inline]
    fn resolved(p: Self::Point) -> bool {
        let _ = p;
        false
    }
    /// The point at fraction `t` of the geodesic from `a` to `b`.
    fn toward(a: Self::Point, b: Self::Point, t: f64) -> Self::Point;
    /// [`Space::seed`] in the working precision, for side lengths `l[m] + lo[m]`
    /// (`l = [l01, l12, l20]`). Default: the double-precision seed (low parts ignored).
    fn seed_ext(l: [f64; 3], lo: [f64; 3]) -> [ExtPoint<Self>; 3] {
        let _ = lo;
        Self::seed(l[0], l[1], l[2]).map(|p| Self::Frame::ext(p, None))
    }
    /// The relative placement of a face `g = (i, j, k)` whose canonical triangle is `cg`
    /// (corner of `i` at index `ti`) on its parent's canonical triangle, where the shared
    /// edge runs from `pi` to `pj`: the isometry taking `cg[ti] ↦ pi`, `cg[ti + 1] ↦ pj`
    /// (side lengths `l_ij`, `l_jk`, `l_ki` of `g`). Default: through the circle
    /// intersection [`Space::third`] and [`Isometry::from_pairs`] in double precision.
    fn relative(
        cg: &[ExtPoint<Self>; 3],
        ti: usize,
        pi: ExtPoint<Self>,
        pj: ExtPoint<Self>,
        l: [f64; 3],
    ) -> Self::Frame {
        let (pi, pj) = (
            <Self::Frame as Frame>::split(pi).0,
            <Self::Frame as Frame>::split(pj).0,
        );
        let pk = Self::third(pi, pj, l[0], l[1], l[2]);
        let q = [pi, pj, pk];
        let mut target = [pi; 3];
        for r in 0..3 {
            target[(ti + r) % 3] = q[r];
        }
        let c0 = <Self::Frame as Frame>::split(cg[0]).0;
        let c1 = <Self::Frame as Frame>::split(cg[1]).0;
        let rel = Self::Iso::from_pairs(c0, c1, target[0], target[1]);
        Self::Frame::from_iso(&rel)
    }
}

#[inline]
fn angle_cs<B: Background>(opposite: f64, b: f64, c: f64) -> (f64, f64) {
    let t = B::angle(opposite, b, c);
    let (s, co) = t.sin_cos();
    (co, s)
}

impl Space for Euclidean {
    type Point = Complex;
    type Iso = RigidMotion;
    type Frame = RigidMotion;
    fn base_point() -> Complex {
        Complex::new(0.0, 0.0)
    }
    fn along_reference(d: f64) -> Complex {
        Complex::new(d, 0.0)
    }
    #[inline]
    fn third(pi: Complex, pj: Complex, lij: f64, ljk: f64, lki: f64) -> Complex {
        let (c, s) = angle_cs::<Euclidean>(ljk, lij, lki);
        let d = pj - pi;
        let n = d.norm();
        let u = if n > 0.0 {
            d / n
        } else {
            Complex::new(1.0, 0.0)
        };
        pi + u * Complex::new(lki * c, lki * s)
    }
    #[inline]
    fn orientation(a: Complex, b: Complex, c: Complex) -> f64 {
        ((b - a).conj() * (c - a)).im
    }
    #[inline]
    fn distance(a: Complex, b: Complex) -> f64 {
        (a - b).norm()
    }
    #[inline]
    fn distance_key(a: Complex, b: Complex) -> f64 {
        (a - b).norm_sqr()
    }
    #[inline]
    fn key_of_distance(d: f64) -> f64 {
        d * d
    }
    fn toward(a: Complex, b: Complex, t: f64) -> Complex {
        a + (b - a) * t
    }
}

impl Space for Hyperbolic {
    type Point = Complex;
    type Iso = Mobius;
    type Frame = MobiusDd;
    fn base_point() -> Complex {
        Complex::new(0.0, 0.0)
    }
    fn along_reference(d: f64) -> Complex {
        Complex::new((0.5 * d).tanh(), 0.0)
    }
    #[inline]
    fn third(pi: Complex, pj: Complex, lij: f64, ljk: f64, lki: f64) -> Complex {
        // Move p_i to the centre: T(z) = (z − p_i)/(1 − p̄_i z); there the hyperbolic circle
        // of radius l_ki around 0 is the Euclidean circle of radius tanh(l_ki/2).
        let (c, s) = angle_cs::<Hyperbolic>(ljk, lij, lki);
        let one = Complex::new(1.0, 0.0);
        let wj = (pj - pi) / (one - pi.conj() * pj);
        let n = wj.norm();
        let u = if n > 0.0 { wj / n } else { one };
        let w = u * Complex::new(c, s) * (0.5 * lki).tanh();
        (w + pi) / (one + pi.conj() * w)
    }
    #[inline]
    fn orientation(a: Complex, b: Complex, c: Complex) -> f64 {
        // Orientation is Möbius invariant; evaluate it with a at the centre, where geodesics
        // through a are straight.
        let one = Complex::new(1.0, 0.0);
        let wb = (b - a) / (one - a.conj() * b);
        let wc = (c - a) / (one - a.conj() * c);
        (wb.conj() * wc).im
    }
    #[inline]
    fn distance(a: Complex, b: Complex) -> f64 {
        disk_distance(a, b)
    }
    #[inline]
    fn distance_key(a: Complex, b: Complex) -> f64 {
        disk_distance_key(a, b)
    }
    /// `sinh²(d/2)` ([`disk_distance_key`]).
    #[inline]
    fn key_of_distance(d: f64) -> f64 {
        let s = (0.5 * d).sinh();
        s * s
    }
    #[inline]
    fn resolved(p: Complex) -> bool {
        1.0 - p.norm_sqr() >= 1e-8
    }
    /// The canonical triangle in double-double: `p0 = 0`, `p1 = tanh(l01/2)`,
    /// `p2 = e^{iθ} tanh(l20/2)` with `e^{iθ} = (1 − t² + 2it)/(1 + t²)` from the half-angle
    /// tangent of the cosine law ([`Background::angle`]), all in double-double from the
    /// double-double lengths.
    // `!(x > 0.0)` is used on purpose: it is also true for NaN.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    fn seed_ext(l: [f64; 3], lo: [f64; 3]) -> [Cdd; 3] {
        use crate::numeric::dd::Dd;
        let [l01, l12, l20] = [0, 1, 2].map(|m| Dd::new(l[m]) + Dd::new(lo[m]));
        let half = Dd::new(0.5);
        let sig = (l01 + l12 + l20) * half;
        let (sa, sb, sc) = (sig - l12, sig - l01, sig - l20);
        let phasor = if !(sa.hi > 0.0) {
            Cdd {
                re: -Dd::ONE,
                im: Dd::ZERO,
            }
        } else if !(sb.hi > 0.0) || !(sc.hi > 0.0) {
            Cdd::ONE
        } else {
            let t2 = sb.sinh() * sc.sinh() / (sig.sinh() * sa.sinh());
            let den = Dd::ONE + t2;
            Cdd {
                re: (Dd::ONE - t2) / den,
                im: Dd::new(2.0) * t2.sqrt() / den,
            }
        };
        let r1 = (l01 * half).tanh();
        let r2 = (l20 * half).tanh();
        [
            Cdd::ZERO,
            Cdd {
                re: r1,
                im: Dd::ZERO,
            },
            phasor.scale(r2),
        ]
    }
    /// In double-double: [`MobiusDd::from_pairs`] on the corners of the shared edge (the two
    /// triangles share its length exactly, so no circle intersection is needed).
    fn relative(cg: &[Cdd; 3], ti: usize, pi: Cdd, pj: Cdd, _l: [f64; 3]) -> MobiusDd {
        MobiusDd::from_pairs(cg[ti], cg[(ti + 1) % 3], pi, pj)
    }
    fn toward(a: Complex, b: Complex, t: f64) -> Complex {
        let m = Mobius::to_origin(a);
        let w = m.apply(b);
        let r = w.norm();
        if r == 0.0 {
            return a;
        }
        let d = 2.0 * r.min(1.0 - f64::EPSILON).atanh();
        m.inverse().apply(w / r * (0.5 * t * d).tanh())
    }
}

impl Space for Spherical {
    type Point = [f64; 3];
    type Iso = Rotation;
    type Frame = Rotation;
    fn base_point() -> [f64; 3] {
        [0.0, 0.0, 1.0]
    }
    fn along_reference(d: f64) -> [f64; 3] {
        [d.sin(), 0.0, d.cos()]
    }
    #[inline]
    fn third(pi: [f64; 3], pj: [f64; 3], lij: f64, ljk: f64, lki: f64) -> [f64; 3] {
        let (c, s) = angle_cs::<Spherical>(ljk, lij, lki);
        let e1 = normalize3(pi);
        let d = [pj[0] - e1[0], pj[1] - e1[1], pj[2] - e1[2]];
        let k = dot3(d, e1);
        let e2 = normalize3([d[0] - k * e1[0], d[1] - k * e1[1], d[2] - k * e1[2]]);
        let e3 = cross3(e1, e2);
        let (sl, cl) = lki.sin_cos();
        normalize3([
            cl * e1[0] + sl * (c * e2[0] + s * e3[0]),
            cl * e1[1] + sl * (c * e2[1] + s * e3[1]),
            cl * e1[2] + sl * (c * e2[2] + s * e3[2]),
        ])
    }
    #[inline]
    fn orientation(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
        det3(a, b, c)
    }
    #[inline]
    fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
        sphere_distance(a, b)
    }
    fn toward(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
        let d = sphere_distance(a, b);
        if d == 0.0 {
            return a;
        }
        let mut q = Self::third(a, b, d, d, t * d);
        // `third` turns by the angle of an isosceles triangle; go straight instead.
        let e1 = normalize3(a);
        let dd = [b[0] - e1[0], b[1] - e1[1], b[2] - e1[2]];
        let k = dot3(dd, e1);
        let e2 = normalize3([dd[0] - k * e1[0], dd[1] - k * e1[1], dd[2] - k * e1[2]]);
        let (sn, cs) = (t * d).sin_cos();
        for i in 0..3 {
            q[i] = cs * e1[i] + sn * e2[i];
        }
        q
    }
}

/// The result of [`layout`]: one position per vertex and what was measured.
#[derive(Debug, Clone)]
pub struct Layout<P> {
    pub geometry: Geometry,
    /// Position of every vertex of the laid-out mesh (rounded to double precision).
    pub positions: Vec<P>,
    /// Low-order parts of the positions when the layout was computed in double-double (H²:
    /// `positions[v] + positions_lo[v]` is the position to ~32 digits, which matters far out
    /// in the Poincaré disk); empty in E² and S².
    pub positions_lo: Vec<P>,
    pub seed_face: u32,
    /// Faces with negative orientation in the layout.
    pub flipped_faces: Vec<u32>,
    /// Faces whose metric triangle is degenerate (zero area) or whose layout has zero area.
    pub degenerate_faces: Vec<u32>,
    /// Largest `|d(p_a, p_b) − l_ab|` over all edges (0 for an exact metric, up to rounding).
    pub max_length_error: f64,
    /// Longest chain of placements from the seed face to a vertex.
    pub depth: u32,
    /// Largest distance of a vertex from the seed vertex (in H² the double-precision
    /// `positions` resolve points at distance r only to about 1e-16·e^r; with
    /// `positions_lo` to about 1e-32·e^r).
    pub max_radius: f64,
}

/// Check that a metric fits the mesh: one finite positive length per edge (below π on the
/// sphere).
pub(crate) fn check_lengths(mesh: &Mesh, lengths: &[f64], geometry: Geometry) -> Result<()> {
    if lengths.len() != mesh.n_edges() {
        return Err(Error::input(format!(
            "the metric has {} edge lengths but the mesh has {} edges",
            lengths.len(),
            mesh.n_edges()
        )));
    }
    for (e, &l) in lengths.iter().enumerate() {
        let bad = !(l > 0.0 && l.is_finite())
            || (geometry == Geometry::Spherical && l >= std::f64::consts::PI);
        if bad {
            return Err(LayoutError::InvalidLength {
                edge: e as u32,
                vertices: mesh.edge_vertices(e as u32),
                length: l,
                geometry,
            }
            .into());
        }
    }
    Ok(())
}

/// Default seed face: on a disk the face farthest (in face-adjacency steps) from the
/// boundary; on a closed mesh a face of smallest eccentricity estimate (two sweeps).
pub fn central_face(mesh: &Mesh) -> u32 {
    let nf = mesh.n_faces();
    if nf == 0 {
        return 0;
    }
    let bfs = |sources: &[u32]| -> Vec<u32> {
        let mut d = vec![u32::MAX; nf];
        let mut q = VecDeque::new();
        for &s in sources {
            d[s as usize] = 0;
            q.push_back(s);
        }
        while let Some(f) = q.pop_front() {
            for h in mesh.face_halfedges(f) {
                let g = mesh.he_face(mesh.he_twin(h));
                if g != NONE && d[g as usize] == u32::MAX {
                    d[g as usize] = d[f as usize] + 1;
                    q.push_back(g);
                }
            }
        }
        d
    };
    let argmax = |d: &[u32]| -> u32 {
        let mut best = 0u32;
        for (f, &x) in d.iter().enumerate() {
            if x != u32::MAX && x > d[best as usize] {
                best = f as u32;
            }
        }
        best
    };
    let boundary_faces: Vec<u32> = (0..nf as u32)
        .filter(|&f| {
            mesh.face_halfedges(f)
                .iter()
                .any(|&h| mesh.is_boundary_halfedge(mesh.he_twin(h)))
        })
        .collect();
    if !boundary_faces.is_empty() {
        return argmax(&bfs(&boundary_faces));
    }
    let da = bfs(&[0]);
    let fa = argmax(&da);
    let d1 = bfs(&[fa]);
    let fb = argmax(&d1);
    let d2 = bfs(&[fb]);
    (0..nf as u32)
        .min_by_key(|&f| (d1[f as usize].max(d2[f as usize]), f))
        .unwrap_or(0)
}

/// Lay out a simply connected mesh (a disk, e.g. a cut mesh, or a closed genus-0 surface on
/// the sphere) with the edge lengths of `metric` (leading parts; a metric of `S`'s geometry)
/// in the model space `S`.
///
/// Errors: wrong number of lengths or invalid values (naming the edge), a metric of another
/// geometry, a mesh that is not connected and simply connected (naming its topology), an
/// out-of-range seed face.
pub fn layout<S: Space>(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    seed_face: Option<u32>,
) -> Result<Layout<S::Point>> {
    layout_parts::<S>(mesh, metric, false, seed_face)
}

/// [`layout`] for an [`IntrinsicMetric`] of `S`'s geometry; its low parts, where present
/// (e.g. [`super::pipeline::cut_disk_polished`]), enter the canonical triangles in the working
/// precision of the space ([`Space::seed_ext`]: double-double in H²; E² and S² ignore them).
///
/// Errors: as [`layout`], low parts that are not finite.
pub fn layout_dd<S: Space>(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    seed_face: Option<u32>,
) -> Result<Layout<S::Point>> {
    layout_parts::<S>(mesh, metric, true, seed_face)
}

/// [`layout`] (`with_low_parts` false) or [`layout_dd`] (true).
fn layout_parts<S: Space>(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    with_low_parts: bool,
    seed_face: Option<u32>,
) -> Result<Layout<S::Point>> {
    if metric.geometry() != S::KIND {
        return Err(Error::input(format!(
            "a {} metric cannot be laid out in the {} model space",
            metric.geometry().name(),
            S::KIND.name()
        )));
    }
    let (lengths, lengths_lo) = (
        metric.lengths(),
        metric.lengths_lo().filter(|_| with_low_parts),
    );
    check_lengths(mesh, lengths, S::KIND)?;
    if let Some(lo) = lengths_lo {
        if let Some(e) = lo.iter().position(|x| !x.is_finite()) {
            let (edge, value) = (e as u32, lo[e]);
            return Err(LayoutError::InvalidLowPart { edge, value }.into());
        }
    }
    let nf = mesh.n_faces();
    if nf == 0 {
        return Err(Error::input("cannot lay out a mesh without faces"));
    }
    let topo = topology(mesh);
    if topo.components.len() != 1 {
        return Err(Error::topology(format!(
            "a layout needs a connected mesh, this one has {} components",
            topo.components.len()
        )));
    }
    let c = &topo.components[0];
    let simply_connected = c.genus == 0 && c.boundary_loops <= 1;
    if !simply_connected {
        let (genus, boundary_loops) = (c.genus, c.boundary_loops);
        return Err(LayoutError::NotSimplyConnected {
            genus,
            boundary_loops,
        }
        .into());
    }
    if c.boundary_loops == 0 && S::KIND != Geometry::Spherical {
        return Err(Error::topology(
            "a closed genus-0 surface can only be laid out on the sphere (use the spherical \
             geometry), or cut it to a disk first",
        ));
    }
    let seed = match seed_face {
        Some(f) if (f as usize) < nf => f,
        Some(face) => return Err(LayoutError::SeedFaceMissing { face, n_faces: nf }.into()),
        None => central_face(mesh),
    };
    let canonical = canonical_triangles::<S>(mesh, lengths, lengths_lo);
    // The relative placement of each face on the parent it was placed from, kept for the
    // second pass: a face placed from the same parent edge again reuses it (same bits).
    let mut relatives: Vec<(u32, Option<S::Frame>)> = vec![(NONE, None); nf];
    let (first, depth) = layout_from::<S>(mesh, lengths, &canonical, seed, &mut relatives);
    if seed_face.is_some() || !mesh.has_boundary() {
        return Ok(measured_layout::<S>(mesh, lengths, &first, seed, depth));
    }
    // Errors grow with the distance from the seed (in H² exponentially, through the
    // resolution of the model near the unit circle): restart from the face nearest to the
    // minimax centre of the boundary. (The first walk's positions are only measured when it
    // is the result.)
    let rounded: Vec<S::Point> = first.iter().map(|&p| S::Frame::split(p).0).collect();
    let centre = minimax_centre::<S>(&boundary_points(mesh, &rounded));
    // The face whose first corner is nearest the centre (the first of equals); each
    // distance measured once, in parallel.
    let d: Vec<f64> = (0..nf as u32)
        .into_par_iter()
        .map(|f| S::distance(rounded[mesh.face(f)[0] as usize], centre))
        .collect();
    let best = (0..nf as u32)
        .min_by(|&f, &g| d[f as usize].total_cmp(&d[g as usize]))
        .unwrap_or(seed);
    if best == seed {
        return Ok(measured_layout::<S>(mesh, lengths, &first, seed, depth));
    }
    let (pos, depth) = layout_from::<S>(mesh, lengths, &canonical, best, &mut relatives);
    Ok(measured_layout::<S>(mesh, lengths, &pos, best, depth))
}

fn boundary_points<P: Copy>(mesh: &Mesh, pos: &[P]) -> Vec<P> {
    mesh.boundary_loops()
        .into_iter()
        .flatten()
        .map(|v| pos[v as usize])
        .collect()
}

/// Approximate centre of the smallest enclosing ball (Bădoiu–Clarkson: move towards the
/// farthest point by a shrinking fraction), 300 iterations.
pub fn minimax_centre<S: Space>(points: &[S::Point]) -> S::Point {
    let Some(&first) = points.first() else {
        return S::base_point();
    };
    let mut c = first;
    for it in 1..300 {
        // The farthest point (the last of equals, as `max_by`), one distance per point; in
        // parallel, the same point: the largest (distance, index).
        let far = points
            .par_iter()
            .enumerate()
            .map(|(i, &p)| (S::distance(c, p), i))
            .max_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
            .map_or(first, |(_, i)| points[i]);
        c = S::toward(c, far, 1.0 / (it as f64 + 1.0));
    }
    c
}

/// The canonical triangle of every face in the working precision of the space
/// ([`Space::seed_ext`]; double-double transcendentals in H², so computed once per layout).
fn canonical_triangles<S: Space>(
    mesh: &Mesh,
    lengths: &[f64],
    lengths_lo: Option<&[f64]>,
) -> Vec<[ExtPoint<S>; 3]> {
    let len = |h: u32| lengths[mesh.he_edge(h) as usize];
    let lo = |h: u32| lengths_lo.map_or(0.0, |l| l[mesh.he_edge(h) as usize]);
    (0..mesh.n_faces() as u32)
        .into_par_iter()
        .map(|f| {
            let [a, b, c] = mesh.face_halfedges(f);
            S::seed_ext([len(a), len(b), len(c)], [lo(a), lo(b), lo(c)])
        })
        .collect()
}

/// [`layout_from`]'s verdicts of a placed face.
const FLIPPED: u8 = 1;
const DEGENERATE: u8 = 2;

/// Breadth-first placement from `seed` with the faces' canonical triangles
/// ([`canonical_triangles`]): the positions in the working precision and the largest
/// breadth-first depth of a vertex.
///
/// The walk's order depends on the lengths alone (not on the frames), so it is run first
/// ([`walk`]); then the relative placements, which read only canonical triangles and lengths,
/// are computed in parallel (rayon), the frames — each its parent's composed with its
/// relative placement — one tree level after the other (the faces of a level in parallel),
/// and the positions in parallel. Every value is the same operation on the same inputs as in
/// a sequential walk, so the layout is the same to the bit.
fn layout_from<S: Space>(
    mesh: &Mesh,
    lengths: &[f64],
    canonical: &[[ExtPoint<S>; 3]],
    seed: u32,
    relatives: &mut [(u32, Option<S::Frame>)],
) -> (Vec<ExtPoint<S>>, u32) {
    let nf = mesh.n_faces();
    let len = |h: u32| lengths[mesh.he_edge(h) as usize];
    let canon = |f: u32| canonical[f as usize];
    let w = walk(mesh, lengths, seed);
    // Relative placement of g = (i, j, k) (counter-clockwise, t = i → j) on its parent f:
    // g's canonical triangle with its corners i, j onto (p_i, p_j) in f's canonical triangle.
    // A face placed from the same parent edge as in an earlier walk reuses it (same bits).
    let rels: Vec<S::Frame> = w
        .steps
        .par_iter()
        .map(|&(g, t)| match relatives[g as usize] {
            (parent, Some(rel)) if parent == t => rel,
            _ => {
                let h = mesh.he_twin(t); // the parent's half-edge j → i
                let cf = canon(mesh.he_face(h));
                // h runs j → i: its origin (corner h % 3) is j, its tip is i.
                let (pj, pi) = (cf[(h % 3) as usize], cf[((h + 1) % 3) as usize]);
                let (tn, tp) = (mesh.he_next(t), mesh.he_prev(t));
                let ti = (t % 3) as usize; // corner of i in g
                S::relative(&canon(g), ti, pi, pj, [len(t), len(tn), len(tp)])
            }
        })
        .collect();
    for (&(g, t), &rel) in w.steps.iter().zip(&rels) {
        relatives[g as usize] = (t, Some(rel));
    }
    // Every face gets a frame: the isometry taking its canonical triangle (vertex 0 at the
    // base point, vertex 1 on the reference direction, `Space::seed`) to its place, composed
    // in the working precision of the space (double-double in H², see [`Frame`]). A
    // neighbour's frame is the parent's frame composed with the relative placement, which is
    // computed near the base point from the metric alone; positions are frames applied to
    // canonical triangles. So no direction is ever taken from the difference of two nearby
    // far-away points (in the Poincaré disk those lose ~1e-16·e^r / l of accuracy).
    let mut frame: Vec<S::Frame> = vec![S::Frame::identity(); nf];
    let parent_frame = |frame: &[S::Frame], i: usize| {
        let f = mesh.he_face(mesh.he_twin(w.steps[i].1));
        frame[f as usize].compose(&rels[i]).normalized()
    };
    for level in &w.levels {
        if level.len() < 64 {
            for &i in level {
                frame[w.steps[i as usize].0 as usize] = parent_frame(&frame, i as usize);
            }
            continue;
        }
        let new: Vec<S::Frame> = level
            .par_iter()
            .map(|&i| parent_frame(&frame, i as usize))
            .collect();
        for (&i, fg) in level.iter().zip(new) {
            frame[w.steps[i as usize].0 as usize] = fg;
        }
    }
    let mut pos: Vec<ExtPoint<S>> = vec![S::Frame::ext(S::base_point(), None); mesh.n_vertices()];
    let tri = canon(seed);
    for (i, &v) in mesh.face(seed).iter().enumerate() {
        pos[v as usize] = tri[i];
    }
    // The third vertex k of the face that placed it, in that face's frame.
    let placed: Vec<ExtPoint<S>> = w
        .placements
        .par_iter()
        .map(|&(_, i)| {
            let (g, t) = w.steps[i as usize];
            let ti = (t % 3) as usize;
            frame[g as usize].apply(canon(g)[(ti + 2) % 3])
        })
        .collect();
    for (&(k, _), p) in w.placements.iter().zip(placed) {
        pos[k as usize] = p;
    }
    (pos, w.depth)
}

/// The [`Layout`] of the placed points `pos`, with its measurements: flipped and degenerate
/// faces, the largest edge-length error and the largest distance from the base point —
/// per face and per edge in parallel (the maxima ignore NaN as a fold with `f64::max` does,
/// in any order).
fn measured_layout<S: Space>(
    mesh: &Mesh,
    lengths: &[f64],
    pos: &[ExtPoint<S>],
    seed: u32,
    depth: u32,
) -> Layout<S::Point> {
    let nf = mesh.n_faces();
    let len = |h: u32| lengths[mesh.he_edge(h) as usize];
    let verdict: Vec<u8> = (0..nf as u32)
        .into_par_iter()
        .map(|f| {
            let [a, b, c] = mesh.face(f);
            let [ha, hb, hc] = mesh.face_halfedges(f);
            let metric_area = S::area(len(hb), len(hc), len(ha));
            let o = S::Frame::orientation(pos[a as usize], pos[b as usize], pos[c as usize]);
            if o < 0.0 {
                FLIPPED
            } else if o == 0.0 || metric_area <= 0.0 {
                DEGENERATE
            } else {
                0
            }
        })
        .collect();
    let with = |x: u8| {
        (0..nf as u32)
            .filter(|&f| verdict[f as usize] == x)
            .collect::<Vec<u32>>()
    };
    let (flipped, degenerate) = (with(FLIPPED), with(DEGENERATE));
    let max_err = (0..mesh.n_edges() as u32)
        .into_par_iter()
        .map(|e| {
            let [a, b] = mesh.edge_vertices(e);
            let d = S::Frame::point_distance(pos[a as usize], pos[b as usize]);
            (d - lengths[e as usize]).abs()
        })
        .reduce(|| 0.0, f64::max);
    let origin = S::Frame::ext(S::base_point(), None);
    let max_radius = pos
        .par_iter()
        .map(|&p| S::Frame::point_distance(origin, p))
        .reduce(|| 0.0, f64::max);
    let mut positions = Vec::with_capacity(pos.len());
    let mut positions_lo = Vec::new();
    for &p in pos {
        let (hi, lo) = S::Frame::split(p);
        positions.push(hi);
        if let Some(lo) = lo {
            positions_lo.push(lo);
        }
    }
    Layout {
        geometry: S::KIND,
        max_radius,
        positions,
        positions_lo,
        seed_face: seed,
        flipped_faces: flipped,
        degenerate_faces: degenerate,
        max_length_error: max_err,
        depth,
    }
}

/// The isometry that best maps layout `b` onto layout `a` (least squares over all vertices)
/// and the largest remaining distance between corresponding vertices after applying it.
pub fn align<S: Space>(a: &[S::Point], b: &[S::Point]) -> Result<(S::Iso, f64)> {
    if a.len() != b.len() {
        return Err(Error::input(
            "cannot align layouts with different numbers of vertices",
        ));
    }
    let pairs: Vec<(S::Point, S::Point)> = b.iter().copied().zip(a.iter().copied()).collect();
    let iso = S::Iso::fit(&pairs)?;
    let dev = pairs
        .iter()
        .map(|&(x, y)| S::distance(iso.apply(x), y))
        .fold(0.0, f64::max);
    Ok((iso, dev))
}

/// The position of vertex `v` of a layout in the working precision of its space.
pub fn ext_position<S: Space>(l: &Layout<S::Point>, v: usize) -> ExtPoint<S> {
    S::Frame::ext(l.positions[v], l.positions_lo.get(v).copied())
}

/// [`align`] for two layouts, in the working precision of the space (double-double in H²,
/// where the double-precision positions of vertices far from the centre of the disk are
/// resolved only to `~1e-16·e^r`): the least-squares isometry mapping `b` onto `a` and the
/// largest remaining geodesic distance between corresponding vertices.
pub fn align_layouts<S: Space>(
    a: &Layout<S::Point>,
    b: &Layout<S::Point>,
) -> Result<(S::Iso, f64)> {
    if a.positions.len() != b.positions.len() {
        return Err(Error::input(
            "cannot align layouts with different numbers of vertices",
        ));
    }
    let pairs: Vec<(ExtPoint<S>, ExtPoint<S>)> = (0..a.positions.len())
        .map(|v| (ext_position::<S>(b, v), ext_position::<S>(a, v)))
        .collect();
    let iso = S::Frame::fit(&pairs)?;
    let dev = pairs
        .iter()
        .map(|&(x, y)| S::Frame::point_distance(iso.apply(x), y))
        .fold(0.0, f64::max);
    Ok((iso.round(), dev))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::dd::disk_orientation_dd;

    /// Hyperbolic distance of two disk points, entirely in double-double.
    fn dist_dd(p: Cdd, q: Cdd) -> crate::numeric::dd::Dd {
        use crate::numeric::dd::Dd;
        let den = (Dd::ONE - p.norm_sqr()) * (Dd::ONE - q.norm_sqr());
        Dd::new(2.0) * ((p - q).norm() / den.sqrt()).asinh()
    }

    #[test]
    fn double_double_seed_triangles_have_their_double_double_side_lengths() {
        use crate::numeric::dd::Dd;
        // Low parts far below double precision must show up in the laid-out distances.
        for (l, lo) in [
            ([0.3, 0.4, 0.5], [1e-17, -2e-17, 3e-18]),
            ([0.05, 0.0502, 0.07], [-3e-19, 1e-19, 2e-19]),
            ([1.5, 2.0, 1.2], [4e-17, 0.0, -1e-17]),
        ] {
            let p = Hyperbolic::seed_ext(l, lo);
            let want = [0, 1, 2].map(|m| Dd::new(l[m]) + Dd::new(lo[m]));
            let got = [
                dist_dd(p[0], p[1]),
                dist_dd(p[1], p[2]),
                dist_dd(p[2], p[0]),
            ];
            for m in 0..3 {
                let e = ((got[m] - want[m]).f64() / l[m]).abs();
                assert!(e < 1e-29, "side {m} of {l:?}: relative error {e:e}");
            }
            assert!(disk_orientation_dd(p[0], p[1], p[2]) > 0.0);
            // Agrees with the double-precision seed to its rounding.
            let q = Hyperbolic::seed(l[0], l[1], l[2]);
            for m in 0..3 {
                assert!((p[m].hi() - q[m]).norm() < 1e-15);
            }
            // The relative placement of a copy across edge 1 → 2 puts its corners on the
            // edge's ends (in double-double).
            let f = Hyperbolic::relative(&p, 1, p[2], p[1], [l[1], l[0], l[2]]);
            let (a, b) = (f.apply(p[1]), f.apply(p[2]));
            assert!(dist_dd(a, p[2]).f64() < 1e-29 && dist_dd(b, p[1]).f64() < 1e-29);
        }
    }

    #[test]
    fn seed_triangles_have_their_side_lengths_and_orientation() {
        fn check<S: Space>(l: [f64; 3]) {
            let p = S::seed(l[0], l[1], l[2]);
            assert!(
                (S::distance(p[0], p[1]) - l[0]).abs() < 1e-13,
                "{:?}",
                S::KIND
            );
            assert!(
                (S::distance(p[1], p[2]) - l[1]).abs() < 1e-13,
                "{:?}",
                S::KIND
            );
            assert!(
                (S::distance(p[2], p[0]) - l[2]).abs() < 1e-13,
                "{:?}",
                S::KIND
            );
            assert!(S::orientation(p[0], p[1], p[2]) > 0.0);
            // The third vertex on the other side of an edge of a triangle placed elsewhere.
            let q = S::third(p[1], p[0], l[0], l[2] * 1.1, l[1] * 0.9);
            assert!(S::orientation(p[1], p[0], q) > 0.0);
            assert!((S::distance(q, p[1]) - l[1] * 0.9).abs() < 1e-12);
            assert!((S::distance(q, p[0]) - l[2] * 1.1).abs() < 1e-12);
        }
        for l in [[0.3, 0.4, 0.5], [1.0, 1.2, 0.7], [0.01, 0.0105, 0.012]] {
            check::<Euclidean>(l);
            check::<Hyperbolic>(l);
            check::<Spherical>(l);
        }
        // Far from the centre of the disk the Möbius recentring keeps the accuracy.
        let p = Complex::new(0.999, 0.0);
        let m = Mobius::from_pairs(
            Complex::new(0.0, 0.0),
            Complex::new(0.1, 0.0),
            p,
            Complex::new(0.999, 0.0001),
        );
        let t = Hyperbolic::seed(0.5, 0.6, 0.7).map(|z| m.apply(z));
        let q = Hyperbolic::third(t[0], t[1], 0.5, 0.6, 0.7);
        assert!(Hyperbolic::distance(q, t[2]) < 1e-9);
    }
}
