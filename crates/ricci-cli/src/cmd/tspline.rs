//! `ricci tspline MESH [--tolerance 0.5%] [--out DIR] [--json]`: a cubic T-spline fitted to the
//! mesh over its domain manifold (paper 003; `ricci::spline::tspline`), exported for CAD.
//!
//! Supported now: closed surfaces of genus 1, over the flat torus of the default conformal flow
//! (for genus 1 the flat layout is the conformal net), and closed surfaces of genus ≥ 2 over
//! the cylinders of a holomorphic 1-form (`tspline_genus`), and connected surfaces of genus 0,
//! closed or with boundary loops, over the flat torus of the double of an annulus (loops
//! filled, one face cut at each of two poles: `ricci::spline::tspline::genus0`; the data lie on
//! half of the torus), and surfaces of genus ≥ 1 with boundary loops over the domain of the
//! surface with its loops filled by fans (no data on the fills; genus 1: the flat torus,
//! genus ≥ 2: the cylinders of a holomorphic 1-form). Several components are refused with a
//! sentence saying what works.
//!
//! `--out DIR` writes `tspline.step` (AP214, one `B_SPLINE_SURFACE_WITH_KNOTS` face per Bézier
//! patch), `tspline.igs` (entity 128 per patch), `surface.obj` (closed welded tessellation on a lattice grid), `tmesh.svg`
//! (the T-mesh in the parameter domain, T-junctions in red), `samples.json` (parameters and
//! points of our evaluation, to check readers against), `tmesh-surface.png` (the T-mesh's
//! edges mapped onto the surface through the fit, T-junctions in red: paper 003 Fig. 5/7),
//! `zebra.png` (reflection lines of the fitted surface) and `tspline.json` (the report).
//! For genus ≥ 2 (`tspline_domain`) the pictures show the domain mesh (`tspline_pictures`)
//! and there is no `tmesh.svg`. For genus 0 it writes only the surface's half of the torus (the Bézier patches clipped to
//! the strip between the seams): `tspline.step`, `tspline.igs`, `surface.obj` (per-patch
//! tessellation), `samples.json`, `spline.json`, `tspline.json`; and JSON `control_points`
//! counts the control points whose blending function meets that half (the budget
//! `--max-control-points` counts the same), `control_points_total` all of them.

