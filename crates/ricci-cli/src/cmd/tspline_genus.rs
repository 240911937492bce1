//! `ricci tspline` on surfaces of genus ≥ 2 (boundary loops filled by fans, the fills without
//! data: [`genus_domain_of`]): the domain manifold is the cylinder
//! decomposition of a holomorphic 1-form with integer imaginary periods
//! (`ricci::spline::tspline::{cylinders, genus_domain}`). By default its strips, glued by
//! translations, carry one spline on one quad mesh (`tspline_domain`, C² on every cell side
//! not at a zero); when they cannot be glued, or with `--per-cylinder`, each
//! cylinder carries its own tensor-product cubic spline (`cylinder_fit`: C² inside a cylinder except C⁰ along the knot
//! lines through the zero copies, pulled towards C¹ by a tangent penalty; the glued boundary
//! rows are shared, so C⁰ across the critical trajectories — the JSON `continuity` reports the
//! gaps and normal angles, measured). At the zeros themselves (the extraordinary points):
//! C⁰, G¹ not guaranteed, the corner normals' angle measured (`continuity.at_zeros`).
//!
//! Writes the same files as the genus-1 path except `tmesh.svg` (and, per cylinder, the
//! pictures): `tspline.step`, `tspline.igs`, `surface.obj` (per-patch tessellation),
//! `samples.json` and `tspline.json`.

use crate::cmd::layout::spinner;
use crate::cmd::tspline::Args;
use crate::util::{print_json, write_atomic};
use ricci::analysis::forms::HolomorphicForms;
use ricci::analysis::forms::{holomorphic_forms, FormsOptions};
use ricci::mesh::Surface;
use ricci::metric::IntrinsicMetric;
use ricci::progress::Progress;
use ricci::spline::tspline::cylinder_fit::{fit_cylinders, GenusFit, GenusFitOptions, GenusStep};
use ricci::spline::tspline::cylinder_jumps::{AtZero, GluedSeams, Seam};
use ricci::spline::tspline::genus0::fill_boundary_loops;
use ricci::spline::tspline::genus_domain::{best_genus_domain, GenusDomain};
use ricci::spline::tspline::glue::gluing;
use ricci::spline::tspline::{BezierPatch, Continuity};
use serde_json::json;
use std::time::Instant;

pub(crate) fn jumps_json(c: &Continuity, orders: usize) -> serde_json::Value {
    let rel = c.relative();
    let per_order: Vec<_> = (0..=orders)
        .map(|k| json!({"order": k, "max_jump": c.jumps[k], "max_partial": c.magnitudes[k], "relative_jump": rel[k]}))
        .collect();
    json!({"per_order": per_order, "relative_jumps": &rel[..=orders], "side_points_compared": c.comparisons})
}

/// Samples of our own evaluation (the B-spline, not the patches) for the CAD check.
fn samples_json(fit: &GenusFit, patches: &[BezierPatch]) -> serde_json::Value {
    let mut out = Vec::with_capacity(2 * patches.len());
    let mut k = 0;
    for (c, s) in fit.splines.iter().enumerate() {
        for _ in 0..s.nu * s.nv {
            let p = &patches[k];
            k += 1;
            for (a, b) in [(0.31, 0.67), (0.73, 0.22)] {
                let (u, v) = (p.u0 + a * (p.u1 - p.u0), p.v0 + b * (p.v1 - p.v0));
                let x = s.point(u - fit.offsets[c], v);
                out.push(json!([u, v, x[0], x[1], x[2]]));
            }
        }
    }
    let bounds: Vec<[f64; 4]> = patches.iter().map(|p| [p.u0, p.u1, p.v0, p.v1]).collect();
    json!({"samples": out, "patches": bounds, "samples_per_patch": 2})
}

