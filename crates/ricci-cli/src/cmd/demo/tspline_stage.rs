//! Demo stage `tspline`: the manifold T-spline of paper 003 (§2–3) on the built-in genus-2
//! surface, by the code path of `ricci tspline surface.off` with its default arguments
//! (`crate::cmd::tspline_genus::genus_domain_of`, `crate::cmd::tspline_domain::domain_spline`):
//! the holomorphic 1-form whose cylinders hold the data best, their strips glued by
//! translations into one quad mesh of knot intervals over the whole domain manifold, one cubic
//! spline on it fitted by least squares with refinement graded towards the zeros, G¹ at the
//! zeros, and its continuity and its distance to the triangles between the vertices measured. Pictures (`crate::cmd::tspline_pictures`): the domain mesh on the
//! surface with the zeros ringed, and zebra stripes.

use super::common::{opts, png};
use super::report::{Section, Status, Table};
use super::{Ctx, Env};
use crate::cmd::tspline::{parse_tolerance, Args};
use crate::cmd::tspline_domain::{domain_spline, DomainSpline};
use crate::cmd::tspline_genus::genus_domain_of;
use crate::cmd::tspline_pictures::{domain_caption, domain_pictures, ZEBRA_CAPTION};
use clap::Parser;
use ricci::spline::tspline::glue::gluing;
use ricci_render::View;
use serde_json::{json, Value};
use std::time::Instant;

/// The command line the stage runs (and the page shows), parsed by the CLI's own parser so
/// that every other default is the command's. The fairness weight is ten times the domain
/// fit's floor (1e-4): on the built-in surface (1 214 vertices, coarse facets) it gives the
/// same control points and a smoother zebra, and a spline nearer the triangles between the
/// vertices (generated genus 2 at 0.5 %: max / rms 1.85 / 0.196 % → 1.74 / 0.183 %).
const COMMAND: [&str; 6] = [
    "tspline",
    "surface.off",
    "--tolerance",
    "0.5%",
    "--smoothing",
    "1e-3",
];

#[derive(Parser)]
struct TsplineCommand {
    #[command(flatten)]
    args: Args,
}

/// Segments per cell side of the tessellation the pictures are rendered from (at most
/// 300 000 triangles: `tspline_pictures`); 2 made the zebra stripes jagged.
const PICTURE_SEGMENTS: usize = 8;

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

