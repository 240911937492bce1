//! `ricci param`'s fallback route for a disk whose own flow fails or stalls (issue 15: a disk
//! whose boundary faces were split off-centre), as `ricci layout` has had since session 10:
//! the E² free-boundary flow on the double (`ricci::flow::double::flow_on_double`) and the
//! surface's map from it (`ricci::layout::double_half::half_subdivision`: the common
//! subdivision of the input and the double's final triangulation, with its UVs), packed into
//! `[0, 1]²`. Reported as `"route": "double"` with `"route_reason"`.

use super::Args;
use crate::util::{print_json, write_atomic};
use ricci::analysis::distortion::uv_stats;
use ricci::flow::target::resolve;
use ricci::flow::TargetSpec;
use ricci::layout::double_half::half_subdivision;
use ricci::layout::export::obj_with_corner_uv;
use ricci::mesh::{Mesh, Surface};
use ricci::metric::Geometry;
use ricci::param::BoundaryMode;
use serde_json::json;
use std::time::Instant;

/// Whether the route through the double applies: one component, a disk, the free boundary,
/// no cones asked for.
pub fn applies(a: &Args, boundary: BoundaryMode, mesh: &Mesh) -> bool {
    let t = ricci::mesh::topology(mesh);
    let disk = matches!(&t.components[..], [c] if c.genus == 0 && c.boundary_loops == 1);
    disk && boundary == BoundaryMode::Free && a.cones.is_none() && !a.sphere && !a.seamless
}

/// `corner_uv` scaled (aspect kept) and moved into `[margin, 1 − margin]²`.
fn pack(corner_uv: &[[f64; 2]], margin: f64) -> Vec<[f64; 2]> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in corner_uv {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let size = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let s = if size > 0.0 {
        (1.0 - 2.0 * margin) / size
    } else {
        1.0
    };
    corner_uv
        .iter()
        .map(|p| [margin + (p[0] - lo[0]) * s, margin + (p[1] - lo[1]) * s])
        .collect()
}

/// `ricci param` of a disk through the double, after its own flow failed with `reason`: the
/// report (as [`super::run`] writes it, plus `route`, `route_reason` and the double's flow)
/// and `--out` (the common subdivision with its UVs). `--svg`/`--png` are not drawn on this
/// route (said on stderr).
pub fn run_double(
    a: &Args,
    surface: &Surface,
    reason: &str,
    progress: &mut dyn ricci::progress::Progress,
    t0: Instant,
) -> anyhow::Result<()> {
    let name = a.mesh.display().to_string();
    let mut inner = || -> anyhow::Result<serde_json::Value> {
        let g = Geometry::Euclidean;
        let target = resolve(&surface.mesh, g, &TargetSpec::FreeBoundary)?;
        let (flow, metric) =
            crate::cmd::layout::double::converged_double_flow(surface, &target, progress)?;
        let h = half_subdivision(&surface.mesh, &surface.positions, &metric, &flow)?;
        let s = &h.subdivision;
        let uv = pack(&s.corner_uv, a.margin);
        let st = uv_stats(&s.positions, &s.triangles, &uv);
        if let Some(path) = &a.out {
            let comments = vec![
                format!("ricci param of {name} (through the flow on its double)"),
                format!(
                    "the common subdivision of the input and the final triangulation of the \
                     flow on its double ({} points on the input surface, {} triangles, each \
                     inside one input face)",
                    s.positions.len(),
                    s.triangles.len()
                ),
                "vt: conformal UVs in [0,1]^2 per corner".to_string(),
            ];
            let text = obj_with_corner_uv(&s.positions, &s.triangles, &uv, &comments);
            write_atomic(path, text.as_bytes())?;
        }
        if a.svg.is_some() || a.png.is_some() {
            eprintln!("note: {name}: no picture is drawn on the route through the double");
        }
        Ok(json!({
            "file": name, "mode": "plane", "route": "double", "route_reason": reason,
            "vertices": surface.mesh.n_vertices(), "faces": surface.mesh.n_faces(),
            "charts": 1, "uv_faces": "common_subdivision",
            "uv": {
                "on": "common_subdivision", "vertices": s.positions.len(),
                "triangles": s.triangles.len(), "flipped_faces": st.flipped_faces,
                "crossings": s.crossings,
            },
            "metric": {
                "source": "flow on the double", "scheme": "conformal",
                "target": target.description, "iterations": flow.iterations,
                "converged": flow.converged, "max_curvature_error": flow.max_error,
                "flips": flow.flips, "boundary_edges_flipped": flow.boundary_edges_flipped,
                "asymmetry": flow.asymmetry,
            },
            "layout_gap": h.layout_gap,
            "flipped_faces": st.flipped_faces, "qc_mean": st.qc_mean, "qc_p95": st.qc_p95,
            "qc_max": st.qc_max, "log_area_sigma": st.log_area_sigma, "distortion": st,
            "cone_count": 0, "cones": [], "seam_length": 0.0, "seam_edges": 0,
            "seamless": false, "boundary": BoundaryMode::Free,
            "seconds": t0.elapsed().as_secs_f64(),
        }))
    };
    let out = inner().map_err(|e| {
        anyhow::anyhow!(
            "{name}: {reason}; the route through the double failed too: {}",
            crate::util::sentence(&e)
        )
    })?;
    if a.json {
        print_json(&out);
    } else {
        eprintln!("note: {name}: {reason}; mapped through the flow on the double");
        super::report(a, &out)?;
    }
    Ok(())
}
