//! Stage `spline`: the manifold triangular B-spline (DMS) over the flat cone metric with one
//! extraordinary point, faired, fitted and with the hole at the cone filled G¹ (paper 000 §5);
//! zebra and patch pictures and the tessellation as OBJ.

use super::common::*;
use super::report::{Section, Status, Table};
use super::Env;
use ricci::progress::NoProgress;
use ricci::spline::surface::{
    flat_domain, run as run_spline, ContinuityReport, FlatDomain, MeshDistance, Singularity,
    SplineOptions, SplineReport, Tessellation,
};
use ricci_render::{render, Paint, Polyline, Style, View};
use serde_json::json;

/// Degree, fairness and tessellation of the demo's spline.
const SPLINE_DEGREE: usize = 3;
const SPLINE_FAIRNESS: usize = 1;
const SPLINE_TESSELLATION: usize = 8;
/// Thin-plate weight of the least-squares fit to the mesh vertices after the fairing: without
/// it the spline follows the control net of the subdivided mesh and its zebra stripes show
/// the mesh's facets, most of all in the finely graded domain around the cone.
const SPLINE_FIT: f64 = 1e-3;

/// The manifold triangular B-spline of degree 3 over a flat cone metric with one extraordinary
/// point (placed by least area distortion), faired with r = 1, the hole at the cone filled
/// by a G¹ patch; zebra stripes show the continuity.
pub fn spline(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("spline", "", "");
    let s = ctx.surface()?;
    env.bar
        .step("flat domain: cone placement, valence, grading, Euclidean flow");
    let t_domain = std::time::Instant::now();
    let dom = flat_domain(s, Singularity::Auto, &mut NoProgress)?;
    let seconds_domain = t_domain.elapsed().as_secs_f64();
    let t_run = std::time::Instant::now();
    env.bar
        .step("knots, bases, fairing, fill patch, tessellation");
    let dist = MeshDistance::new(&s.positions, s.mesh.faces());
    let spline_opts = SplineOptions {
        degree: SPLINE_DEGREE,
        fairness: SPLINE_FAIRNESS,
        fit_smoothing: Some(SPLINE_FIT),
        ..SplineOptions::default()
    };
    let (rep, tess, control) = run_spline(
        &dom.charts,
        &dist,
        &spline_opts,
        SPLINE_TESSELLATION,
        &mut NoProgress,
    )?;
    let seconds_run = t_run.elapsed().as_secs_f64();
    let c = &rep.continuity;

    env.bar.step("spline pictures");
    spline_pictures(&mut sec, env, &tess, c)?;

    env.out
        .write("spline.obj", tessellation_obj(&tess).as_bytes())?;

    let mut notes = Vec::new();
    if c.smoothness.unwrap_or(0) + 1 < SPLINE_DEGREE {
        notes.push(format!("measured continuity only {}", c.class));
    }
    if c.max_seam_normal_jump_deg > 0.5 {
        notes.push(format!(
            "normal jump {:.2}° along the seam",
            c.max_seam_normal_jump_deg
        ));
    }
    if !notes.is_empty() {
        sec.status = Status::Warning(notes.join("; "));
    }
    sec.headline = format!(
        "degree {SPLINE_DEGREE}, {}, {} control points, rms error {:.3}% of the diagonal",
        c.class, rep.control_points, rep.rms_error_percent
    );
    sec.paragraphs.push(format!(
        "Dahmen–Micchelli–Seidel triangular B-splines over the flat cone metric: every domain \
         vertex carries a cloud of n + 1 knots in its own developed frame, every triangle's \
         basis lives in a chart that contains its support, so the surface does not depend on the \
         chart it is evaluated in. The one-ring of the extraordinary point (cone angle {:.4} = \
         2π − 2πχ) is removed and filled by a patch that meets the spline G¹. Control points come \
         from the degree-n subdivision of the domain and are faired by constrained least squares \
         with r = {SPLINE_FAIRNESS} (paper 000 eq. 14), then fitted to the mesh vertices by least \
         squares with a thin-plate term of weight λ = {SPLINE_FIT:e}.",
        c.seams.first().map(|x| x.cone_angle).unwrap_or(f64::NAN)
    ));
    let seconds = (seconds_domain, seconds_run);
    sec.tables.push(spline_table(&rep, &dom, seconds));
    sec.files = vec![(
        "spline.obj".into(),
        "the tessellated spline surface (group `fill` is the patch at the extraordinary point)"
            .into(),
    )];
    sec.commands = vec![
        "ricci spline surface.off --degree 3 --fairness 1 --fit 1e-3 --out spline --json".into(),
    ];
    sec.summary = spline_summary(&rep, &dom, &tess, control.len(), seconds);
    Ok(sec)
}

