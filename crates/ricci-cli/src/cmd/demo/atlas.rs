//! Stage `atlas`: the affine atlas with one extraordinary point — cone placement by least
//! area distortion, connectivity modification, flat cone metric, charts and rigid transitions
//! (paper 000 §4 Steps 1–5, paper 002 §5.2).

use super::common::*;
use super::report::{Section, Status, Table};
use super::Env;
use crate::cmd::atlas::svg as atlas_svg;
use ricci::atlas::{AffineAtlas, AtlasOptions, AtlasReport, FlatCharts};
use ricci::metric::Geometry;
use ricci::progress::NoProgress;
use ricci_render::plot::{face_colors, layout_figure, ColorBar, LayoutCopy, LayoutPlot};
use ricci_render::render::Uvs;
use ricci_render::{render, Checker, Colormap, Paint, Style, View};
use serde_json::json;
use std::f64::consts::PI;

/// Checks across the central chart in the atlas's checkerboard picture.
const ATLAS_CHECKS: f64 = 24.0;

/// The affine atlas with one extraordinary point: automatic cone placement by least area
/// distortion, connectivity modification, flat metric with all of 2πχ on the cone, canonical
/// cut through it, central chart + cut charts with rigid transitions.
pub fn atlas(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("atlas", "", "");
    let s = ctx.surface()?;
    env.bar
        .step("affine atlas: cone placement, refinement, flat metric, cut, charts");
    let atlas = AffineAtlas::build(s, &AtlasOptions::default(), &mut NoProgress)?;
    let r = &atlas.report;
    let cone = r.singular_vertices.first().copied();
    let mesh = atlas.mesh();
    let faces = mesh.faces();
    let pos = atlas.positions();

    let (corner_uv, outside, extent) = central_chart(&atlas);

    let (log_ratio, spread) = area_distortion(&corner_uv, faces, pos);

    env.bar.step("atlas pictures");
    // The central chart in the plane, faces coloured by log area ratio.
    let tris: Vec<[u32; 3]> = (0..faces.len() as u32)
        .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
        .collect();
    let mut copy = LayoutCopy::new(&corner_uv, &tris);
    copy.face_colors = Some(face_colors(
        &log_ratio,
        Colormap::CoolWarm,
        (-spread, spread),
    ));
    copy.edges = None;
    let mut plot = LayoutPlot::new(copy);
    plot.colorbar = Some(ColorBar {
        colormap: Colormap::CoolWarm,
        range: (-spread, spread),
        label: "log(flat / R³ area)".into(),
    });
    plot.title = "Central chart (flat, cone at the corners)".into();
    plot.size = 720.0;
    let fig = layout_figure(&plot)?;
    sec.pictures.push(figure(
        env,
        "atlas-chart",
        &fig,
        &format!(
            "The central chart: the surface cut through the cone vertex and laid out with its flat metric; every corner of the polygon is the cone. Colour (bar at the right): log of the area ratio flat / R³, centred on the median; blue = shrunk, red = enlarged, clamped at ±{spread:.2} (the 98th percentile: the faces at the cone shrink to a point)."
        ),
        true,
    )?);
    // Checkerboard of the flat chart on the surface: conformal, and uniform in scale away
    // from the cone — the picture of paper 000 Fig. 9.
    for (file, view, caption) in [
        (
            "atlas-checker.png",
            View::default(),
            "Checkerboard of the central chart on the surface: the flat metric is conformal to the surface's, so the checks are squares; all the curvature sits at one point. Across the cut curves the checks jump: the charts on the two sides differ by a rotation (the holonomy of the flat cone metric).",
        ),
        (
            "atlas-checker-back.png",
            back_view(),
            "The same texture from behind.",
        ),
    ] {
        let st = Style {
            paint: Paint::Checker(Checker::new(
                Uvs::PerCorner(&corner_uv),
                ATLAS_CHECKS / extent,
            )),
            ..Style::default()
        };
        let img = render(pos, faces, &st, &opts(view))?;
        sec.pictures.push(png(env, file, &img.image, caption)?);
    }
    env.out.write(
        "atlas-overview.svg",
        atlas_svg::overview_svg(&atlas, 900.0).as_bytes(),
    )?;
    if let Some(p) = sec.pictures.first_mut() {
        p.alternatives.push("atlas-overview.svg".into());
    }

    let status_notes = status_notes(r, outside);
    if !status_notes.is_empty() {
        sec.status = Status::Warning(status_notes.join("; "));
    }
    sec.headline = format!(
        "one cone at vertex {}, {} charts, transitions rigid to {:.1e}",
        cone.map(|v| v.to_string()).unwrap_or_else(|| "—".into()),
        r.charts.len(),
        r.max_transition_error
    );
    sec.paragraphs.push(format!(
        "An affine structure needs at least one singular point on a surface of genus ≥ 2. The \
         cone vertex is chosen by least area distortion (linearized flow for every vertex, the \
         best {} confirmed by full flows), its valence is raised by metric-preserving edge \
         splits (Chow–Luo: ≥ 4 − 2K̄/π), and the Euclidean Ricci flow puts all of 2πχ = {:.4} on it. \
         The charts — the fundamental domain cut through the cone, and charts across the cut \
         curves — cover every point but the cone; their transition maps are rigid motions.",
        r.placement.as_ref().map(|p| p.confirmed.len()).unwrap_or(0),
        2.0 * PI * ctx.chi as f64
    ));
    sec.tables.push(atlas_table(r, cone));
    if let Some(p) = &r.placement {
        let mut pt = Table::new(
            "Cone placement: candidates confirmed by full flows",
            &["vertex", "linearized estimate", "measured distortion"],
        );
        for c in &p.confirmed {
            pt.row(vec![
                c.vertex.to_string(),
                format!("{:.4}", c.estimate),
                format!("{:.4}", c.measured),
            ]);
        }
        sec.tables.push(pt);
    }
    sec.files = vec![(
        "atlas-overview.svg".into(),
        "every chart, each placed by one transition from the central chart".into(),
    )];
    sec.commands = vec!["ricci atlas surface.off --out atlas --json".into()];
    sec.summary = json!({
        "singular_vertex": cone,
        "charts": r.charts.len(),
        "max_transition_error": r.max_transition_error,
        "area_distortion": r.area_distortion,
        "flipped_faces": r.flipped_faces,
        "max_curvature_error": r.max_curvature_error,
        "gauss_bonnet_error": r.gauss_bonnet_error,
        "flow_converged": r.flow_converged,
        "faces_without_home": r.faces_without_home,
        "cone_curvature": cone.map(|v| {
            ricci::metric::curvature(atlas.mesh(), Geometry::Euclidean, atlas.lengths())[v as usize]
        }),
        "refined_vertices": r.refinement.vertices_after,
    });
    ctx.atlas = Some(atlas);
    Ok(sec)
}

