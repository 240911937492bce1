//! Target curvatures and Ricci flow solvers (paper 001 §V, paper 000 §4 Step 3, paper 002
//! §4.3, §6.2.1, §7.1; docs/DESIGN.md §3).
//!
//! [`ricci_flow`] takes connectivity and Euclidean edge lengths (never positions), builds the
//! initial conformal structure of the chosen scheme ([`crate::metric::conformal`]), resolves and
//! checks the target ([`target`]) and runs Newton's method or the gradient flow ([`newton`]).
//! [`polish`] refines a converged H² metric beyond double precision (separately; the solvers
//! do not call it). [`adaptive`] reruns the flow on metric-preserving refinements of the mesh
//! where its metric degenerates (targets the given triangulation cannot reach).
//! The result carries per-vertex `u`, `K`, `K̄`, per-edge final lengths, the residual history
//! and an honest `converged` flag.
//!
//! [`Scheme::Conformal`] runs [`conformal`] instead (discrete conformal equivalence with
//! intrinsic Delaunay flips): its result lives on an intrinsic triangulation, returned in
//! [`FlowResult::triangulation`]; `u`, `curvature`, `target` and `fixed` are per input vertex,
//! `lengths` are by edge id of the simplicial mesh [`IntrinsicResult::simplicial`] (not of the
//! input mesh).
//!
//! Conventions of the result:
//! * Euclidean metrics are determined up to scale; the result is scaled so its area equals the
//!   area of the input mesh (when no vertex is held fixed).
//! * Hyperbolic and spherical metrics read the input lengths scaled by `input_scale` (reported;
//!   by default the factor that makes the Euclidean area equal the area the target asks for).
//! * Genus-0 closed surfaces in S²: Newton's method on the spherical energy first; if it does
//!   not converge, the robust route of [`sphere`] (puncture, flat disk with a round boundary,
//!   stereographic projection, Möbius centring, spherical Newton polish). `route` says which.
//!   With [`Scheme::Conformal`] (the default): [`sphere::conformal_sphere`] — the flat
//!   metric of the surface with one vertex at infinity (vertex scaling with Delaunay flips,
//!   the link of that vertex kept convex), stereographic projection, Möbius centring of the
//!   vertex areas; the result is the spherical metric on the final Delaunay triangulation
//!   (the convex hull of the points), `route` "puncture".

#![allow(clippy::needless_range_loop)]

pub mod adaptive;
pub mod conformal;
pub mod double;
pub(crate) mod error;
mod hessian_pattern;
pub(crate) mod newton;
pub mod polish;
mod solver;
pub mod sphere;
pub mod target;
pub mod uniformize;

pub use adaptive::ricci_flow_refined;
pub use error::FlowError;
pub use solver::{Solver, SphereRoute};
pub use target::{separated_vertices, Target, TargetSpec};
pub use uniformize::{
    flow_with_fallback, Fallback, FallbackFlow, TargetPolicy, UniformizationOptions,
};

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::metric::{euler_characteristic, ConformalStructure, Evaluator, Geometry, Scheme};
use crate::progress::Progress;
use serde::Serialize;
use std::f64::consts::PI;
use std::time::Instant;

/// The scheme used when the user names none: [`Scheme::Conformal`] (discrete conformal
/// equivalence — vertex scaling with intrinsic Delaunay flips: the conformal class of the
/// user's own mesh) in all three geometries (S² through a puncture,
/// [`sphere::conformal_sphere`]).
pub fn default_scheme(_geometry: Geometry) -> Scheme {
    Scheme::Conformal
}

/// Options of [`ricci_flow`].
#[derive(Debug, Clone)]
pub struct FlowOptions {
    pub geometry: Geometry,
    pub scheme: Scheme,
    pub target: TargetSpec,
    pub solver: Solver,
    /// Stop when max |K − K̄| ≤ tolerance.
    pub tolerance: f64,
    /// Iteration limit (default 30 for Newton, 200 000 for the gradient flow).
    pub max_iterations: Option<usize>,
    /// Step ε of the gradient flow (paper 001: "no greater than 0.05").
    pub gradient_step: f64,
    /// Scale applied to the input lengths in H² and S² (`None`: automatic, see module docs).
    pub input_scale: Option<f64>,
    pub sphere_route: SphereRoute,
}

