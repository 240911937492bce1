//! Demo stage `param`: the conformal UV map of the built-in surface with its cones
//! (`ricci param`, `ricci::param::parametrize`): greedy cones, conformal flow with intrinsic
//! Delaunay flips, cut through the cones and the handles, UVs on the surface's own faces.

use super::report::{Picture, Section, Table};
use super::{Ctx, Env};
use ricci::layout::export::obj_with_corner_uv;
use ricci::param::svg::uv_svg;
use ricci::param::{parametrize, ConeSpec, ParamOptions};
use ricci::progress::NoProgress;
use ricci_render::render::Uvs;
use ricci_render::{render, Checker, Paint, RenderOptions, Style, View};
use serde_json::json;

/// Cones of the demo's map (genus 2: Gauss–Bonnet asks for 2πχ = −4π in all).
const DEMO_CONES: usize = 8;

pub fn param(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("param", "", "");
    let s = ctx
        .surface
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("no surface"))?;
    env.bar
        .step("conformal UV map: greedy cones, conformal flow with flips, cut, layout");
    let opts = ParamOptions {
        cones: ConeSpec::Count(DEMO_CONES),
        ..ParamOptions::default()
    };
    let p = parametrize(s, &opts, &mut NoProgress)?;
    let c = &p.charts[0];
    let cones: Vec<u32> = c.cones.iter().map(|c| c.vertex).collect();
    env.out.write(
        "param-uv.svg",
        uv_svg(&s.mesh, &p.corner_uv, &p.seam, &cones, 720.0, 300_000).as_bytes(),
    )?;
    let st = Style {
        paint: Paint::Checker(Checker::new(Uvs::PerCorner(&p.corner_uv), 24.0)),
        ..Style::default()
    };
    let img = render(
        &s.positions,
        s.mesh.faces(),
        &st,
        &RenderOptions {
            width: 720,
            height: 540,
            supersample: 3,
            view: View::default(),
            ..RenderOptions::default()
        },
    )?;
    env.out.write("param-checker.png", &img.image.to_png()?)?;
    sec.pictures.push(Picture {
        file: "param-checker.png".into(),
        caption: "Checkerboard of the UV map on the surface: conformal, so the checks are \
                  squares; their size changes only slowly (the cones take the curvature). \
                  Across the seams (the cut through the cones) the checks do not line up: the \
                  UVs of the two sides differ by a rotation and a translation."
            .into(),
        width: img.image.width,
        height: img.image.height,
        // The UV layout itself (cones red, seams blue), linked below the picture.
        alternatives: vec!["param-uv.svg".into()],
    });
    let comments = vec!["ricci param of the demo surface".to_string()];
    env.out.write(
        "param-uv.obj",
        obj_with_corner_uv(&s.positions, s.mesh.faces(), &p.corner_uv, &comments).as_bytes(),
    )?;
    sec.tables.push(Table::key_values(
        "Conformal UV map",
        vec![
            ("cones", c.cones.len().to_string()),
            (
                "cone angles (°)",
                c.cones
                    .iter()
                    .map(|c| format!("{:.1}", c.angle.to_degrees()))
                    .collect::<Vec<_>>()
                    .join(", "),
            ),
            ("flipped faces", p.stats.flipped_faces.to_string()),
            (
                "qc mean / p95 / max",
                format!(
                    "{:.4} / {:.4} / {:.4}",
                    p.stats.qc_mean, p.stats.qc_p95, p.stats.qc_max
                ),
            ),
            (
                "σ(log area ratio)",
                format!("{:.4}", p.stats.log_area_sigma),
            ),
            ("seam length", format!("{:.4}", c.seam_length)),
            ("intrinsic flips", c.flips.to_string()),
            ("seconds", format!("{:.3}", p.seconds)),
        ],
    ));
    sec.files = vec![
        (
            "param-uv.obj".into(),
            "the surface with its UVs (`f v/vt`)".into(),
        ),
        ("param-uv.svg".into(), "the UV layout".into()),
    ];
    sec.commands = vec![format!(
        "ricci param surface.off --cones {DEMO_CONES} --out param-uv.obj --svg param-uv.svg --json"
    )];
    sec.summary = json!({
        "cones": c.cones, "flipped_faces": p.stats.flipped_faces, "qc_mean": p.stats.qc_mean,
        "qc_p95": p.stats.qc_p95, "qc_max": p.stats.qc_max,
        "log_area_sigma": p.stats.log_area_sigma, "seam_length": c.seam_length,
        "seconds": p.seconds,
    });
    sec.headline = format!(
        "{} cones, 0 of {} faces flipped: {}, qc p95 {:.3}",
        c.cones.len(),
        s.mesh.n_faces(),
        if p.stats.flipped_faces == 0 {
            "valid"
        } else {
            "NOT valid"
        },
        p.stats.qc_p95
    );
    Ok(sec)
}
