//! Stage `cone`: a flat metric with all curvature 2πχ on one vertex (Thurston circle
//! packing, paper 000 §4 Steps 2–3): the Chow–Luo refusal on the unrefined surface, the
//! valence raise and grading that meet it, and the flow on the refined mesh.

use super::common::*;
use super::report::{num, Section, Status, Table};
use super::Env;
use crate::cmd::flow::metric_json;
use ricci::flow::{flow_with_fallback, FlowResult, TargetSpec, UniformizationOptions};
use ricci::mesh::Surface;
use ricci::metric::refine::{Refined, Refiner};
use ricci::metric::{Geometry, Scheme};
use ricci_render::{render, Colormap, Paint, Scalar, Style, View};
use serde_json::json;
use std::f64::consts::PI;

pub fn single_cone(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("cone", "", "");
    let s = ctx.surface()?;
    let chi = ctx.chi;
    let k_cone = 2.0 * PI * chi as f64;
    // The cone vertex: the one farthest out along the chain of handles (x largest), away from
    // the blend between the tori. (The affine atlas chooses it by area distortion instead.)
    let v = (0..s.mesh.n_vertices() as u32)
        .filter(|&v| !s.mesh.is_isolated(v))
        .max_by(|&a, &b| s.positions[a as usize][0].total_cmp(&s.positions[b as usize][0]))
        .ok_or_else(|| anyhow::anyhow!("the surface has no vertex"))?;
    let valence_before = s.mesh.valence(v);
    // Without the refinement the flow refuses the target (Chow–Luo); show its reason.
    env.bar.step("the target on the unrefined surface");
    let lengths = s.edge_lengths();
    let o =
        UniformizationOptions::single(Some(Geometry::Euclidean), Scheme::Thurston, FLOW_TOLERANCE)
            .with_target(TargetSpec::SingleCone(Some(v)));
    let refusal = match flow_with_fallback(&s.mesh, &lengths, &o, None, env.bar) {
        Err(e) => Some(e.to_string()),
        Ok(_) => None,
    };
    env.bar.step(&format!(
        "raising the valence of vertex {v} to {CONE_VALENCE} and grading around it"
    ));
    let (refined, raised, graded) = refine_around(s, &lengths, v)?;
    let valence_after = refined.mesh.valence(v);
    let r = flow_with_fallback(&refined.mesh, &refined.lengths, &o, None, env.bar)?.result;
    if !r.converged {
        sec.status = Status::Warning(format!(
            "the flow did not converge: max |K − K̄| = {:.3e} > {:.0e} after {} steps",
            r.max_curvature_error, r.tolerance, r.iterations
        ));
    }
    let k_at_cone = r.curvature[v as usize];
    let max_elsewhere = max_curvature_elsewhere(&r, v);
    env.bar.step("pictures");
    sec.paragraphs.push(format!(
        "All the curvature 2πχ = {k_cone:.6} on one vertex, flat everywhere else (paper 000). A \
         vertex of valence {valence_before} cannot carry it: the Chow–Luo condition asks for \
         valence ≥ 4 − 2K̄/π = {:.0}, and the flow refuses the target otherwise. So its valence \
         is first raised to at least {CONE_VALENCE} by intrinsic edge splits (they keep the metric \
         exactly) and the mesh is graded around it ({} splits in all), then the Euclidean flow \
         runs on the refined mesh.",
        4.0 - 2.0 * k_cone / PI,
        raised + graded
    ));
    sec.paragraphs.push(
        "Scheme: Thurston circle packing, the papers' scheme (paper 000 §4), on purpose: this \
         stage shows its Chow–Luo condition and the refinement that meets it. (The default \
         `conformal` scheme, which flips edges instead, has no such condition.)"
            .into(),
    );
    sec.paragraphs.push(match &refusal {
        Some(e) => format!(
            "On the unrefined surface, `ricci flow surface.off --target single-cone:{v}` \
             refuses: {e}"
        ),
        None => format!(
            "(The unrefined surface was not refused the target single-cone:{v}; the \
             refinement is done all the same.)"
        ),
    });
    let plot = residual_plot(&r, "E² with one cone (Thurston): max |K − K̄| (rad)")?;
    sec.pictures.push(figure(
        env,
        "cone-residuals",
        &plot,
        "Residual history of the flat flow with one cone (log scale).",
        true,
    )?);
    if let Some(p) = &refined.positions {
        let st = Style {
            paint: Paint::Scalar(Scalar {
                label: "u = log(radius)".into(),
                ..Scalar::per_vertex(&r.u, Colormap::Viridis)
            }),
            legend: true,
            ..Style::default()
        };
        let img = render(p, refined.mesh.faces(), &st, &opts(View::default()))?;
        sec.pictures.push(png(
            env,
            "cone-factor.png",
            &img.image,
            "Conformal factor u = log γ of the flat metric: the circles shrink towards the cone.",
        )?);
    }
    let metric = metric_json(&r, &refined.mesh, "surface.off refined around the cone");
    env.out.write(
        "cone-metric.json",
        serde_json::to_string(&metric)?.as_bytes(),
    )?;
    sec.tables.push(result_table(
        &r,
        &refined,
        v,
        (valence_before, valence_after),
        raised + graded,
        k_cone,
    ));
    sec.tables.push(history_table(&r));
    sec.files = vec![(
        "cone-metric.json".into(),
        "the flat metric with one cone on the refined mesh (u, K, K̄, lengths)".into(),
    )];
    sec.headline = format!(
        "K = {k_at_cone:.6} at vertex {v} (valence {valence_before} → {valence_after}), |K| ≤ {max_elsewhere:.1e} elsewhere; {} Newton steps",
        r.iterations
    );
    // (`--scheme thurston` on the unrefined surface is the refusal quoted above.)
    sec.commands = vec![
        format!("ricci flow surface.off --target single-cone:{v} --out cone-conformal.json"),
        format!("ricci atlas surface.off --singularity {v} --out atlas-{v}"),
    ];
    sec.summary = cone_summary(
        &r,
        &refined,
        v,
        refusal,
        (valence_before, valence_after),
        raised + graded,
        k_cone,
    );
    ctx.cone = Some((refined, r, v));
    Ok(sec)
}

