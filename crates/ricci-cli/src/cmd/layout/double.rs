//! `ricci layout`'s fallback route for a disk whose own flow fails or stalls (issue 15: a disk
//! whose boundary faces were split off-centre; the E² free-boundary flow of the surface stalls
//! on faces that need a flip across the boundary): the flow on the double
//! (`ricci::flow::double::flow_on_double`) and the surface's map from it
//! (`ricci::layout::double_half::half_subdivision`, the common subdivision of the input and the
//! double's final triangulation, with its UVs). Reported as `"route": "double"`.

use super::Args;
use crate::util::write_atomic;
use ricci::flow::double::flow_on_double;
use ricci::flow::target::resolve;
use ricci::flow::TargetPolicy;
use ricci::layout::double_half::half_subdivision;
use ricci::layout::export::obj_with_corner_uv;
use ricci::layout::isometry::Complex;
use ricci::layout::svg::fundamental_domain_svg;
use ricci::mesh::{Mesh, Surface};
use ricci::metric::{Geometry, IntrinsicMetric};
use serde_json::{json, Value};

/// Whether the route through the double applies: one component, a disk, no metric file, E²
/// (or the default geometry, E² for a disk).
pub fn applies(a: &Args, geometry: Option<Geometry>, mesh: &Mesh) -> bool {
    let t = ricci::mesh::topology(mesh);
    let disk = matches!(&t.components[..], [c] if c.genus == 0 && c.boundary_loops == 1);
    disk && a.metric.is_none() && geometry.is_none_or(|g| g == Geometry::Euclidean)
}

/// The layout through the double (module docs): fills `out` like the surface's own route
/// (`flipped_faces`, `uv`, no deck group) plus `route`, `route_reason` and the double's flow;
/// writes `--out` (the common subdivision with its UVs) and `--svg`.
/// The E² flow of `surface` (one disk) on its double to `target` at the layout tolerance, with
/// the input's Euclidean metric; refused with one sentence when it does not converge or ends
/// with degenerate faces. Shared by `ricci layout` and `ricci param` (their route through the
/// double).
pub fn converged_double_flow(
    surface: &Surface,
    target: &ricci::flow::Target,
    progress: &mut dyn ricci::progress::Progress,
) -> anyhow::Result<(ricci::flow::double::DoubleFlow, IntrinsicMetric)> {
    let g = Geometry::Euclidean;
    let tolerance = ricci::flow::uniformize::layout_tolerance(g);
    let metric = IntrinsicMetric::euclidean(surface.edge_lengths());
    let flow = flow_on_double(
        &surface.mesh,
        metric.lengths(),
        g,
        target,
        tolerance,
        progress,
    )?;
    if !flow.converged || flow.degenerate_faces > 0 {
        anyhow::bail!(
            "the flow on the double did not converge either (max |K − K̄| = {:.3e} after {} \
             iterations, {} degenerate faces){}",
            flow.max_error,
            flow.iterations,
            flow.degenerate_faces,
            flow.stop_reason
                .as_deref()
                .map(|r| format!(": {r}"))
                .unwrap_or_default()
        );
    }
    Ok((flow, metric))
}

