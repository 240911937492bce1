//! `ricci flow MESH --geometry … --scheme … --target … --solver … --tolerance T
//! [--max-iterations N] [--widen-boundary N] [--refine-degenerate N --refined-out MESH]
//! [--out METRIC.json] [--json]`: discrete Ricci flow (`ricci::flow`), optionally on a
//! metric-preserving refinement of the input (`ricci::metric::refine`, `ricci::flow::adaptive`).
//!
//! METRIC.json holds the final discrete metric: geometry, scheme, per-vertex `u`, `curvature`
//! and `target_curvature` (null where the vertex was held fixed), and per-edge `lengths` with
//! `edge_vertices` (edge `i` joins `edge_vertices[i]`), so other tools can match edges.

use crate::util::read_surface;
use crate::util::{print_json, write_json_atomic};
use indicatif::{ProgressBar, ProgressStyle};
use ricci::flow::{
    ricci_flow, FlowError, FlowOptions, FlowResult, Solver, SphereRoute, TargetSpec,
};
use ricci::metric::{Geometry, Scheme};
use serde_json::json;
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Route {
    Auto,
    Newton,
    Puncture,
}

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (OBJ, OFF, PLY, STL); one connected component.
    pub mesh: PathBuf,
    /// Background geometry: euclidean, hyperbolic or spherical (default: the one the
    /// surface's topology uniformizes to — spherical for closed genus 0, euclidean for genus 1
    /// and for disks, hyperbolic otherwise; euclidean for cone, free-boundary and
    /// round-boundary targets, hyperbolic for geodesic-boundary).
    #[arg(long)]
    pub geometry: Option<Geometry>,
    /// Discrete conformal scheme: conformal (vertex scaling with intrinsic Delaunay flips —
    /// the conformal class of the mesh itself; default in E² and H²), thurston (the papers'
    /// circle packing; default on the sphere and with --solver gradient), tangential,
    /// inversive or yamabe (plain vertex scaling on the input's triangulation).
    #[arg(long)]
    pub scheme: Option<Scheme>,
    /// Target curvature: uniform, cone:V=K,..., single-cone:V, free-boundary, round-boundary,
    /// geodesic-boundary or file:PATH (K in radians; -2pi, pi/2 accepted). Default: uniform
    /// for closed surfaces, free-boundary in E² and geodesic-boundary in H² for bordered ones.
    #[arg(long)]
    pub target: Option<TargetSpec>,
    /// Optimizer: newton or gradient (the papers' flow u += ε(K̄ − K)).
    #[arg(long, default_value = "newton")]
    pub solver: Solver,
    /// Stop when max |K − K̄| is at most this.
    #[arg(long, default_value_t = 1e-10, allow_hyphen_values = true)]
    pub tolerance: f64,
    /// Iteration limit (default 30 for Newton, 200000 for the gradient flow).
    #[arg(long)]
    pub max_iterations: Option<usize>,
    /// Step ε of the gradient flow.
    #[arg(long, default_value_t = 0.05)]
    pub step: f64,
    /// Factor applied to the input lengths in H² and S² (default: match the target's area).
    #[arg(long)]
    pub input_scale: Option<f64>,
    /// Genus-0 surfaces to the sphere: spherical Newton, the puncture route, or Newton then
    /// the puncture route if Newton fails.
    #[arg(long, value_enum, default_value = "auto")]
    pub sphere_route: Route,
    /// Before the flow, give every boundary vertex at least N faces by metric-preserving
    /// splits of the edges opposite it (N = 2 removes boundary "ears", which round and
    /// geodesic boundaries cannot reach; N = 3 also helps Thurston packing at boundary
    /// vertices with two faces). Needs --refined-out: the metric is on the refined mesh.
    #[arg(long, value_name = "N", requires = "refined_out")]
    pub widen_boundary: Option<usize>,
    /// Adaptive refinement, up to N rounds: after a flow, bisect (longest-edge bisection, in
    /// the input metric) every face whose final metric violates a triangle inequality or has
    /// an angle near 0 or π, and flow again (while a circle packing is refused by Chow–Luo,
    /// a vertex-scaling flow finds the faces) — for targets the triangulation cannot reach
    /// as it is (e.g. a zig-zag boundary made round: face.off needs 13 rounds after
    /// --widen-boundary 3). Needs --refined-out: the metric is on the refined mesh.
    #[arg(long, value_name = "N", requires = "refined_out")]
    pub refine_degenerate: Option<usize>,
    /// Where to write the refined mesh of --widen-boundary / --refine-degenerate (input
    /// vertices keep their ids and positions, new vertices are appended).
    #[arg(long, value_name = "MESH")]
    pub refined_out: Option<PathBuf>,
    /// Write the final metric (per-vertex u, K, K̄; per-edge lengths) to this JSON file.
    #[arg(long, short = 'o')]
    pub out: Option<PathBuf>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// METRIC.json of a flow result (also written by `ricci demo`): see