/// The central chart (chart 0 holds every face once) as per-corner coordinates (NaN for a
/// face it misses), the number of faces it misses, and its extent (largest side of its box).
fn central_chart(atlas: &AffineAtlas) -> (Vec<[f64; 2]>, usize, f64) {
    let faces = atlas.mesh().faces();
    let mut corner_uv: Vec<[f64; 2]> = Vec::with_capacity(3 * faces.len());
    let mut outside = 0usize;
    for f in 0..faces.len() as u32 {
        match atlas.face_coords(0, f) {
            Some(c) => corner_uv.extend(c),
            None => {
                outside += 1;
                corner_uv.extend([[f64::NAN; 2]; 3]);
            }
        }
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in corner_uv.iter().filter(|p| p[0].is_finite()) {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
    (corner_uv, outside, extent)
}

/// Area distortion per face: log(flat area / R³ area), centred on the median (the flat
/// metric's scale is arbitrary), the measure of paper 000 Step 1 before squaring; and the
/// symmetric colour range for it.
fn area_distortion(
    corner_uv: &[[f64; 2]],
    faces: &[[u32; 3]],
    pos: &[[f64; 3]],
) -> (Vec<f64>, f64) {
    let area = |p: [[f64; 3]; 3]| {
        let (u, v) = (
            [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]],
            [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]],
        );
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
    };
    let mut log_ratio: Vec<f64> = (0..faces.len())
        .map(|f| {
            let c = &corner_uv[3 * f..3 * f + 3];
            let flat = 0.5
                * ((c[1][0] - c[0][0]) * (c[2][1] - c[0][1])
                    - (c[2][0] - c[0][0]) * (c[1][1] - c[0][1]))
                    .abs();
            let t = faces[f];
            let a3 = area([pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]]);
            (flat / a3).ln()
        })
        .collect();
    // Centred on the median: the faces at the cone, shrunk towards a point, skew the mean.
    let mut finite: Vec<f64> = log_ratio
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .collect();
    finite.sort_by(f64::total_cmp);
    let mean = finite.get(finite.len() / 2).copied().unwrap_or(0.0);
    for x in &mut log_ratio {
        *x -= mean;
    }
    // Symmetric colour range at the 98th percentile of |log ratio| (the faces next to the
    // cone, where the flat metric shrinks to a point, would wash out the rest).
    let mut dev: Vec<f64> = finite.iter().map(|x| (x - mean).abs()).collect();
    dev.sort_by(f64::total_cmp);
    let spread = dev
        .get((dev.len() as f64 * 0.98) as usize)
        .or(dev.last())
        .copied()
        .unwrap_or(0.0)
        .max(1e-12);
    (log_ratio, spread)
}