pub fn layout_through_double(
    a: &Args,
    surface: &Surface,
    reason: &str,
    out: &mut Value,
    progress: &mut dyn ricci::progress::Progress,
) -> anyhow::Result<()> {
    let g = Geometry::Euclidean;
    let policy = match &a.target {
        Some(t) => TargetPolicy::Given(t.parse().map_err(|e: String| anyhow::anyhow!(e))?),
        None => TargetPolicy::Topology,
    };
    let target = resolve(&surface.mesh, g, &policy.resolve(&surface.mesh, g))?;
    let (flow, metric) = converged_double_flow(surface, &target, progress)
        .map_err(|e| anyhow::anyhow!("{e}; no layout computed"))?;
    crate::util::stage_done("flow");
    let h = half_subdivision(&surface.mesh, &surface.positions, &metric, &flow)?;
    crate::util::stage_done("layout");
    let s = &h.subdivision;
    out["route"] = json!("double");
    out["route_reason"] = json!(reason);
    out["metric"] = json!({
        "source": "flow on the double", "scheme": "conformal", "target": target.description,
        "iterations": flow.iterations, "converged": flow.converged,
        "max_curvature_error": flow.max_error, "initial_flips": flow.initial_flips,
        "flips": flow.flips, "boundary_edges_flipped": flow.boundary_edges_flipped,
        "asymmetry": flow.asymmetry,
    });
    out["flipped_faces"] = json!(s.flipped_faces);
    out["degenerate_faces"] = json!(0);
    out["layout_gap"] = json!(h.layout_gap);
    out["deck_generators"] = json!([]);
    out["relation_error"] = Value::Null;
    out["uv"] = json!({
        "on": "common_subdivision", "faces": "common_subdivision",
        "flipped_faces": s.flipped_faces, "vertices": s.n_vertices(),
        "triangles": s.triangles.len(), "crossings": s.crossings,
        "t_flipped_faces": s.t_flipped_faces, "seam_faces": 0,
        "region_faces": h.region_faces, "crossing_faces": h.crossing_faces,
    });
    crate::util::stage_done("deck");
    let what = format!(
        "the common subdivision of the input and the final triangulation of the flow on its \
         double ({} vertices on the input surface, {} faces, {} flipped)",
        s.n_vertices(),
        s.triangles.len(),
        s.flipped_faces
    );
    if let Some(path) = &a.out {
        let comments = vec![
            format!(
                "ricci layout of {} (euclidean, through the double)",
                a.mesh.display()
            ),
            format!("v, f: {what}"),
            "vt: layout coordinates per corner".to_string(),
        ];
        let text = obj_with_corner_uv(&s.positions, &s.triangles, &s.corner_uv, &comments);
        write_atomic(path, text.as_bytes())?;
        eprintln!("wrote {}: euclidean UVs on {what}", path.display());
    }
    if let Some(path) = &a.svg {
        let mesh = Mesh::from_triangles(s.n_vertices(), s.triangles.clone())?;
        let mut z = vec![Complex::new(0.0, 0.0); s.n_vertices()];
        for (t, tr) in s.triangles.iter().enumerate() {
            for (i, &v) in tr.iter().enumerate() {
                let p = s.corner_uv[3 * t + i];
                z[v as usize] = Complex::new(p[0], p[1]);
            }
        }
        let svg = fundamental_domain_svg(&mesh, &z, None, g, 30_000);
        write_atomic(path, svg.as_bytes())?;
    }
    Ok(())
}

/// `ricci layout` of a disk through the double, after its own flow failed with `reason`:
/// the whole report (as [`super::run`] writes it) and the files.
pub fn run_double(
    a: &Args,
    surface: &Surface,
    reason: &str,
    bar: &mut super::Bar,
    t0: std::time::Instant,
) -> anyhow::Result<()> {
    bar.0.set_message("flow on the double");
    let mut out = json!({
        "file": a.mesh.display().to_string(),
        "geometry": Geometry::Euclidean.name(),
        "genus": 0,
        "boundary_loops": 1,
    });
    layout_through_double(a, surface, reason, &mut out, bar).map_err(|e| {
        anyhow::anyhow!(
            "{}: {reason}; the route through the double failed too: {}",
            a.mesh.display(),
            crate::util::sentence(&e)
        )
    })?;
    bar.0.finish_and_clear();
    crate::util::stage_done("output");
    let (cpu, wall) = crate::util::stages_take();
    out["timings"] = cpu;
    out["timings_wall"] = wall;
    out["metric_polish"] = json!({"applied": false, "reason": "not a hyperbolic metric"});
    out["seconds"] = json!(t0.elapsed().as_secs_f64());
    if a.json {
        crate::util::print_json(&out);
    } else {
        eprintln!(
            "note: {}: {reason}; laid out through the flow on the double",
            a.mesh.display()
        );
        super::print_text(a, Geometry::Euclidean, &out);
    }
    Ok(())
}
