//! Conformal maps of closed genus-0 surfaces onto the unit sphere (`ricci param --sphere`).
//!
//! The map is the conformal scheme's sphere ([`crate::flow::sphere::conformal_sphere`], run
//! through [`crate::flow::ricci_flow`] with the spherical geometry): discrete conformal
//! equivalence with intrinsic Delaunay flips, the flat picture of the surface with one vertex
//! at infinity, stereographic projection, and **Möbius centring** (the area-weighted centroid
//! of the vertices is the origin, vertex weights a third of the incident 3D face areas;
//! Baden–Crane–Kazhdan 2018 §3.2 centre the same way). Every input vertex gets its point on
//! the sphere, and the final intrinsic triangulation `T` is the convex hull of these points.
//!
//! The input's own faces, drawn as chord triangles between the points of their vertices, may
//! be turned inwards where `T` flipped edges: then the map is given on the **common
//! subdivision** of the input and `T` ([`crate::layout::subdivision_uv::sphere_common_subdivision`],
//! Gillespie–Springborn–Crane 2021 §5), whose pieces are positively oriented on the sphere,
//! and the report says which (`uv_faces`).
//!
//! Distortion is measured from each 3D triangle (input face, or subdivision piece on its
//! input face) to the chord triangle of its image, oriented by the outward normal: a face
//! with `det[p0, p1, p2] ≤ 0` counts as flipped.

use crate::analysis::distortion::{face_distortion, stats, DistortionStats};
use crate::error::{Error, Result};
use crate::flow::{flow_with_fallback, TargetSpec, UniformizationOptions};
use crate::layout::subdivision_uv::{sphere_common_subdivision, sphere_flipped_faces};
use crate::mesh::{topology, Surface};
use crate::metric::{Geometry, IntrinsicMetric, Scheme};
use crate::numeric::vec3::{cross, dot, norm, sub};
use crate::progress::Progress;
use serde::Serialize;
use std::time::Instant;

/// The common subdivision of [`SphereMap`]: its points on the input surface, its points on
/// the sphere, its triangles.
pub type Subdivision = (Vec<[f64; 3]>, Vec<[f64; 3]>, Vec<[u32; 3]>);

/// The result of [`sphere_map`].
#[derive(Debug, Clone, Serialize)]
pub struct SphereMap {
    /// Image of every input vertex on the unit sphere.
    #[serde(skip)]
    pub positions: Vec<[f64; 3]>,
    /// `"input"` (the input's faces are all positively oriented on the sphere) or
    /// `"common_subdivision"` (see the module docs).
    pub uv_faces: String,
    /// With `uv_faces = "common_subdivision"`: its points on the input surface, its points
    /// on the sphere and its triangles (counter-clockwise seen from outside).
    #[serde(skip)]
    pub subdivision: Option<Subdivision>,
    /// Input faces not positively oriented as chord triangles of their vertices' points.
    pub input_flipped_faces: usize,
    pub scheme: String,
    pub flow_iterations: usize,
    pub max_curvature_error: f64,
    /// Intrinsic flips of the flow (isometric and Ptolemy).
    pub flips: usize,
    /// |area-weighted centroid| of the points (Möbius centring).
    pub centroid_norm: f64,
    /// Distortion of the faces that carry the map (`uv_faces`): qc = σmax/σmin of the map
    /// from each 3D triangle to its chord triangle, σ of the log area ratio.
    pub stats: DistortionStats,
    /// The same measure on the input's own faces (flipped ones counted, not measured).
    pub input_stats: DistortionStats,
    pub seconds: f64,
}