/// Raise the valence of `v` to [`CONE_VALENCE`] by metric-preserving splits and grade the mesh
/// around it: the refined surface and the numbers of raising and grading splits.
fn refine_around(s: &Surface, lengths: &[f64], v: u32) -> anyhow::Result<(Refined, usize, usize)> {
    let valence_before = s.mesh.valence(v);
    let mut rf = Refiner::new(&s.mesh, lengths, Geometry::Euclidean, Some(&s.positions))?;
    let raised = rf.raise_valence(v, CONE_VALENCE)?;
    let mean_spoke = {
        let sum: f64 = s
            .mesh
            .outgoing(v)
            .map(|h| lengths[s.mesh.he_edge(h) as usize])
            .sum();
        sum / valence_before.max(1) as f64
    };
    let theta = rf.cone_angle(v);
    let radius = 1.5 * CONE_VALENCE as f64 * mean_spoke / theta.max(1e-3);
    let graded = rf.grade_around(
        v,
        CONE_VALENCE,
        radius,
        40 * CONE_VALENCE * CONE_VALENCE + 1000,
    )?;
    let refined = rf.finish()?;
    Ok((refined, raised, graded))
}

/// The stage's result table.
fn result_table(
    r: &FlowResult,
    refined: &Refined,
    v: u32,
    (valence_before, valence_after): (usize, usize),
    splits: usize,
    k_cone: f64,
) -> Table {
    let k_at_cone = r.curvature[v as usize];
    let max_elsewhere = max_curvature_elsewhere(r, v);
    Table::key_values(
        "Result",
        vec![
            ("cone vertex", v.to_string()),
            (
                "valence before → after",
                format!("{valence_before} → {valence_after}"),
            ),
            ("edge splits", splits.to_string()),
            (
                "refined mesh (V / F)",
                format!("{} / {}", refined.mesh.n_vertices(), refined.mesh.n_faces()),
            ),
            ("target 2πχ", num(k_cone)),
            ("curvature at the cone", num(k_at_cone)),
            ("max |K| elsewhere", format!("{max_elsewhere:.3e}")),
            ("Newton steps", r.iterations.to_string()),
            ("converged", r.converged.to_string()),
            ("max |K − K̄|", format!("{:.3e}", r.max_curvature_error)),
            (
                "Gauss–Bonnet error",
                format!("{:.3e}", r.gauss_bonnet_error),
            ),
            ("time (s)", format!("{:.3}", r.seconds)),
        ],
    )
}

/// The stage's JSON summary: the flow's, and the cone, the refusal and the refinement.
fn cone_summary(
    r: &FlowResult,
    refined: &Refined,
    v: u32,
    refusal: Option<String>,
    (valence_before, valence_after): (usize, usize),
    splits: usize,
    k_cone: f64,
) -> serde_json::Value {
    let mut summary = flow_summary(r);
    summary["cone_vertex"] = json!(v);
    summary["refused_without_refinement"] = json!(refusal);
    summary["cone_curvature"] = json!(r.curvature[v as usize]);
    summary["target_cone_curvature"] = json!(k_cone);
    summary["max_curvature_elsewhere"] = json!(max_curvature_elsewhere(r, v));
    summary["valence_before"] = json!(valence_before);
    summary["valence_after"] = json!(valence_after);
    summary["splits"] = json!(splits);
    summary["refined_vertices"] = json!(refined.mesh.n_vertices());
    summary["refined_faces"] = json!(refined.mesh.n_faces());
    summary
}

/// max |K| over the vertices other than the cone `v`.
fn max_curvature_elsewhere(r: &FlowResult, v: u32) -> f64 {
    r.curvature
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != v as usize)
        .map(|(_, k)| k.abs())
        .fold(0.0, f64::max)
}
