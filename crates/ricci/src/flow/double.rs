//! The conformal flow ([`super::conformal`]) of a surface with boundary run on its double
//! ([`crate::mesh::double_cover`]; docs/notes/wave2-s6-spec6.md "Design: boundaries through the
//! double cover"; Gu–Luo–Sun–Wu 2018 define the discrete conformal class of a surface with
//! boundary through its double).
//!
//! On the surface itself boundary edges never flip, so a vertex split close to a boundary edge
//! keeps its thin triangle: the input metric's triangulation is not Delaunay across the
//! boundary, and the flow with `u = 0` held on the boundary can drive that triangle through
//! the triangle inequality (issue 15, the split-boundary disk: "the line search found no
//! decrease"). On the double the boundary edges are ordinary edges: the isometric and Ptolemy
//! flips may cross the boundary, and the σ-symmetric target (`K̄` mirrored, boundary targets
//! doubled since a boundary vertex's cone angle is twice its boundary angle) has a
//! σ-symmetric solution (the energy is strictly convex once a vertex is held).
//!
//! The double is built here as an [`IntrinsicTriangulation`] ([`double_triangulation`]), a
//! Δ-complex, so that an interior edge of the surface joining two boundary vertices (which
//! [`crate::mesh::double_cover`] refuses: a [`Mesh`] has one edge per vertex pair) is allowed.
//!
//! The solution is a metric on the double's final Delaunay triangulation, whose edges may
//! cross the fixed curve of σ (the surface's boundary): cutting that triangulation back to one
//! half (for the layout and the common subdivision of the surface) is not done here.

use super::conformal::{solve, ConformalSettings};
use super::newton::max_error;
use super::{IterationRecord, Target};
use crate::error::{Error, Result};
use crate::mesh::double::double_vertices;
use crate::mesh::{Mesh, NONE};
use crate::metric::intrinsic::IntrinsicTriangulation;
use crate::metric::Geometry;
use crate::progress::Progress;

/// What [`flow_on_double`] produced.
#[derive(Debug, Clone)]
pub struct DoubleFlow {
    /// For every edge id of the double, the edge of the surface it is a copy of.
    pub edge_origin: Vec<u32>,
    /// The involution on the double's vertices (fixes exactly the surface's boundary vertices).
    pub sigma: Vec<u32>,
    /// `u` per vertex of the double.
    pub u_double: Vec<f64>,
    /// `u` per vertex of the surface (the double's first `V` vertices).
    pub u: Vec<f64>,
    /// Curvature `K` per vertex of the surface, in the surface's convention (`π − Σθ` on the
    /// boundary: half the double's cone curvature there).
    pub curvature: Vec<f64>,
    /// The double's final Delaunay triangulation (base coordinates; `u` not applied).
    pub triangulation: IntrinsicTriangulation,
    pub converged: bool,
    /// max |K − K̄| on the double's free vertices.
    pub max_error: f64,
    pub iterations: usize,
    pub history: Vec<IterationRecord>,
    /// Faces of the final triangulation violating a triangle inequality.
    pub degenerate_faces: usize,
    /// Isometric flips to the input metric's Delaunay triangulation of the double.
    pub initial_flips: usize,
    /// Ptolemy flips of the solve.
    pub flips: usize,
    /// Boundary edges of the surface that are not edges of the final triangulation.
    pub boundary_edges_flipped: usize,
    /// max |u(v) − u(σ(v))|: the solution's distance from σ-symmetry (rounding only).
    pub asymmetry: f64,
    pub notes: Vec<String>,
    /// Why the solve stopped short of the tolerance ([`super::newton::stop_reason`]).
    pub stop_reason: Option<String>,
}

/// The target of the double from the surface's `target` (module docs): `K̄` mirrored and
/// doubled at the boundary vertices, the same vertices held. Round boundaries (targets that
/// move with the metric) are refused.
pub fn double_target(target: &Target, sigma: &[u32]) -> Result<Target> {
    if target.is_dynamic() {
        return Err(Error::input(
            "a round boundary moves with the metric; the flow on the double takes fixed targets",
        ));
    }
    let o = |v: usize| v.min(sigma[v] as usize);
    let curvature = (0..sigma.len())
        .map(|v| {
            let k = target.curvature[o(v)];
            if sigma[v] as usize == v {
                2.0 * k
            } else {
                k
            }
        })
        .collect();
    let fixed = (0..sigma.len()).map(|v| target.fixed[o(v)]).collect();
    Ok(Target {
        curvature,
        fixed,
        round_loops: Vec::new(),
        description: format!("{} (on the double)", target.description),
    })
}

