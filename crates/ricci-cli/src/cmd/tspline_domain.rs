//! `ricci tspline` on closed surfaces of genus ≥ 2, the default: one cubic spline on the quad
//! mesh of knot intervals over the whole domain manifold (the strips of the cylinders of a
//! holomorphic 1-form glued by translations; `ricci::spline::tspline::{domain_mesh,
//! domain_fit, domain_continuity}`, paper 003 §2–3), fitted by least squares, refined at the
//! zeros (graded towards them, the graded lines ending in T-junctions a cell beyond the zeros'
//! corner blocks: JSON `t_junctions`, `control_points` = the T-mesh's vertices; `spline.json`'s
//! `control` is the net of the full graded mesh they span) while the error there exceeds the tolerance
//! and uniformly while it is exceeded elsewhere. Two fits: the input vertices only, and with
//! points on the input triangles (centroid, edge midpoints) too; the one nearer the triangles
//! between the vertices is kept (JSON `max_deviation_between_vertices_percent`,
//! `rms_deviation_between_vertices_percent`, `between_vertices_data`). Continuity, measured
//! across every cell side (JSON `continuity`): G¹ at the zeros (the extraordinary points; C¹
//! in the translation chart, by linear conditions on the control points around every zero;
//! `normal_angle_at_zeros_degrees`), C² on every other side — reported apart for the sides
//! one knot interval from a zero and the sides farther.
//!
//! Surfaces with boundary loops: the loops are filled by fans for the domain and the fills
//! carry no data (JSON `filled_loops`).
//!
//! Writes `tspline.step`, `tspline.igs` (one Bézier patch per Bézier element — the cells of a
//! strip merged where the spline is one polynomial, JSON `patches` next to `cells` and
//! `bezier_elements`; the strips side by side in the parameter plane), `surface.obj` (per-patch
//! tessellation, `--tessellation` segments per cell side: neighbouring patches' tessellations
//! meet vertex to vertex), `samples.json` (our
//! evaluation from the blending functions), `tmesh-surface.png` and `zebra.png` (the domain
//! mesh on the surface and reflection lines: `tspline_pictures`; not with `--no-pictures`)
//! and `tspline.json`.

use crate::cmd::layout::Bar;
use crate::cmd::tspline::Args;
use crate::cmd::tspline_genus::{
    filled_json, jumps_json, print_report, shared_keys, warn_not_converged, write_files,
};
use crate::cmd::tspline_pictures::{domain_caption, domain_pictures, ZEBRA_CAPTION};
use crate::util::write_atomic;
use ricci::analysis::forms::HolomorphicForms;
use ricci::mesh::Surface;
use ricci::progress::Progress;
use ricci::spline::tspline::bezier_elements::{
    domain_elements, spline_point, strip_cells, DomainElement,
};
use ricci::spline::tspline::domain_continuity::{side_continuity, SideContinuity};
use ricci::spline::tspline::domain_fit::{
    deviation_between_vertices, fit_domain_mesh, fit_domain_mesh_on_triangles, DomainFit,
    DomainFitOptions,
};
use ricci::spline::tspline::genus_domain::GenusDomain;
use ricci::spline::tspline::glue::Gluing;
use ricci::spline::tspline::{BezierPatch, Continuity};
use ricci_render::RenderOptions;
use serde_json::json;
use std::time::Instant;

/// Relative jump below which an order counts as continuous.
const CONTINUOUS: f64 = 1e-8;

fn class(c: &Continuity) -> String {
    match c.class(CONTINUOUS) {
        Some(k) => format!("C{k}"),
        None => "discontinuous".to_string(),
    }
}

