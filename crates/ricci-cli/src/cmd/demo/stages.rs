//! The stages of `ricci demo`: each takes what earlier stages left in [`Ctx`], calls the
//! library (no math here), writes pictures and files through [`Env`] and returns a
//! [`Section`] for the page and the JSON.

use super::report::{num, Picture, Section, Status, Table};
use super::Env;
use crate::cmd::{atlas::svg as atlas_svg, cut::cut_obj, flow::metric_json, info::info_json};
use ricci::analysis::spectrum::fuchsian_spectrum;
use ricci::atlas::{AffineAtlas, AtlasOptions, FlatCharts};
use ricci::flow::{ricci_flow, FlowOptions, FlowResult, TargetSpec};
use ricci::layout::cover::{tiles_by_radius, word_string};
use ricci::layout::export::obj_with_uv;
use ricci::layout::isometry::Complex;
use ricci::layout::pipeline::{cut_disk, CutDisk};
use ricci::layout::place::{layout as place, minimax_centre};
use ricci::layout::{deck_group, DeckGroup, Isometry, Layout, Mobius};
use ricci::mesh::io::{read_surface, write_to, Encoding, Format};
use ricci::mesh::refine::{Refined, Refiner};
use ricci::mesh::{generate, quality::angle_stats, topology, Surface};
use ricci::metric::{euler_characteristic, Geometry, Hyperbolic, Scheme};
use ricci::progress::NoProgress;
use ricci_render::plot::{
    face_colors, layout_figure, line_plot_figure, ColorBar, Figure, Item, LayoutCopy, LayoutPlot,
    LinePlot, Series, Side,
};
use ricci_render::render::Uvs;
use ricci_render::{
    color, fields, gltf, render, Checker, Colormap, Image, Paint, Polyline, RenderOptions, Scalar,
    ScalarRange, Style, View, Wireframe,
};
use serde_json::json;
use std::f64::consts::PI;

/// Tolerance of both flows: max |K − K̄| (the value `ricci layout` uses; 1e-12 stalls at
/// rounding on large meshes, 1e-11 is reached here in a few Newton steps).
pub const FLOW_TOLERANCE: f64 = 1e-11;
/// Valence the single cone's vertex is raised to (Chow–Luo needs ≥ 4 − 2K̄/π = 12 for a cone
/// of 2πχ = −4π; a few more spokes keep the Thurston angles comfortably inside the bound).
pub const CONE_VALENCE: usize = 16;
/// Copies of the fundamental polygon in the tiling picture.
pub const TILES: usize = 300;
/// Geodesic lengths listed.
pub const SPECTRUM_COUNT: usize = 8;
/// Checks per unit of Poincaré-disk coordinates in the checkerboard pictures.
pub const CHECKS: f64 = 14.0;

/// What the stages computed, for the stages after them.
pub struct Ctx {
    pub resolution: u32,
    pub surface: Option<Surface>,
    pub chi: i64,
    pub hyperbolic: Option<FlowResult>,
    pub disk: Option<CutDisk>,
    pub layout: Option<Layout<Complex>>,
    pub group: Option<DeckGroup<Mobius>>,
    /// The refined surface and flat metric with one cone (for the affine atlas stage).
    pub cone: Option<(Refined, FlowResult, u32)>,
    /// The affine atlas (for the manifold spline stage).
    pub atlas: Option<AffineAtlas>,
}

impl Ctx {
    pub fn new(resolution: u32) -> Ctx {
        Ctx {
            resolution,
            surface: None,
            chi: 0,
            hyperbolic: None,
            disk: None,
            layout: None,
            group: None,
            cone: None,
            atlas: None,
        }
    }
    fn surface(&self) -> anyhow::Result<&Surface> {
        self.surface
            .as_ref()
            .ok_or_else(|| anyhow::anyhow!("no surface"))
    }
}

// ---------------------------------------------------------------------------------------------
// Pictures.

/// Width and height of the surface renders (the genus-2 surface is about 5 × 3 × 0.8).
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

fn back_view() -> View {
    View {
        eye_direction: [-0.4, -0.3, -1.0],
        ..View::default()
    }
}

/// Write an image as PNG and describe it.
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

/// Write a 2D figure as `stem.png` and, with `svg`, `stem.svg`.
fn figure(
    env: &mut Env,
    stem: &str,
    fig: &Figure,
    caption: &str,
    svg: bool,
) -> anyhow::Result<Picture> {
    let img = fig.to_image(1.0)?;
    let mut p = png(env, &format!("{stem}.png"), &img, caption)?;
    if svg {
        let file = format!("{stem}.svg");
        env.out.write(&file, fig.to_svg().as_bytes())?;
        p.alternatives.push(file);
    }
    Ok(p)
}