use crate::cmd::layout::spinner;
use crate::cmd::tspline_pictures::{line, render_net_and_zebra};
use crate::util::{print_json, read_surface, write_atomic, write_json_atomic, UsageError};
use ricci::spline::tspline::curves::{tmesh_on_surface, torus_tessellation};
use ricci::spline::tspline::export::{iges, obj, obj_with_breaks, step, torus_obj};
use ricci::spline::tspline::fit::{
    area_weighted_rms, counted, fit, flat_torus_domain, vertex_areas, FitOptions, FitResult,
};
use ricci::spline::tspline::genus0::{fill_boundary_loops, genus0_domain};
use ricci::spline::tspline::half::Half;
use ricci::spline::tspline::{
    chart_independence, continuity, extract_elements, BezierPatch, ChartIndependence, Continuity,
    Lattice, TSpline,
};
use ricci_render::{Image, Polyline, RenderOptions, View};
use serde_json::json;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (OBJ, OFF, PLY, STL): one connected surface, closed or with boundary loops
    /// (filled for the domain; the fills carry no data), of any genus.
    pub mesh: PathBuf,
    /// Fitting tolerance L∞, as a fraction of the longest bounding-box side ("0.5%" or 0.005).
    #[arg(long, default_value = "0.5%")]
    pub tolerance: String,
    /// Weight of the (scale-free) thin-plate fairness term.
    #[arg(long, default_value_t = 1e-5)]
    pub smoothing: f64,
    /// Faces of the initial tensor-product T-mesh (about).
    #[arg(long, default_value_t = 64)]
    pub initial_faces: usize,
    /// Refine only faces whose error exceeds this fraction of the largest error (0 = every
    /// face above the tolerance, paper 003's rule).
    #[arg(long, default_value_t = 0.5)]
    pub mark_fraction: f64,
    /// Before the first fit, split faces holding more than this many mesh vertices (0 = uniform
    /// start).
    #[arg(long, default_value_t = 80)]
    pub max_points_per_face: usize,
    /// Rounds of parameter correction after every fit (each data point's parameter moved to
    /// the foot of its perpendicular on the surface, then refit); 0 = the conformal parameters.
    #[arg(long, default_value_t = 0)]
    pub parameter_correction: usize,
    /// Gauss–Newton steps per data point in each round of parameter correction.
    #[arg(long, default_value_t = 3)]
    pub correction_steps: usize,
    /// Target rms error ("0.05%" or 0.0005; 0 = none): after L∞ is met, the faces with the
    /// largest sums of squared errors are refined until the rms is at most this.
    #[arg(long, default_value = "0")]
    pub rms_tolerance: String,
    /// Stop the correction rounds of a refit once a round lowers the rms by less than this
    /// fraction of it (0 = always all --parameter-correction rounds; e.g. 0.02). Genus 1.
    #[arg(long, default_value_t = 0.0)]
    pub correction_gain: f64,
    /// Refinements for the rms (after L∞ is met): split the K faces with the largest sums of
    /// squared errors per refit (0 = every face above --mark-fraction of the largest). Genus 1.
    #[arg(long, default_value_t = 0)]
    pub rms_marks: usize,
    /// Weight every mesh vertex by its area (a third of the incident triangles) in the fit,
    /// the rms target and the marking: the squared error integrated over the surface rather
    /// than summed over vertices. The reported rms_error_percent stays the vertex rms. Genus 1.
    #[arg(long)]
    pub area_weights: bool,
    /// Factor applied to the thin-plate weight after every refinement (1 = constant).
    #[arg(long, default_value_t = 1.0)]
    pub smoothing_decay: f64,
    /// Genus ≥ 2: fit one tensor-product spline per cylinder of the holomorphic 1-form (C⁰
    /// across the critical trajectories and the knot lines through the zeros) instead of the
    /// default, one spline on the domain manifold's quad mesh (C² on every cell side not at a
    /// zero, C⁰ at the zeros).
    #[arg(long)]
    pub per_cylinder: bool,
    /// Budget: refinement iterations.
    #[arg(long, default_value_t = 30)]
    pub max_iterations: usize,
    /// Budget: control points.
    #[arg(long, default_value_t = 20_000)]
    pub max_control_points: usize,
    /// Segments per patch side (on average) in surface.obj, the lattice-grid tessellation.
    #[arg(long, default_value_t = 4)]
    pub tessellation: usize,
    /// Output directory.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// With --out: leave out the two PNG pictures (tmesh-surface.png, zebra.png).
    #[arg(long)]
    pub no_pictures: bool,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

pub(crate) fn parse_tolerance(s: &str) -> Result<f64, UsageError> {
    parse_fraction("--tolerance", s, false)
}

/// A fraction given as "0.5%" or 0.005, in (0, 1) (or [0, 1) with `zero`).
fn parse_fraction(flag: &str, s: &str, zero: bool) -> Result<f64, UsageError> {
    let t = s.trim();
    let (num, pct) = match t.strip_suffix('%') {
        Some(n) => (n.trim(), true),
        None => (t, false),
    };
    let x: f64 = num
        .parse()
        .map_err(|_| UsageError(format!("{flag} {s}: not a number (use 0.5% or 0.005)")))?;
    let x = if pct { x / 100.0 } else { x };
    if !((x > 0.0 || (zero && x == 0.0)) && x < 1.0) {
        return Err(UsageError(format!(
            "{flag} {s} must be between 0 and 100 %"
        )));
    }
    Ok(x)
}

