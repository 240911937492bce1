//! `ricci tspline` on closed surfaces of genus ≥ 2: the domain manifold is the cylinder
//! decomposition of a holomorphic 1-form with integer imaginary periods
//! (`ricci::spline::tspline::{cylinders, genus_domain}`), and each cylinder carries its own
//! tensor-product cubic spline (`cylinder_fit`: C² inside a cylinder, not joined across the
//! critical trajectories — the JSON `continuity` reports the jumps there, measured).
//!
//! Writes the same files as the genus-1 path except the pictures and `tmesh.svg`:
//! `tspline.step`, `tspline.igs`, `surface.obj` (per-patch tessellation), `samples.json` and
//! `tspline.json`.

use crate::cmd::layout::spinner;
use crate::cmd::tspline::Args;
use crate::util::{print_json, write_atomic};
use ricci::analysis::forms::{holomorphic_forms, FormsOptions};
use ricci::mesh::Surface;
use ricci::spline::tspline::cylinder_fit::{fit_cylinders, GenusFit, GenusFitOptions};
use ricci::spline::tspline::export::{iges, obj, step};
use ricci::spline::tspline::genus_domain::best_genus_domain;
use ricci::spline::tspline::{BezierPatch, Continuity};
use serde_json::json;
use std::time::Instant;

fn jumps_json(c: &Continuity, orders: usize) -> serde_json::Value {
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
                let x = fit.point(c, u - fit.offsets[c], v);
                out.push(json!([u, v, x[0], x[1], x[2]]));
            }
        }
    }
    let bounds: Vec<[f64; 4]> = patches.iter().map(|p| [p.u0, p.u1, p.v0, p.v1]).collect();
    json!({"samples": out, "patches": bounds, "samples_per_patch": 2})
}

pub fn run_genus(a: &Args, surface: &Surface, tolerance: f64, t0: Instant) -> anyhow::Result<()> {
    let mut bar = spinner(a.json);
    bar.0.set_message("holomorphic 1-forms");
    let h = holomorphic_forms(
        &surface.mesh,
        &surface.edge_lengths(),
        Some(&surface.positions),
        &FormsOptions::default(),
        &mut bar,
    )?;
    bar.0.set_message("cylinders of the critical trajectories");
    let domain = best_genus_domain(&h, surface.positions.len())?;
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
    let inside = fit.interior_jumps(&patches, 3);
    let (glued, midpoints) = fit.glued_jumps(&patches, &domain);
    bar.0.finish_and_clear();
    let class_inside = match inside.class(1e-8) {
        Some(k) => format!("C{k}"),
        None => "discontinuous".to_string(),
    };
    let last = fit.steps.last().cloned();
    let (rms, max) = last.as_ref().map_or((f64::NAN, f64::NAN), |s| {
        (s.rms_error_percent, s.max_error_percent)
    });
    let gap_percent = 100.0 * glued.jumps[0] / fit.scale;
    let dec = &domain.decomposition;
    let cylinders: Vec<_> = domain
        .cylinders
        .iter()
        .zip(&fit.splines)
        .zip(&fit.offsets)
        .map(|((c, s), off)| {
            json!({"band": c.band, "bottom": c.bottom, "height": c.height, "circumference": c.circumference,
                   "data_points": c.data_points, "spans_u": s.nu, "spans_v": s.nv,
                   "control_points": s.control.len(), "u_offset": off})
        })
        .collect();
    let mut out = json!({
        "file": a.mesh.display().to_string(),
        "domain": format!("cylinders of a holomorphic 1-form with integer imaginary periods (genus {})", h.genus),
        "form": {"imaginary_part": "sum of n_k times the harmonic form dual to loop k", "n": domain.combination, "saddle_levels": domain.levels},
        "zeros": dec.zeros,
        "critical_levels": dec.levels,
        "cylinders": cylinders,
        "control_points": fit.control_points(),
        "t_junctions": 0,
        "bezier_patches": patches.len(),
        "rms_error_percent": rms,
        "max_error_percent": max,
        "tolerance_percent": 100.0 * tolerance,
        "converged": fit.converged,
        "iterations": fit.steps.len(),
        "steps": fit.steps,
        "continuity": {
            "class": format!("{class_inside} inside each cylinder; not joined across the critical trajectories (jump up to {gap_percent:.3} % of the longest side)"),
            "inside_cylinders": {"class": class_inside, "jumps": jumps_json(&inside, 3)},
            "across_critical_trajectories": {
                "class": "discontinuous",
                "max_gap_percent": gap_percent,
                "crossings": domain.crossings.len(),
                "midpoints": midpoints,
                "glue_weight": opts.glue,
                "jumps": jumps_json(&glued, 2),
                "note": "separate splines per cylinder, pulled together by a least-squares penalty at the crossings (not C0); the zeros lie on these trajectories, so the same jumps hold at the extraordinary points"
            },
            "extraordinary_points": dec.zeros.len(),
        },
        "data_points": surface.positions.len(),
        "unassigned_points": domain.unassigned.len(),
        "holonomy_defect": domain.holonomy_defect,
        "scale": fit.scale,
        "seconds_fit": fit_seconds,
        "seconds": t0.elapsed().as_secs_f64(),
    });
    if !fit.converged {
        eprintln!(
            "warning: {}: the fit stopped at L∞ {:.3} % above the tolerance {:.3} % (budget: {} iterations, {} control points)",
            a.mesh.display(),
            max,
            100.0 * tolerance,
            opts.max_iterations,
            opts.max_control_points
        );
    }
    if let Some(dir) = &a.out {
        write_atomic(
            &dir.join("tspline.step"),
            step(&patches, "tspline").as_bytes(),
        )?;
        write_atomic(
            &dir.join("tspline.igs"),
            iges(&patches, "tspline").as_bytes(),
        )?;
        write_atomic(
            &dir.join("surface.obj"),
            obj(&patches, a.tessellation).as_bytes(),
        )?;
        write_atomic(
            &dir.join("samples.json"),
            serde_json::to_string(&samples_json(&fit, &patches))?.as_bytes(),
        )?;
        out["out"] = json!(dir.display().to_string());
        out["seconds"] = json!(t0.elapsed().as_secs_f64());
        write_atomic(
            &dir.join("tspline.json"),
            serde_json::to_string_pretty(&out)?.as_bytes(),
        )?;
    }
    if a.json {
        print_json(&out);
    } else {
        println!(
            "{}: {} cylinders, {} control points, {} Bézier patches, error rms {:.3}% max {:.3}% of the longest side, {} iterations, {} inside cylinders, jumps across the critical trajectories up to {:.3}%, {:.2} s",
            a.mesh.display(),
            fit.splines.len(),
            fit.control_points(),
            patches.len(),
            rms,
            max,
            fit.steps.len(),
            class_inside,
            gap_percent,
            t0.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