/// Distortion of the map of the 3D triangles `faces` (points `x3`) to the chord triangles of
/// `xs` (points on the unit sphere), flattened in the frame of their outward normal.
fn chord_distortion(
    x3: &[[f64; 3]],
    xs: &[[f64; 3]],
    faces: &[[u32; 3]],
) -> Vec<crate::analysis::distortion::FaceDistortion> {
    faces
        .iter()
        .map(|tri| {
            let p = tri.map(|v| x3[v as usize]);
            let q = tri.map(|v| xs[v as usize]);
            let e1 = sub(q[1], q[0]);
            let l1 = norm(e1).max(1e-300);
            let e1 = [e1[0] / l1, e1[1] / l1, e1[2] / l1];
            // (q1 − q0) × (q2 − q0) · (q0 + q1 + q2) = 3 det[q0, q1, q2]: the sign of the
            // flattened area is the orientation on the sphere.
            let out = [
                q[0][0] + q[1][0] + q[2][0],
                q[0][1] + q[1][1] + q[2][1],
                q[0][2] + q[1][2] + q[2][2],
            ];
            let e2 = cross(out, e1);
            let l2 = norm(e2).max(1e-300);
            let e2 = [e2[0] / l2, e2[1] / l2, e2[2] / l2];
            let flat = |v: [f64; 3]| [dot(sub(v, q[0]), e1), dot(sub(v, q[0]), e2)];
            face_distortion(p, [[0.0, 0.0], flat(q[1]), flat(q[2])])
        })
        .collect()
}

/// Norm of the area-weighted centroid of `x` (weights: a third of the incident 3D areas).
fn centroid_norm(surface: &Surface, x: &[[f64; 3]]) -> f64 {
    let mut w = vec![0.0; x.len()];
    for tri in surface.mesh.faces() {
        let p = |i: usize| surface.positions[tri[i] as usize];
        let a = 0.5 * norm(cross(sub(p(1), p(0)), sub(p(2), p(0))));
        for &v in tri {
            w[v as usize] += a / 3.0;
        }
    }
    let total: f64 = w.iter().sum();
    let mut g = [0.0; 3];
    for (p, &wi) in x.iter().zip(&w) {
        for k in 0..3 {
            g[k] += wi * p[k] / total.max(1e-300);
        }
    }
    norm(g)
}

/// See the module docs. The surface must be connected, closed and of genus 0.
pub fn sphere_map(surface: &Surface, progress: &mut dyn Progress) -> Result<SphereMap> {
    let t0 = Instant::now();
    let mesh = &surface.mesh;
    let t = topology(mesh);
    if t.components.len() != 1 || t.components[0].genus != 0 || t.components[0].boundary_loops != 0
    {
        return Err(Error::topology(
            "--sphere needs a connected closed surface of genus 0",
        ));
    }
    let fo = UniformizationOptions::single(Some(Geometry::Spherical), Scheme::Conformal, 1e-10)
        .with_target(TargetSpec::Uniform);
    progress.report("flow", None, "conformal map to the sphere");
    let lengths = surface.edge_lengths();
    let r = flow_with_fallback(mesh, &lengths, &fo, None, progress)?.result;
    if !r.converged {
        return Err(Error::numerical(format!(
            "the spherical flow did not converge (max |K − K̄| = {:.3e})",
            r.max_curvature_error
        )));
    }
    let tr = r
        .triangulation
        .as_ref()
        .filter(|t| t.points.len() == mesh.n_vertices())
        .ok_or_else(|| Error::numerical("the spherical flow returned no points on the sphere"))?;
    let x = tr.points.clone();
    let input_flipped = sphere_flipped_faces(&x, mesh.faces()).len();
    let input_stats = stats(&chord_distortion(&surface.positions, &x, mesh.faces()));
    let (uv_faces, subdivision, st) = if input_flipped == 0 {
        ("input", None, input_stats.clone())
    } else {
        progress.report("subdivision", None, "common subdivision on the sphere");
        let s = sphere_common_subdivision(
            mesh,
            &surface.positions,
            &IntrinsicMetric::euclidean(lengths.to_vec()),
            &tr.triangulation,
            &r.u,
            &x,
        )?;
        let d = chord_distortion(&s.positions, &s.sphere_points, &s.triangles);
        let sub = (s.positions, s.sphere_points, s.triangles);
        ("common_subdivision", Some(sub), stats(&d))
    };
    Ok(SphereMap {
        centroid_norm: centroid_norm(surface, &x),
        positions: x,
        uv_faces: uv_faces.into(),
        subdivision,
        input_flipped_faces: input_flipped,
        scheme: r.scheme.to_string(),
        flow_iterations: r.iterations,
        max_curvature_error: r.max_curvature_error,
        flips: tr.initial_flips + tr.flips,
        stats: st,
        input_stats,
        seconds: t0.elapsed().as_secs_f64(),
    })
}