/// Residual history (max |K − K̄| per Newton step) as a log-scale line plot.
fn residual_plot(r: &FlowResult, title: &str) -> anyhow::Result<Figure> {
    let pts: Vec<[f64; 2]> = r
        .history
        .iter()
        .map(|h| [h.iteration as f64, h.max_curvature_error])
        .collect();
    let tol: Vec<[f64; 2]> = vec![
        [0.0, r.tolerance],
        [
            r.history.last().map_or(1, |h| h.iteration) as f64,
            r.tolerance,
        ],
    ];
    Ok(line_plot_figure(
        &[
            Series {
                name: "max |K − K̄|".into(),
                points: pts,
                color: color::categorical(0),
            },
            Series {
                name: format!("tolerance {:.0e}", r.tolerance),
                points: tol,
                color: [0.55, 0.55, 0.55],
            },
        ],
        &LinePlot {
            title: title.into(),
            x_label: "Newton step".into(),
            y_label: String::new(),
            log_y: true,
            width: 600.0,
            height: 400.0,
        },
    )?)
}

fn history_table(r: &FlowResult) -> Table {
    let mut t = Table::new(
        "Newton steps",
        &["step", "max |K − K̄|", "largest |Δu|", "time (s)"],
    );
    for h in &r.history {
        t.row(vec![
            h.iteration.to_string(),
            format!("{:.3e}", h.max_curvature_error),
            format!("{:.3e}", h.step),
            format!("{:.4}", h.seconds),
        ]);
    }
    t
}

fn flow_summary(r: &FlowResult) -> serde_json::Value {
    json!({
        "geometry": r.geometry,
        "scheme": r.scheme,
        "solver": r.solver,
        "target": r.target_description,
        "iterations": r.iterations,
        "converged": r.converged,
        "tolerance": r.tolerance,
        "max_curvature_error": r.max_curvature_error,
        "gauss_bonnet_error": r.gauss_bonnet_error,
        "area": r.area,
        "flow_seconds": r.seconds,
        "history": r.history.iter().map(|h| json!({
            "iteration": h.iteration, "max_curvature_error": h.max_curvature_error,
            "step": h.step, "seconds": h.seconds})).collect::<Vec<_>>(),
        "notes": r.notes,
    })
}

/// Colour of generator `letter` (a1 → 0, b1 → 1, …), the same in every picture.
fn generator_color(letters: &[String], label: &str) -> color::Rgb {
    let base = label.trim_end_matches("^-1");
    color::categorical(letters.iter().position(|l| l == base).unwrap_or(7))
}