/// The JSON `continuity` of the genus ≥ 2 fit, the class inside the cylinders and across the
/// critical trajectories, and the gap there in percent of the longest side.
fn continuity_json(
    fit: &GenusFit,
    inside: &Continuity,
    lines: &Seam,
    seams: &GluedSeams,
    zeros: usize,
    glue: f64,
) -> (serde_json::Value, String, &'static str, f64) {
    let class_inside = match inside.class(1e-8) {
        Some(k) => format!("C{k}"),
        None => "discontinuous".to_string(),
    };
    let gap_percent = 100.0 * seams.max_gap() / fit.scale;
    let across_class = match (&fit.gluing, seams.max_gap() <= 1e-9 * fit.scale) {
        (Ok(_), true) => "C0",
        _ => "discontinuous",
    };
    let note = match &fit.gluing {
        Ok(_) => "the top row of control points of every strip is the bottom row of the strip glued to it (shared unknowns): C0 by construction; the normals' angle across is measured (not G1). The zeros lie on these trajectories and on the knot lines. Crossings of mesh edges within near_zero_fraction of the circumference from a zero are reported apart (near_zeros): an edge passing by the cone point can be developed to the wrong side of the zero, so its two sides are not the same point of our surface".to_string(),
        Err(why) => format!("separate splines per cylinder pulled together by a least-squares penalty at the crossings (not C0), because {why}"),
    };
    let v = json!({
        "class": format!("{class_inside} inside each cylinder away from the knot lines through the zeros (C0 there, normals up to {:.2}° apart); {across_class} across the critical trajectories (gap {gap_percent:.2e} % of the longest side, normals up to {:.2}° apart)", lines.max_angle_degrees, seams.max_angle_degrees()),
        "inside_cylinders": {"class": class_inside, "jumps": jumps_json(inside, 3)},
        "knot_lines": {"class": if fit.gluing.is_ok() && lines.max_gap <= 1e-9 * fit.scale { "C0" } else { "none or discontinuous" },
                       "max_gap_percent": 100.0 * lines.max_gap / fit.scale, "max_normal_angle_degrees": lines.max_angle_degrees,
                       "side_points_compared": lines.comparisons},
        "across_critical_trajectories": {
            "class": across_class,
            "max_gap_percent": gap_percent,
            "max_normal_angle_degrees": seams.max_angle_degrees(),
            "crossings": seams.crossings,
            "midpoints": seams.midpoints,
            "strips": seams.strips,
            "near_zeros": seams.near_zeros,
            "near_zero_fraction": ricci::spline::tspline::cylinder_jumps::NEAR_ZERO,
            "outlier_crossings": fit.gluing.as_ref().map(|g| g.outliers).ok(),
            "glues": fit.gluing.as_ref().map(|g| g.glues.len()).unwrap_or(0),
            "gluing_mismatch": fit.gluing.as_ref().map(|g| g.mismatch).ok(),
            "glue_weight": if fit.gluing.is_ok() { 0.0 } else { glue },
            "jumps": {"side_points_compared": seams.crossings.comparisons + seams.midpoints.comparisons + seams.strips.comparisons + seams.near_zeros.comparisons},
            "note": note
        },
        "extraordinary_points": zeros,
    });
    (v, class_inside, across_class, gap_percent)
}

/// The JSON `continuity.at_zeros`: what the spline guarantees at an extraordinary point (C⁰:
/// the patches around every copy of the zero meet in one point) and what it does not (G¹: the
/// angle between their normals there, measured; it shrinks under refinement, README).
fn zeros_json(at: &[AtZero], scale: f64) -> serde_json::Value {
    let gap = at.iter().map(|z| z.max_gap).fold(0.0, f64::max);
    let angle = at
        .iter()
        .map(|z| z.max_normal_angle_degrees)
        .fold(0.0, f64::max);
    let c0 = !at.is_empty() && gap <= 1e-9 * scale;
    json!({
        "class": if c0 { "C0 (G1 not guaranteed: normals measured)" } else { "not measured or discontinuous" },
        "max_gap_percent": 100.0 * gap / scale,
        "max_normal_angle_degrees": angle,
        "zeros": at,
        "note": "paper 003: the manifold T-spline is well defined except at the extraordinary points; every copy of a zero is the corner of the two strips on either side of its knot line, on the cylinder above or below it; all these corner patches are evaluated at the zero: their points agree (C0) and their normals differ by the angle given",
    })
}

/// The warning when a genus ≥ 2 fit stops above the tolerance (L∞ `max` in percent).
pub(crate) fn warn_not_converged(a: &Args, max: f64, tolerance: f64, max_iterations: usize) {
    eprintln!(
        "warning: {}: the fit stopped at L∞ {:.3} % above the tolerance {:.3} % (budget: {} iterations, {} control points)",
        a.mesh.display(),
        max,
        100.0 * tolerance,
        max_iterations,
        a.max_control_points
    );
}