impl Default for FlowOptions {
    fn default() -> Self {
        FlowOptions {
            geometry: Geometry::Euclidean,
            scheme: Scheme::Thurston,
            target: TargetSpec::Uniform,
            solver: Solver::Newton,
            tolerance: 1e-10,
            max_iterations: None,
            gradient_step: 0.05,
            input_scale: None,
            sphere_route: SphereRoute::Auto,
        }
    }
}

/// One line of the residual history.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct IterationRecord {
    pub iteration: usize,
    pub max_curvature_error: f64,
    /// Convex Ricci energy relative to the start (`None` when the target moves with the
    /// metric or the energy is not tracked).
    pub energy: Option<f64>,
    /// Largest |Δu| of the step that led here.
    pub step: f64,
    pub seconds: f64,
}

/// The outcome of a flow.
#[derive(Debug, Clone, Serialize)]
pub struct FlowResult {
    pub geometry: Geometry,
    pub scheme: Scheme,
    pub solver: Solver,
    /// "newton", "gradient", or for the sphere "newton" / "puncture" (the robust route).
    pub route: String,
    pub target_description: String,
    /// Final variables per vertex (circle packings: `log γ`, `log tanh(γ/2)`, `log tan(γ/2)`;
    /// vertex scaling: the log conformal factor).
    pub u: Vec<f64>,
    /// Final curvature per vertex.
    pub curvature: Vec<f64>,
    /// Target curvature per vertex (meaningless where `fixed`).
    pub target: Vec<f64>,
    /// Vertices whose `u` was held at its initial value (free boundary).
    pub fixed: Vec<bool>,
    /// Final edge lengths by edge id (background geometry).
    pub lengths: Vec<f64>,
    pub iterations: usize,
    pub history: Vec<IterationRecord>,
    pub converged: bool,
    pub tolerance: f64,
    pub max_curvature_error: f64,
    /// |Σ K + λ·Area − 2πχ| of the final metric.
    pub gauss_bonnet_error: f64,
    /// Background area of the final metric.
    pub area: f64,
    pub input_scale: f64,
    /// Thurston: edges whose intersection angle was clamped into [0, π/2].
    pub clamped_edges: usize,
    /// Relative difference of the initial scheme lengths from the (scaled) input lengths.
    pub initial_length_error: f64,
    /// Faces violating a triangle inequality in the final metric (vertex scaling, inversive).
    pub degenerate_faces: usize,
    /// Vertices pinned to remove the E² scale freedom.
    pub pinned: Vec<u32>,
    pub seconds: f64,
    pub notes: Vec<String>,
    /// Why the flow stopped short of its target when it did not converge (the iteration
    /// budget, the line search, the flip budget, …; faces violating the triangle inequality
    /// are counted in `degenerate_faces`), for the sentence of [`FlowError::not_converged`].
    pub stop_reason: Option<String>,
    /// [`Scheme::Conformal`] only: the final intrinsic triangulation (then `lengths` belong to
    /// its simplicial mesh `triangulation.simplicial.mesh`, not to the input mesh).
    pub triangulation: Option<IntrinsicResult>,
}

/// The intrinsic triangulation a [`Scheme::Conformal`] flow ends on.
#[derive(Debug, Clone, Serialize)]
pub struct IntrinsicResult {
    /// The final Delaunay Δ-complex: same vertex ids as the input; `lambda` holds the final
    /// metric's log Penner coordinates (`u` already applied); `flip_log` lists every flip
    /// (edge ids, in order) from the input triangulation — first the isometric flips to the
    /// input metric's Delaunay triangulation, then the Ptolemy flips of the solve.
    #[serde(skip)]
    pub triangulation: crate::metric::intrinsic::IntrinsicTriangulation,
    /// A simplicial mesh with the same metric (self-loops and multi-edges split at their
    /// midpoints, new vertices flat and appended), the mesh `FlowResult::lengths` refer to.
    #[serde(skip)]
    pub simplicial: crate::metric::intrinsic::SimplicialMesh,
    /// Isometric flips that made the input metric Delaunay.
    pub initial_flips: usize,
    /// Ptolemy flips of the solve (including line-search trials).
    pub flips: usize,
    /// Edge splits of `to_simplicial`.
    pub splits: usize,
    /// Vertices of the simplicial mesh (input vertices + splits).
    pub simplicial_vertices: usize,
    /// S² only: the input vertices' points on the unit sphere
    /// ([`sphere::ConformalSphere::positions`]; `triangulation` is their convex hull, faces
    /// counter-clockwise seen from outside); empty in E² and H².
    #[serde(skip)]
    pub points: Vec<[f64; 3]>,
}