/// A small black ring around vertex `v` in its tangent plane (radius 2% of the bounding box
/// diagonal), to mark a point on the surface.
fn base_marker(pos: &[[f64; 3]], tris: &[[u32; 3]], v: u32) -> Polyline {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in pos {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diag = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
    let r = 0.02 * diag;
    let n = ricci_render::render::vertex_normals(pos, tris)
        .get(v as usize)
        .copied()
        .unwrap_or([0.0, 0.0, 1.0]);
    // An orthonormal pair (e1, e2) orthogonal to n.
    let a = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let cross = |x: [f64; 3], y: [f64; 3]| {
        [
            x[1] * y[2] - x[2] * y[1],
            x[2] * y[0] - x[0] * y[2],
            x[0] * y[1] - x[1] * y[0],
        ]
    };
    let unit = |x: [f64; 3]| {
        let l = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt().max(1e-300);
        [x[0] / l, x[1] / l, x[2] / l]
    };
    let e1 = unit(cross(n, a));
    let e2 = unit(cross(n, e1));
    let c = pos.get(v as usize).copied().unwrap_or([0.0; 3]);
    Polyline {
        points: (0..32)
            .map(|i| {
                let t = i as f64 * std::f64::consts::TAU / 32.0;
                let (x, y) = (r * t.cos(), r * t.sin());
                [
                    c[0] + x * e1[0] + y * e2[0],
                    c[1] + x * e1[1] + y * e2[1],
                    c[2] + x * e1[2] + y * e2[2],
                ]
            })
            .collect(),
        color: [0.0, 0.0, 0.0],
        width: 3.0,
        closed: true,
    }
}

// ---------------------------------------------------------------------------------------------
// 1. Surface.

pub fn surface(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("surface", "", "");
    let n = ctx.resolution;
    let generated = generate::genus_with_progress(2, n, env.bar)?;
    env.bar.step("writing and validating surface.off");
    let mut bytes = Vec::new();
    write_to(&mut bytes, &generated, Format::Off, Encoding::Ascii)?;
    env.out.write("surface.off", &bytes)?;
    // Validate what was written: read the file back like any mesh file.
    let (s, build) = read_surface(&env.out.staging.join("surface.off"))?;
    if s.mesh.n_faces() != generated.mesh.n_faces()
        || s.mesh.n_vertices() != generated.mesh.n_vertices()
    {
        anyhow::bail!(
            "surface.off reads back with {} vertices and {} faces instead of {} and {}",
            s.mesh.n_vertices(),
            s.mesh.n_faces(),
            generated.mesh.n_vertices(),
            generated.mesh.n_faces()
        );
    }
    let info = info_json("surface.off", &s, &build);
    env.out
        .write("info.json", serde_json::to_string_pretty(&info)?.as_bytes())?;
    let t = topology(&s.mesh);
    let q = angle_stats(&s);
    let chi = euler_characteristic(&s.mesh);
    if t.components.len() != 1 || t.genus() != 2 || t.boundary_loops() != 0 {
        anyhow::bail!(
            "the built-in surface should be one closed genus-2 surface but has {} component(s), genus {}, {} boundary loop(s)",
            t.components.len(),
            t.genus(),
            t.boundary_loops()
        );
    }
    // Gauss–Bonnet of the embedding itself: Σ angle defects = 2πχ.
    let defect = fields::angle_defect(&s.positions, s.mesh.faces())?;
    let total_defect: f64 = defect.iter().sum();

    env.bar.step("rendering");
    let tris = s.mesh.faces();
    let r = render(
        &s.positions,
        tris,
        &Style::default(),
        &opts(View::default()),
    )?;
    sec.pictures.push(png(
        env,
        "surface.png",
        &r.image,
        "The built-in genus-2 surface: two blended tori, remeshed isotropically.",
    )?);
    let wire = Style {
        wireframe: Some(Wireframe {
            opacity: 0.55,
            ..Wireframe::default()
        }),
        ..Style::default()
    };
    let r = render(
        &s.positions,
        tris,
        &wire,
        &opts(View {
            eye_direction: [0.0, 0.35, 1.0],
            ..View::default()
        }),
    )?;
    sec.pictures.push(png(
        env,
        "surface-wireframe.png",
        &r.image,
        "Its triangulation (the flows are intrinsic: they only read the edge lengths).",
    )?);
    sec.paragraphs.push(format!(
        "The surface every later stage works on: generated by `ricci generate genus2 -n {n}`, \
         written as surface.off, read back and validated like any input file."
    ));
    sec.tables.push(Table::key_values(
        "Topology and quality",
        vec![
            ("vertices", s.mesh.n_vertices().to_string()),
            ("edges", s.mesh.n_edges().to_string()),
            ("faces", s.mesh.n_faces().to_string()),
            ("components", t.components.len().to_string()),
            ("boundary loops", t.boundary_loops().to_string()),
            ("Euler characteristic χ", chi.to_string()),
            ("genus", t.genus().to_string()),
            ("min angle (°)", format!("{:.2}", q.min_angle_deg)),
            ("max angle (°)", format!("{:.2}", q.max_angle_deg)),
            (
                "Σ angle defect − 2πχ",
                format!("{:.3e}", total_defect - 2.0 * PI * chi as f64),
            ),
        ],
    ));
    sec.files = vec![
        ("surface.off".into(), "the surface (OFF)".into()),
        (
            "info.json".into(),
            "what `ricci info surface.off --json` reports".into(),
        ),
    ];
    sec.summary = json!({
        "resolution": n,
        "vertices": s.mesh.n_vertices(),
        "edges": s.mesh.n_edges(),
        "faces": s.mesh.n_faces(),
        "components": t.components.len(),
        "boundary_loops": t.boundary_loops(),
        "euler_characteristic": chi,
        "genus": t.genus(),
        "min_angle_deg": q.min_angle_deg,
        "max_angle_deg": q.max_angle_deg,
        "total_angle_defect": total_defect,
    });
    sec.commands = vec![
        format!("ricci generate genus2 -n {n} --out surface.off"),
        "ricci info surface.off --json".into(),
        "ricci render surface.off --wireframe --out surface-wireframe.png".into(),
    ];
    sec.headline = format!(
        "{} vertices, {} faces, χ = {chi}, genus {}, angles {:.1}°–{:.1}°",
        s.mesh.n_vertices(),
        s.mesh.n_faces(),
        t.genus(),
        q.min_angle_deg,
        q.max_angle_deg
    );
    ctx.chi = chi;
    ctx.surface = Some(s);
    Ok(sec)
}

// ---------------------------------------------------------------------------------------------
// 2. Hyperbolic uniformization.

pub fn hyperbolic_flow(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("flow", "", "");
    let s = ctx.surface()?;
    // The default scheme of `ricci flow` (discrete conformal equivalence): the conformal
    // class of the surface's own polyhedral metric.
    let opts_flow = FlowOptions {
        geometry: Geometry::Hyperbolic,
        scheme: Scheme::Conformal,
        target: TargetSpec::Uniform,
        tolerance: FLOW_TOLERANCE,
        ..FlowOptions::default()
    };
    let r = ricci_flow(&s.mesh, &s.edge_lengths(), &opts_flow, env.bar)?;
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

// ---------------------------------------------------------------------------------------------
// 3. Flat metric with one cone.

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
    let o = FlowOptions {
        geometry: Geometry::Euclidean,
        scheme: Scheme::Thurston,
        target: TargetSpec::SingleCone(Some(v)),
        tolerance: FLOW_TOLERANCE,
        ..FlowOptions::default()
    };
    let refusal = match ricci_flow(&s.mesh, &lengths, &o, env.bar) {
        Err(e) => Some(e.to_string()),
        Ok(_) => None,
    };
    env.bar.step(&format!(
        "raising the valence of vertex {v} to {CONE_VALENCE} and grading around it"
    ));
    let mut rf = Refiner::new(&s.mesh, &lengths, Geometry::Euclidean, Some(&s.positions))?;
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
    let valence_after = refined.mesh.valence(v);
    let r = ricci_flow(&refined.mesh, &refined.lengths, &o, env.bar)?;
    if !r.converged {
        sec.status = Status::Warning(format!(
            "the flow did not converge: max |K − K̄| = {:.3e} > {:.0e} after {} steps",
            r.max_curvature_error, r.tolerance, r.iterations
        ));
    }
    let k_at_cone = r.curvature[v as usize];
    let max_elsewhere = r
        .curvature
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != v as usize)
        .map(|(_, k)| k.abs())
        .fold(0.0, f64::max);
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
    sec.tables.push(Table::key_values(
        "Result",
        vec![
            ("cone vertex", v.to_string()),
            (
                "valence before → after",
                format!("{valence_before} → {valence_after}"),
            ),
            ("edge splits", (raised + graded).to_string()),
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
    let mut summary = flow_summary(&r);
    summary["cone_vertex"] = json!(v);
    summary["refused_without_refinement"] = json!(refusal);
    summary["cone_curvature"] = json!(k_at_cone);
    summary["target_cone_curvature"] = json!(k_cone);
    summary["max_curvature_elsewhere"] = json!(max_elsewhere);
    summary["valence_before"] = json!(valence_before);
    summary["valence_after"] = json!(valence_after);
    summary["splits"] = json!(raised + graded);
    summary["refined_vertices"] = json!(refined.mesh.n_vertices());
    summary["refined_faces"] = json!(refined.mesh.n_faces());
    sec.summary = summary;
    ctx.cone = Some((refined, r, v));
    Ok(sec)
}

// ---------------------------------------------------------------------------------------------
// 4. Canonical loops.

pub fn loops(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("loops", "", "");
    let s = ctx.surface()?;
    let h = ctx
        .hyperbolic
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("no hyperbolic metric"))?;
    let d = cut_disk(
        &s.mesh,
        &h.lengths,
        Geometry::Hyperbolic,
        Some(&s.positions),
        None,
        env.bar,
    )?;
    env.bar.step("pictures");
    let c = &d.cut;
    let pos = c
        .refined
        .positions
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("the cut lost the positions"))?;
    let letters = &d.polygon.letters;
    let lines: Vec<Polyline> = c
        .loops
        .iter()
        .map(|l| Polyline {
            points: l.vertices.iter().map(|&v| pos[v as usize]).collect(),
            color: generator_color(letters, &l.label),
            width: 3.5,
            closed: l.vertices.first() != l.vertices.last(),
        })
        .collect();
    let mut lines = lines;
    lines.push(base_marker(pos, c.refined.mesh.faces(), c.base));
    let st = Style {
        polylines: lines,
        ..Style::default()
    };
    for (file, view, caption) in [
        (
            "loops.png",
            View::default(),
            "The loops a1 b1 a2 b2 through the base vertex (black ring; colours as in the polygon), front.",
        ),
        (
            "loops-base.png",
            View {
                eye_direction: {
                    let n = ricci_render::render::vertex_normals(pos, c.refined.mesh.faces())
                        .get(c.base as usize)
                        .copied()
                        .unwrap_or([0.0, 0.0, 1.0]);
                    [n[0], n[1], n[2] + 0.8]
                },
                ..View::default()
            },
            "The same loops seen from above the base vertex, where all eight sides meet.",
        ),
    ] {
        let img = render(pos, c.refined.mesh.faces(), &st, &opts(view))?;
        sec.pictures.push(png(env, file, &img.image, caption)?);
    }
    env.out.write("cut.obj", cut_obj(c).as_bytes())?;
    let disk_ok = {
        let t = topology(&c.cut_mesh);
        t.components.len() == 1 && t.euler_characteristic() == 1 && t.boundary_loops() == 1
    };
    sec.paragraphs.push(format!(
        "A canonical system of loops through base vertex {}: cutting along them opens the \
         surface into a disk whose boundary reads {} ({} sides). The base vertex first gets \
         valence ≥ {} by metric-preserving splits ({} splits). Loop lengths are measured in the \
         hyperbolic metric of the previous stage.",
        c.base,
        c.boundary_word,
        c.polygon.len(),
        c.report.min_valence,
        c.report.refinement_splits
    ));
    let mut lt = Table::new("Loops", &["loop", "edges", "hyperbolic length"]);
    for l in &c.loops {
        lt.row(vec![
            l.label.clone(),
            l.halfedges.len().to_string(),
            num(l.length),
        ]);
    }
    sec.tables.push(lt);
    let labels: Vec<&str> = c.loops.iter().map(|l| l.label.as_str()).collect();
    let mut header = vec!["·"];
    header.extend(labels.iter().copied());
    let mut it = Table::new("Algebraic intersection numbers", &header);
    for (i, row) in c.intersection_matrix.iter().enumerate() {
        let mut cells = vec![labels.get(i).copied().unwrap_or("?").to_string()];
        cells.extend(row.iter().map(|x| x.to_string()));
        it.row(cells);
    }
    sec.tables.push(it);
    sec.tables.push(Table::key_values(
        "Cut",
        vec![
            ("boundary word", c.boundary_word.clone()),
            ("polygon sides", c.polygon.len().to_string()),
            ("base vertex", c.base.to_string()),
            (
                "valence of the base",
                format!("{} → {}", c.report.valence_before, c.report.valence_after),
            ),
            (
                "cut mesh (V / F)",
                format!("{} / {}", c.cut_mesh.n_vertices(), c.cut_mesh.n_faces()),
            ),
            ("cut mesh is a disk", disk_ok.to_string()),
            ("time (s)", format!("{:.3}", c.report.seconds)),
        ],
    ));
    sec.files = vec![(
        "cut.obj".into(),
        "the cut mesh, each polygon side an `l` polyline group (as `ricci cut` writes it)".into(),
    )];
    sec.summary = json!({
        "genus": c.genus,
        "base_vertex": c.base,
        "boundary_word": c.boundary_word,
        "polygon_sides": c.polygon.len(),
        "loops": c.loops.iter().map(|l| json!({"label": l.label, "edges": l.halfedges.len(), "length": l.length})).collect::<Vec<_>>(),
        "intersection_matrix": c.intersection_matrix,
        "disk": disk_ok,
        "refinement_splits": c.report.refinement_splits,
        "cut_vertices": c.cut_mesh.n_vertices(),
        "cut_faces": c.cut_mesh.n_faces(),
    });
    sec.commands =
        vec!["ricci cut surface.off --metric hyperbolic-metric.json --out cut.obj".into()];
    sec.headline = format!("boundary word `{}`", c.boundary_word);
    ctx.disk = Some(d);
    Ok(sec)
}

// ---------------------------------------------------------------------------------------------
// 5. Layout, deck group, tiling, checkerboard.

pub fn layout(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("layout", "", "");
    let d = ctx.disk.as_ref().ok_or_else(|| anyhow::anyhow!("no cut"))?;
    env.bar.step("layout in the Poincaré disk");
    let l = place::<Hyperbolic>(&d.mesh, &d.lengths, None)?;
    env.bar.step("deck group");
    let g = deck_group::<Hyperbolic>(&l, &d.polygon)?;
    let relation_error = g
        .relation_error
        .ok_or_else(|| anyhow::anyhow!("the deck group relation could not be evaluated"))?;
    let uv: Vec<[f64; 2]> = l.positions.iter().map(|z| [z.re, z.im]).collect();
    let letters = &d.polygon.letters;
    let sides_of = |map: &Mobius, labelled: bool| -> Vec<Side> {
        d.polygon
            .sides
            .iter()
            .map(|s| Side {
                points: s
                    .vertices
                    .iter()
                    .map(|&v| {
                        let z = map.apply(l.positions[v as usize]);
                        [z.re, z.im]
                    })
                    .collect(),
                color: generator_color(letters, &s.label),
                label: if labelled {
                    s.label.clone()
                } else {
                    String::new()
                },
            })
            .collect()
    };
    env.bar.step("pictures of the polygon");
    let mut plot = LayoutPlot::new(LayoutCopy::new(&uv, d.mesh.faces()));
    plot.sides = sides_of(&Mobius::identity(), true);
    plot.disk = true;
    plot.title = "Fundamental polygon".into();
    plot.size = 720.0;
    let fig = layout_figure(&plot)?;
    sec.pictures.push(figure(
        env,
        "polygon",
        &fig,
        &format!("The cut surface laid out isometrically in the Poincaré disk: the polygon {}, sides coloured by generator.", d.polygon.word()),
        true,
    )?);

    // Tiling: copies of the polygon (as a fan around the image of its centre), breadth first.
    env.bar.step(&format!("tiling with {TILES} copies"));
    let centre = minimax_centre::<Hyperbolic>(&l.positions);
    let tiles = tiles_by_radius::<Hyperbolic>(&g, &d.polygon, centre, 12.0, TILES)?;
    let boundary: Vec<u32> = d
        .polygon
        .sides
        .iter()
        .flat_map(|s| {
            s.vertices[..s.vertices.len().saturating_sub(1)]
                .iter()
                .copied()
        })
        .collect();
    // The fundamental domain with its triangles; every other copy as one filled polygon
    // under its sides, tinted by its word so that neighbours differ.
    let mut tp = LayoutPlot::new(LayoutCopy::new(&uv, d.mesh.faces()));
    tp.sides = tiles
        .iter()
        .enumerate()
        .flat_map(|(i, t)| sides_of(&t.map, i == 0))
        .collect();
    tp.disk = true;
    tp.title = format!("{} copies of the polygon", tiles.len());
    tp.size = 720.0;
    let mut fig = layout_figure(&tp)?;
    // Disk pictures start with the disk itself: its centre and radius give the frame.
    let frame = match fig.items.first() {
        Some(Item::Circle { center, radius, .. }) => Some((*center, *radius)),
        _ => None,
    };
    if let Some((c, r)) = frame {
        let mut by_depth: std::collections::BTreeMap<usize, Vec<Vec<[f64; 2]>>> =
            Default::default();
        for t in tiles.iter().skip(1) {
            let pts = boundary
                .iter()
                .map(|&v| {
                    let z = t.map.apply(l.positions[v as usize]);
                    [c[0] + r * z.re, c[1] - r * z.im]
                })
                .collect();
            // Neighbouring copies differ in the last letter of their words (or its sign).
            let last = t.word.last().map_or(0, |&(l, inv)| 2 * l + inv as usize);
            by_depth
                .entry((last + t.word.len()) % 8)
                .or_default()
                .push(pts);
        }
        for (k, (tint, polygons)) in by_depth.into_iter().enumerate() {
            fig.items.insert(
                1 + k,
                Item::Polygons {
                    polygons,
                    fill: Some(color::tint(color::categorical(tint), 0.75)),
                    stroke: None,
                    stroke_width: 0.0,
                    class: "tiles",
                },
            );
        }
    }
    sec.pictures.push(figure(
        env,
        "tiling",
        &fig,
        "A part of the universal cover: images of the polygon under the deck group (the unit circle is the circle at infinity).",
        false,
    )?);

    // Checkerboard of the hyperbolic layout on the (refined) surface, uv.obj and a glTF.
    env.bar.step("checkerboard, uv.obj and surface.glb");
    let c = &d.cut;
    let pos = c
        .refined
        .positions
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("the cut lost the positions"))?;
    let faces = c.refined.mesh.faces();
    let corner_uv: Vec<[f64; 2]> = d
        .mesh
        .faces()
        .iter()
        .flat_map(|t| t.iter().map(|&v| uv[v as usize]))
        .collect();
    for (file, view, caption) in [
        (
            "checker.png",
            View::default(),
            "Checkerboard of the Poincaré-disk coordinates on the surface. The map is conformal: in the small the checks are squares (angles are kept), but their size follows the conformal factor — they grow on the surface where the polygon's spikes reach towards the unit circle, which the disk model compresses.",
        ),
        ("checker-back.png", back_view(), "The same texture from behind."),
    ] {
        let st = Style {
            paint: Paint::Checker(Checker::new(Uvs::PerCorner(&corner_uv), CHECKS)),
            ..Style::default()
        };
        let img = render(pos, faces, &st, &opts(view))?;
        sec.pictures.push(png(env, file, &img.image, caption)?);
    }
    let obj = obj_with_uv(
        pos,
        faces,
        &uv,
        d.mesh.faces(),
        &[
            "ricci demo: the genus-2 surface with its hyperbolic layout".to_string(),
            "vt: Poincaré-disk coordinates of the cut mesh".to_string(),
        ],
    );
    env.out.write("uv.obj", obj.as_bytes())?;
    let glb = gltf::glb(
        pos,
        faces,
        &gltf::GlbOptions {
            uvs: Some(Uvs::PerCorner(&corner_uv)),
            checker_frequency: Some(CHECKS),
            colors: None,
            name: Some("genus2".into()),
        },
    )?;
    env.out.write("surface.glb", &glb)?;

    let flipped = l.flipped_faces.len();
    if flipped > 0 {
        sec.status = Status::Warning(format!("{flipped} faces are flipped in the layout"));
    }
    sec.paragraphs.push(format!(
        "The cut mesh is laid out face by face in the Poincaré disk with the hyperbolic edge \
         lengths; the Möbius maps pairing its sides generate the deck group, a Fuchsian group. \
         Its relation a1 b1 a1⁻¹ b1⁻¹ a2 b2 a2⁻¹ b2⁻¹ = id holds to {relation_error:.1e} \
         (double-precision layout; `ricci layout` without `--no-polish` polishes the metric \
         and the layout in double-double and reaches ~1e-28)."
    ));
    let mut gt = Table::new(
        "Deck generators z ↦ (az + b)/(b̄z + ā)",
        &[
            "generator",
            "a",
            "b",
            "|a|² − |b|²",
            "trace",
            "translation length",
        ],
    );
    let mut gens_json = Vec::new();
    for (name, m) in g.named_generators() {
        let det = m.a.norm_sqr() - m.b.norm_sqr();
        gt.row(vec![
            name.clone(),
            format!("{:.6} {:+.6}i", m.a.re, m.a.im),
            format!("{:.6} {:+.6}i", m.b.re, m.b.im),
            format!("{det:.12}"),
            format!("{:.6}", m.trace()),
            format!("{:.6}", m.translation_length()),
        ]);
        gens_json.push(json!({
            "letter": name, "a": [m.a.re, m.a.im], "b": [m.b.re, m.b.im],
            "trace": m.trace(), "translation_length": m.translation_length(),
        }));
    }
    sec.tables.push(gt);
    sec.tables.push(Table::key_values(
        "Layout",
        vec![
            ("relation error", format!("{relation_error:.3e}")),
            (
                "max side-pairing spread",
                format!("{:.3e}", g.max_edge_spread),
            ),
            (
                "max edge length error",
                format!("{:.3e}", l.max_length_error),
            ),
            ("flipped faces", flipped.to_string()),
            ("seed face", l.seed_face.to_string()),
            ("tiles drawn", tiles.len().to_string()),
        ],
    ));
    sec.files = vec![
        (
            "uv.obj".into(),
            "the surface with Poincaré-disk texture coordinates (as `ricci layout --out` writes it)"
                .into(),
        ),
        (
            "surface.glb".into(),
            "glTF binary with the UVs and an embedded checker texture, for any glTF viewer".into(),
        ),
    ];
    sec.summary = json!({
        "geometry": "hyperbolic",
        "flipped_faces": flipped,
        "relation_error": relation_error,
        "relation_condition": g.relation_condition,
        "max_edge_spread": g.max_edge_spread,
        "max_length_error": l.max_length_error,
        "seed_face": l.seed_face,
        "deck_generators": gens_json,
        "tiles": tiles.len(),
        "tile_words": tiles.iter().take(12).map(|t| word_string(&g.letters, &t.word)).collect::<Vec<_>>(),
        "boundary_word": d.polygon.word(),
    });
    sec.commands = vec![
        // The same metric and the same double-precision layout (without --no-polish the
        // command polishes the metric and the layout in double-double: relation error
        // ~1e-28 instead of the ~1e-12 shown here).
        "ricci layout surface.off --metric hyperbolic-metric.json --no-polish --out uv.obj --svg polygon.svg".into(),
        format!("ricci layout surface.off --metric hyperbolic-metric.json --no-polish --tiling {TILES} --svg tiling.svg"),
    ];
    sec.headline = format!(
        "relation error {relation_error:.1e}, {flipped} flipped faces, {} copies tiled",
        tiles.len()
    );
    ctx.layout = Some(l);
    ctx.group = Some(g);
    Ok(sec)
}