/// With `--out`: the STEP, IGES, OBJ (per-patch tessellation; `breaks`: see
/// `write_patch_files`), samples and report files of a genus ≥ 2 fit; the report gets `out`
/// and the final `seconds`.
pub(crate) fn write_files(
    a: &Args,
    patches: &[BezierPatch],
    breaks: Option<&[(Vec<f64>, Vec<f64>)]>,
    samples: impl FnOnce() -> serde_json::Value,
    out: &mut serde_json::Value,
    t0: Instant,
) -> anyhow::Result<()> {
    let Some(dir) = &a.out else {
        return Ok(());
    };
    crate::cmd::tspline::write_patch_files(dir, a, patches, breaks)?;
    write_atomic(
        &dir.join("samples.json"),
        serde_json::to_string(&samples())?.as_bytes(),
    )?;
    out["out"] = json!(dir.display().to_string());
    out["seconds"] = json!(t0.elapsed().as_secs_f64());
    write_atomic(
        &dir.join("tspline.json"),
        serde_json::to_string_pretty(out)?.as_bytes(),
    )?;
    Ok(())
}

/// The report keys both genus ≥ 2 fits share: the input, the form and its zeros, the errors of
/// the last step, the budget's outcome, the data and the times.
#[allow(clippy::too_many_arguments)]
pub(crate) fn shared_keys(
    out: &mut serde_json::Value,
    a: &Args,
    surface: &Surface,
    domain: &GenusDomain,
    steps: &[GenusStep],
    converged: bool,
    tolerance: f64,
    scale: f64,
    fit_seconds: f64,
    t0: Instant,
) {
    let (rms, max) = steps.last().map_or((f64::NAN, f64::NAN), |s| {
        (s.rms_error_percent, s.max_error_percent)
    });
    let dec = &domain.decomposition;
    for (k, v) in [
        ("file", json!(a.mesh.display().to_string())),
        (
            "form",
            json!({"imaginary_part": "sum of n_k times the harmonic form dual to loop k", "n": domain.combination, "saddle_levels": domain.levels}),
        ),
        ("zeros", json!(dec.zeros)),
        ("critical_levels", json!(dec.levels)),
        ("t_junctions", json!(0)),
        ("rms_error_percent", json!(rms)),
        ("max_error_percent", json!(max)),
        ("tolerance_percent", json!(100.0 * tolerance)),
        ("converged", json!(converged)),
        ("iterations", json!(steps.len())),
        ("steps", json!(steps)),
        ("data_points", json!(surface.positions.len())),
        ("unassigned_points", json!(domain.unassigned.len())),
        ("holonomy_defect", json!(domain.holonomy_defect)),
        ("scale", json!(scale)),
        ("seconds_fit", json!(fit_seconds)),
        ("seconds", json!(t0.elapsed().as_secs_f64())),
    ] {
        out[k] = v;
    }
}

/// The report on stdout: the JSON object with `--json`, else the one line `text`.
pub(crate) fn print_report(a: &Args, out: &serde_json::Value, text: impl FnOnce() -> String) {
    if a.json {
        print_json(out);
    } else {
        println!("{}", text());
    }
}

/// The domain of a connected surface of genus ≥ 2: its boundary loops, if any, filled by fans
/// (`fill_boundary_loops`; the fills' centres carry no data: only the first
/// `surface.positions.len()` vertices are data points), the holomorphic 1-forms of the closed
/// surface and the cylinders of the best form. The one path of `ricci tspline` and of the
/// demo's `tspline` stage.
pub(crate) fn genus_domain_of(
    surface: &Surface,
    progress: &mut dyn Progress,
) -> anyhow::Result<(HolomorphicForms, GenusDomain, usize)> {
    let filled = if surface.mesh.boundary_loops().is_empty() {
        None
    } else {
        Some(fill_boundary_loops(surface)?)
    };
    let (closed, loops) = filled.as_ref().map_or((surface, 0), |(s, n)| (s, *n));
    progress.report("tspline", None, "holomorphic 1-forms");
    let h = holomorphic_forms(
        &closed.mesh,
        &IntrinsicMetric::euclidean(closed.edge_lengths()),
        Some(&closed.positions),
        &FormsOptions::default(),
        progress,
    )?;
    progress.report("tspline", None, "cylinders of the critical trajectories");
    let domain = best_genus_domain(&h, surface.positions.len())?;
    Ok((h, domain, loops))
}