/// The JSON `continuity`: per class of sides, the class measured and the jumps per order.
fn continuity_json(s: &SideContinuity, zeros: usize, scale: f64) -> serde_json::Value {
    let group = |c: &Continuity, sides: usize, what: &str| json!({"class": class(c), "sides": sides, "what": what, "jumps": jumps_json(c, 3)});
    let gap = s.all().jumps[0];
    json!({
        "class": format!(
            "{} at the zeros ({} sides with a zero at an end), {} on the {} sides one knot interval from a zero, {} on the other {} sides (at least two knot intervals from every zero); chart-independent to {:.1e} % of the longest side",
            class(&s.at_zeros), s.sides[0], class(&s.one_interval_from_zeros), s.sides[1],
            class(&s.elsewhere), s.sides[2], 100.0 * gap / scale
        ),
        "measured": format!("jumps of every partial derivative of orders 0-3 between the two Bézier patches of every cell side at {SIDE_SAMPLES} points per side, relative to the largest partial of that order; C^k = relative jumps of orders <= k below {CONTINUOUS:e}"),
        "at_zeros": group(&s.at_zeros, s.sides[0], "sides with a zero at an end: G1 — C1 in the translation chart, by linear conditions the fit keeps on the control points around every zero (the first derivatives at the zero span one plane)"),
        "normal_angle_at_zeros_degrees": s.normal_angle_at_zeros,
        "one_interval_from_zeros": group(&s.one_interval_from_zeros, s.sides[1], "sides with an end one knot interval from a zero: C2 by construction (every cell within two intervals of a zero has the same size)"),
        "elsewhere": group(&s.elsewhere, s.sides[2], "all other sides, on the critical trajectories and the former knot lines included: C2 by construction"),
        "chart_independence_percent": 100.0 * gap / scale,
        "extraordinary_points": zeros,
    })
}

const SIDE_SAMPLES: usize = 5;

/// Points per cell side at which the distance to the input triangles is measured.
const BETWEEN_SAMPLES: usize = 4;

/// Samples of our own evaluation (the blending functions of the cell under each sample, not
/// the patches) for the CAD check: two per exported Bézier element.
fn samples_json(fit: &DomainFit, elements: &[DomainElement]) -> serde_json::Value {
    let ids = strip_cells(&fit.mesh);
    let offsets = fit.mesh.export_offsets();
    let mut out = Vec::with_capacity(2 * elements.len());
    for e in elements {
        let p = &e.patch;
        for (a, b) in [(0.31, 0.67), (0.73, 0.22)] {
            let (u, v) = (p.u0 + a * (p.u1 - p.u0), p.v0 + b * (p.v1 - p.v0));
            let x = spline_point(&fit.mesh, &ids, &offsets, e.strip, (u, v), &fit.control);
            out.push(json!([u, v, x[0], x[1], x[2]]));
        }
    }
    let bounds: Vec<[f64; 4]> = elements
        .iter()
        .map(|e| [e.patch.u0, e.patch.u1, e.patch.v0, e.patch.v1])
        .collect();
    json!({"samples": out, "patches": bounds, "samples_per_patch": 2})
}

/// A fitted domain-mesh spline and its report (the JSON of `ricci tspline --json` but `out`).
pub struct DomainSpline {
    pub fit: DomainFit,
    /// The Bézier elements (cells merged where the spline is one polynomial).
    pub elements: Vec<DomainElement>,
    pub patches: Vec<BezierPatch>,
    pub report: serde_json::Value,
    pub max_iterations: usize,
}

