//! `ricci spline MESH [--degree N] [--fairness R] [--singularity auto|V] [--fit LAMBDA]
//! [--tessellation M] [--out DIR] [--json]`: a manifold triangular B-spline surface with at most
//! one extraordinary point (paper 000 §5).
//!
//! The flat metric and charts come from the spline's own atlas (`--charts local`, default: the
//! flow's flat metric — genus 1 uniform, open free boundary, genus ≥ 2 one cone placed by least
//! area distortion after raising its valence and grading its neighbourhood — with one chart per
//! face: the development of every face sharing a vertex with it,
//! `ricci::spline::manifold::LocalCharts`) or from the paper's affine atlas (`--charts atlas`:
//! `ricci::atlas::AffineAtlas`, central chart + cut-curve charts). Both are affine atlases of a
//! flat cone metric with rigid transitions; the fairing over `AffineAtlas` is still slow and
//! does not reach its tolerance on eight.off (see BENCHMARKS.md), so `local` is the default. Then the subdivision control points, the fairing with
//! parameter `r`, optionally the least-squares fit to the mesh vertices, and the G¹ fill patch
//! at the cone. `--out DIR` writes `surface.obj` (tessellation; the fill patch is group
//! `fill`), `surface_vertices.json` (per tessellation vertex: domain face and chart, −1 on the
//! fill), `control_net.obj` (control points and the net of every domain triangle),
//! `boundaries.obj` (images of the domain edges and the seams as polylines) and
//! `spline.json` (the report).

use crate::util::read_surface;
use crate::util::{check_vertex, print_json, write_atomic, Reporter, UsageError};
use ricci::atlas::{AffineAtlas, AtlasOptions, FlatCharts, Singularity as AtlasSingularity};
use ricci::spline::dms::control_net_edges;
use ricci::spline::surface::{
    flat_domain, run as run_spline, MeshDistance, Singularity, SplineOptions, SplineReport,
    Tessellation,
};
use serde_json::json;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (OBJ, OFF, PLY, STL).
    pub mesh: PathBuf,
    /// Spline degree n (2..=5).
    #[arg(long, default_value_t = 3)]
    pub degree: usize,
    /// Fairness parameter r (0 ≤ r ≤ n − 1; paper 000 eq. 14).
    #[arg(long, default_value_t = 1)]
    pub fairness: usize,
    /// Singular vertex of a closed surface of genus ≥ 2: auto (least area distortion) or a
    /// vertex id.
    #[arg(long, default_value = "auto")]
    pub singularity: String,
    /// After the fairing, fit the control points to the mesh vertices with this thin-plate
    /// weight (e.g. 1e-3).
    #[arg(long)]
    pub fit: Option<f64>,
    /// Chart provider: local (`LocalCharts`: one developed chart per face on the flow's flat
    /// metric, valence raised and graded around the cone) or atlas (`ricci::atlas::AffineAtlas`:
    /// the paper's central + cut-curve charts; its fairing is still slow). Both place the
    /// cone by least area distortion.
    #[arg(long, default_value = "local")]
    pub charts: String,
    /// Segments per domain edge in the tessellation (8: fine enough for zebra stripes, whose
    /// reflected normals must change less than a stripe per tessellation triangle).
    #[arg(long, default_value_t = 8)]
    pub tessellation: usize,
    /// Output directory.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Budget in CPU-seconds: the command estimates its cost up front (scaled from measured
    /// runs, BENCHMARKS.md) and refuses to start when the estimate exceeds it; 0 = no limit.
    #[arg(long, default_value_t = 120.0, allow_hyphen_values = true)]
    pub budget: f64,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Estimated CPU-seconds and peak memory (GB) of `ricci spline` on `faces` faces: measured on
/// the demo's surface (2 432 faces, BENCHMARKS.md, *Spline budget*) per degree and fit,
/// linear in the faces; degrees other than 3 and 4 scale with the cube of the basis functions
/// per triangle (the simplex-spline recurrence and the dense per-face blocks).
pub fn estimate(faces: usize, degree: usize, fairness: usize, fit: bool) -> (f64, f64) {
    let scale = faces as f64 / 2432.0;
    // (CPU-seconds, GB) at degree 3 (r = 1) and 4 (r = 2), without and with the fit.
    let (cpu, gb) = match (degree, fit) {
        (3, false) => (EST_D3.0, EST_D3.1),
        (3, true) => (EST_D3_FIT.0, EST_D3_FIT.1),
        (4, false) => (EST_D4.0, EST_D4.1),
        (4, true) => (
            EST_D4.0 * EST_D3_FIT.0 / EST_D3.0,
            EST_D4.1 * EST_D3_FIT.1 / EST_D3.1,
        ),
        (n, f) => {
            let base = if f { EST_D3_FIT } else { EST_D3 };
            let nb = ((n + 1) * (n + 2) / 2) as f64;
            let k = (nb / 10.0).powi(3);
            (base.0 * k, base.1 * k)
        }
    };
    // Fairness adds constraint rows (about linear in r + 1).
    let r = (fairness as f64 + 1.0) / if degree == 4 { 3.0 } else { 2.0 };
    (cpu * scale * r.max(0.5), gb * scale * r.max(0.5))
}