// ---------------------------------------------------------------------------------------------
// 6. Length spectrum.

pub fn spectrum(ctx: &mut Ctx, env: &mut Env) -> anyhow::Result<Section> {
    let mut sec = Section::new("spectrum", "", "");
    let (Some(d), Some(l), Some(g)) = (&ctx.disk, &ctx.layout, &ctx.group) else {
        anyhow::bail!("no layout");
    };
    env.bar.step("enumerating closed geodesics");
    let sp = fuchsian_spectrum(l, &d.polygon, g, SPECTRUM_COUNT, 2_000_000)?;
    let lengths = sp.lengths();
    let shortest_generator = g
        .named_generators()
        .iter()
        .map(|(_, m)| m.translation_length())
        .fold(f64::INFINITY, f64::min);
    sec.paragraphs.push(format!(
        "The shortest closed geodesics of the hyperbolic metric: one length 2 acosh(|tr γ|/2) \
         per free homotopy class (unoriented, powers included). Every class shorter than \
         {:.4} is guaranteed to be listed. The generators are closed geodesic classes too, so \
         none is shorter than the first length.",
        sp.complete_up_to
    ));
    let mut t = Table::new(
        "Shortest closed geodesics (curvature −1)",
        &["k", "length", "length / shortest"],
    );
    let first = lengths.first().copied().unwrap_or(1.0);
    for (i, x) in lengths.iter().enumerate() {
        t.row(vec![
            (i + 1).to_string(),
            format!("{x:.6}"),
            format!("{:.4}", x / first),
        ]);
    }
    sec.tables.push(t);
    sec.tables.push(Table::key_values(
        "Search",
        vec![
            ("complete up to", format!("{:.6}", sp.complete_up_to)),
            ("tiles visited", sp.tiles.to_string()),
            ("unmatched links", sp.unmatched_links.to_string()),
            ("shortest generator", format!("{shortest_generator:.6}")),
        ],
    ));
    if sp.unmatched_links > 0 {
        sec.status = Status::Warning(format!(
            "{} links to unenumerated tiles: classes may be over-counted",
            sp.unmatched_links
        ));
    }
    sec.commands = vec![format!(
        "ricci spectrum surface.off --count {SPECTRUM_COUNT}"
    )];
    sec.headline = format!(
        "systole {:.6}; {} lengths up to {:.4}",
        first,
        lengths.len(),
        lengths.last().copied().unwrap_or(0.0)
    );
    sec.summary = json!({
        "genus": d.cut.genus,
        "lengths": lengths,
        "complete_up_to": sp.complete_up_to,
        "tiles": sp.tiles,
        "unmatched_links": sp.unmatched_links,
        "shortest_generator_translation_length": shortest_generator,
    });
    Ok(sec)
}

