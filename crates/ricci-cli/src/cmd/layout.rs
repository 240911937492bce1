//! `ricci layout MESH [--geometry G] [--target T] [--metric METRIC.json] [--base V]
//! [--seed-face F] [--tiling N] [--out UV.obj] [--svg PIC.svg] [--json]`: cut the surface to a
//! disk along canonical loops, lay it out isometrically with its uniformization metric (or the
//! given metric) in the plane, the Poincaré disk or on the sphere, and compute the deck group.
//!
//! Closed genus-0 surfaces go onto the sphere whole; disks are laid out as they are; every
//! other surface is cut first (`ricci::cut`). Hyperbolic metrics are polished to double-double
//! before the layout (`ricci::flow::polish`; `--no-polish` turns it off): the report's
//! `metric_polish` says what it did (`steps`, `residual_dd`, …, `applied: false` with a
//! `reason` when it could not be applied, e.g. a metric with cone points). Without `--metric` the Ricci flow of the
//! geometry is run (tolerance 1e-12 in H², 1e-10 otherwise). The seed face is a face id of the cut mesh (default:
//! the face nearest the centre of the polygon). `--tiling N` draws the first N copies of the
//! fundamental polygon (breadth first through the side pairings) instead of the polygon.
//! UV.obj keeps the surface's own vertices (`v`) and gives every corner the layout coordinate
//! of its cut-mesh vertex (`vt`; for the sphere, `v` are the points on the unit sphere).
//! The JSON's `timings` gives the CPU seconds of the process per stage (`input`, `flow`,
//! `polish`, `cut`, `layout`, `deck`, `output` — UVs and files), `timings_wall` the wall seconds.

use crate::util::read_surface;
use crate::util::{print_json, write_atomic, UsageError};
use indicatif::{ProgressBar, ProgressStyle};
use ricci::flow::{FlowError, FlowResult};
use ricci::layout::cover::{tiles_by_radius, word_string};
use ricci::layout::deck::{deck_group_ext, DeckFrames};
use ricci::layout::export::obj_with_corner_uv;
use ricci::layout::input_uv::input_face_uvs;
use ricci::layout::isometry::Complex;
use ricci::layout::pipeline::{uniformization_geometry, CutDisk};
use ricci::layout::place::{layout, layout_dd, minimax_centre, Space};
use ricci::layout::subdivision_uv::{
    common_subdivision_uvs_ext, sphere_common_subdivision, sphere_flipped_faces,
    sphere_orientation, LaidOut,
};
use ricci::layout::svg::{fundamental_domain_svg, sphere_svg, tiling_svg};
use ricci::layout::{DeckGroup, Isometry, Layout};
use ricci::mesh::{topology, Mesh, Surface};
use ricci::metric::file::MetricFile;
use ricci::metric::{Euclidean, Geometry, Hyperbolic, IntrinsicMetric, Scheme, Spherical};
use serde_json::{json, Value};
use std::path::PathBuf;
use std::time::Instant;

mod cut;
pub(crate) mod double;
pub mod file_metric;
mod json;
mod text;
mod tolerance;
use json::deck_json;
pub use json::JsonIso;
use text::print_text;

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (OBJ, OFF, PLY, STL).
    pub mesh: PathBuf,
    /// euclidean | hyperbolic | spherical (default: the uniformization geometry).
    #[arg(long)]
    pub geometry: Option<String>,
    /// Target curvature of the flow (see `ricci flow`; default uniform / free-boundary /
    /// geodesic-boundary by topology). Ignored with --metric.
    #[arg(long)]
    pub target: Option<String>,
    /// Discrete conformal scheme of the flow (see `ricci flow`; default: conformal — vertex
    /// scaling with intrinsic Delaunay flips — in E² and H², thurston on the sphere). Ignored
    /// with --metric.
    #[arg(long)]
    pub scheme: Option<Scheme>,
    /// Metric from `ricci flow --out` (JSON with `geometry` and per-edge `lengths`).
    #[arg(long)]
    pub metric: Option<PathBuf>,
    /// Base vertex of the canonical loops.
    #[arg(long)]
    pub base: Option<u32>,
    /// Seed face of the layout (a face id of the cut mesh).
    #[arg(long)]
    pub seed_face: Option<u32>,
    /// Draw this many copies of the fundamental polygon (universal cover) in the SVG.
    #[arg(long)]
    pub tiling: Option<usize>,
    /// Output OBJ with texture coordinates.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Output SVG picture.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Hyperbolic metrics: lay out the flow's double-precision metric as it is, without
    /// polishing it to double-double first.
    #[arg(long)]
    pub no_polish: bool,
    /// Newton iteration budget of the flow (default: the scheme's, e.g. 30 for vertex scaling
    /// with flips); a flow that runs out of it is refused with the reason. Ignored with --metric.
    #[arg(long)]
    pub max_iterations: Option<usize>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// How far the flow behind a layout or a spectrum may go: its tolerance (default