/// Measured on the demo surface (2 432 faces): degree 3 r = 1 without / with `--fit 1e-3`,
/// degree 4 r = 2 without fit (CPU-seconds, peak GB).
const EST_D3: (f64, f64) = (2.8, 0.26);
const EST_D3_FIT: (f64, f64) = (8.2, 0.57);
const EST_D4: (f64, f64) = (6.7, 0.39);

pub fn run(a: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let singularity = check_args(&a)?;
    let use_atlas = match a.charts.as_str() {
        "atlas" => true,
        "local" => false,
        c => return Err(UsageError(format!("--charts must be atlas or local, not '{c}'")).into()),
    };
    let (surface, _) = read_surface(&a.mesh)?;
    if let Singularity::Vertex(v) = singularity {
        check_vertex("--singularity", v, surface.mesh.n_vertices())?;
    }
    let mut bar = Reporter::new(a.json);
    let stem = a
        .mesh
        .file_stem()
        .map_or("spline".into(), |s| s.to_string_lossy().into_owned());
    let no_out = format!(
        "warning: no --out: the spline was computed and only its numbers are reported; to keep \
         the surface, try: ricci spline {} --out {stem}-spline",
        a.mesh.display()
    );
    check_budget(&a, surface.mesh.n_faces(), &mut bar)?;
    let t_ricci = Instant::now();
    let dist = MeshDistance::new(&surface.positions, surface.mesh.faces());
    let opts = SplineOptions {
        degree: a.degree,
        fairness: a.fairness,
        fit_smoothing: a.fit,
        ..SplineOptions::default()
    };
    let provider: Box<dyn FlatCharts + Sync> = if use_atlas {
        let o = AtlasOptions {
            singularity: match singularity {
                Singularity::Auto => AtlasSingularity::Auto,
                Singularity::Vertex(v) => AtlasSingularity::Vertex(v),
            },
            ..AtlasOptions::default()
        };
        Box::new(AffineAtlas::build(&surface, &o, &mut bar)?)
    } else {
        Box::new(flat_domain(&surface, singularity, &mut bar)?.charts)
    };
    let t_ricci = t_ricci.elapsed().as_secs_f64();
    let charts: &(dyn FlatCharts + Sync) = provider.as_ref();
    // The fairing and the fit's solves report nothing while they run: a heartbeat line every
    // 10 s on stderr (when it is not a terminal) shows the command is alive.
    let (rep, tess, control) =
        bar.with_heartbeat(|bar| run_spline(charts, &dist, &opts, a.tessellation, bar))?;
    bar.bar.0.finish_and_clear();
    let topo = ricci::mesh::topology(&surface.mesh);
    let singular: Option<u32> = charts.singular_vertices().first().copied();
    let mut out = json!({
        "file": a.mesh.display().to_string(),
        "degree": rep.degree,
        "fairness": rep.fairness,
        "control_points": rep.control_points,
        "domain_faces": rep.domain_faces,
        "active_faces": rep.active_faces,
        "rms_error_percent": rep.rms_error_percent,
        "max_error_percent": rep.max_error_percent,
        "fill_max_error_percent": rep.fill_max_error_percent,
        "continuity": rep.continuity,
        "seconds": 0.0,
        "seconds_spline": rep.seconds,
        "seconds_ricci": t_ricci,
        "seconds_total": 0.0,
        "genus": topo.genus(),
        "boundary_loops": topo.boundary_loops(),
        "singular_vertex": singular,
        "added_vertices": charts.mesh().n_vertices() - surface.mesh.n_vertices(),
        "charts": {"provider": a.charts, "count": charts.n_charts()},
        "space": rep.space,
        "fairing_report": rep.fairing,
        "fit": rep.fit,
        "fit_ridge": rep.fit_ridge,
        "timings": {"knots": rep.seconds_knots, "fairing": rep.seconds_fairing, "fit": rep.seconds_fit, "fill": rep.seconds_fill},
        "tessellation": {"vertices": tess.positions.len(), "triangles": tess.triangles.len(), "spline_triangles": tess.spline_triangles},
    });
    // A fairing that stopped above its tolerance is said, on stderr and in the JSON, before
    // anything is written (the result is usable, but its continuity is only as good as the
    // residual reached).
    let f = &rep.fairing;
    out["converged"] = json!(f.converged);
    if !f.converged {
        eprintln!(
            "warning: {}: the fairing (r = {}) stopped at a relative constraint residual of \
             {:.1e} after {} steps (tolerance {:.0e}): the pieces meet only to that accuracy; \
             try: --fairness {}",
            a.mesh.display(),
            f.fairness,
            f.max_constraint_residual,
            f.refinement_steps,
            f.tolerance,
            f.fairness.saturating_sub(1)
        );
    }
    if let Some(dir) = &a.out {
        write_outputs(dir, charts, &rep, &tess, &control, &mut out, t0)?;
    }
    // `seconds`: the whole command (reading, flat domain, spline, measuring, writing).
    let total = t0.elapsed().as_secs_f64();
    out["seconds_total"] = json!(total);
    out["seconds"] = json!(total);
    // After the work (a failure stays one sentence on stderr): the result was not kept.
    if a.out.is_none() {
        eprintln!("{no_out}");
    }
    if a.json {
        print_json(&out);
    } else {
        println!(
            "{}: degree {} (r = {}), {} control points on {} of {} faces; {}; error rms {:.3}% max {:.3}% of the diagonal; {:.2} s",
            a.mesh.display(),
            rep.degree,
            rep.fairness,
            rep.control_points,
            rep.active_faces,
            rep.domain_faces,
            rep.continuity.class,
            rep.rms_error_percent,
            rep.max_error_percent,
            total
        );
        if let Some(dir) = &a.out {
            println!(
                "wrote {}/: surface.obj, surface_vertices.json, control_net.obj, boundaries.obj, spline.json",
                dir.display()
            );
        }
    }
    Ok(())
}