impl FlowResult {
    /// The metric the flow reached (geometry and lengths, double precision), on the mesh the
    /// lengths belong to (the input's, or `triangulation.simplicial.mesh`).
    pub fn metric(&self) -> crate::metric::IntrinsicMetric {
        crate::metric::IntrinsicMetric::new(self.geometry, self.lengths.clone())
    }

    /// The metric file of this result on `mesh` (the mesh the flow ran on): the format read
    /// by [`crate::metric::file::read_metric_file`] — geometry, what the flow reached
    /// (`converged`, `max_curvature_error`, `degenerate_faces`), per-vertex `u`, `curvature`
    /// and `target_curvature` (null where the vertex was held fixed), per-edge `lengths` with
    /// `edge_vertices` (edge `i` joins `edge_vertices[i]`). `source` names the input.
    ///
    /// A [`Scheme::Conformal`] result lives on its intrinsic triangulation: then the edges
    /// are those of `triangulation.simplicial.mesh` (whatever `mesh` is given), and the file
    /// also holds its `faces` (input vertices keep their ids, split vertices are appended) and
    /// `"triangulation": "intrinsic"`, so that readers rebuild the mesh the lengths belong to.
    pub fn metric_json(&self, mesh: &Mesh, source: &str) -> serde_json::Value {
        let intrinsic = self.triangulation.as_ref().map(|t| &t.simplicial.mesh);
        let mesh = intrinsic.unwrap_or(mesh);
        let target: Vec<serde_json::Value> = self
            .target
            .iter()
            .zip(&self.fixed)
            .map(|(&t, &f)| {
                if f {
                    serde_json::Value::Null
                } else {
                    serde_json::json!(t)
                }
            })
            .collect();
        let edge_vertices: Vec<[u32; 2]> = (0..mesh.n_edges() as u32)
            .map(|e| mesh.edge_vertices(e))
            .collect();
        let mut v = serde_json::json!({
            "mesh": source,
            "geometry": self.geometry,
            "scheme": self.scheme,
            "solver": self.solver,
            "route": self.route,
            "target": self.target_description,
            "converged": self.converged,
            "max_curvature_error": self.max_curvature_error,
            "gauss_bonnet_error": self.gauss_bonnet_error,
            "degenerate_faces": self.degenerate_faces,
            "input_scale": self.input_scale,
            "area": self.area,
            "vertices": mesh.n_vertices(),
            "edges": mesh.n_edges(),
            "u": self.u,
            "curvature": self.curvature,
            "target_curvature": target,
            "edge_vertices": edge_vertices,
            "lengths": self.lengths,
        });
        if let Some(t) = &self.triangulation {
            v["triangulation"] = serde_json::json!("intrinsic");
            v["faces"] = serde_json::json!(mesh.faces());
            v["input_vertices"] = serde_json::json!(t.triangulation.n_vertices);
            v["flips"] = serde_json::json!(t.initial_flips + t.flips);
            v["splits"] = serde_json::json!(t.splits);
        }
        v
    }
}

/// Whether the target holds some (non-isolated) vertex fixed, and the vertex pinned to remove
/// the E² scale freedom when none is: the interior vertex with the largest valence (ties:
/// smallest id).
fn scale_pin(mesh: &Mesh, geometry: Geometry, target: &Target) -> (bool, Vec<u32>) {
    let has_fixed = target
        .fixed
        .iter()
        .enumerate()
        .any(|(v, &f)| f && !mesh.is_isolated(v as u32));
    let mut pinned = Vec::new();
    if geometry == Geometry::Euclidean && !has_fixed {
        let v = (0..mesh.n_vertices() as u32)
            .filter(|&v| !mesh.is_isolated(v))
            .max_by(|&a, &b| {
                let ka = (!mesh.is_boundary_vertex(a), mesh.valence(a));
                let kb = (!mesh.is_boundary_vertex(b), mesh.valence(b));
                ka.cmp(&kb).then(b.cmp(&a))
            });
        if let Some(v) = v {
            pinned.push(v);
        }
    }
    (has_fixed, pinned)
}