/// The T-mesh in the parameter domain as SVG: faces in black, T-junctions in red.
fn tmesh_svg(ts: &TSpline) -> String {
    let m = &ts.basis.mesh;
    let lat = m.lattice;
    let size = 900.0;
    let k = size / lat.width.max(lat.height);
    let (w, h) = (lat.width * k, lat.height * k);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{:.0}\" height=\"{:.0}\" viewBox=\"-10 -10 {:.1} {:.1}\">",
        w + 20.0,
        h + 20.0,
        w + 20.0,
        h + 20.0
    );
    let _ = writeln!(s, "<rect x=\"0\" y=\"0\" width=\"{w:.2}\" height=\"{h:.2}\" fill=\"white\" stroke=\"black\" stroke-width=\"1.5\"/>");
    for f in m.faces() {
        let _ = writeln!(
            s,
            "<rect x=\"{:.3}\" y=\"{:.3}\" width=\"{:.3}\" height=\"{:.3}\" fill=\"none\" stroke=\"black\" stroke-width=\"0.6\"/>",
            f.u0 * k,
            h - f.v1 * k,
            (f.u1 - f.u0) * k,
            (f.v1 - f.v0) * k
        );
    }
    for t in m.t_junctions() {
        let _ = writeln!(
            s,
            "<circle cx=\"{:.3}\" cy=\"{:.3}\" r=\"2.2\" fill=\"red\"/>",
            t.u * k,
            h - t.v * k
        );
    }
    s.push_str("</svg>\n");
    s
}

/// Pictures of the fitted surface, rendered from the lattice-grid tessellation with about
/// `per_side` segments per Bézier patch side: the T-mesh on the surface (edges in dark grey,
/// T-junctions as red loops; paper 003 Fig. 5/7) and zebra stripes (reflection lines).
pub fn pictures(
    ts: &TSpline,
    patches: usize,
    per_side: usize,
    size: (u32, u32),
    view: View,
) -> anyhow::Result<(Image, Image)> {
    let lattice = ts.basis.mesh.lattice;
    let per = (patches.max(1) as f64).sqrt() * per_side as f64;
    let ratio = (lattice.width / lattice.height).sqrt();
    let (n, m) = ((per * ratio).ceil() as usize, (per / ratio).ceil() as usize);
    let (positions, triangles) = torus_tessellation(ts, n.min(2000), m.min(2000));
    let opts = RenderOptions {
        width: size.0,
        height: size.1,
        supersample: 2,
        view,
        ..RenderOptions::default()
    };
    let curves = tmesh_on_surface(ts, 6, 0.3);
    let mut polylines: Vec<Polyline> = curves
        .edges
        .into_iter()
        .map(|points| line(points, [0.12, 0.12, 0.16], 1.0, false))
        .collect();
    polylines.extend(
        curves
            .t_junctions
            .into_iter()
            .map(|points| line(points, [0.9, 0.05, 0.05], 2.5, true)),
    );
    render_net_and_zebra(&positions, &triangles, polylines, &opts)
}

fn samples_json(ts: &TSpline, patches: &[BezierPatch]) -> serde_json::Value {
    let mut out = Vec::with_capacity(2 * patches.len());
    for p in patches {
        for (a, b) in [(0.31, 0.67), (0.73, 0.22)] {
            let (u, v) = (p.u0 + a * (p.u1 - p.u0), p.v0 + b * (p.v1 - p.v0));
            let x = ts.point(u, v);
            out.push(json!([u, v, x[0], x[1], x[2]]));
        }
    }
    let bounds: Vec<[f64; 4]> = patches.iter().map(|p| [p.u0, p.u1, p.v0, p.v1]).collect();
    json!({"samples": out, "patches": bounds, "samples_per_patch": 2})
}