/// An estimate up front ([`estimate`]): refused when over `--budget`, printed when long.
fn check_budget(a: &Args, n_faces: usize, bar: &mut Reporter) -> anyhow::Result<()> {
    // An estimate up front (`estimate`), refused when over the budget; printed when long.
    let (est_seconds, est_gb) = estimate(n_faces, a.degree, a.fairness, a.fit.is_some());
    if a.budget > 0.0 && est_seconds > a.budget {
        // The same command with a budget above the estimate.
        let mut cmd = format!(
            "ricci spline {} --degree {} --fairness {}",
            a.mesh.display(),
            a.degree,
            a.fairness
        );
        if let Some(l) = a.fit {
            let _ = write!(cmd, " --fit {l}");
        }
        if a.singularity != "auto" {
            let _ = write!(cmd, " --singularity {}", a.singularity);
        }
        if a.charts != "local" {
            let _ = write!(cmd, " --charts {}", a.charts);
        }
        if a.tessellation != 8 {
            let _ = write!(cmd, " --tessellation {}", a.tessellation);
        }
        if let Some(o) = &a.out {
            let _ = write!(cmd, " --out {}", o.display());
        }
        let raise = (est_seconds * 2.0 / 100.0).ceil() * 100.0;
        anyhow::bail!(
            "{}: a degree-{} spline (r = {}{}) on {} faces would take roughly {:.0} CPU-seconds \
             and {:.1} GB of memory, over the budget of {:.0} s (--budget), so nothing was \
             computed; try: {cmd} --budget {raise:.0}",
            a.mesh.display(),
            a.degree,
            a.fairness,
            if a.fit.is_some() { ", fitted" } else { "" },
            n_faces,
            est_seconds,
            est_gb,
            a.budget,
        );
    }
    if est_seconds > 30.0 {
        bar.line(&format!(
            "estimate: {} faces at degree {}: roughly {:.0} CPU-seconds and {:.1} GB of memory \
             (budget {:.0} s); progress follows{}",
            n_faces,
            a.degree,
            est_seconds,
            est_gb,
            a.budget,
            if a.out.is_none() {
                " (no --out: nothing will be written)"
            } else {
                ""
            }
        ));
    }
    Ok(())
}

/// Writes `surface.obj`, `surface_vertices.json`, `control_net.obj`, `boundaries.obj` and
/// `spline.json` into `dir` (each atomically).
fn write_outputs(
    dir: &std::path::Path,
    charts: &(dyn FlatCharts + Sync),
    rep: &SplineReport,
    tess: &Tessellation,
    control: &[f64],
    out: &mut serde_json::Value,
    t0: Instant,
) -> anyhow::Result<()> {
    let surface_obj = surface_obj(rep, tess);
    let side = json!({"face": tess.vertex_face, "chart": tess.vertex_chart});
    let c = control_net_obj(charts, control, rep.degree, rep.control_points);
    let bo = boundaries_obj(tess);
    out["out"] = json!(dir.display().to_string());
    out["seconds_total"] = json!(t0.elapsed().as_secs_f64());
    out["seconds"] = out["seconds_total"].clone();
    write_atomic(&dir.join("surface.obj"), surface_obj.as_bytes())?;
    write_atomic(
        &dir.join("surface_vertices.json"),
        serde_json::to_string(&side)?.as_bytes(),
    )?;
    write_atomic(&dir.join("control_net.obj"), c.as_bytes())?;
    write_atomic(&dir.join("boundaries.obj"), bo.as_bytes())?;
    write_atomic(
        &dir.join("spline.json"),
        serde_json::to_string_pretty(&*out)?.as_bytes(),
    )?;
    Ok(())
}