/// The input checks of [`ricci_flow`]: one component, one length per edge, a positive
/// tolerance.
fn check_flow_input(mesh: &Mesh, lengths: &[f64], options: &FlowOptions) -> Result<()> {
    let topo = crate::mesh::topology(mesh);
    if topo.components.len() != 1 {
        return Err(Error::topology(format!(
            "Ricci flow needs a connected mesh; this one has {} components",
            topo.components.len()
        )));
    }
    if lengths.len() != mesh.n_edges() {
        return Err(Error::input(format!(
            "{} edge lengths given for a mesh with {} edges",
            lengths.len(),
            mesh.n_edges()
        )));
    }
    if options.tolerance.is_nan() || options.tolerance <= 0.0 {
        return Err(Error::input(format!(
            "tolerance {} must be positive",
            options.tolerance
        )));
    }
    Ok(())
}

/// The factor applied to the input lengths: `options.input_scale`, else 1 in E²; in H²/S² the
/// factor that gives the area Gauss–Bonnet asks for, or mean edge length 0.1 with free
/// boundaries.
fn input_scale(
    options: &FlowOptions,
    chi: i64,
    target: &Target,
    lengths: &[f64],
    euclid_area: f64,
) -> f64 {
    let geometry = options.geometry;
    match (options.input_scale, options.geometry) {
        (Some(s), _) => s,
        (None, Geometry::Euclidean) => 1.0,
        (None, _) => {
            let sum: f64 = target.curvature.iter().sum();
            let want = (geometry.curvature() * (2.0 * PI * chi as f64 - sum)).max(0.0);
            let has_fixed = target.fixed.iter().any(|&f| f);
            if want > 0.0 && !has_fixed && euclid_area > 0.0 {
                (want / euclid_area).sqrt()
            } else {
                // Free boundaries in H²/S²: mean edge length 0.1.
                let mean = lengths.iter().sum::<f64>() / lengths.len().max(1) as f64;
                0.1 / mean
            }
        }
    }
}

/// The solver part of [`ricci_flow`] for the schemes other than [`Scheme::Conformal`].
struct SolverCase<'a> {
    mesh: &'a Mesh,
    lengths: &'a [f64],
    options: &'a FlowOptions,
    chi: i64,
    has_fixed: bool,
    pinned: &'a [u32],
}

impl SolverCase<'_> {
    /// Newton's method (with the puncture route for spheres) or the gradient flow from the
    /// structure's `u0`: the outcome and the route taken; notes of the setup go to `notes`.
    fn run(
        &self,
        ev: &mut Evaluator,
        target: &mut Target,
        notes: &mut Vec<String>,
        progress: &mut dyn Progress,
    ) -> Result<(newton::SolveOutcome, String)> {
        let SolverCase {
            mesh,
            lengths,
            options,
            chi,
            has_fixed,
            pinned,
        } = *self;
        let geometry = options.geometry;
        let u0 = ev.structure.u0.clone();
        let line_search = if target.is_dynamic() || geometry == Geometry::Spherical {
            newton::LineSearch::Residual
        } else {
            newton::LineSearch::Energy
        };
        let max_it = options.max_iterations.unwrap_or(match options.solver {
            Solver::Newton => 30,
            Solver::Gradient => 200_000,
        });
        let mut route = options.solver.name().to_string();
        if ev.structure.clamped_edges > 0 {
            notes.push(format!(
                "{} of {} edges had their Thurston intersection angle clamped into [0, π/2] \
                 (circles that did not meet were made tangent); the initial metric differs from the \
                 input there (initial length error up to {:.1}%)",
                ev.structure.clamped_edges,
                mesh.n_edges(),
                100.0 * ev.structure.initial_length_error
            ));
        }
        let outcome = match options.solver {
            Solver::Gradient => newton::gradient_flow(
                ev,
                target,
                u0,
                &newton::GradientSettings {
                    tolerance: options.tolerance,
                    max_iterations: max_it,
                    step: options.gradient_step,
                    keep_mean: geometry == Geometry::Euclidean && !has_fixed,
                },
                progress,
            )?,
            Solver::Newton => {
                let settings = newton::NewtonSettings {
                    tolerance: options.tolerance,
                    max_iterations: max_it,
                    line_search,
                    pinned: pinned.to_vec(),
                    indefinite: geometry == Geometry::Spherical,
                };
                let sphere_case = geometry == Geometry::Spherical && chi == 2 && !has_fixed;
                if sphere_case && options.sphere_route == SphereRoute::Puncture {
                    route = "puncture".into();
                    sphere::puncture_route(mesh, lengths, ev, target, &settings, options, progress)?
                } else {
                    let out = newton::newton(ev, target, u0, &settings, progress)?;
                    if sphere_case && !out.converged && options.sphere_route == SphereRoute::Auto {
                        notes.push(format!(
                            "spherical Newton did not converge (max |K − K̄| = {:.3e} after {} \
                             iterations); switched to the puncture route",
                            out.max_error, out.iterations
                        ));
                        notes.extend(out.notes.iter().cloned());
                        route = "puncture".into();
                        sphere::puncture_route(
                            mesh, lengths, ev, target, &settings, options, progress,
                        )?
                    } else {
                        out
                    }
                }
            }
        };
        Ok((outcome, route))
    }
}