/// The `continuity` report: derivative jumps per order across every side shared by two Bézier
/// patches, and the largest difference between charts (genus 1: lattice translations).
fn continuity_json(
    class: &str,
    jumps: &Continuity,
    charts: &ChartIndependence,
) -> serde_json::Value {
    let rel = jumps.relative();
    let per_order: Vec<_> = (0..4)
        .map(|k| json!({"order": k, "max_jump": jumps.jumps[k], "max_partial": jumps.magnitudes[k], "relative_jump": rel[k]}))
        .collect();
    let crel = charts.relative();
    json!({
        "class": class,
        "jumps": jumps.jumps,
        "magnitudes": jumps.magnitudes,
        "relative_jumps": rel,
        "orders": [0, 1, 2, 3],
        "per_order": per_order,
        "side_points_compared": jumps.comparisons,
        "extraordinary_points": 0,
        "chart_independence": {
            "max": charts.max_relative(),
            "relative_differences": crel,
            "differences": charts.differences,
            "magnitudes": charts.magnitudes,
            "orders": [0, 1, 2],
            "comparisons": charts.comparisons,
            "transitions": "lattice translations"
        }
    })
}

/// The ranges of the numeric arguments (usage errors, exit 2).
fn check_ranges(a: &Args) -> anyhow::Result<()> {
    if !(a.smoothing >= 0.0 && a.smoothing.is_finite()) {
        return Err(UsageError(format!("--smoothing {} must be ≥ 0", a.smoothing)).into());
    }
    if !(0.0..1.0).contains(&a.mark_fraction) {
        return Err(UsageError(format!(
            "--mark-fraction {} is not in [0, 1)",
            a.mark_fraction
        ))
        .into());
    }
    if !(1..=64).contains(&a.tessellation) {
        return Err(UsageError(format!(
            "--tessellation {} is not in 1..=64",
            a.tessellation
        ))
        .into());
    }
    if !(a.smoothing_decay > 0.0 && a.smoothing_decay <= 1.0) {
        return Err(UsageError(format!(
            "--smoothing-decay {} is not in (0, 1]",
            a.smoothing_decay
        ))
        .into());
    }
    if !(1..=20).contains(&a.correction_steps) {
        return Err(UsageError(format!(
            "--correction-steps {} is not in 1..=20",
            a.correction_steps
        ))
        .into());
    }
    if !(0.0..1.0).contains(&a.correction_gain) {
        return Err(UsageError(format!(
            "--correction-gain {} is not in [0, 1)",
            a.correction_gain
        ))
        .into());
    }
    if a.rms_marks > 100_000 {
        return Err(UsageError(format!("--rms-marks {} is not in 0..=100000", a.rms_marks)).into());
    }
    if a.parameter_correction > 10 {
        return Err(UsageError(format!(
            "--parameter-correction {} is not in 0..=10",
            a.parameter_correction
        ))
        .into());
    }
    if !(4..=100_000).contains(&a.initial_faces) {
        return Err(UsageError(format!(
            "--initial-faces {} is not in 4..=100000",
            a.initial_faces
        ))
        .into());
    }
    Ok(())
}

/// The flat-torus domain of a genus-0 or genus-1 surface: one parameter per input vertex, the
/// lattice, the domain's name, the genus-0 report and the surface's half of the torus.
type Domain = (
    Vec<[f64; 2]>,
    Lattice,
    &'static str,
    Option<serde_json::Value>,
    Option<Half>,
);

fn flat_domain(
    surface: &ricci::mesh::Surface,
    genus0: bool,
    loops: usize,
    bar: &mut crate::cmd::layout::Bar,
) -> anyhow::Result<Domain> {
    Ok(if genus0 {
        let d = genus0_domain(surface, bar)?;
        let info = json!({
            "filled_loops": d.filled_loops,
            "poles": d.poles,
            "cut_faces": d.cut_faces,
            "double_vertices": d.double_vertices,
            "surface_half": d.half,
        });
        let name = "flat torus of the double of an annulus (genus 0: loops filled, a face cut at two poles; data on half of the torus)";
        (d.uv, d.lattice, name, Some(info), d.half)
    } else if loops > 0 {
        // genus 1 with boundary: the loops filled by fans (no data on them), the flat torus
        let (filled, _) = fill_boundary_loops(surface)?;
        let (uv, lattice) = flat_torus_domain(&filled, bar)?;
        let n = surface.positions.len();
        let name = "flat torus of the surface with its boundary loops filled by fans (genus 1 with boundary; the fills carry no data)";
        (uv[..n].to_vec(), lattice, name, None, None)
    } else {
        let (uv, lattice) = flat_torus_domain(surface, bar)?;
        (uv, lattice, "flat torus (genus 1)", None, None)
    })
}