// ---------------------------------------------------------------------------------------------
// Affine atlas (paper 000 §4).

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

    // The central chart (chart 0 holds every face once) as per-corner coordinates.
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

    // Area distortion per face: log(flat area / R³ area), centred (the flat metric's scale
    // is arbitrary), the measure of paper 000 Step 1 before squaring.
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

    let kinds = |k: &str| r.charts.iter().filter(|c| c.kind == k).count();
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
    sec.tables.push(t);
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

// ---------------------------------------------------------------------------------------------
// Manifold spline (paper 000 §5).

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
    use ricci::spline::surface::{
        flat_domain, run as run_spline, MeshDistance, Singularity, SplineOptions,
    };
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
    let tris = &tess.triangles;
    let pos = &tess.positions;
    // The extraordinary point: the tessellation vertex nearest the centroid of the fill
    // patch (vertex_face < 0), ringed in orange in the pictures, which look at it along its normal.
    let fill: Vec<usize> = (0..pos.len())
        .filter(|&i| tess.vertex_face.get(i).is_some_and(|&f| f < 0))
        .collect();
    let ep = (!fill.is_empty()).then(|| {
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
    });
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

    // The tessellated surface as OBJ (the fill patch as group `fill`).
    let mut obj = String::from("# ricci demo: manifold triangular B-spline (tessellation)\n");
    for p in pos {
        obj.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
    }
    obj.push_str("g spline\n");
    for (i, t) in tris.iter().enumerate() {
        if i == tess.spline_triangles {
            obj.push_str("g fill\n");
        }
        obj.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    env.out.write("spline.obj", obj.as_bytes())?;

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
    sec.tables.push(Table::key_values(
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
    ));
    sec.files = vec![(
        "spline.obj".into(),
        "the tessellated spline surface (group `fill` is the patch at the extraordinary point)"
            .into(),
    )];
    sec.commands = vec![
        "ricci spline surface.off --degree 3 --fairness 1 --fit 1e-3 --out spline --json".into(),
    ];
    sec.summary = json!({
        "degree": rep.degree,
        "fairness": rep.fairness,
        "control_points": rep.control_points,
        "control_values": control.len(),
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
    });
    Ok(sec)
}