/// The stage (see the module docs).
pub fn tspline(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let t0 = Instant::now();
    let mut sec = Section::new("tspline", "", "");
    let surface = ctx.surface()?;
    let a = TsplineCommand::try_parse_from(COMMAND)?.args;
    let tolerance = parse_tolerance(&a.tolerance)?;
    env.bar
        .step("holomorphic 1-forms and the cylinders of the critical trajectories");
    let (h, domain, filled) = genus_domain_of(surface, &mut *env.bar)?;
    let g = gluing(&domain).map_err(|why| {
        anyhow::anyhow!("the cylinders' strips do not glue into one domain mesh ({why})")
    })?;
    env.bar.step("domain-mesh spline: fit and continuity");
    let r = domain_spline(
        &a,
        surface,
        &h,
        &domain,
        &g,
        filled,
        tolerance,
        t0,
        &mut *env.bar,
    )?;
    let seconds_fit = t0.elapsed().as_secs_f64();
    env.bar
        .step("the domain mesh on the surface and zebra pictures");
    let (net, zebra, info) = domain_pictures(&r.fit, PICTURE_SEGMENTS, &opts(View::default()))?;
    let cells = r.fit.mesh.n_cells();
    sec.pictures.push(png(
        env,
        "tspline-tmesh.png",
        &net,
        &domain_caption(&info, cells),
    )?);
    sec.pictures
        .push(png(env, "tspline-zebra.png", &zebra, ZEBRA_CAPTION)?);
    let rep = &r.report;
    let c = &rep["continuity"];
    let class = |k: &str| c[k]["class"].as_str().unwrap_or("?").to_string();
    let sides = |k: &str| c[k]["sides"].as_u64().unwrap_or(0);
    let rms = num(&rep["rms_error_percent"]);
    let max = num(&rep["max_error_percent"]);
    let zeros = domain.decomposition.zeros.len();
    let expected = class("at_zeros") == "C1"
        && class("one_interval_from_zeros") == "C2"
        && class("elsewhere") == "C2";
    if !r.fit.converged || !expected {
        sec.status = Status::Warning(format!(
            "the fit reached L∞ {max:.3} % (tolerance {:.1} %); continuity {} at the zeros, {} / {} elsewhere",
            100.0 * tolerance,
            class("at_zeros"),
            class("one_interval_from_zeros"),
            class("elsewhere")
        ));
    }
    sec.headline = format!(
        "{} control points on {cells} cells, L∞ {max:.3}% / rms {rms:.3}%, {} at the {zeros} zeros, {} elsewhere",
        r.fit.mesh.n_control_points(),
        class("at_zeros"),
        class("elsewhere")
    );
    sec.paragraphs.push(format!(
        "The domain manifold of the genus-2 surface ({} vertices) is built from a holomorphic \
         1-form ω with integer imaginary periods: its horizontal trajectories through the {zeros} \
         zeros (the extraordinary points) cut the surface into {} flat cylinders, cut again \
         into {} rectangular strips whose sides are glued by translations. Every strip is \
         divided into cells (knot intervals), the same number along every chain of glued \
         strips, so the cells form one conforming quad mesh of the closed surface (valence 4 \
         everywhere but at the zeros); near the zeros the cells are graded, halving towards \
         them, and the graded lines end in T-junctions a cell beyond the zeros' corner blocks \
         ({} T-junctions), so the mesh is fine only where the error asks for it. One cubic \
         T-spline lives on it: one control point per vertex of the T-mesh (local knot vectors \
         by ray casting, knot insertion into the full graded mesh), each cell a bicubic Bézier patch whose points are \
         blossoms of the B-spline over the neighbouring intervals (at a zero: the mean of the \
         first side points around it). Its control points are fitted to the surface's vertices \
         by least squares plus thin-plate fairness, under linear conditions that make the \
         surface G¹ at every zero, refined (at the zeros while the error there exceeds the \
         tolerance, uniformly otherwise) until L∞ ≤ {:.1} % of the longest side ({} fits).",
        surface.positions.len(),
        domain.cylinders.len(),
        r.fit.mesh.rects.len(),
        r.fit.mesh.n_t_junctions(),
        100.0 * tolerance,
        r.fit.steps.len(),
    ));
    sec.paragraphs.push(format!(
        "Continuity is measured, not assumed: the jumps of every partial derivative of orders \
         0–3 between the two Bézier patches of every cell side. {} on the {} sides with a \
         zero at an end (G¹ by construction: C¹ in the translation chart, normals within {:.1e}° \
         along those sides), {} on the {} sides one knot interval \
         from a zero and {} on the other {} sides. The numbers are those of \
         `ricci tspline surface.off --json` (the same code, the same defaults).",
        class("at_zeros"),
        sides("at_zeros"),
        num(&c["normal_angle_at_zeros_degrees"]),
        class("one_interval_from_zeros"),
        sides("one_interval_from_zeros"),
        class("elsewhere"),
        sides("elsewhere")
    ));
    sec.paragraphs.push(between_vertices_paragraph(
        &r,
        surface.positions.len(),
        cells,
    ));
    sec.tables.push(results_table(
        &r,
        domain.cylinders.len(),
        zeros,
        tolerance,
        [seconds_fit, t0.elapsed().as_secs_f64()],
    ));
    sec.commands = vec![format!("ricci {} --out tspline --json", COMMAND.join(" "))];
    sec.summary = json!({
        "vertices": surface.positions.len(),
        "genus": h.genus,
        "zeros": zeros,
        "cylinders": domain.cylinders.len(),
        "strips": r.fit.mesh.rects.len(),
        "control_points": rep["control_points"],
        "cells": rep["cells"],
        "mesh_vertices": rep["mesh_vertices"],
        "bezier_patches": rep["bezier_patches"],
        "patches": rep["patches"],
        "t_junctions": rep["t_junctions"],
        "iterations": rep["iterations"],
        "rms_error_percent": rep["rms_error_percent"],
        "max_error_percent": rep["max_error_percent"],
        "tolerance_percent": rep["tolerance_percent"],
        "converged": rep["converged"],
        "continuity": rep["continuity"],
        "pictures": {"knot_line_stride": info.stride, "segments_per_cell_side": info.segments_per_cell_side, "triangles": info.triangles},
        "seconds": t0.elapsed().as_secs_f64(),
    });
    Ok(sec)
}