/// `ricci tspline`: when it fails after writing part of `--out DIR`, those files are removed
/// again (`all_or_nothing`): a failed run leaves no half-written directory.
pub fn run_cmd(a: Args) -> anyhow::Result<()> {
    let dir = a.out.clone();
    crate::util::all_or_nothing(dir.as_deref(), || run_tspline(a))
}

fn run_tspline(a: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let tolerance = parse_tolerance(&a.tolerance)?;
    let rms_tolerance = parse_fraction("--rms-tolerance", &a.rms_tolerance, true)?;
    check_ranges(&a)?;
    let (surface, _) = read_surface(&a.mesh)?;
    let topo = ricci::mesh::topology(&surface.mesh);
    let (comps, genus, loops) = match topo.components.first() {
        Some(c) => (topo.components.len(), c.genus, c.boundary_loops),
        None => (0, 0, 0),
    };
    if comps == 1 && genus >= 2 {
        return crate::cmd::tspline_genus::run_genus(&a, &surface, tolerance, t0);
    }
    let genus0 = comps == 1 && genus == 0;
    if comps != 1 {
        anyhow::bail!(
            "{}: ricci tspline fits one connected surface (closed or with boundary loops, of any genus); this mesh has {comps} components: save each component to its own file and fit them one by one",
            a.mesh.display()
        );
    }
    let mut bar = spinner(a.json);
    bar.0.set_message("flat metric and layout");
    let (uv, lattice, domain, genus0_json, half) = flat_domain(&surface, genus0, loops, &mut bar)?;
    let opts = FitOptions {
        tolerance,
        smoothing: a.smoothing,
        initial_faces: a.initial_faces,
        max_iterations: a.max_iterations.max(1),
        max_control_points: a.max_control_points,
        mark_fraction: a.mark_fraction,
        max_points_per_face: a.max_points_per_face,
        parameter_correction: a.parameter_correction,
        correction_steps: a.correction_steps,
        rms_tolerance,
        smoothing_decay: a.smoothing_decay,
        correction_gain: a.correction_gain,
        rms_marks: a.rms_marks,
        weights: if a.area_weights {
            vertex_areas(&surface)
        } else {
            Vec::new()
        },
        budget_half: half,
        ..FitOptions::default()
    };
    bar.0.set_message("fitting");
    let r = fit(&surface.positions, &uv, lattice, &opts, &mut bar)?;
    let fit_seconds = t0.elapsed().as_secs_f64();
    bar.0.set_message("Bézier extraction");
    let (patches, merge) = extract_elements(&r.spline);
    let jumps = continuity(&patches, lattice, 3);
    let charts = chart_independence(&r.spline, lattice, 24);
    bar.0.finish_and_clear();
    let rel = jumps.relative();
    // C^k: jumps of orders ≤ k below 1e-8 of the largest partial of that order (the patches
    // come from an interpolation at interior nodes: rounding grows with the order)
    let class = match jumps.class(1e-8) {
        Some(k) => format!("C{k}"),
        None => "discontinuous".to_string(),
    };
    let last = r.steps.last().cloned();
    let max = last.as_ref().map_or(f64::NAN, |s| s.max_error_percent);
    // the vertex rms (with --area-weights the steps' rms is the weighted one)
    let n = r.errors.len().max(1) as f64;
    let rms = 100.0 * (r.errors.iter().map(|e| e * e).sum::<f64>() / n).sqrt() / r.scale;
    let mut out = json!({
        "file": a.mesh.display().to_string(),
        "domain": domain,
        "genus0": genus0_json,
        "lattice": {"width": lattice.width, "height": lattice.height, "shift": lattice.shift},
        "control_points": counted(&r.spline.basis.anchors, half),
        "control_points_total": r.spline.control.len(),
        "control_points_counted": if half.is_some() {
            "those whose blending function's support meets the surface's half of the torus (genus0.surface_half; the mirror half holds no data); control_points_total counts the mirror half's too"
        } else {
            "all"
        },
        "faces": r.spline.basis.mesh.faces().len(),
        "t_junctions": r.spline.basis.mesh.t_junctions().len(),
        "analysis_suitable": r.spline.basis.mesh.is_analysis_suitable(),
        "cells": merge.cells,
        "patches": patches.len(),
        "bezier_patches": patches.len(),
        "bezier_elements": merge,
        "rms_error_percent": rms,
        "rms_error_percent_area_weighted": area_weighted_rms(&surface, &r.errors)
            .map(|x| 100.0 * x / r.scale),
        "max_error_percent": max,
        "tolerance_percent": 100.0 * tolerance,
        "converged": r.converged,
        "refinement_stalled": r.stalled,
        "iterations": r.steps.len(),
        "steps": r.steps,
        "continuity": continuity_json(&class, &jumps, &charts),
        "data_points": surface.positions.len(),
        "parameter_correction": opts.parameter_correction,
        "correction_steps": opts.correction_steps,
        "rms_tolerance_percent": 100.0 * rms_tolerance,
        "smoothing_decay": opts.smoothing_decay,
        "correction_gain": opts.correction_gain,
        "rms_marks": opts.rms_marks,
        "area_weights": a.area_weights,
        "scale": r.scale,
        "seconds_fit": fit_seconds,
        "seconds": t0.elapsed().as_secs_f64(),
    });
    warn_stopped(&a, &r, max, tolerance, &opts);
    if let Some(dir) = &a.out {
        write_outputs(dir, &a, &r, &patches, half)?;
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
            "{}: {} control points ({} T-junctions, {} Bézier patches), error rms {:.3}% max {:.3}% of the longest side, {} iterations, {} (jumps {:.1e} {:.1e} {:.1e} {:.1e}), {:.2} s",
            a.mesh.display(),
            r.spline.control.len(),
            r.spline.basis.mesh.t_junctions().len(),
            patches.len(),
            rms,
            max,
            r.steps.len(),
            class,
            rel[0],
            rel[1],
            rel[2],
            rel[3],
            t0.elapsed().as_secs_f64()
        );
    }
    Ok(())
}

