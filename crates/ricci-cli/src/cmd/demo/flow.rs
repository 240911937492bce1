//! Stage `flow`: hyperbolic uniformization of the surface by the default conformal scheme
//! (discrete conformal equivalence in H², Gu–Luo–Sun–Wu 2018; paper 001 §V, paper 002 §4.3):
//! residual history, curvature before and after, the metric as JSON.

use super::common::*;
use super::report::{num, Section, Status, Table};
use super::Env;
use crate::cmd::flow::metric_json;
use ricci::flow::{flow_with_fallback, TargetSpec, UniformizationOptions};
use ricci::metric::{Geometry, Scheme};
use ricci_render::{fields, render, Colormap, Paint, Scalar, ScalarRange, Style, View};
use std::f64::consts::PI;

pub fn hyperbolic_flow(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("flow", "", "");
    let s = ctx.surface()?;
    // The default scheme of `ricci flow` (discrete conformal equivalence): the conformal
    // class of the surface's own polyhedral metric.
    let opts_flow = UniformizationOptions::single(
        Some(Geometry::Hyperbolic),
        Scheme::Conformal,
        FLOW_TOLERANCE,
    )
    .with_target(TargetSpec::Uniform);
    let r = flow_with_fallback(&s.mesh, &s.edge_lengths(), &opts_flow, None, env.bar)?.result;
    // The later stages cut and lay out the surface with these lengths, on its own faces: the
    // intrinsic Delaunay triangulation must be the input's (no flip, no split; so it is on
    // the isotropic built-in surface).
    let (flips, splits) = r
        .triangulation
        .as_ref()
        .map_or((0, 0), |t| (t.initial_flips + t.flips, t.splits));
    if let Some(t) = &r.triangulation {
        if t.simplicial.mesh.faces() != s.mesh.faces() {
            anyhow::bail!(
                "the conformal flow's intrinsic Delaunay triangulation differs from the surface's \
                 ({flips} flips, {splits} splits), and the later stages need the metric on the \
                 surface's own triangles; try: ricci demo with another --resolution"
            );
        }
    }
    if !r.converged {
        sec.status = Status::Warning(format!(
            "the flow did not converge: max |K − K̄| = {:.3e} > {:.0e} after {} steps",
            r.max_curvature_error, r.tolerance, r.iterations
        ));
    }
    env.bar.step("pictures");
    sec.paragraphs.push(format!(
        "Scheme: discrete conformal equivalence (`conformal`, the default of `ricci flow`; \
         Gu–Luo–Sun–Wu 2018): vertex scaling sinh(l/2) = e^((u_i+u_j)/2) sinh(l⁰/2) of the \
         surface's own edge lengths on the intrinsic Delaunay triangulation of the current \
         metric ({flips} flips and {splits} splits were needed here: the isotropic surface is \
         Delaunay throughout), solved by Newton's method (sparse Cholesky) down to \
         max |K − K̄| ≤ {:.0e}. Every vertex gets angle sum 2π, so the hyperbolic area is \
         −2πχ = {:.6} by Gauss–Bonnet. (The papers' Thurston circle packing computes the \
         structure of a nearby surface; `--scheme thurston` runs it.)",
        r.tolerance,
        -2.0 * PI * ctx.chi as f64
    ));
    let plot = residual_plot(&r, "H² flow (conformal scheme): max |K − K̄| (rad)")?;
    sec.pictures.push(figure(
        env,
        "flow-residuals",
        &plot,
        "Residual history (log scale): quadratic convergence of Newton's method.",
        true,
    )?);
    // Curvature before (the embedding's angle defect) and after (the hyperbolic metric's),
    // on one colour scale.
    let before = fields::angle_defect(&s.positions, s.mesh.faces())?;
    let mut abs: Vec<f64> = before.iter().map(|k| k.abs()).collect();
    abs.sort_by(f64::total_cmp);
    let m = abs
        .get((abs.len() * 99 / 100).min(abs.len().saturating_sub(1)))
        .copied()
        .unwrap_or(1.0)
        .max(1e-6);
    for (file, values, caption) in [
        (
            "curvature-before.png",
            &before,
            "Curvature before: angle defect 2π − Σθ of the embedded surface (rad).",
        ),
        (
            "curvature-after.png",
            &r.curvature,
            "Curvature after: 2π − Σθ of the hyperbolic metric, same scale — zero everywhere.",
        ),
    ] {
        let st = Style {
            paint: Paint::Scalar(Scalar {
                range: ScalarRange::Fixed(-m, m),
                label: "angle defect (rad)".into(),
                ..Scalar::per_vertex(values, Colormap::CoolWarm)
            }),
            legend: true,
            ..Style::default()
        };
        let img = render(&s.positions, s.mesh.faces(), &st, &opts(View::default()))?;
        sec.pictures.push(png(env, file, &img.image, caption)?);
    }
    let metric = metric_json(&r, &s.mesh, "surface.off");
    env.out.write(
        "hyperbolic-metric.json",
        serde_json::to_string(&metric)?.as_bytes(),
    )?;
    sec.tables.push(Table::key_values(
        "Result",
        vec![
            ("scheme / solver", format!("{} / {}", r.scheme, r.solver)),
            ("Newton steps", r.iterations.to_string()),
            ("converged", r.converged.to_string()),
            ("max |K − K̄|", format!("{:.3e}", r.max_curvature_error)),
            (
                "Gauss–Bonnet error",
                format!("{:.3e}", r.gauss_bonnet_error),
            ),
            ("hyperbolic area", num(r.area)),
            ("area − 4π", format!("{:.3e}", r.area - 4.0 * PI)),
            ("intrinsic flips / splits", format!("{flips} / {splits}")),
            ("time (s)", format!("{:.3}", r.seconds)),
        ],
    ));
    sec.tables.push(history_table(&r));
    sec.files = vec![(
        "hyperbolic-metric.json".into(),
        "the metric: u, K, K̄ per vertex, lengths per edge (as `ricci flow --out` writes it)".into(),
    )];
    sec.commands = vec![
        format!("ricci flow surface.off --tolerance {FLOW_TOLERANCE:.0e} --out hyperbolic-metric.json"),
        "ricci render surface.off --scalar angle-defect --out curvature-before.png".into(),
        "ricci render surface.off --scalar hyperbolic-metric.json:curvature --out curvature-after.png".into(),
    ];
    sec.headline = format!(
        "{} Newton steps to max |K − K̄| = {:.1e}; hyperbolic area − 4π = {:.1e}",
        r.iterations,
        r.max_curvature_error,
        r.area - 4.0 * PI
    );
    sec.summary = flow_summary(&r);
    ctx.hyperbolic = Some(r);
    Ok(sec)
}
