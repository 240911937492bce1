//! Demo stage `pou`: the partition-of-unity surface over the hyperbolic structure (paper 004,
//! `ricci::spline::pou`, `ricci pou`) of the built-in genus-2 surface, drawn with the same
//! zebra views as the manifold spline's stage so the two can be compared picture by picture:
//! the spline has an extraordinary point with a G¹ fill, this surface has none.

use super::report::{Picture, Section, Status, Table};
use super::Ctx;
use super::Env;
use ricci::spline::pou::{run, PouOptions};
use ricci_render::{render, Image, Paint, RenderOptions, Style, View};
use serde_json::json;

/// The size and views of the spline stage's zebra pictures.
const RENDER_W: u32 = 760;
const RENDER_H: u32 = 520;

fn opts(view: View) -> RenderOptions {
    RenderOptions {
        width: RENDER_W,
        height: RENDER_H,
        supersample: 3,
        view,
        ..RenderOptions::default()
    }
}

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
pub fn pou(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("pou", "", "");
    let s = ctx
        .surface
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("no surface"))?;
    env.bar
        .step("hyperbolic atlas, bases, local quadratics, fit, checks");
    let popts = PouOptions {
        tessellation: 8,
        ..PouOptions::default()
    };
    let mut progress = ricci::progress::NoProgress;
    let (rep, tess, _) = run(s, &popts, &mut progress)?;

    env.bar.step("partition-of-unity pictures");
    let views = [
        (
            "pou-zebra.png",
            View::default(),
            "Reflection lines (zebra) on the partition-of-unity surface, the view of the spline stage's first zebra picture: no extraordinary point, no fill patch.",
        ),
        (
            "pou-zebra-back.png",
            View {
                eye_direction: [-0.4, -0.3, -1.0],
                ..View::default()
            },
            "From behind, the view of the spline stage's second zebra picture (where the spline has its extraordinary point and fill patch): the stripes run on without a special point.",
        ),
    ];
    for (file, view, caption) in views {
        let st = Style {
            paint: Paint::Zebra(ricci_render::Zebra {
                stripes: 8.0,
                ..ricci_render::Zebra::default()
            }),
            ..Style::default()
        };
        let img = render(&tess.positions, &tess.triangles, &st, &opts(view))?;
        sec.pictures.push(png(env, file, &img.image, caption)?);
    }
    let mut obj = String::from("# ricci demo: partition-of-unity surface (tessellation)\n");
    for p in &tess.positions {
        obj.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
    }
    for t in &tess.triangles {
        obj.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    env.out.write("pou.obj", obj.as_bytes())?;

    let j = &rep.continuity.relative_jumps;
    if j.iter().any(|x| *x > rep.continuity.tolerance)
        || rep
            .chart_independence
            .relative
            .iter()
            .any(|x| *x > rep.continuity.tolerance)
    {
        sec.status = Status::Warning(format!(
            "derivatives differ between charts: jumps {j:?}, chart independence {:?}",
            rep.chart_independence.relative
        ));
    }
    sec.headline = format!(
        "{}, {} control points, rms error {:.3}% of the diagonal, no extraordinary point",
        rep.continuity.class, rep.control_points, rep.rms_error_percent
    );
    sec.paragraphs.push(format!(
        "The hyperbolic metric of the surface gives charts in the Poincaré disk with Möbius \
         transitions. Every vertex carries a C∞ bump of the hyperbolic distance on a disk that \
         covers its two-ring and a local quadratic in its own chart; normalized, the bumps are a \
         partition of unity and the surface is F = Σ wᵢ (Pᵢ + Qᵢ). The quadratics are fitted \
         to the mesh around each vertex, the constants Pᵢ by least squares with a thin-plate \
         term. Everything is measured in hyperbolic distance, so F is the same in every chart and \
         C∞ everywhere: compare its zebra stripes with the spline stage's (same views), whose \
         extraordinary point needs a G¹ fill. Derivative jumps across chart boundaries are \
         measured up to order 3 at {} points.",
        rep.continuity.samples
    ));
    let e = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:.1e}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    sec.tables.push(Table::key_values(
        "Partition-of-unity surface (ricci pou)",
        vec![
            (
                "radius factor, local degree, fit smoothing",
                format!(
                    "{}, {}, {:e}",
                    rep.radius_factor, rep.local_degree, popts.fit.smoothing
                ),
            ),
            ("extraordinary points", "none".into()),
            ("control points", rep.control_points.to_string()),
            (
                "bases per chart (mean)",
                format!("{:.1}", rep.mean_controls_per_chart),
            ),
            ("continuity", rep.continuity.class.clone()),
            ("relative derivative jumps, orders 0..3", e(j)),
            (
                "chart independence, orders 0..2",
                e(&rep.chart_independence.relative),
            ),
            (
                "distance to the input mesh (rms / max, % of diagonal)",
                format!(
                    "{:.4} / {:.4}",
                    rep.rms_error_percent, rep.max_error_percent
                ),
            ),
            (
                "time (atlas, charts, fit, checks; total)",
                format!(
                    "{:.2}, {:.2}, {:.2}, {:.2}; {:.2} s",
                    rep.seconds_atlas,
                    rep.seconds_charts,
                    rep.seconds_fit,
                    rep.seconds_checks,
                    rep.seconds
                ),
            ),
        ],
    ));
    sec.files = vec![(
        "pou.obj".into(),
        "the tessellated partition-of-unity surface".into(),
    )];
    sec.commands = vec!["ricci pou surface.off --tessellation 8 --out pou --json".into()];
    sec.summary = json!({
        "control_points": rep.control_points,
        "local_degree": rep.local_degree,
        "rms_error_percent": rep.rms_error_percent,
        "max_error_percent": rep.max_error_percent,
        "continuity": rep.continuity,
        "chart_independence": rep.chart_independence.relative,
        "tessellation_vertices": tess.positions.len(),
        "tessellation_triangles": tess.triangles.len(),
        "seconds": rep.seconds,
    });
    Ok(sec)
}