/// Zebra stripes (front, and looking at the extraordinary point) and the patch structure.
fn spline_pictures(
    sec: &mut Section,
    env: &mut Env,
    tess: &Tessellation,
    c: &ContinuityReport,
) -> anyhow::Result<()> {
    let tris = &tess.triangles;
    let pos = &tess.positions;
    let ep = extraordinary_point(tess);
    let ep_view = match ep {
        Some(i) => {
            let n = ricci_render::render::vertex_normals(pos, tris)
                .get(i)
                .copied()
                .unwrap_or([0.0, 0.0, 1.0]);
            View {
                eye_direction: [n[0] + 0.25, n[1] + 0.2, n[2]],
                ..View::default()
            }
        }
        None => back_view(),
    };
    let ep_ring: Vec<Polyline> = ep
        .map(|i| {
            let mut r = base_marker(pos, tris, i as u32);
            // Orange: visible on the zebra's black and white stripes and on grey.
            r.color = [1.0, 0.5, 0.0];
            r.width = 4.0;
            r
        })
        .into_iter()
        .collect();
    // Zebra stripes: reflection lines bend smoothly on a C² surface and stay continuous
    // across the seam of the G¹ fill.
    for (file, view, caption) in [
        (
            "spline-zebra.png",
            View::default(),
            "Reflection lines (zebra) on the spline surface: smooth stripes everywhere, across domain edges, chart boundaries and the seam of the fill patch.",
        ),
        (
            "spline-zebra-back.png",
            ep_view,
            "Looking at the extraordinary point (orange ring): the G¹ fill patch is the small disk inside the ring. Around it the domain was refined (valence raised, neighbourhood graded), so the stripes bend at the scale of its small triangles.",
        ),
    ] {
        let st = Style {
            paint: Paint::Zebra(ricci_render::Zebra {
                stripes: 8.0,
                ..ricci_render::Zebra::default()
            }),
            polylines: ep_ring.clone(),
            ..Style::default()
        };
        let img = render(pos, tris, &st, &opts(view))?;
        sec.pictures.push(png(env, file, &img.image, caption)?);
    }
    // Patch structure: the images of the domain edges, and the seams (red) around the cone.
    let n_seams = c.seams.len();
    let n_lines = tess.boundaries.len();
    let lines: Vec<Polyline> = tess
        .boundaries
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let seam = i + n_seams >= n_lines;
            Polyline {
                points: b.clone(),
                color: if seam {
                    [0.85, 0.1, 0.1]
                } else {
                    [0.25, 0.3, 0.4]
                },
                width: if seam { 3.0 } else { 0.6 },
                closed: false,
            }
        })
        .collect();
    let mut lines = lines;
    lines.extend(ep_ring.iter().cloned());
    let st = Style {
        polylines: lines,
        ..Style::default()
    };
    let img = render(pos, tris, &st, &opts(ep_view))?;
    sec.pictures.push(png(
        env,
        "spline-patches.png",
        &img.image,
        "Patch boundaries seen from above the extraordinary point (orange ring): images of the domain triangles' edges (grey, dense where the domain was graded towards the point) and the seam of the G¹ fill patch (red).",
    )?);
    Ok(())
}

/// The extraordinary point: the tessellation vertex nearest the centroid of the fill patch
/// (vertex_face < 0), ringed in orange in the pictures, which look at it along its normal.
fn extraordinary_point(tess: &Tessellation) -> Option<usize> {
    let pos = &tess.positions;
    let fill: Vec<usize> = (0..pos.len())
        .filter(|&i| tess.vertex_face.get(i).is_some_and(|&f| f < 0))
        .collect();
    (!fill.is_empty()).then(|| {
        let n = fill.len() as f64;
        let m = fill.iter().fold([0.0; 3], |a, &i| {
            [
                a[0] + pos[i][0] / n,
                a[1] + pos[i][1] / n,
                a[2] + pos[i][2] / n,
            ]
        });
        let d = |i: usize| (0..3).map(|k| (pos[i][k] - m[k]).powi(2)).sum::<f64>();
        fill.iter()
            .copied()
            .min_by(|&a, &b| d(a).total_cmp(&d(b)))
            .unwrap_or(fill[0])
    })
}