/// The ranges of the numeric arguments, and the singular vertex.
fn check_args(a: &Args) -> anyhow::Result<Singularity> {
    if !(2..=5).contains(&a.degree) {
        return Err(UsageError(format!("--degree {} is not in 2..=5", a.degree)).into());
    }
    if a.fairness >= a.degree {
        return Err(UsageError(format!(
            "--fairness {} must be between 0 and n − 1 = {}",
            a.fairness,
            a.degree - 1
        ))
        .into());
    }
    if !(1..=64).contains(&a.tessellation) {
        return Err(UsageError(format!(
            "--tessellation {} is not in 1..=64",
            a.tessellation
        ))
        .into());
    }
    if !(a.budget >= 0.0 && a.budget.is_finite()) {
        return Err(UsageError(format!(
            "--budget {} must be a number of CPU-seconds ≥ 0 (0: no limit)",
            a.budget
        ))
        .into());
    }
    if let Some(l) = a.fit {
        if !(l >= 0.0 && l.is_finite()) {
            return Err(UsageError(format!("--fit {l} must be a finite weight ≥ 0")).into());
        }
    }
    let singularity = match a.singularity.as_str() {
        "auto" => Singularity::Auto,
        v => Singularity::Vertex(v.parse().map_err(|_| {
            UsageError(format!(
                "--singularity must be auto or a vertex id, not '{v}'"
            ))
        })?),
    };
    Ok(singularity)
}

/// `surface.obj`: the tessellation, the fill patches as group `fill`.
fn surface_obj(rep: &SplineReport, tess: &Tessellation) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# ricci spline: degree {} fairness {} ({} spline + {} fill triangles)",
        rep.degree,
        rep.fairness,
        tess.spline_triangles,
        tess.triangles.len() - tess.spline_triangles
    );
    for p in &tess.positions {
        let _ = writeln!(s, "v {} {} {}", p[0], p[1], p[2]);
    }
    let _ = writeln!(s, "g spline");
    for (k, t) in tess.triangles.iter().enumerate() {
        if k == tess.spline_triangles {
            let _ = writeln!(s, "g fill");
        }
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

/// `control_net.obj`: the control points of the active triangles (those not at a singular
/// vertex) and their nets ([`control_net_edges`]).
fn control_net_obj(
    charts: &(dyn FlatCharts + Sync),
    control: &[f64],
    n: usize,
    control_points: usize,
) -> String {
    let mesh = charts.mesh();
    let nb = (n + 1) * (n + 2) / 2;
    let mut c = String::new();
    let _ = writeln!(
        c,
        "# ricci spline control net: {} control points",
        control_points
    );
    let mut index = vec![0usize; mesh.n_faces()];
    let mut next = 1;
    for f in 0..mesh.n_faces() {
        let active = mesh
            .face(f as u32)
            .iter()
            .all(|v| !charts.singular_vertices().contains(v));
        if !active {
            continue;
        }
        index[f] = next;
        for k in 0..nb {
            let p = &control[(f * nb + k) * 3..(f * nb + k) * 3 + 3];
            let _ = writeln!(c, "v {} {} {}", p[0], p[1], p[2]);
        }
        next += nb;
    }
    let net = control_net_edges(n);
    for &first in &index {
        if first == 0 {
            continue;
        }
        for &(k, j) in &net {
            let _ = writeln!(c, "l {} {}", first + k, first + j);
        }
    }
    c
}

/// `boundaries.obj`: the images of the domain edges and the seams as polylines.
fn boundaries_obj(tess: &Tessellation) -> String {
    let mut bo = String::new();
    let _ = writeln!(
        bo,
        "# ricci spline patch boundaries: {} polylines",
        tess.boundaries.len()
    );
    let mut vi = 1;
    for line in &tess.boundaries {
        for p in line {
            let _ = writeln!(bo, "v {} {} {}", p[0], p[1], p[2]);
        }
        let ids: Vec<String> = (vi..vi + line.len()).map(|i| i.to_string()).collect();
        let _ = writeln!(bo, "l {}", ids.join(" "));
        vi += line.len();
    }
    bo
}