/// `ricci::flow::FlowResult::metric_json` and `ricci::metric::file`.
pub fn metric_json(r: &FlowResult, mesh: &ricci::mesh::Mesh, source: &str) -> serde_json::Value {
    r.metric_json(mesh, source)
}

pub fn run(a: Args) -> anyhow::Result<()> {
    if !(a.tolerance.is_finite() && a.tolerance > 0.0) {
        return Err(crate::util::UsageError(format!(
            "--tolerance {} must be a positive number (the largest |K − K̄| accepted, e.g. 1e-10)",
            a.tolerance
        ))
        .into());
    }
    let (surface, _report) = read_surface(&a.mesh)?;
    let options = flow_options(&a, &surface)?;
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{elapsed:>4} [{bar:30}] {prefix}: {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let mut progress = |stage: &str, fraction: Option<f64>, message: &str| {
        bar.set_prefix(stage.to_string());
        if let Some(f) = fraction {
            bar.set_position((f.clamp(0.0, 1.0) * 1000.0) as u64);
        }
        bar.set_message(message.to_string());
    };
    let (surface, refinement, result) = refine_and_flow(&a, surface, &options, &mut progress)?;
    bar.finish_and_clear();
    let r = result.map_err(|e| anyhow::anyhow!("{}: {e}", a.mesh.display()))?;
    let source = a.mesh.display().to_string();
    if let Some(path) = &a.refined_out {
        ricci::mesh::io::write_surface(path, &surface)?;
    }
    if let Some(out) = &a.out {
        write_json_atomic(out, metric_json(&r, &surface.mesh, &source))?;
    }
    if !r.converged {
        eprintln!("warning: {source}: {}", FlowError::not_converged(&r));
    }
    if a.json {
        print_json(&report_json(&a, &r, &surface, &source, refinement));
    } else {
        print_report(&a, &r, &source);
    }
    Ok(())
}

/// The flow's options from the arguments: the geometry, target and scheme the surface's
/// topology calls for unless given.
fn flow_options(a: &Args, surface: &ricci::mesh::Surface) -> anyhow::Result<FlowOptions> {
    // Targets that name a flat metric (cones, free or round boundary) or a hyperbolic one.
    let flat = matches!(
        a.target,
        Some(TargetSpec::Cones(_))
            | Some(TargetSpec::SingleCone(_))
            | Some(TargetSpec::FreeBoundary)
            | Some(TargetSpec::RoundBoundary)
    );
    let geometry = match a.geometry {
        Some(g) => g,
        None if flat => Geometry::Euclidean,
        None if matches!(a.target, Some(TargetSpec::GeodesicBoundary)) => Geometry::Hyperbolic,
        None => ricci::flow::uniformize::uniformization_geometry(&surface.mesh)
            .map_err(|e| anyhow::anyhow!("{}: {e}", a.mesh.display()))?,
    };
    let target = match &a.target {
        Some(t) => t.clone(),
        None => ricci::flow::uniformize::topology_target(&surface.mesh, geometry),
    };
    Ok(FlowOptions {
        geometry,
        // The gradient flow is the papers' method (the conformal scheme is solved by Newton
        // only): with `--solver gradient` and no scheme, the papers' Thurston packing.
        scheme: a.scheme.unwrap_or_else(|| match a.solver {
            Solver::Gradient => Scheme::Thurston,
            Solver::Newton => ricci::flow::default_scheme(geometry),
        }),
        target,
        solver: a.solver,
        tolerance: a.tolerance,
        max_iterations: a.max_iterations,
        gradient_step: a.step,
        input_scale: a.input_scale,
        sphere_route: match a.sphere_route {
            Route::Auto => SphereRoute::Auto,
            Route::Newton => SphereRoute::Newton,
            Route::Puncture => SphereRoute::Puncture,
        },
    })
}

/// What [`refine_and_flow`] returns: the surface the metric lives on, the refinement report
/// and the flow's result.
type Flowed = (
    ricci::mesh::Surface,
    serde_json::Value,
    ricci::Result<FlowResult>,
);

/// The flow, after `--widen-boundary` and with `--refine-degenerate` when asked: the surface
/// the metric lives on, the refinement report (`null` without refinement) and the flow's
/// result. An error of the widening is returned at once, one of the flow in the result.
fn refine_and_flow(
    a: &Args,
    surface: ricci::mesh::Surface,
    options: &FlowOptions,
    progress: &mut dyn ricci::progress::Progress,
) -> anyhow::Result<Flowed> {
    let mut lengths = surface.edge_lengths();
    let mut surface = surface;
    let mut refinement = serde_json::Value::Null;
    let mut widen_splits = 0;
    if let Some(n) = a.widen_boundary {
        let r = ricci::metric::refine::widen_boundary(
            &surface.mesh,
            &lengths,
            Geometry::Euclidean, // the input lengths are Euclidean
            Some(&surface.positions),
            n,
        )
        .map_err(|e| anyhow::anyhow!("{}: {e}", a.mesh.display()))?;
        widen_splits = r.splits();
        refinement = json!({
            "min_faces": n,
            "splits": r.splits(),
            "vertices": r.mesh.n_vertices(),
            "faces": r.mesh.n_faces(),
            "refined_out": a.refined_out.as_ref().map(|p| p.display().to_string()),
        });
        lengths = r.lengths;
        surface = ricci::mesh::Surface {
            mesh: r.mesh,
            positions: r.positions.unwrap_or_default(),
            uvs: None,
        };
    }
    let result = if let Some(rounds) = a.refine_degenerate {
        let start = ricci::metric::refine::Refined::identity(
            &surface.mesh,
            &lengths,
            Some(&surface.positions),
        );
        ricci::flow::ricci_flow_refined(start, options, rounds, progress).map(|(rf, r)| {
            refinement = json!({
                "min_faces": a.widen_boundary,
                "refine_degenerate": rounds,
                "splits": widen_splits + rf.splits(),
                "vertices": rf.mesh.n_vertices(),
                "faces": rf.mesh.n_faces(),
                "refined_out": a.refined_out.as_ref().map(|p| p.display().to_string()),
            });
            surface = ricci::mesh::Surface {
                mesh: rf.mesh,
                positions: rf.positions.unwrap_or_default(),
                uvs: None,
            };
            r
        })
    } else {
        ricci_flow(&surface.mesh, &lengths, options, progress)
    };
    Ok((surface, refinement, result))
}

/// The `--json` report.
fn report_json(
    a: &Args,
    r: &FlowResult,
    surface: &ricci::mesh::Surface,
    source: &str,
    refinement: serde_json::Value,
) -> serde_json::Value {
    json!({
        "mesh": source,
        "vertices": surface.mesh.n_vertices(),
        "faces": surface.mesh.n_faces(),
        "geometry": r.geometry,
        "scheme": r.scheme,
        "solver": r.solver,
        "route": r.route,
        "method": format!("{} ({})", r.solver, r.route),
        "target": r.target_description,
        "iterations": r.iterations,
        "max_curvature_error": r.max_curvature_error,
        "gauss_bonnet_error": r.gauss_bonnet_error,
        "converged": r.converged,
        "tolerance": r.tolerance,
        "seconds": r.seconds,
        "area": r.area,
        "input_scale": r.input_scale,
        "clamped_edges": r.clamped_edges,
        "initial_length_error": r.initial_length_error,
        "degenerate_faces": r.degenerate_faces,
        "stop_reason": r.stop_reason,
        "flips": r.triangulation.as_ref().map(|t| t.initial_flips + t.flips),
        "triangulation": r.triangulation.as_ref().map(|t| json!({
            "kind": "intrinsic",
            "initial_flips": t.initial_flips,
            "flips": t.flips,
            "splits": t.splits,
            "vertices": t.simplicial.mesh.n_vertices(),
            "faces": t.simplicial.mesh.n_faces(),
        })),
        "pinned": r.pinned,
        "notes": r.notes,
        "refinement": refinement,
        "history": r.history,
        "out": a.out.as_ref().map(|p| p.display().to_string()),
    })
}

/// The report for people.
fn print_report(a: &Args, r: &FlowResult, source: &str) {
    println!(
        "{source}: {} {} metric ({}), target {}",
        r.geometry, r.scheme, r.route, r.target_description
    );
    println!(
        "  {} after {} {} iteration(s): max |K − K̄| = {:.3e}, Gauss–Bonnet residual {:.3e}, \
         {:.3} s",
        if r.converged {
            "converged"
        } else {
            "NOT converged"
        },
        r.iterations,
        r.solver,
        r.max_curvature_error,
        r.gauss_bonnet_error,
        r.seconds
    );
    for h in &r.history {
        println!(
            "    {:5}  max |K − K̄| {:.3e}  step {:.2e}  {:.3} s",
            h.iteration, h.max_curvature_error, h.step, h.seconds
        );
    }
    if let Some(t) = &r.triangulation {
        println!(
            "  intrinsic Delaunay triangulation: {} + {} flips, {} splits ({} vertices, {} \
             faces)",
            t.initial_flips,
            t.flips,
            t.splits,
            t.simplicial.mesh.n_vertices(),
            t.simplicial.mesh.n_faces()
        );
    }
    for n in &r.notes {
        println!("  note: {n}");
    }
    if let Some(out) = &a.out {
        println!("  metric written to {}", out.display());
    }
}