/// Fit the domain-mesh spline of `surface` (its data points: `surface.positions`) over
/// `domain` glued by `gluing`, measure its continuity and write the report: the one path of
/// `ricci tspline` on genus ≥ 2 and of the demo's `tspline` stage. `filled` boundary loops
/// were filled for the domain (no data on them).
#[allow(clippy::too_many_arguments)]
pub fn domain_spline(
    a: &Args,
    surface: &Surface,
    h: &HolomorphicForms,
    domain: &GenusDomain,
    gluing: &Gluing,
    filled: usize,
    tolerance: f64,
    t0: Instant,
    progress: &mut dyn Progress,
) -> anyhow::Result<DomainSpline> {
    progress.report("tspline", None, "fitting the spline on the domain mesh");
    let opts = DomainFitOptions {
        tolerance,
        smoothing: a.smoothing.max(1e-4),
        max_iterations: a.max_iterations.max(1),
        max_control_points: a.max_control_points,
        ..DomainFitOptions::default()
    };
    // two fits — the input vertices only, and points on the input triangles too — and the
    // one nearer the triangles between the vertices is kept (the second is not always:
    // docs/notes/wave2-s14-tsz18.md)
    let triangles = surface.mesh.faces();
    let vertices_only = fit_domain_mesh(domain, gluing, &surface.positions, &opts)?;
    let on_triangles =
        fit_domain_mesh_on_triangles(domain, gluing, &surface.positions, triangles, &opts)?;
    let fit_seconds = t0.elapsed().as_secs_f64();
    progress.report(
        "tspline",
        None,
        "distance to the input triangles between the vertices",
    );
    let a_dev = deviation_between_vertices(
        &vertices_only,
        &surface.positions,
        triangles,
        BETWEEN_SAMPLES,
    );
    let b_dev = deviation_between_vertices(
        &on_triangles,
        &surface.positions,
        triangles,
        BETWEEN_SAMPLES,
    );
    let on = on_triangles.converged >= vertices_only.converged && b_dev.0 < a_dev.0;
    let (fit, (between_max, between_rms)) = if on {
        (on_triangles, b_dev)
    } else {
        (vertices_only, a_dev)
    };
    for line in &fit.refinements {
        progress.report("tspline", None, line);
    }
    progress.report("tspline", None, "derivative jumps across every cell side");
    let sides = side_continuity(&fit.mesh, &fit.control, SIDE_SAMPLES);
    let (elements, merge) = domain_elements(&fit.mesh, &fit.control);
    let patches: Vec<BezierPatch> = elements.iter().map(|e| e.patch).collect();
    let mesh = &fit.mesh;
    let continuity = continuity_json(&sides, domain.decomposition.zeros.len(), fit.scale);
    let offsets = mesh.export_offsets();
    let strips: Vec<_> = mesh
        .rects
        .iter()
        .zip(&offsets)
        .map(|(r, off)| {
            json!({"cylinder": r.cylinder, "strip": r.strip, "length": r.length, "height": r.height,
                   "cells_u": r.m, "cells_v": r.n, "u_offset": off})
        })
        .collect();
    let with = if filled > 0 {
        format!(" of the surface with its {filled} boundary loop(s) filled by fans (the fills carry no data)")
    } else {
        String::new()
    };
    let mut report = json!({
        "domain": format!("cylinders of a holomorphic 1-form with integer imaginary periods (genus {}){with}, their strips glued by translations into one quad mesh of knot intervals", h.genus),
        "spline": "domain_mesh",
        "filled_loops": filled_json(filled),
        "strips": strips,
        "cells": mesh.n_cells(),
        "control_points": mesh.n_control_points(),
        "t_junctions": mesh.n_t_junctions(),
        "mesh_vertices": mesh.n_vertices(),
        "patches": patches.len(),
        "blocks": mesh.blocks.len(),
        "block_cells": ricci::spline::tspline::domain_fit::graded_cells(&mesh.blocks),
        "block_levels": mesh.blocks.iter().map(|b| b.level).max().unwrap_or(0),
        "refinements": fit.refinements,
        "bezier_patches": patches.len(),
        "bezier_elements": merge,
        "continuity": continuity,
        "gluing_mismatch": gluing.mismatch,
        "gluing": {
            "interfaces": gluing.interfaces,
            "added_points": gluing.added_points,
            "max_line_slope": gluing.max_slope,
            "sheared_cylinders": gluing.rigid(domain).is_some(),
            "what": "interfaces: intervals of the critical trajectories between zero copies (or whole circles); added_points: points added on them so every cylinder has as many on its top circle as on its bottom (regular vertices of the mesh); lines join them across each cylinder, max_line_slope = largest |u_top - u_bottom| / H; sheared_cylinders: every cylinder's lines parallel and its knot lengths its widths",
        },
        "max_deviation_between_vertices_percent": between_max,
        "rms_deviation_between_vertices_percent": between_rms,
        "between_vertices_data": if on { "points on the input triangles (centroid, edge midpoints) in the least squares too, weight 0.1 per point times area over mean area; kept because nearer the triangles between the vertices than the fit of the vertices only" } else { "the input vertices only (the fit with points on the input triangles too was not nearer the triangles between the vertices)" },
        "between_vertices_measured": format!("the spline at {BETWEEN_SAMPLES}x{BETWEEN_SAMPLES} points of every cell (cell coordinates (i + 1/2)/{BETWEEN_SAMPLES}) to the closest point of the input triangles, in percent of the longest bounding-box side (the tolerance is checked at the input vertices; filled loops have no triangles to be near)"),
    });
    shared_keys(
        &mut report,
        a,
        surface,
        domain,
        &fit.steps,
        fit.converged,
        tolerance,
        fit.scale,
        fit_seconds,
        t0,
    );
    // the result's errors: the returned fit's (the best step's when not converged)
    let (rms, max) = fit.errors_percent();
    report["rms_error_percent"] = json!(rms);
    report["max_error_percent"] = json!(max);
    // shared_keys says 0 (the per-cylinder fit has none)
    report["t_junctions"] = json!(fit.mesh.n_t_junctions());
    Ok(DomainSpline {
        fit,
        elements,
        patches,
        report,
        max_iterations: opts.max_iterations,
    })
}