/// Run discrete Ricci flow on a connected mesh with Euclidean edge `lengths` (by edge id).
pub fn ricci_flow(
    mesh: &Mesh,
    lengths: &[f64],
    options: &FlowOptions,
    progress: &mut dyn Progress,
) -> Result<FlowResult> {
    let t0 = Instant::now();
    check_flow_input(mesh, lengths, options)?;
    let geometry = options.geometry;
    let chi = euler_characteristic(mesh);
    let mut target = target::resolve(mesh, geometry, &options.target)?;
    // Input scale.
    let euclid_area = crate::metric::total_area(mesh, Geometry::Euclidean, lengths);
    let scale = input_scale(options, chi, &target, lengths, euclid_area);
    if options.scheme == Scheme::Conformal {
        return conformal_flow(
            mesh,
            lengths,
            options,
            target,
            scale,
            euclid_area,
            t0,
            progress,
        );
    }
    let structure = ConformalStructure::new(mesh, lengths, geometry, options.scheme, scale)?;
    let mut ev = Evaluator::new(mesh, structure);
    let u0 = ev.structure.u0.clone();
    if !ev.evaluate(&u0) {
        return Err(Error::numerical(
            "the initial metric lies outside the domain of the scheme",
        ));
    }
    if target.is_dynamic() {
        target::set_round_totals(&mut target, &ev.ws.lengths, &ev.ws.dlengths, &ev.data.edges);
    }
    target::check_gauss_bonnet(mesh, geometry, &target)?;
    let phi = ev
        .structure
        .intersection_angles()
        .unwrap_or_else(|| vec![0.0; mesh.n_edges()]);
    target::check_chow_luo(mesh, geometry, &target, &phi)?;

    let (has_fixed, pinned) = scale_pin(mesh, geometry, &target);
    let case = SolverCase {
        mesh,
        lengths,
        options,
        chi,
        has_fixed,
        pinned: &pinned,
    };
    let mut notes = Vec::new();
    let (outcome, route) = case.run(&mut ev, &mut target, &mut notes, progress)?;
    notes.extend(outcome.notes.iter().cloned());
    let mut u = outcome.u;
    // Final evaluation and normalization.
    if !ev.evaluate(&u) {
        return Err(Error::numerical(
            "the final metric lies outside the domain of the scheme",
        ));
    }
    if geometry == Geometry::Euclidean && !has_fixed && ev.ws.area > 0.0 && euclid_area > 0.0 {
        // Scale to the input area: lengths scale by e^c when every u moves by c.
        let c = 0.5 * (euclid_area / ev.ws.area).ln();
        for x in u.iter_mut() {
            *x += c;
        }
        ev.evaluate(&u);
    }
    if target.is_dynamic() {
        target.update_round(&ev.ws.lengths, &ev.ws.dlengths, &ev.data.edges);
    }
    let max_err = newton::max_error(&ev.ws.curvature, &target);
    let ksum: f64 = ev.ws.curvature.iter().sum();
    let gb = (ksum + geometry.curvature() * ev.ws.area - 2.0 * PI * chi as f64).abs();
    let converged = outcome.converged && max_err <= options.tolerance;
    let mut stop_reason = (!converged).then(|| outcome.stop_reason.clone()).flatten();
    if !converged && (target.is_dynamic() || matches!(options.target, TargetSpec::GeodesicBoundary))
    {
        let ears = (0..mesh.n_vertices() as u32)
            .filter(|&v| mesh.is_boundary_vertex(v) && mesh.vertex_faces(v).count() == 1)
            .count();
        if ears > 0 {
            let why = format!(
                "{ears} boundary vertices have a single face (ears): a round or geodesic \
                 boundary needs their one corner to open to nearly π, which degenerates the \
                 triangle; split the edges opposite the ears first"
            );
            add_reason(&mut stop_reason, &why);
            notes.push(why);
        }
    }
    if outcome.converged && !converged {
        let why = format!("after rescaling, max |K − K̄| = {max_err:.3e} exceeds the tolerance");
        add_reason(&mut stop_reason, &why);
        notes.push(why);
    }
    // A curvature reached with faces that violate the triangle inequality (their angles
    // extended by 0, 0, π) is not a polyhedral metric on this triangulation: not converged.
    let degenerate = ev.ws.degenerate_faces;
    let converged = converged && degenerate == 0;
    if degenerate > 0 {
        notes.push(format!(
            "{degenerate} face(s) violate the triangle inequality in the final metric: no \
             discrete conformal metric with this target on this triangulation (try \
             --refine-degenerate N with --refined-out, or another scheme)"
        ));
    }
    Ok(FlowResult {
        geometry,
        scheme: options.scheme,
        solver: options.solver,
        route,
        target_description: target.description.clone(),
        u,
        curvature: ev.ws.curvature.clone(),
        target: target.curvature.clone(),
        fixed: target.fixed.clone(),
        lengths: ev.ws.lengths.clone(),
        iterations: outcome.iterations,
        history: outcome.history,
        converged,
        tolerance: options.tolerance,
        max_curvature_error: max_err,
        gauss_bonnet_error: gb,
        area: ev.ws.area,
        input_scale: scale,
        clamped_edges: ev.structure.clamped_edges,
        initial_length_error: ev.structure.initial_length_error,
        degenerate_faces: ev.ws.degenerate_faces,
        pinned,
        seconds: t0.elapsed().as_secs_f64(),
        notes,
        stop_reason,
        triangulation: None,
    })
}