/// The conformal flow of `mesh` (with boundary) with Euclidean edge `lengths` and `target`
/// (per vertex of `mesh`) in `geometry` (E² or H²), solved on the double (module docs). When
/// no vertex is held in E², one boundary vertex is pinned at `u = 0` (the scale).
pub fn flow_on_double(
    mesh: &Mesh,
    lengths: &[f64],
    geometry: Geometry,
    target: &Target,
    tolerance: f64,
    progress: &mut dyn Progress,
) -> Result<DoubleFlow> {
    if geometry == Geometry::Spherical {
        return Err(Error::input(
            "the flow on the double runs in E² or H² (the double of a surface with boundary)",
        ));
    }
    if lengths.len() != mesh.n_edges() || target.curvature.len() != mesh.n_vertices() {
        return Err(Error::input(format!(
            "{} lengths and {} targets for {} edges and {} vertices",
            lengths.len(),
            target.curvature.len(),
            mesh.n_edges(),
            mesh.n_vertices()
        )));
    }
    let (mut tri, sigma, edge_origin) = double_triangulation(mesh, geometry, lengths)?;
    let mut dtarget = double_target(target, &sigma)?;
    let flip_budget = 200 * tri.n_edges() + 10_000;
    let init = tri.make_delaunay_isometric(geometry, flip_budget);
    if !init.delaunay {
        return Err(Error::numerical(format!(
            "the double's input metric did not become Delaunay within {flip_budget} flips"
        )));
    }
    let nd = sigma.len();
    let has_fixed = dtarget.fixed.iter().any(|&f| f);
    let pinned: Vec<u32> = if geometry == Geometry::Euclidean && !has_fixed {
        (0..nd as u32)
            .filter(|&v| sigma[v as usize] == v)
            .take(1)
            .collect()
    } else {
        Vec::new()
    };
    let settings = ConformalSettings {
        geometry,
        tolerance,
        max_iterations: 50,
        flip_budget,
        pinned,
    };
    let out = solve(&mut tri, &mut dtarget, &settings, progress)?;
    let asymmetry = (0..nd)
        .map(|v| (out.u[v] - out.u[sigma[v] as usize]).abs())
        .fold(0.0f64, f64::max);
    // Boundary edges keep their ids (< E) in the double.
    let boundary_edges_flipped = (0..mesh.n_edges() as u32)
        .filter(|&e| mesh.is_boundary_edge(e))
        .filter(|&e| {
            let mut a = tri.edge_vertices(e);
            let mut b = mesh.edge_vertices(e);
            a.sort_unstable();
            b.sort_unstable();
            a != b
        })
        .count();
    let nv = mesh.n_vertices();
    let curvature = (0..nv)
        .map(|v| {
            let k = out.state.curvature[v];
            if sigma[v] as usize == v {
                0.5 * k
            } else {
                k
            }
        })
        .collect();
    let max_err = max_error(&out.state.curvature, &dtarget);
    let degenerate_faces = out.state.degenerate_faces;
    Ok(DoubleFlow {
        u: out.u[..nv].to_vec(),
        u_double: out.u,
        curvature,
        converged: out.converged && degenerate_faces == 0,
        max_error: max_err,
        iterations: out.iterations,
        history: out.history,
        degenerate_faces,
        initial_flips: init.flips,
        flips: out.flips,
        boundary_edges_flipped,
        asymmetry,
        notes: out.notes,
        stop_reason: out.stop_reason,
        triangulation: tri,
        edge_origin,
        sigma,
    })
}

/// The double of `mesh` as a Δ-complex with the log Penner coordinates of `lengths`
/// (module docs): faces `0..F` and edges `0..E` are the surface's (same ids), face `F + f` the
/// mirror of face `f` (half-edge `3f + i` mirrored to `3(F + f) + 2 − i`), then one new edge
/// per interior edge; a boundary edge's two sides are a half-edge and its mirror. Returns the
/// triangulation, `σ` ([`double_vertices`]) and the surface edge of every edge.
pub fn double_triangulation(
    mesh: &Mesh,
    geometry: Geometry,
    lengths: &[f64],
) -> Result<(IntrinsicTriangulation, Vec<u32>, Vec<u32>)> {
    let half = IntrinsicTriangulation::from_mesh(mesh, geometry, lengths)?;
    let sigma = double_vertices(mesh)?;
    let nf = half.n_faces() as u32;
    let nh = 3 * nf as usize;
    let ne = half.n_edges();
    let mirror = |h: u32| 3 * (nf + h / 3) + 2 - h % 3;
    let mut tri = half.clone();
    tri.n_vertices = sigma.len();
    tri.origin.resize(2 * nh, NONE);
    tri.twin.resize(2 * nh, NONE);
    tri.edge.resize(2 * nh, NONE);
    tri.boundary_vertex = vec![false; sigma.len()];
    let mut edge_origin: Vec<u32> = (0..ne as u32).collect();
    let mut mirror_edge = vec![NONE; ne];
    for e in 0..ne as u32 {
        if !half.is_boundary_edge(e) {
            mirror_edge[e as usize] = edge_origin.len() as u32;
            edge_origin.push(e);
            tri.lambda.push(half.lambda[e as usize]);
            tri.edge_he.push(mirror(half.edge_he[e as usize]));
        }
    }
    for h in 0..nh as u32 {
        // The mirror of h runs from σ(tip h) to σ(origin h).
        let m = mirror(h) as usize;
        tri.origin[m] = sigma[half.tip(h) as usize];
        let (e, t) = (half.edge[h as usize], half.twin[h as usize]);
        if t == NONE {
            tri.twin[h as usize] = m as u32;
            tri.twin[m] = h;
            tri.edge[m] = e;
        } else {
            tri.twin[m] = mirror(t);
            tri.edge[m] = mirror_edge[e as usize];
        }
    }
    tri.check()?;
    Ok((tri, sigma, edge_origin))
}
