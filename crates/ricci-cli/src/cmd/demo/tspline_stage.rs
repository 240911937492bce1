//! Demo stage `tspline`: the manifold T-spline of paper 003 (`ricci::spline::tspline`,
//! `ricci tspline`). Only genus-1 domains are built so far (the flat torus of the conformal
//! flow is the conformal net for genus 1), and the built-in surface has genus 2, so the stage
//! fits a generated torus of revolution (`ricci generate torus --resolution 32`): flat metric,
//! lattice, adaptive fit at 0.5 %, Bézier extraction, derivative jumps across every patch
//! side, and the T-mesh drawn on the surface (T-junctions in red, paper 003 Fig. 5/7) with
//! zebra stripes.

use super::report::{Picture, Section, Status, Table};
use super::Ctx;
use super::Env;
use crate::cmd::tspline::pictures;
use ricci::spline::tspline::fit::{fit, flat_torus_domain, FitOptions};
use ricci::spline::tspline::{continuity, extract};
use ricci_render::{Image, View};
use serde_json::json;
use std::time::Instant;

fn png(env: &mut Env, file: &str, img: &Image, caption: &str) -> anyhow::Result<Picture> {
    env.out.write(file, &img.to_png()?)?;
    Ok(Picture {
        file: file.into(),
        caption: caption.into(),
        width: img.width,
        height: img.height,
        alternatives: Vec::new(),
    })
}

/// The stage (see the module docs).
pub fn tspline(_ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let t0 = Instant::now();
    let mut sec = Section::new("tspline", "", "");
    env.bar
        .step("torus of revolution, flat torus, adaptive T-spline fit");
    let surface = ricci::mesh::generate::torus::torus(1.0, 0.5, 32)?;
    let mut progress = ricci::progress::NoProgress;
    let (uv, lattice) = flat_torus_domain(&surface, &mut progress)?;
    let opts = FitOptions {
        tolerance: 0.005,
        ..FitOptions::default()
    };
    let r = fit(&surface.positions, &uv, lattice, &opts, &mut progress)?;
    let patches = extract(&r.spline);
    let jumps = continuity(&patches, lattice, 3);
    let rel = jumps.relative();
    let class = jumps
        .class(1e-8)
        .map_or("discontinuous".to_string(), |k| format!("C{k}"));
    let last = r
        .steps
        .last()
        .ok_or_else(|| anyhow::anyhow!("the T-spline fit made no step"))?;
    let seconds_fit = t0.elapsed().as_secs_f64();

    env.bar.step("T-mesh on the surface and zebra pictures");
    let (net, zebra) = pictures(&r.spline, patches.len(), 4, (760, 520), View::default())?;
    sec.pictures.push(png(
        env,
        "tspline-tmesh.png",
        &net,
        "The T-mesh on the surface: the images of the T-mesh edges under the fitted T-spline (paper 003 Fig. 5/7); red loops mark the T-junctions, where a row of control points ends.",
    )?);
    sec.pictures.push(png(
        env,
        "tspline-zebra.png",
        &zebra,
        "Reflection lines (zebra) on the T-spline: C² everywhere, so the stripes run smoothly across the patch boundaries and the T-junctions.",
    )?);
    let t = r.spline.basis.mesh.t_junctions().len();
    if !r.converged || class != "C2" {
        sec.status = Status::Warning(format!(
            "the fit reached L∞ {:.3} % (tolerance 0.5 %), continuity {class}",
            last.max_error_percent
        ));
    }
    sec.headline = format!(
        "{} control points, {} T-junctions, L∞ {:.3}% / rms {:.3}%, {class}",
        r.spline.control.len(),
        t,
        last.max_error_percent,
        last.rms_error_percent
    );
    sec.paragraphs.push(format!(
        "The built-in surface has genus 2, whose T-spline domain needs the conformal net of \
         holomorphic 1-forms (not built yet), so this stage fits a torus of revolution \
         ({} vertices). Its flat metric gives the lattice W = {:.4}, H = {:.4}, shift {:.1e}; \
         a periodic T-mesh over it carries cubic blending functions with inferred knot vectors, \
         kept analysis-suitable. The control points are fitted to the vertices by least squares \
         plus thin-plate fairness, and faces whose error exceeds the tolerance are split \
         (1-to-4 or 1-to-2) until L∞ ≤ 0.5 % of the longest side.",
        surface.positions.len(),
        lattice.width,
        lattice.height,
        lattice.shift
    ));
    let e = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:.1e}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    sec.tables.push(Table::key_values(
        "Manifold T-spline of the torus (ricci tspline)",
        vec![
            ("control points", r.spline.control.len().to_string()),
            ("T-junctions", t.to_string()),
            ("Bézier patches", patches.len().to_string()),
            ("fit steps", r.steps.len().to_string()),
            (
                "error rms / L∞ (% of the longest side)",
                format!(
                    "{:.4} / {:.4}",
                    last.rms_error_percent, last.max_error_percent
                ),
            ),
            ("continuity", class.clone()),
            ("relative derivative jumps, orders 0..3", e(&rel)),
            (
                "time (fit; total)",
                format!("{seconds_fit:.2}; {:.2} s", t0.elapsed().as_secs_f64()),
            ),
        ],
    ));
    sec.commands = vec![
        "ricci generate torus --resolution 32 --out torus.off".into(),
        "ricci tspline torus.off --tolerance 0.5% --out tspline --json".into(),
    ];
    sec.summary = json!({
        "vertices": surface.positions.len(),
        "lattice": {"width": lattice.width, "height": lattice.height, "shift": lattice.shift},
        "control_points": r.spline.control.len(),
        "t_junctions": t,
        "bezier_patches": patches.len(),
        "rms_error_percent": last.rms_error_percent,
        "max_error_percent": last.max_error_percent,
        "converged": r.converged,
        "continuity": {"class": class, "relative_jumps": rel},
        "seconds": t0.elapsed().as_secs_f64(),
    });
    Ok(sec)
}
