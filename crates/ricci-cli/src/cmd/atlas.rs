//! `ricci atlas MESH [--singularity auto|V] [--cones V=K,...] [--scheme S] [--tolerance T]
//! --out DIR [--json]`: the affine atlas with a single extraordinary point
//! (`ricci::atlas::AffineAtlas`, paper 000 §4).
//!
//! DIR receives `atlas.json` (the JSON report below plus every chart's faces and corner
//! coordinates), `overview.svg` (the central chart with the cut charts mapped into it) and
//! `chart-K.svg` for every chart. Every file is written atomically. With `--singularity auto`
//! every candidate flow of the placement prints one line on stderr (vertex, converged or not,
//! distortion or best residual, iterations, seconds).

use crate::util::read_surface;
use crate::util::{print_json, write_atomic, UsageError};
use indicatif::{ProgressBar, ProgressStyle};
use ricci::atlas::{AffineAtlas, AtlasOptions, FlatCharts, Singularity};
use ricci::flow::TargetSpec;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (OBJ, OFF, PLY, STL).
    pub mesh: PathBuf,
    /// Singular vertex of a closed surface of genus ≥ 2: `auto` (least area distortion) or a
    /// vertex id.
    #[arg(long, default_value = "auto")]
    pub singularity: String,
    /// Cones instead of a single singular vertex (closed surfaces): `V=K,...`, curvatures in
    /// radians (`-2pi`, `pi/2` accepted), summing to 2πχ.
    #[arg(long)]
    pub cones: Option<String>,
    /// Conformal scheme of the flow: thurston (the papers'), tangential, inversive, yamabe.
    #[arg(long, default_value = "thurston")]
    pub scheme: String,
    /// Flow tolerance: max |K − K̄|.
    #[arg(long, default_value_t = 1e-10)]
    pub tolerance: f64,
    /// Output directory (atlas.json, overview.svg, chart-K.svg).
    #[arg(long, short = 'o')]
    pub out: PathBuf,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let options = parse_options(&a)?;
    let (s, _) = read_surface(&a.mesh)?;
    check_vertices(&options, s.mesh.n_vertices() as u32)?;
    let bar = ProgressBar::new(100);
    bar.set_style(
        ProgressStyle::with_template("{spinner} atlas {prefix:>9} [{bar:30}] {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut progress = |stage: &str, f: Option<f64>, msg: &str| {
        // The automatic placement reports one line per candidate flow: keep those on stderr.
        if stage == "placement candidate" {
            let line = format!("placement: {msg}");
            if bar.is_hidden() {
                eprintln!("{line}");
            } else {
                bar.println(line);
            }
            return;
        }
        bar.set_prefix(stage.to_string());
        if let Some(f) = f {
            bar.set_position((100.0 * f.clamp(0.0, 1.0)) as u64);
        }
        bar.set_message(msg.to_string());
    };
    let atlas = AffineAtlas::build(&s, &options, &mut progress);
    bar.finish_and_clear();
    let atlas = atlas?;
    let r = &atlas.report;
    let singular_vertex = if r.singular_vertices.len() == 1 {
        json!(r.singular_vertices[0])
    } else {
        Value::Null
    };
    let mut v = json!({
        "file": a.mesh.display().to_string(),
        "genus": r.genus,
        "boundary_loops": r.boundary_loops,
        "target": r.target,
        "singular_vertex": singular_vertex,
        "singular_vertices": r.singular_vertices,
        "charts": atlas.n_charts(),
        "max_transition_error": r.max_transition_error,
        "area_distortion": r.area_distortion,
        "flipped_faces": r.flipped_faces,
        "max_length_error": r.max_length_error,
        "faces_without_home": r.faces_without_home,
        "flow": {
            "scheme": r.scheme,
            "converged": r.flow_converged,
            "iterations": r.flow_iterations,
            "max_curvature_error": r.max_curvature_error,
            "gauss_bonnet_error": r.gauss_bonnet_error,
            "tolerance": a.tolerance,
        },
        "placement": r.placement,
        "refinement": r.refinement,
        "boundary_word": r.boundary_word,
        "vertices": atlas.mesh().n_vertices(),
        "faces": atlas.mesh().n_faces(),
        "chart_list": r.charts,
        "notes": r.notes,
        "out": a.out.display().to_string(),
        "seconds": 0.0,
    });
    write_files(&a.out, &atlas, &v)?;
    if !r.flow_converged {
        eprintln!(
            "warning: the Ricci flow did not converge (max |K − K̄| = {:.3e})",
            r.max_curvature_error
        );
    }
    v["seconds"] = json!(t0.elapsed().as_secs_f64());
    if a.json {
        print_json(&v);
    } else {
        print_summary(&a, &atlas);
    }
    Ok(())
}

/// The atlas options from the arguments (usage errors before the mesh is read).
fn parse_options(a: &Args) -> anyhow::Result<AtlasOptions> {
    let singularity = match a.singularity.trim() {
        "auto" => Singularity::Auto,
        v => Singularity::Vertex(v.parse::<u32>().map_err(|_| {
            UsageError(format!("--singularity '{v}': expected auto or a vertex id"))
        })?),
    };
    let cones = match &a.cones {
        None => None,
        Some(list) => match format!("cone:{list}").parse::<TargetSpec>() {
            Ok(TargetSpec::Cones(c)) => Some(c),
            Ok(_) => None,
            Err(e) => return Err(UsageError(format!("--cones: {e}")).into()),
        },
    };
    let scheme = a
        .scheme
        .parse()
        .map_err(|e: String| UsageError(format!("--scheme: {e}")))?;
    if !(a.tolerance > 0.0 && a.tolerance.is_finite()) {
        return Err(UsageError(format!("--tolerance {} must be positive", a.tolerance)).into());
    }
    let options = AtlasOptions {
        singularity,
        cones,
        scheme,
        tolerance: a.tolerance,
        ..AtlasOptions::default()
    };
    Ok(options)
}