/// `layout_tolerance` of the geometry) and its iteration budget (default the scheme's).
#[derive(Clone, Copy, Debug, Default)]
pub struct FlowLimits {
    pub tolerance: Option<f64>,
    pub max_iterations: Option<usize>,
}

/// Per-edge lengths from a metric file (`ricci flow --out`): `lengths` by edge id, matched by
/// the vertex pairs in `edge_vertices` (`[[a, b], …]`) when present.
pub fn read_metric(path: &std::path::Path, surface: &Surface) -> anyhow::Result<MetricFile> {
    let m = ricci::metric::file::read_metric_file(path, &surface.mesh)?;
    m.check_usable(&path.display().to_string())?;
    Ok(m)
}

pub struct Bar(pub ProgressBar);
impl ricci::progress::Progress for Bar {
    fn report(&mut self, stage: &str, _f: Option<f64>, message: &str) {
        self.0.set_message(format!("{stage}: {message}"));
    }
}

pub fn spinner(json: bool) -> Bar {
    let bar = if json {
        ProgressBar::hidden()
    } else {
        ProgressBar::new_spinner()
    };
    bar.set_style(
        ProgressStyle::with_template("{spinner} {elapsed} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(120));
    Bar(bar)
}

/// A metric with its reports.
pub struct PolishedLengths {
    /// The metric, with double-double low parts when it was polished.
    pub metric: IntrinsicMetric,
    /// The triangulation the lengths belong to when it is not the input's: the intrinsic
    /// Delaunay triangulation of a conformal flow (or of a metric file that brings its own).
    /// Input vertices keep their ids in it.
    pub mesh: Option<Mesh>,
    /// The `metric` report.
    pub report: Value,
    /// The `metric_polish` report.
    pub polish: Value,
    /// The flow that computed the metric (`None` with `--metric`).
    pub flow: Option<ricci::flow::FlowResult>,
}

/// When the hyperbolic metric is polished to double-double.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Polish {
    /// Not at all (`--no-polish`).
    Off,
    /// At once, on the metric's own triangulation, before the cut (whose splits keep the
    /// double-double lengths converged: `cut_disk_polished` only checks the refined metric).
    Now,
}

/// [`metric`], then for hyperbolic metrics (unless `polish` is `Off`) the double-double polish
/// (`ricci::layout::pipeline::polish_uniformization` for the flow's metric,
/// `polish_lengths` — vertex scaling in place — for a metric file). A polish that cannot be
/// applied (a target other than 0, a metric with cone points) is reported, not an error.
/// `limits.tolerance` replaces `layout_tolerance` for the flow (reported as `flow_tolerance`).
#[allow(clippy::too_many_arguments)]
pub fn polished_metric(
    surface: &Surface,
    geometry: Option<Geometry>,
    target: Option<&str>,
    scheme: Option<Scheme>,
    metric_file: Option<&PathBuf>,
    polish: Polish,
    limits: FlowLimits,
    progress: &mut dyn ricci::progress::Progress,
) -> anyhow::Result<PolishedLengths> {
    use ricci::layout::pipeline::{polish_lengths, polish_uniformization};
    let (g, own, lengths, flow, mut report) = metric_and_flow(
        surface,
        geometry,
        target,
        scheme,
        metric_file,
        limits,
        progress,
    )?;
    if let Some(t) = limits.tolerance {
        report["flow_tolerance"] = json!(t);
    }
    crate::util::stage_done("flow");
    let mut out = PolishedLengths {
        metric: IntrinsicMetric::new(g, lengths),
        mesh: own,
        report,
        polish: json!({"applied": false, "reason": "not a hyperbolic metric"}),
        flow: None,
    };
    if g != Geometry::Hyperbolic {
        out.flow = flow;
        return Ok(out);
    }
    if polish == Polish::Off {
        out.polish = json!({"applied": false, "reason": "--no-polish"});
        out.flow = flow;
        return Ok(out);
    }
    progress.report("polish", None, "polishing the metric to double-double");
    let res = match (&flow, &out.mesh) {
        (Some(f), _) => polish_uniformization(
            &surface.mesh,
            &IntrinsicMetric::euclidean(surface.edge_lengths()),
            f,
        ),
        (None, own) => polish_lengths(own.as_ref().unwrap_or(&surface.mesh), &out.metric),
    };
    match res {
        Ok(p) => {
            out.polish = json!({
                "applied": true, "method": if flow.is_some() { "flow variables" } else { "vertex scaling in place" },
                "steps": p.steps, "residual_start": p.residual_start,
                "residual_dd": p.residual_dd, "converged": p.converged,
            });
            out.metric = p.metric;
        }
        Err(e) => out.polish = json!({"applied": false, "reason": e.to_string()}),
    }
    crate::util::stage_done("polish");
    out.flow = flow;
    Ok(out)
}

/// (geometry, the triangulation of the metric when it is not the input's, lengths, the flow,
/// the `metric` report).
type MetricAndFlow = (
    Geometry,
    Option<Mesh>,
    Vec<f64>,
    Option<ricci::flow::FlowResult>,
    Value,
);

/// The metric to use: from the file or from the flow (returned too, with its report).
fn metric_and_flow(
    surface: &Surface,
    geometry: Option<Geometry>,
    target: Option<&str>,
    scheme: Option<Scheme>,
    metric_file: Option<&PathBuf>,
    limits: FlowLimits,
    progress: &mut dyn ricci::progress::Progress,
) -> anyhow::Result<MetricAndFlow> {
    if let Some(path) = metric_file {
        let MetricFile {
            geometry: g,
            lengths: l,
            mesh: own,
            converged,
            ..
        } = read_metric(path, surface)?;
        if let Some(want) = geometry {
            if want != g {
                return Err(UsageError(format!(
                    "--geometry {want} contradicts the metric file's geometry {g}"
                ))
                .into());
            }
        }
        let mut report = json!({"source": path.display().to_string()});
        let k = file_metric::interior_curvature(own.as_ref().unwrap_or(&surface.mesh), g, &l);
        file_metric::report(&mut report, converged, k);
        if let Some(m) = &own {
            report["triangulation"] = json!({
                "kind": "intrinsic", "vertices": m.n_vertices(), "faces": m.n_faces(),
            });
        }
        return Ok((g, own, l, None, report));
    }
    let g = match geometry {
        Some(g) => g,
        None => uniformization_geometry(&surface.mesh)?,
    };
    // The uniformization options of the layout pipeline: the tolerance per geometry
    // (`layout_tolerance`) and the topology's target unless one is given.
    let scheme = scheme.unwrap_or_else(|| ricci::flow::default_scheme(g));
    let mut uniformization = ricci::flow::UniformizationOptions::single(
        Some(g),
        scheme,
        limits
            .tolerance
            .unwrap_or_else(|| ricci::flow::uniformize::layout_tolerance(g)),
    );
    if let Some(t) = target {
        uniformization.target = ricci::flow::TargetPolicy::Given(
            t.parse()
                .map_err(|e: String| UsageError(format!("--target: {e}")))?,
        );
    }
    let opts = uniformization.flow_options(&surface.mesh, scheme, limits.max_iterations)?;
    let r = ricci::flow::ricci_flow(&surface.mesh, &surface.edge_lengths(), &opts, progress)?;
    let mut report = json!({
        "source": "flow", "scheme": r.scheme, "target": r.target_description,
        "iterations": r.iterations,
        "converged": r.converged, "max_curvature_error": r.max_curvature_error,
        "gauss_bonnet_error": r.gauss_bonnet_error, "seconds": r.seconds,
    });
    if !r.converged {
        anyhow::bail!("{}; no layout computed", FlowError::not_converged(&r));
    }
    let own = r.triangulation.as_ref().map(|t| {
        report["triangulation"] = json!({
            "kind": "intrinsic", "flips": t.initial_flips + t.flips, "splits": t.splits,
            "vertices": t.simplicial.mesh.n_vertices(), "faces": t.simplicial.mesh.n_faces(),
        });
        t.simplicial.mesh.clone()
    });
    let lengths = r.lengths.clone();
    Ok((g, own, lengths, Some(r), report))
}

/// Lay out the cut disk (or the disk `work`), compute the deck group and write the files.
/// `work` is the triangulation the metric lives on (the input's, or the intrinsic one of a
/// conformal flow, input vertices first).
#[allow(clippy::too_many_arguments)]
fn planar<S: Space<Point = Complex>>(
    a: &Args,
    surface: &Surface,
    work: &Mesh,
    disk: Option<&CutDisk>,
    metric: &IntrinsicMetric,
    flow: Option<&FlowResult>,
    out: &mut Value,
) -> anyhow::Result<()>
where
    S::Iso: JsonIso,
{
    let (mesh, metric) = match disk {
        Some(d) => (&d.mesh, &d.metric),
        None => (work, metric),
    };
    let l: Layout<Complex> = layout_dd::<S>(mesh, metric, a.seed_face)?;
    crate::util::stage_done("layout");
    out["flipped_faces"] = json!(l.flipped_faces.len());
    out["degenerate_faces"] = json!(l.degenerate_faces.len());
    out["seed_face"] = json!(l.seed_face);
    out["max_length_error"] = json!(l.max_length_error);
    out["depth"] = json!(l.depth);
    let poly = disk.map(|d| &d.polygon);
    let (group, frames) = match poly {
        Some(p) if p.sides.iter().any(|s| s.partner.is_some()) => {
            let (g, f) = deck_group_ext::<S>(&l, p)?;
            (Some(g), Some(f))
        }
        _ => (None, None),
    };
    crate::util::stage_done("deck");
    match (&group, poly) {
        (Some(g), Some(p)) => {
            let dj = deck_json(g, p);
            out["deck_generators"] = dj["generators"].clone();
            out["side_pairings"] = dj["side_pairings"].clone();
            out["relation_error"] = json!(g.relation_error);
            out["relation_condition"] = json!(g.relation_condition);
            out["max_edge_spread"] = json!(g.max_edge_spread);
            out["max_edge_spread_matrix"] = json!(g.max_edge_spread_matrix);
            out["max_vertex_error"] = json!(g.max_vertex_error);
            if S::KIND == Geometry::Euclidean {
                // Genus 1: the flat torus's modulus τ from the two translations.
                let t: Vec<Complex> = g
                    .generators
                    .iter()
                    .flatten()
                    .map(|m| m.apply(Complex::new(0.0, 0.0)) - Complex::new(0.0, 0.0))
                    .collect();
                if t.len() == 2 {
                    if let Ok(tau) = ricci::analysis::spectrum::torus_modulus(t[0], t[1]) {
                        out["modulus"] = json!([tau.0, tau.1]);
                    }
                }
            }
        }
        _ => {
            out["deck_generators"] = json!([]);
            out["relation_error"] = Value::Null;
        }
    }
    let origin: Vec<u32> = match disk {
        Some(d) => d.vertex_origin.clone(),
        None => (0..mesh.n_vertices() as u32).collect(),
    };
    let laid = LaidOut {
        positions: &l.positions,
        positions_lo: &l.positions_lo,
        origin: &origin,
    };
    planar_uv::<S>(
        a,
        surface,
        flow,
        &laid,
        group.as_ref(),
        frames.as_ref(),
        out,
    )?;
    if let Some(path) = &a.svg {
        let svg = match (a.tiling, &group, poly) {
            (Some(n), Some(g), Some(p)) => {
                let base = minimax_centre::<S>(&l.positions);
                let radius = if S::KIND == Geometry::Hyperbolic {
                    12.0
                } else {
                    f64::MAX
                };
                let tiles = tiles_by_radius::<S>(g, p, base, radius, n.max(1))?;
                out["tiles"] = json!(tiles.len());
                out["tile_words"] = json!(tiles
                    .iter()
                    .take(50)
                    .map(|t| word_string(&g.letters, &t.word))
                    .collect::<Vec<_>>());
                let drawn: Vec<Vec<(Option<usize>, Vec<Complex>)>> = tiles
                    .iter()
                    .map(|t| {
                        p.sides
                            .iter()
                            .map(|s| {
                                (
                                    s.letter,
                                    s.vertices
                                        .iter()
                                        .map(|&v| t.map.apply(l.positions[v as usize]))
                                        .collect(),
                                )
                            })
                            .collect()
                    })
                    .collect();
                tiling_svg(&drawn, S::KIND)
            }
            _ => fundamental_domain_svg(mesh, &l.positions, poly, S::KIND, 30_000),
        };
        write_atomic(path, svg.as_bytes())?;
    }
    Ok(())
}

/// `uv` of the report and `--out` (E², H²): the input's own faces, each corner at the layout
/// position of its vertex mapped across the seams by the deck group
/// (`ricci::layout::input_uv`); when some of their UV triangles are flipped or degenerate and
/// the metric comes from a conformal flow, the common subdivision of the input and the
/// flow's intrinsic triangulation instead (`ricci::layout::subdivision_uv`: points on the
/// input surface, projective interpolation of the layout).
#[allow(clippy::too_many_arguments)]
fn planar_uv<S: Space<Point = Complex>>(
    a: &Args,
    surface: &Surface,
    flow: Option<&FlowResult>,
    laid: &LaidOut<'_>,
    group: Option<&DeckGroup<S::Iso>>,
    frames: Option<&DeckFrames<S::Frame>>,
    out: &mut Value,
) -> anyhow::Result<()>
where
    S::Iso: JsonIso,
{
    let uvs = input_face_uvs::<S>(&surface.mesh, laid.positions, laid.origin, group)?;
    let n_flipped = uvs.flipped_faces.len();
    let mut uv = json!({
        "on": "input", "faces": "input", "flipped_faces": n_flipped,
        "input_flipped_faces": n_flipped, "seam_faces": uvs.seam_faces,
    });
    let intrinsic = flow.and_then(|f| f.triangulation.as_ref().map(|t| (&t.triangulation, &f.u)));
    let mut sub = None;
    if n_flipped > 0 {
        match intrinsic {
            Some((t, u)) => match common_subdivision_uvs_ext::<S>(
                &surface.mesh,
                &surface.positions,
                &IntrinsicMetric::euclidean(surface.edge_lengths()),
                t,
                u,
                laid,
                group,
                frames,
            ) {
                Ok(s) => sub = Some(s),
                Err(e) => {
                    uv["common_subdivision_error"] = json!(e.to_string());
                    eprintln!(
                        "warning: {}: {n_flipped} input face(s) have flipped UV triangles and the \
                         common subdivision failed ({e}); writing the input's faces",
                        a.mesh.display()
                    );
                }
            },
            None => eprintln!(
                "warning: {}: {n_flipped} input face(s) have flipped or degenerate UV triangles \
                 (a common subdivision needs the intrinsic triangulation of a conformal flow: \
                 run without --metric, with the default scheme)",
                a.mesh.display()
            ),
        }
    }
    let kind = S::KIND.name();
    let what = match &sub {
        Some(s) => {
            uv["on"] = json!("common_subdivision");
            uv["faces"] = json!("common_subdivision");
            uv["flipped_faces"] = json!(s.flipped_faces);
            uv["vertices"] = json!(s.n_vertices());
            uv["triangles"] = json!(s.triangles.len());
            uv["crossings"] = json!(s.crossings);
            uv["seam_faces"] = json!(s.seam_faces);
            uv["t_flipped_faces"] = json!(s.t_flipped_faces);
            uv["recentred_faces"] = json!(s.recentred_faces);
            uv["nudged_uvs"] = json!(s.nudged_uvs);
            format!(
                "the common subdivision of the input and the intrinsic triangulation ({} \
                 vertices on the input surface, {} faces, {} flipped; the input's own faces \
                 would have {n_flipped} flipped UV triangle(s))",
                s.n_vertices(),
                s.triangles.len(),
                s.flipped_faces
            )
        }
        None => format!(
            "the input's {} vertices and {} faces ({n_flipped} flipped UV triangle(s))",
            surface.mesh.n_vertices(),
            surface.mesh.n_faces()
        ),
    };
    out["uv"] = uv;
    if let Some(path) = &a.out {
        let mut comments = vec![
            format!("ricci layout of {} ({kind})", a.mesh.display()),
            format!("v, f: {what}"),
            "vt: layout coordinates per corner (Poincaré disk for hyperbolic); several vt per \
             vertex along the seams"
                .to_string(),
        ];
        if let Some(s) = sub.as_ref().filter(|s| s.recentred_faces > 0) {
            comments.push(format!(
                "vt: {} face(s) of the intrinsic triangulation lie too far out in the disk for \
                 double precision and are written at their deck image nearest the centre (one \
                 more seam around each)",
                s.recentred_faces
            ));
        }
        if let Some(s) = sub.as_ref().filter(|s| s.nudged_uvs > 0) {
            comments.push(format!(
                "vt: {} UV(s) moved by at most 3 ulps so that pieces positively oriented in \
                 exact arithmetic stay so after rounding",
                s.nudged_uvs
            ));
        }
        let text = match &sub {
            Some(s) => obj_with_corner_uv(&s.positions, &s.triangles, &s.corner_uv, &comments),
            None => {
                let corner: Vec<[f64; 2]> = uvs.corner.iter().map(|z| [z.re, z.im]).collect();
                obj_with_corner_uv(&surface.positions, surface.mesh.faces(), &corner, &comments)
            }
        };
        write_atomic(path, text.as_bytes())?;
        eprintln!("wrote {}: {kind} UVs on {what}", path.display());
    }
    Ok(())
}

/// The layout on the sphere (closed genus 0). With the conformal flow's points
/// (`ricci::flow::sphere::conformal_sphere`) the report measures them against the metric and
/// `--out` writes the input's faces on the sphere, or — when some of them are not positively
/// oriented there — the common subdivision (`ricci::layout::subdivision_uv`); without (a
/// metric file, another scheme), the metric is laid out face by face.
fn sphere_layout(
    a: &Args,
    surface: &Surface,
    work: &Mesh,
    metric: &IntrinsicMetric,
    flow: Option<&FlowResult>,
    out: &mut Value,
) -> anyhow::Result<()> {
    out["deck_generators"] = json!([]);
    out["relation_error"] = Value::Null;
    let conformal = flow.and_then(|f| {
        f.triangulation
            .as_ref()
            .filter(|t| !t.points.is_empty())
            .map(|t| (t, &f.u))
    });
    let Some((t, u)) = conformal else {
        return sphere_from_lengths(a, work, metric, out);
    };
    let tri = &t.triangulation;
    let points = &t.points;
    let t_faces: Vec<[u32; 3]> = (0..tri.n_faces() as u32).map(|f| tri.face(f)).collect();
    let bad = sphere_flipped_faces(points, &t_faces);
    let degenerate = bad
        .iter()
        .filter(|&&f| {
            let v = t_faces[f as usize].map(|v| points[v as usize]);
            let d = sphere_orientation(v[0], v[1], v[2]);
            d.is_nan() || d >= 0.0
        })
        .count();
    let mut max_err = 0.0f64;
    for e in 0..tri.n_edges() as u32 {
        let [i, j] = tri.edge_vertices(e);
        let (p, q) = (points[i as usize], points[j as usize]);
        let chord = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
        let metric = 2.0 * (0.5 * tri.lambda[e as usize]).exp().min(1.0).asin();
        max_err = max_err.max((2.0 * (0.5 * chord).min(1.0).asin() - metric).abs());
    }
    out["flipped_faces"] = json!(bad.len() - degenerate);
    out["degenerate_faces"] = json!(degenerate);
    out["seed_face"] = Value::Null;
    out["max_length_error"] = json!(max_err);
    let input_bad = sphere_flipped_faces(points, surface.mesh.faces()).len();
    let mut uv = json!({
        "on": "input", "faces": "input", "flipped_faces": input_bad,
        "input_flipped_faces": input_bad, "points": "conformal_sphere",
    });
    let sub = if input_bad > 0 {
        let s = sphere_common_subdivision(
            &surface.mesh,
            &surface.positions,
            &IntrinsicMetric::euclidean(surface.edge_lengths()),
            tri,
            u,
            points,
        )?;
        uv["on"] = json!("common_subdivision");
        uv["faces"] = json!("common_subdivision");
        uv["flipped_faces"] = json!(s.flipped_faces);
        uv["vertices"] = json!(s.n_vertices());
        uv["triangles"] = json!(s.triangles.len());
        uv["crossings"] = json!(s.crossings);
        Some(s)
    } else {
        None
    };
    out["uv"] = uv;
    if let Some(path) = &a.out {
        let (pts, faces, what) = match &sub {
            Some(s) => (
                &s.sphere_points[..],
                &s.triangles[..],
                format!(
                    "the common subdivision of the input and the intrinsic triangulation ({} \
                     vertices, {} faces, {} not positively oriented; the input's own faces \
                     would have {input_bad})",
                    s.n_vertices(),
                    s.triangles.len(),
                    s.flipped_faces
                ),
            ),
            None => (
                &points[..],
                surface.mesh.faces(),
                format!(
                    "the input's {} vertices and {} faces (0 not positively oriented)",
                    surface.mesh.n_vertices(),
                    surface.mesh.n_faces()
                ),
            ),
        };
        let mut text = format!(
            "# ricci layout of {} on the unit sphere\n# v: points on the unit sphere; f: {what}\n",
            a.mesh.display()
        );
        for p in pts {
            text.push_str(&format!("v {:e} {:e} {:e}\n", p[0], p[1], p[2]));
        }
        for t in faces {
            text.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
        }
        write_atomic(path, text.as_bytes())?;
        eprintln!(
            "wrote {}: points on the unit sphere, {what}",
            path.display()
        );
    }
    if let Some(path) = &a.svg {
        write_atomic(path, sphere_svg(&surface.mesh, points).as_bytes())?;
    }
    Ok(())
}

/// The sphere laid out face by face from the lengths (a metric file, or a scheme without the
/// conformal sphere's points); `--out` writes the metric's triangulation.
fn sphere_from_lengths(
    a: &Args,
    work: &Mesh,
    metric: &IntrinsicMetric,
    out: &mut Value,
) -> anyhow::Result<()> {
    let l = layout::<Spherical>(work, metric, a.seed_face)?;
    out["flipped_faces"] = json!(l.flipped_faces.len());
    out["degenerate_faces"] = json!(l.degenerate_faces.len());
    out["seed_face"] = json!(l.seed_face);
    out["max_length_error"] = json!(l.max_length_error);
    if !l.flipped_faces.is_empty() || !l.degenerate_faces.is_empty() {
        // Never silently: a layout placed triangle by triangle cannot resolve triangles a
        // map shrinks to ~1e-5.
        eprintln!(
            "warning: {}: the sphere layout has {} flipped and {} degenerate face(s) (laid out \
             face by face from the lengths; the points cannot resolve its smallest triangles); \
             the counts are in the JSON",
            a.mesh.display(),
            l.flipped_faces.len(),
            l.degenerate_faces.len()
        );
    }
    if let Some(path) = &a.out {
        let mut text = format!(
            "# ricci layout of {} on the unit sphere\n# v: points on the unit sphere; f: the \
             metric's triangulation\n",
            a.mesh.display()
        );
        for p in &l.positions {
            text.push_str(&format!("v {:e} {:e} {:e}\n", p[0], p[1], p[2]));
        }
        for t in work.faces() {
            text.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
        }
        write_atomic(path, text.as_bytes())?;
        eprintln!(
            "wrote {}: points on the unit sphere, the metric's triangulation ({} vertices, {} \
             faces)",
            path.display(),
            work.n_vertices(),
            work.n_faces()
        );
    }
    if let Some(path) = &a.svg {
        write_atomic(path, sphere_svg(work, &l.positions).as_bytes())?;
    }
    Ok(())
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    crate::util::stages_start();
    let geometry: Option<Geometry> = match &a.geometry {
        Some(g) => Some(g.parse().map_err(UsageError)?),
        None => None,
    };
    if a.tiling == Some(0) {
        return Err(UsageError("--tiling needs at least one copy".into()).into());
    }
    let (surface, _) = read_surface(&a.mesh)?;
    crate::util::stage_done("input");
    if let Some(b) = a.base {
        crate::util::check_vertex("--base", b, surface.mesh.n_vertices())?;
    }
    let mut bar = spinner(a.json);
    let polished = polished_metric(
        &surface,
        geometry,
        a.target.as_deref(),
        a.scheme,
        a.metric.as_ref(),
        if a.no_polish {
            Polish::Off
        } else {
            Polish::Now
        },
        FlowLimits {
            tolerance: tolerance::flow_tolerance(&a, &surface.mesh, geometry),
            max_iterations: a.max_iterations,
        },
        &mut bar,
    );
    let PolishedLengths {
        metric,
        mesh: own_mesh,
        report: metric_report,
        polish: mut polish_report,
        flow,
    } = match polished {
        Ok(p) => p,
        // The surface's own flow failed or stalled: a disk is laid out through its double.
        Err(e)
            if e.downcast_ref::<UsageError>().is_none()
                && double::applies(&a, geometry, &surface.mesh) =>
        {
            let reason = crate::util::sentence(&e).replace("; no layout computed", "");
            return double::run_double(&a, &surface, &reason, &mut bar, t0);
        }
        Err(e) => anyhow::bail!("{}: {}", a.mesh.display(), crate::util::sentence(&e)),
    };
    let mut metric_report = metric_report;
    if let Some(w) = file_metric::layout_warning(&metric_report) {
        eprintln!("warning: {}: {w}", a.mesh.display());
        metric_report["warning"] = json!(w);
    }
    let geometry = metric.geometry();
    // The triangulation the metric lives on, and the input's positions when it is the input.
    let work: &Mesh = own_mesh.as_ref().unwrap_or(&surface.mesh);
    let work_positions = own_mesh.is_none().then_some(&surface.positions[..]);
    let t = topology(&surface.mesh);
    let comp = t
        .components
        .first()
        .ok_or_else(|| anyhow::anyhow!("the mesh has no faces"))?;
    let mut out = json!({
        "file": a.mesh.display().to_string(),
        "geometry": geometry.name(),
        "genus": comp.genus,
        "boundary_loops": comp.boundary_loops,
        "metric": metric_report,
    });
    let simply_connected = comp.genus == 0 && comp.boundary_loops <= 1;
    if geometry == Geometry::Spherical {
        if !(simply_connected && comp.boundary_loops == 0) {
            anyhow::bail!("spherical layouts need a closed genus-0 surface");
        }
        bar.0.set_message("layout on the sphere");
        sphere_layout(&a, &surface, work, &metric, flow.as_ref(), &mut out)?;
    } else {
        let disk = if simply_connected && comp.boundary_loops == 1 {
            None
        } else {
            let d = cut::cut_stage(
                work,
                &metric,
                work_positions,
                a.base,
                &mut polish_report,
                &mut out,
                &mut bar,
            )?;
            crate::util::stage_done("cut");
            Some(d)
        };
        bar.0.set_message("layout and deck group");
        match geometry {
            Geometry::Hyperbolic => planar::<Hyperbolic>(
                &a,
                &surface,
                work,
                disk.as_ref(),
                &metric,
                flow.as_ref(),
                &mut out,
            )?,
            _ => planar::<Euclidean>(
                &a,
                &surface,
                work,
                disk.as_ref(),
                &metric,
                flow.as_ref(),
                &mut out,
            )?,
        }
    }
    bar.0.finish_and_clear();
    crate::util::stage_done("output");
    let (cpu, wall) = crate::util::stages_take();
    out["timings"] = cpu;
    out["timings_wall"] = wall;
    out["metric_polish"] = polish_report;
    out["seconds"] = json!(t0.elapsed().as_secs_f64());
    if a.json {
        print_json(&out);
    } else {
        print_text(&a, geometry, &out);
    }
    Ok(())
}