/// Append `why` to the reasons a flow stopped short (`"; "`-separated).
fn add_reason(reason: &mut Option<String>, why: &str) {
    *reason = Some(match reason.take() {
        Some(r) => format!("{r}; {why}"),
        None => why.to_string(),
    });
}

/// [`ricci_flow`] for [`Scheme::Conformal`]: isometric flips to the input metric's intrinsic
/// Delaunay triangulation, Newton's method of [`conformal`], E² area normalization, and the
/// simplicial mesh of the final metric.
#[allow(clippy::too_many_arguments)]
fn conformal_flow(
    mesh: &Mesh,
    lengths: &[f64],
    options: &FlowOptions,
    mut target: Target,
    scale: f64,
    euclid_area: f64,
    t0: Instant,
    progress: &mut dyn Progress,
) -> Result<FlowResult> {
    use crate::metric::intrinsic::IntrinsicTriangulation;
    let geometry = options.geometry;
    if options.solver != Solver::Newton {
        return Err(Error::input(
            "the conformal scheme is solved by Newton's method only (use --solver newton)",
        ));
    }
    if geometry == Geometry::Spherical {
        return conformal_sphere_flow(mesh, lengths, options, target, t0, progress);
    }
    let chi = euler_characteristic(mesh);
    let scaled: Vec<f64> = lengths.iter().map(|&l| l * scale).collect();
    let mut tri = IntrinsicTriangulation::from_mesh(mesh, geometry, &scaled)?;
    if target.is_dynamic() {
        target::set_round_totals(&mut target, &scaled, &[], &[]);
    }
    target::check_gauss_bonnet(mesh, geometry, &target)?;
    for v in 0..mesh.n_vertices() as u32 {
        if target.fixed[v as usize] || mesh.is_isolated(v) {
            continue;
        }
        let max = if mesh.is_boundary_vertex(v) {
            PI
        } else {
            2.0 * PI
        };
        if target.curvature[v as usize] >= max {
            return Err(FlowError::NoConeAngle {
                vertex: v,
                curvature: target.curvature[v as usize],
                limit: max,
            }
            .into());
        }
    }
    let flip_budget = 200 * mesh.n_edges() + 10_000;
    let init = tri.make_delaunay_isometric(geometry, flip_budget);
    if !init.delaunay {
        return Err(Error::numerical(format!(
            "the input metric did not become Delaunay within {flip_budget} flips"
        )));
    }
    let (has_fixed, pinned) = scale_pin(mesh, geometry, &target);
    let settings = conformal::ConformalSettings {
        geometry,
        tolerance: options.tolerance,
        max_iterations: options.max_iterations.unwrap_or(if target.is_dynamic() {
            200
        } else {
            50
        }),
        flip_budget,
        pinned: pinned.clone(),
    };
    let out = conformal::solve(&mut tri, &mut target, &settings, progress)?;
    let mut notes = out.notes.clone();
    let mut u = out.u;
    let mut state = out.state;
    if geometry == Geometry::Euclidean && !has_fixed && state.area > 0.0 && euclid_area > 0.0 {
        // Scale to the input area (the Penner Delaunay criterion is scale invariant).
        let c = 0.5 * (euclid_area / state.area).ln();
        for x in u.iter_mut() {
            *x += c;
        }
        if !conformal::evaluate(&mut tri, geometry, &u, flip_budget, &mut state) {
            return Err(Error::numerical("the final metric needed too many flips"));
        }
    }
    if target.is_dynamic() {
        let l = tri.lengths(Geometry::Euclidean, &u);
        target.update_round(&l, &[], &[]);
    }
    let max_err = newton::max_error(&state.curvature, &target);
    let ksum: f64 = state.curvature.iter().sum();
    let gb = (ksum + geometry.curvature() * state.area - 2.0 * PI * chi as f64).abs();
    let degenerate = state.degenerate_faces;
    let converged = out.converged && max_err <= options.tolerance && degenerate == 0;
    let mut stop_reason = (!converged).then(|| out.stop_reason.clone()).flatten();
    if out.converged && max_err > options.tolerance {
        let why = format!("after rescaling, max |K − K̄| = {max_err:.3e} exceeds the tolerance");
        add_reason(&mut stop_reason, &why);
        notes.push(why);
    }
    if degenerate > 0 {
        notes.push(format!(
            "{degenerate} face(s) of the final Delaunay triangulation violate the triangle \
             inequality"
        ));
    }
    let simplicial = tri.to_simplicial(geometry, &u)?;
    // Bake u into the stored coordinates.
    let mut final_tri = tri.clone();
    for e in 0..tri.n_edges() as u32 {
        final_tri.lambda[e as usize] = tri.scaled_lambda(e, &u);
    }
    let result_lengths = simplicial.lengths.clone();
    let triangulation = IntrinsicResult {
        points: Vec::new(),
        initial_flips: init.flips,
        flips: out.flips,
        splits: simplicial.splits,
        simplicial_vertices: simplicial.mesh.n_vertices(),
        triangulation: final_tri,
        simplicial,
    };
    Ok(FlowResult {
        geometry,
        scheme: options.scheme,
        solver: options.solver,
        route: "newton".into(),
        target_description: target.description.clone(),
        u,
        curvature: state.curvature.clone(),
        target: target.curvature.clone(),
        fixed: target.fixed.clone(),
        lengths: result_lengths,
        iterations: out.iterations,
        history: out.history,
        converged,
        tolerance: options.tolerance,
        max_curvature_error: max_err,
        gauss_bonnet_error: gb,
        area: state.area,
        input_scale: scale,
        clamped_edges: 0,
        initial_length_error: 0.0,
        degenerate_faces: degenerate,
        pinned,
        seconds: t0.elapsed().as_secs_f64(),
        notes,
        stop_reason,
        triangulation: Some(triangulation),
    })
}