/// The vertices named by `--singularity` and `--cones` exist (`nv` vertices).
fn check_vertices(options: &AtlasOptions, nv: u32) -> anyhow::Result<()> {
    if let Singularity::Vertex(v) = options.singularity {
        crate::util::check_vertex("--singularity", v, nv as usize)?;
    }
    if let Some(c) = &options.cones {
        if let Some(&(v, _)) = c.iter().find(|c| c.0 >= nv) {
            return Err(UsageError(format!(
                "--cones: vertex {v}: the mesh has only {nv} vertices"
            ))
            .into());
        }
    }
    Ok(())
}

/// `atlas.json` (the report `v` with every chart's faces and corner coordinates, the home
/// charts, positions and triangles), `overview.svg` and `chart-K.svg` in `out`.
fn write_files(out: &Path, atlas: &AffineAtlas, v: &Value) -> anyhow::Result<()> {
    // Files: the report with the charts, and the pictures.
    let charts: Vec<Value> = (0..atlas.n_charts() as u32)
        .map(|c| {
            let (faces, coords) = atlas.chart_faces(c).unwrap_or((&[], &[]));
            json!({"id": c, "faces": faces, "coords": coords})
        })
        .collect();
    let mut file = v.clone();
    file["chart_faces"] = Value::Array(charts);
    file["home_chart"] = json!((0..atlas.mesh().n_faces() as u32)
        .map(|f| atlas.home_chart(f))
        .collect::<Vec<_>>());
    file["positions"] = json!(atlas.positions());
    file["triangles"] = json!(atlas.mesh().faces());
    write_atomic(
        &out.join("atlas.json"),
        serde_json::to_string(&file)?.as_bytes(),
    )?;
    write_atomic(
        &out.join("overview.svg"),
        svg::overview_svg(atlas, 900.0).as_bytes(),
    )?;
    for c in 0..atlas.n_charts() as u32 {
        if let Some(pic) = svg::chart_svg(atlas, c, 700.0) {
            write_atomic(&out.join(format!("chart-{c}.svg")), pic.as_bytes())?;
        }
    }
    Ok(())
}

/// The human-readable summary on stdout.
fn print_summary(a: &Args, atlas: &AffineAtlas) {
    let r = &atlas.report;
    let sing = if r.singular_vertices.is_empty() {
        "no singular vertex".to_string()
    } else {
        format!("singular vertices {:?}", r.singular_vertices)
    };
    println!(
        "{}: genus {}, {} boundary loops, {sing} ({})",
        a.mesh.display(),
        r.genus,
        r.boundary_loops,
        r.target
    );
    println!(
        "  flow ({}): converged {}, max |K − K̄| = {:.2e}; area distortion {:.4}",
        r.scheme, r.flow_converged, r.max_curvature_error, r.area_distortion
    );
    println!(
        "  {} charts, {} flipped faces, max transition error {:.2e}, {} faces without home chart",
        atlas.n_charts(),
        r.flipped_faces,
        r.max_transition_error,
        r.faces_without_home
    );
    println!("  wrote {}", a.out.display());
}

/// SVG pictures of an affine atlas: the library's charts and overview drawn by
/// `ricci_render::atlas`.
pub mod svg {
    use ricci::atlas::{AffineAtlas, ChartId, FlatCharts};
    use ricci_render::atlas::{self as pictures, FaceRole};

    /// What face `f` is to chart `c`.
    fn role(atlas: &AffineAtlas, c: ChartId, f: u32) -> FaceRole {
        match atlas.home_chart(f) {
            Some(h) if h == c => FaceRole::Home,
            None => FaceRole::Singular,
            _ => FaceRole::Other,
        }
    }

    /// Chart `c` in its own coordinates (`None` if there is no such chart).
    pub fn chart_svg(atlas: &AffineAtlas, c: ChartId, size: f64) -> Option<String> {
        let (faces, coords) = atlas.chart_faces(c)?;
        let roles: Vec<FaceRole> = faces.iter().map(|&f| role(atlas, c, f)).collect();
        Some(pictures::chart_svg(c as usize, coords, &roles, size))
    }

    /// The central chart with every other chart's home faces mapped into it (empty if the
    /// atlas has no chart).
    pub fn overview_svg(atlas: &AffineAtlas, size: f64) -> String {
        let Some((faces, coords)) = atlas.chart_faces(0) else {
            return String::new();
        };
        let roles: Vec<FaceRole> = faces.iter().map(|&f| role(atlas, 0, f)).collect();
        let others: Vec<(usize, Vec<pictures::Corners>)> = atlas
            .overview()
            .into_iter()
            .map(|(c, tris)| (c as usize, tris))
            .collect();
        pictures::overview_svg(coords, &roles, &others, atlas.n_charts(), size)
    }
}