/// The paragraph on the distance between the vertices (`vertices`: the input's; `cells`: the
/// domain mesh's), from the report of `ricci tspline`.
fn between_vertices_paragraph(r: &DomainSpline, vertices: usize, cells: usize) -> String {
    format!(
        "The tolerance is checked at the {} vertices; the surface between them is measured \
         too: the spline at 16 points of every cell is within {:.2} % (max) and {:.3} % (rms) \
         of the longest side of the input triangles ({}). With {} control points \
         ({:.2} vertices per cell) the fairness shapes the cells without a vertex, and the \
         zebra stripes show where.",
        vertices,
        num(&r.report["max_deviation_between_vertices_percent"]),
        num(&r.report["rms_deviation_between_vertices_percent"]),
        if r.report["between_vertices_data"]
            .as_str()
            .unwrap_or("")
            .starts_with("points")
        {
            "points on the triangles are data too"
        } else {
            "the vertices are the only data"
        },
        r.fit.mesh.n_control_points(),
        vertices as f64 / cells.max(1) as f64
    )
}

/// The stage's table: the domain mesh, the fit and its measured continuity, from the report of
/// `ricci tspline` (`seconds`: fit and continuity; total).
fn results_table(
    r: &DomainSpline,
    cylinders: usize,
    zeros: usize,
    tolerance: f64,
    seconds: [f64; 2],
) -> Table {
    let rep = &r.report;
    let c = &rep["continuity"];
    let class = |k: &str| c[k]["class"].as_str().unwrap_or("?").to_string();
    let sides = |k: &str| c[k]["sides"].as_u64().unwrap_or(0);
    let (rms, max) = (
        num(&rep["rms_error_percent"]),
        num(&rep["max_error_percent"]),
    );
    let cells = r.fit.mesh.n_cells();
    let e = |k: &str| {
        c[k]["jumps"]["relative_jumps"]
            .as_array()
            .map(|v| {
                v.iter()
                    .map(|x| format!("{:.1e}", num(x)))
                    .collect::<Vec<_>>()
                    .join(", ")
            })
            .unwrap_or_default()
    };
    Table::key_values(
        "Domain-mesh spline of the genus-2 surface (ricci tspline)",
        vec![
            (
                "zeros of the form (extraordinary points)",
                zeros.to_string(),
            ),
            (
                "cylinders / strips",
                format!("{cylinders} / {}", r.fit.mesh.rects.len()),
            ),
            ("control points", r.fit.mesh.n_control_points().to_string()),
            (
                "cells / Bézier patches (elements: cells merged where one polynomial)",
                format!("{cells} / {}", r.patches.len()),
            ),
            ("T-junctions", r.fit.mesh.n_t_junctions().to_string()),
            ("fit steps", r.fit.steps.len().to_string()),
            (
                "error rms / L∞ (% of the longest side)",
                format!("{rms:.4} / {max:.4}"),
            ),
            (
                "distance to the triangles between the vertices, max / rms (%)",
                format!(
                    "{:.3} / {:.4}",
                    num(&rep["max_deviation_between_vertices_percent"]),
                    num(&rep["rms_deviation_between_vertices_percent"])
                ),
            ),
            (
                "normal angle along the sides at the zeros (degrees)",
                format!("{:.1e}", num(&c["normal_angle_at_zeros_degrees"])),
            ),
            (
                "tolerance L∞",
                format!("{:.1} %, converged: {}", 100.0 * tolerance, r.fit.converged),
            ),
            (
                "data points without a cylinder (on a critical level)",
                rep["unassigned_points"].to_string(),
            ),
            (
                "continuity at the zeros",
                format!("{} ({} sides)", class("at_zeros"), sides("at_zeros")),
            ),
            ("relative jumps at the zeros, orders 0..3", e("at_zeros")),
            (
                "continuity one interval from a zero",
                format!(
                    "{} ({} sides)",
                    class("one_interval_from_zeros"),
                    sides("one_interval_from_zeros")
                ),
            ),
            (
                "relative jumps there, orders 0..3",
                e("one_interval_from_zeros"),
            ),
            (
                "continuity elsewhere",
                format!("{} ({} sides)", class("elsewhere"), sides("elsewhere")),
            ),
            ("relative jumps elsewhere, orders 0..3", e("elsewhere")),
            (
                "time (fit and continuity; total)",
                format!("{:.2}; {:.2} s", seconds[0], seconds[1]),
            ),
        ],
    )
}