/// The JSON `filled_loops` of a genus ≥ 2 report: how many boundary loops were filled by fans
/// and that the fills carry no data.
pub(crate) fn filled_json(loops: usize) -> serde_json::Value {
    json!({"loops": loops, "note": if loops == 0 { "closed surface: nothing filled" } else { "each boundary loop filled by a fan around its centroid for the domain (a closed surface of the same genus); the fills carry no data: the spline over them is not fitted to anything, only faired, and is not part of the input surface" }})
}

pub fn run_genus(a: &Args, surface: &Surface, tolerance: f64, t0: Instant) -> anyhow::Result<()> {
    let mut bar = spinner(a.json);
    let (h, domain, loops) = genus_domain_of(surface, &mut bar)?;
    let mut refused = None;
    if !a.per_cylinder {
        match gluing(&domain) {
            Ok(g) => {
                let spline = crate::cmd::tspline_domain::domain_spline(
                    a, surface, &h, &domain, &g, loops, tolerance, t0, &mut bar,
                )?;
                return crate::cmd::tspline_domain::run_domain(a, spline, tolerance, t0, bar);
            }
            Err(why) => {
                eprintln!(
                    "warning: {}: the cylinders' strips do not glue into one domain mesh ({why}); fitting one spline per cylinder instead (as --per-cylinder)",
                    a.mesh.display()
                );
                refused = Some(why);
            }
        }
    }
    let opts = GenusFitOptions {
        tolerance,
        smoothing: a.smoothing.max(1e-4),
        max_iterations: a.max_iterations.max(1),
        max_control_points: a.max_control_points,
        ..GenusFitOptions::default()
    };
    bar.0.set_message("fitting the cylinders");
    let fit = fit_cylinders(&domain, &surface.positions, &opts)?;
    let fit_seconds = t0.elapsed().as_secs_f64();
    let patches = fit.patches();
    let (inside, lines) = fit.interior_jumps(&patches, 3);
    let seams = fit.glued_seams(&patches, &domain, 3);
    let at_zeros = fit.at_zeros(&patches, &domain);
    bar.0.finish_and_clear();
    let (mut continuity, class_inside, across_class, gap_percent) = continuity_json(
        &fit,
        &inside,
        &lines,
        &seams,
        domain.decomposition.zeros.len(),
        opts.glue,
    );
    continuity["at_zeros"] = zeros_json(&at_zeros, fit.scale);
    let last = fit.steps.last().cloned();
    let (rms, max) = last.as_ref().map_or((f64::NAN, f64::NAN), |s| {
        (s.rms_error_percent, s.max_error_percent)
    });
    let cylinders: Vec<_> = domain
        .cylinders
        .iter()
        .zip(&fit.splines)
        .zip(&fit.offsets)
        .map(|((c, s), off)| {
            json!({"band": c.band, "bottom": c.bottom, "height": c.height, "circumference": c.circumference,
                   "data_points": c.data_points, "spans_u": s.nu, "spans_v": s.nv,
                   "knot_lines": s.lines, "spans_per_strip": s.spans, "shift": s.shift, "shear": s.shear,
                   "control_slots": s.control.len(), "u_offset": off})
        })
        .collect();
    let mut out = json!({
        "domain": format!("cylinders of a holomorphic 1-form with integer imaginary periods (genus {})", h.genus),
        "spline": "per_cylinder",
        "domain_mesh_refused": refused,
        "filled_loops": filled_json(loops),
        "cylinders": cylinders,
        "control_points": fit.control_points(),
        "bezier_patches": patches.len(),
        "continuity": continuity,
    });
    shared_keys(
        &mut out,
        a,
        surface,
        &domain,
        &fit.steps,
        fit.converged,
        tolerance,
        fit.scale,
        fit_seconds,
        t0,
    );
    if !fit.converged {
        warn_not_converged(a, max, tolerance, opts.max_iterations);
    }
    write_files(
        a,
        &patches,
        None,
        || samples_json(&fit, &patches),
        &mut out,
        t0,
    )?;
    print_report(a, &out, || {
        format!(
            "{}: {} cylinders, {} control points, {} Bézier patches, error rms {:.3}% max {:.3}% of the longest side, {} iterations, {} inside cylinders (C0 on the knot lines), {} across the critical trajectories (gap {:.2e}%, normals up to {:.2}°), {:.2} s",
            a.mesh.display(),
            fit.splines.len(),
            fit.control_points(),
            patches.len(),
            rms,
            max,
            fit.steps.len(),
            class_inside,
            across_class,
            gap_percent,
            seams.max_angle_degrees(),
            t0.elapsed().as_secs_f64()
        )
    });
    Ok(())
}