/// The tessellated surface as OBJ (the fill patch as group `fill`).
fn tessellation_obj(tess: &Tessellation) -> String {
    let mut obj = String::from("# ricci demo: manifold triangular B-spline (tessellation)\n");
    for p in &tess.positions {
        obj.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
    }
    obj.push_str("g spline\n");
    for (i, t) in tess.triangles.iter().enumerate() {
        if i == tess.spline_triangles {
            obj.push_str("g fill\n");
        }
        obj.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    obj
}

/// The spline's report as a table (`seconds`: flat domain and the rest, wall clock).
fn spline_table(rep: &SplineReport, dom: &FlatDomain, seconds: (f64, f64)) -> Table {
    let c = &rep.continuity;
    let (seconds_domain, seconds_run) = seconds;
    Table::key_values(
        "Manifold spline (ricci spline)",
        vec![
            (
                "degree n, fairness r, fit λ",
                format!("{SPLINE_DEGREE}, {SPLINE_FAIRNESS}, {SPLINE_FIT:e}"),
            ),
            (
                "extraordinary point",
                dom.singular
                    .map(|v| format!("vertex {v}"))
                    .unwrap_or_else(|| "none".into()),
            ),
            (
                "domain",
                format!(
                    "{} faces ({} active), flat metric by {} ({} steps, max |K − K̄| = {:.1e})",
                    rep.domain_faces,
                    rep.active_faces,
                    dom.scheme.name(),
                    dom.flow_iterations,
                    dom.flow_max_curvature_error
                ),
            ),
            ("control points", rep.control_points.to_string()),
            ("continuity", c.class.clone()),
            (
                "relative derivative jumps, orders 0..n",
                c.relative_jumps
                    .iter()
                    .map(|j| format!("{j:.1e}"))
                    .collect::<Vec<_>>()
                    .join(", "),
            ),
            (
                "max normal jump along the seam",
                format!("{:.2e}°", c.max_seam_normal_jump_deg),
            ),
            (
                "distance to the input mesh (rms / max, % of diagonal)",
                format!(
                    "{:.4} / {:.4}",
                    rep.rms_error_percent, rep.max_error_percent
                ),
            ),
            (
                "time (s): flat domain, knots, fairing, fit, fill, measuring; total",
                format!(
                    "{:.2}, {:.2}, {:.2}, {:.2}, {:.2}, {:.2}; {:.2}",
                    seconds_domain,
                    rep.seconds_knots,
                    rep.seconds_fairing,
                    rep.seconds_fit,
                    rep.seconds_fill,
                    (seconds_run - rep.seconds).max(0.0),
                    seconds_domain + seconds_run
                ),
            ),
        ],
    )
}

/// The stage's JSON summary.
fn spline_summary(
    rep: &SplineReport,
    dom: &FlatDomain,
    tess: &Tessellation,
    control_values: usize,
    seconds: (f64, f64),
) -> serde_json::Value {
    let c = &rep.continuity;
    let (seconds_domain, seconds_run) = seconds;
    let (pos, tris) = (&tess.positions, &tess.triangles);
    json!({
        "degree": rep.degree,
        "fairness": rep.fairness,
        "control_points": rep.control_points,
        "control_values": control_values,
        "domain_faces": rep.domain_faces,
        "singular_vertex": dom.singular,
        "rms_error_percent": rep.rms_error_percent,
        "max_error_percent": rep.max_error_percent,
        "continuity": {
            "class": c.class,
            "smoothness": c.smoothness,
            "relative_jumps": c.relative_jumps,
            "tolerance": c.tolerance,
            "max_seam_normal_jump_deg": c.max_seam_normal_jump_deg,
            "seams": c.seams.len(),
        },
        "tessellation_vertices": pos.len(),
        "tessellation_triangles": tris.len(),
        "fill_triangles": tris.len() - tess.spline_triangles,
        "seconds": seconds_domain + seconds_run,
        "timings": {
            "domain": seconds_domain, "knots": rep.seconds_knots,
            "fairing": rep.seconds_fairing, "fit": rep.seconds_fit,
            "fill": rep.seconds_fill, "measure": (seconds_run - rep.seconds).max(0.0),
        },
    })
}
