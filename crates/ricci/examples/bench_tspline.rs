//! Paper 003 Table 1 for the genus-1 models: T-spline fits over the flat torus with the
//! marking strategies of `FitOptions::mark_fraction`.
//!
//! `cargo run --release -p ricci --example bench_tspline -- MESH TOLERANCE [mark_fraction …]`
//! (TOLERANCE as a fraction, e.g. 0.0044; env SMOOTHING, INITIAL_FACES, MAX_POINTS_PER_FACE,
//! PARAMETER_CORRECTION, CORRECTION_STEPS, RMS_TOLERANCE, SMOOTHING_DECAY, MAX_CONTROL_POINTS,
//! RMS_MARKS, CORRECTION_GAIN, CG_TOLERANCE, AREA_WEIGHTS=1 (vertex-area weights; the trace's rms is then weighted)
//! override the defaults). Prints, per strategy: control points, rms %, L∞ %,
//! iterations, converged, CPU seconds of the fit (the domain is computed once, timed apart).
use ricci::progress::NoProgress;
use ricci::spline::tspline::fit::{
    area_weighted_rms, fit, flat_torus_domain, vertex_areas, FitOptions,
};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: bench_tspline MESH TOLERANCE [mark_fraction …]");
        std::process::exit(2);
    }
    let (surface, _) = ricci::mesh::io::read_surface(std::path::Path::new(&args[1]))?;
    let tol: f64 = args[2].parse()?;
    let fractions: Vec<f64> = if args.len() > 3 {
        args[3..]
            .iter()
            .map(|s| s.parse())
            .collect::<Result<_, _>>()?
    } else {
        vec![FitOptions::default().mark_fraction]
    };
    let t = Instant::now();
    let topo = ricci::mesh::topology(&surface.mesh);
    let genus0 = topo.components.len() == 1 && topo.components[0].genus == 0;
    let (uv, lattice, half) = if genus0 {
        let d = ricci::spline::tspline::genus0::genus0_domain(&surface, &mut NoProgress)?;
        let p = d.poles.map(|v| surface.positions[v as usize]);
        println!(
            "genus 0: {} loops filled, poles {:?} at {:?}, cut faces {:?}, double {} vertices",
            d.filled_loops, d.poles, p, d.cut_faces, d.double_vertices
        );
        (d.uv, d.lattice, d.half)
    } else {
        let (uv, lattice) = flat_torus_domain(&surface, &mut NoProgress)?;
        (uv, lattice, None)
    };
    println!(
        "{}: {} points, lattice W {:.4} H {:.4} s {:.2e}, domain {:.2} s",
        args[1],
        uv.len(),
        lattice.width,
        lattice.height,
        lattice.shift,
        t.elapsed().as_secs_f64()
    );
    println!("mark_fraction | control points | rms % | L∞ % | iterations | converged | fit s");
    let d = FitOptions::default();
    for f in fractions {
        let opts = FitOptions {
            tolerance: tol,
            mark_fraction: f,
            max_iterations: 60,
            smoothing: std::env::var("SMOOTHING")
                .ok()
                .and_then(|s| s.parse().ok())
                .unwrap_or(FitOptions::default().smoothing),
            max_points_per_face: std::env::var("MAX_POINTS_PER_FACE")
                .ok()
                .and_then(|s| s.parse().ok())
                .unwrap_or(FitOptions::default().max_points_per_face),
            initial_faces: std::env::var("INITIAL_FACES")
                .ok()
                .and_then(|s| s.parse().ok())
                .unwrap_or(FitOptions::default().initial_faces),
            parameter_correction: env("PARAMETER_CORRECTION", d.parameter_correction),
            correction_steps: env("CORRECTION_STEPS", d.correction_steps),
            correction_gain: env("CORRECTION_GAIN", d.correction_gain),
            rms_tolerance: env("RMS_TOLERANCE", d.rms_tolerance),
            smoothing_decay: env("SMOOTHING_DECAY", d.smoothing_decay),
            max_control_points: env("MAX_CONTROL_POINTS", d.max_control_points),
            rms_marks: env("RMS_MARKS", d.rms_marks),
            cg_tolerance: env("CG_TOLERANCE", d.cg_tolerance),
            weights: if env("AREA_WEIGHTS", 0) == 1 {
                vertex_areas(&surface)
            } else {
                Vec::new()
            },
            // HALF=0: count the control points of the empty half of a genus-0 torus too
            budget_half: if env("HALF", 1) == 1 { half } else { None },
            ..FitOptions::default()
        };
        let t = Instant::now();
        let r = fit(&surface.positions, &uv, lattice, &opts, &mut NoProgress)?;
        let s = r.steps.last().ok_or("no fit step")?;
        println!(
            "{f} | {} (on the surface's half: {}) | {:.4} | {:.4} | {} | {} | {:.2}",
            s.control_points,
            ricci::spline::tspline::fit::counted(&r.spline.basis.anchors, opts.budget_half),
            s.rms_error_percent,
            s.max_error_percent,
            r.steps.len(),
            r.converged,
            t.elapsed().as_secs_f64()
        );
        let trace: Vec<String> = r
            .steps
            .iter()
            .map(|s| {
                format!(
                    "{}→{:.3}/{:.4} ({} cg)",
                    s.control_points, s.max_error_percent, s.rms_error_percent, s.cg_iterations
                )
            })
            .collect();
        println!("  {}", trace.join(", "));
        if let Some(a) = area_weighted_rms(&surface, &r.errors) {
            let n = r.errors.len() as f64;
            let v = (r.errors.iter().map(|e| e * e).sum::<f64>() / n).sqrt();
            println!(
                "  vertex rms {:.4} %, area-weighted rms {:.4} %",
                100.0 * v / r.scale,
                100.0 * a / r.scale
            );
        }
    }
    Ok(())
}

fn env<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}