/// `ricci tspline` on genus ≥ 2 after [`domain_spline`]: the warning when the fit stopped
/// above the tolerance, the pictures and files of `--out`, the report on stdout.
pub fn run_domain(
    a: &Args,
    spline: DomainSpline,
    tolerance: f64,
    t0: Instant,
    mut bar: Bar,
) -> anyhow::Result<()> {
    let DomainSpline {
        fit,
        elements,
        patches,
        report: mut out,
        max_iterations,
    } = spline;
    let (rms, max) = fit.errors_percent();
    if !fit.converged {
        warn_not_converged(a, max, tolerance, max_iterations);
    }
    if let (Some(dir), false) = (&a.out, a.no_pictures) {
        bar.report(
            "tspline",
            None,
            "pictures of the domain mesh and zebra stripes",
        );
        let opts = RenderOptions {
            width: 1200,
            height: 900,
            supersample: 2,
            ..RenderOptions::default()
        };
        let (net, zebra, info) = domain_pictures(&fit, a.tessellation, &opts)?;
        write_atomic(&dir.join("tmesh-surface.png"), &net.to_png()?)?;
        write_atomic(&dir.join("zebra.png"), &zebra.to_png()?)?;
        out["pictures"] = json!({
            "tmesh-surface.png": domain_caption(&info, fit.mesh.n_cells()),
            "zebra.png": ZEBRA_CAPTION,
            "knot_line_stride": info.stride,
            "triangles": info.triangles,
        });
    }
    bar.0.finish_and_clear();
    // the OBJ tessellated cell by cell inside every element: watertight where the cells are
    let offsets = fit.mesh.export_offsets();
    let breaks: Vec<_> = elements
        .iter()
        .map(|e| e.breaks(&fit.mesh, &offsets))
        .collect();
    write_files(
        a,
        &patches,
        Some(&breaks),
        || samples_json(&fit, &elements),
        &mut out,
        t0,
    )?;
    let mesh = &fit.mesh;
    print_report(a, &out, || {
        format!(
            "{}: domain mesh of {} strips, {} control points, {} Bézier patches, error rms {:.3}% max {:.3}% of the longest side, {} iterations; continuity: {}; {:.2} s",
            a.mesh.display(),
            mesh.rects.len(),
            mesh.n_vertices(),
            patches.len(),
            rms,
            max,
            fit.steps.len(),
            out["continuity"]["class"].as_str().unwrap_or(""),
            t0.elapsed().as_secs_f64()
        )
    });
    Ok(())
}