/// What is wrong with the atlas, if anything (for the stage's warning).
fn status_notes(r: &AtlasReport, outside: usize) -> Vec<String> {
    let mut status_notes = Vec::new();
    if r.flipped_faces > 0 {
        status_notes.push(format!("{} flipped faces in the charts", r.flipped_faces));
    }
    if !r.flow_converged {
        status_notes.push("the flat flow did not converge".to_string());
    }
    if r.faces_without_home > 0 {
        status_notes.push(format!(
            "{} faces without a home chart",
            r.faces_without_home
        ));
    }
    if outside > 0 {
        status_notes.push(format!("{outside} faces missing from the central chart"));
    }
    status_notes
}

/// The atlas's report as a table.
fn atlas_table(r: &AtlasReport, cone: Option<u32>) -> Table {
    let kinds = |k: &str| r.charts.iter().filter(|c| c.kind == k).count();
    let mut t = Table::key_values(
        "Affine atlas",
        vec![
            (
                "singular vertex",
                cone.map(|v| v.to_string()).unwrap_or_else(|| "none".into()),
            ),
            (
                "area distortion Σ(log S − log s)²/n",
                format!("{:.4}", r.area_distortion),
            ),
            (
                "refinement",
                format!(
                    "{} → {} vertices ({} + {} + {} + {} splits, {} flips; {} vertices \
                     within 3 rings below valence 6)",
                    r.refinement.vertices_before,
                    r.refinement.vertices_after,
                    r.refinement.splits_step2,
                    r.refinement.splits_cut,
                    r.refinement.splits_ring,
                    r.refinement.splits_ring_room,
                    r.refinement.flips_ring,
                    r.refinement.low_valence_after
                ),
            ),
            (
                "flat flow",
                format!(
                    "{} ({} steps, max |K − K̄| = {:.1e}, Gauss–Bonnet {:.1e})",
                    r.scheme, r.flow_iterations, r.max_curvature_error, r.gauss_bonnet_error
                ),
            ),
            (
                "charts",
                format!(
                    "{} (central {}, cut {})",
                    r.charts.len(),
                    kinds("central"),
                    r.charts.len() - kinds("central")
                ),
            ),
            (
                "max transition error",
                format!("{:.3e}", r.max_transition_error),
            ),
            (
                "max chart length error",
                format!("{:.3e}", r.max_length_error),
            ),
            ("flipped faces", r.flipped_faces.to_string()),
            (
                "faces without a home chart",
                r.faces_without_home.to_string(),
            ),
            ("boundary word", r.boundary_word.clone()),
        ],
    );
    t.caption = "Affine atlas (ricci atlas)".into();
    t
}