/// [`ricci_flow`] for [`Scheme::Conformal`] in S²: [`sphere::conformal_sphere`] (the flat
/// picture with one vertex at infinity, stereographic projection, Möbius centring), reported
/// as a spherical metric on the final Delaunay triangulation (the convex hull of the points).
fn conformal_sphere_flow(
    mesh: &Mesh,
    lengths: &[f64],
    options: &FlowOptions,
    target: Target,
    t0: Instant,
    progress: &mut dyn Progress,
) -> Result<FlowResult> {
    let geometry = Geometry::Spherical;
    let uniform = target
        .fixed
        .iter()
        .zip(&target.curvature)
        .enumerate()
        .all(|(v, (&f, &k))| mesh.is_isolated(v as u32) || (!f && k.abs() <= 1e-14));
    if !uniform {
        return Err(Error::input(
            "the conformal scheme reaches the sphere with the uniform target only (every \
             vertex flat on the round sphere); use --scheme yamabe for other spherical targets",
        ));
    }
    let s = sphere::conformal_sphere(
        mesh,
        lengths,
        // The flat solve a decade below the asked tolerance: the projection carries its
        // residual to the sphere with a little rounding.
        (0.1 * options.tolerance).clamp(1e-13, 1e-11),
        options.max_iterations.unwrap_or(50),
        progress,
    )?;
    let mut tri = s.triangulation.clone();
    let flip_budget = 200 * mesh.n_edges() + 10_000;
    let mut state = conformal::ConformalState::default();
    if !conformal::evaluate(&mut tri, geometry, &[], flip_budget, &mut state) {
        return Err(Error::numerical(
            "the final spherical metric needed too many flips",
        ));
    }
    let mut notes = s.notes.clone();
    notes.insert(
        0,
        format!(
            "sphere through a puncture: vertex {} at infinity, {} round(s) of the flat disk \
             ({} Newton steps, max |K| = {:.1e}, link of {} vertices, largest boundary angle − π \
             = {:.1e}), stereographic projection, Möbius centring of the vertex areas; the \
             points' chords match the metric to max |Δλ| = {:.1e}",
            s.puncture,
            s.rounds,
            s.iterations,
            s.flat_error,
            s.link_vertices,
            s.convexity_excess,
            s.conformal_residual
        ),
    );
    if state.flips > 0 {
        notes.push(format!(
            "{} cocircular flip(s) on the sphere after the projection",
            state.flips
        ));
    }
    let max_err = newton::max_error(&state.curvature, &target);
    let ksum: f64 = state.curvature.iter().sum();
    let gb = (ksum + state.area - 4.0 * PI).abs();
    let degenerate = state.degenerate_faces;
    if degenerate > 0 {
        notes.push(format!(
            "{degenerate} face(s) of the final triangulation violate the triangle inequality"
        ));
    }
    if s.inverted_faces > 0 {
        notes.push(format!(
            "{} face(s) are not positively oriented in the point positions (chords near \
             double-precision resolution; the metric is exact)",
            s.inverted_faces
        ));
    }
    let converged = max_err <= options.tolerance && degenerate == 0;
    let simplicial = tri.to_simplicial(geometry, &[])?;
    let triangulation = IntrinsicResult {
        points: s.positions.clone(),
        initial_flips: s.initial_flips,
        flips: s.flips + state.flips,
        splits: simplicial.splits,
        simplicial_vertices: simplicial.mesh.n_vertices(),
        triangulation: tri,
        simplicial,
    };
    let result_lengths = triangulation.simplicial.lengths.clone();
    Ok(FlowResult {
        geometry,
        scheme: options.scheme,
        solver: options.solver,
        route: "puncture".into(),
        target_description: target.description.clone(),
        u: s.u,
        curvature: state.curvature.clone(),
        target: target.curvature.clone(),
        fixed: target.fixed.clone(),
        lengths: result_lengths,
        iterations: s.iterations,
        history: s.history,
        converged,
        tolerance: options.tolerance,
        max_curvature_error: max_err,
        gauss_bonnet_error: gb,
        area: state.area,
        input_scale: 1.0,
        clamped_edges: 0,
        initial_length_error: 0.0,
        degenerate_faces: degenerate,
        pinned: Vec::new(),
        seconds: t0.elapsed().as_secs_f64(),
        notes,
        stop_reason: None,
        triangulation: Some(triangulation),
    })
}