/// The warning when the genus-0 / genus-1 fit stopped above the tolerance (L∞ `max` in
/// percent): at the budget, or because the worst faces cannot be split (`FitResult::stalled`).
fn warn_stopped(a: &Args, r: &FitResult, max: f64, tolerance: f64, opts: &FitOptions) {
    let (file, tol) = (a.mesh.display(), 100.0 * tolerance);
    if r.stalled {
        eprintln!(
            "warning: {file}: the fit stopped at L∞ {max:.3} % above the tolerance {tol:.3} %: the T-mesh faces holding the worst points cannot be split further (the conformal domain crowds those points within 1e-10 of its size, as on long thin protrusions); the result is the last fit"
        );
    } else if !r.converged {
        eprintln!(
            "warning: {file}: the fit stopped at L∞ {max:.3} % above the tolerance {tol:.3} % (budget: {} iterations, {} control points)",
            opts.max_iterations, opts.max_control_points
        );
    }
}

/// The files of `--out DIR` but the report (see the module docs).
fn write_outputs(
    dir: &std::path::Path,
    a: &Args,
    r: &FitResult,
    patches: &[BezierPatch],
    half: Option<Half>,
) -> anyhow::Result<()> {
    if let Some(h) = half {
        return write_half_outputs(dir, a, r, &h.clip(patches));
    }
    let lattice = r.spline.basis.mesh.lattice;
    write_atomic(
        &dir.join("tspline.step"),
        step(patches, "tspline").as_bytes(),
    )?;
    write_atomic(
        &dir.join("tspline.igs"),
        iges(patches, "tspline").as_bytes(),
    )?;
    // lattice grid with about `tessellation` segments per patch side
    let per = (patches.len() as f64).sqrt() * a.tessellation as f64;
    let ratio = (lattice.width / lattice.height).sqrt();
    let (n, m) = ((per * ratio).ceil() as usize, (per / ratio).ceil() as usize);
    write_atomic(
        &dir.join("surface.obj"),
        torus_obj(&r.spline, n, m).as_bytes(),
    )?;
    write_atomic(&dir.join("tmesh.svg"), tmesh_svg(&r.spline).as_bytes())?;
    if !a.no_pictures {
        let (net, zebra) = pictures(
            &r.spline,
            patches.len(),
            a.tessellation,
            (1200, 900),
            View::default(),
        )?;
        write_atomic(&dir.join("tmesh-surface.png"), &net.to_png()?)?;
        write_atomic(&dir.join("zebra.png"), &zebra.to_png()?)?;
    }
    write_atomic(
        &dir.join("samples.json"),
        serde_json::to_string(&samples_json(&r.spline, patches))?.as_bytes(),
    )?;
    write_json_atomic(&dir.join("spline.json"), spline_json(r, patches))?;
    Ok(())
}

/// `tspline.step`, `tspline.igs` (one face per Bézier patch) and `surface.obj` (tessellated
/// patch by patch, `a.tessellation` segments between consecutive `breaks` of each patch when
/// given, else along each whole side): the files of every domain whose patches are not a
/// closed torus grid.
pub(crate) fn write_patch_files(
    dir: &std::path::Path,
    a: &Args,
    patches: &[BezierPatch],
    breaks: Option<&[(Vec<f64>, Vec<f64>)]>,
) -> anyhow::Result<()> {
    write_atomic(
        &dir.join("tspline.step"),
        step(patches, "tspline").as_bytes(),
    )?;
    write_atomic(
        &dir.join("tspline.igs"),
        iges(patches, "tspline").as_bytes(),
    )?;
    write_atomic(
        &dir.join("surface.obj"),
        match breaks {
            Some(b) => obj_with_breaks(patches, b, a.tessellation),
            None => obj(patches, a.tessellation),
        }
        .as_bytes(),
    )
}

/// The files of `--out DIR` for the genus-0 domain: only the surface's half of the torus (the
/// Bézier patches clipped to it), tessellated patch by patch; no pictures of the torus.
fn write_half_outputs(
    dir: &std::path::Path,
    a: &Args,
    r: &FitResult,
    patches: &[BezierPatch],
) -> anyhow::Result<()> {
    write_patch_files(dir, a, patches, None)?;
    write_atomic(
        &dir.join("samples.json"),
        serde_json::to_string(&samples_json(&r.spline, patches))?.as_bytes(),
    )?;
    write_json_atomic(&dir.join("spline.json"), spline_json(r, patches))?;
    Ok(())
}

/// `spline.json`: the fitted spline as arrays — anchors (parameters of the control points) and
/// control points, the data points' parameters (corrected when asked) and errors, and the
/// Bézier patches (`[u0, u1, v0, v1]` and 4×4 control points, `[i][j]` with `i` along `u`) that
/// evaluate it anywhere after reducing `(u, v)` to the fundamental domain of the lattice.
fn spline_json(r: &FitResult, patches: &[BezierPatch]) -> serde_json::Value {
    let lattice = r.spline.basis.mesh.lattice;
    let anchors: Vec<[f64; 2]> = r.spline.basis.anchors.iter().map(|a| [a.u, a.v]).collect();
    let bounds: Vec<[f64; 4]> = patches.iter().map(|p| [p.u0, p.u1, p.v0, p.v1]).collect();
    let control: Vec<_> = patches.iter().map(|p| p.control).collect();
    json!({
        "lattice": {"width": lattice.width, "height": lattice.height, "shift": lattice.shift},
        "anchors": anchors,
        "control": r.spline.control,
        "params": r.params,
        "errors": r.errors,
        "scale": r.scale,
        "patch_bounds": bounds,
        "patch_control": control,
    })
}
