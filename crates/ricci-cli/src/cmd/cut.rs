//! `ricci cut MESH [--base V] [--metric METRIC.json] [--min-valence N] --out CUT.obj
//! [--svg PIC.svg] [--json]`: canonical fundamental group generators through a base vertex and
//! the mesh sliced open along them (`ricci::cut::canonical_cut`).
//!
//! CUT.obj holds the cut mesh (a disk; refined around the base vertex when that was needed):
//! `v` lines (positions copied to every copy of a cut vertex), `f` lines, and then every side of
//! the fundamental polygon as a named group with an `l` polyline over the cut mesh's boundary
//! vertices (`g a1`, `g b1`, `g a1^-1`, …; readers that ignore `l` lines still see the disk).
//! METRIC.json (from `ricci flow`) gives `geometry` and per-edge `lengths`, either as
//! a list of numbers with a parallel list `edge_vertices: [[u, v], …]` (what `ricci flow`
//! writes), as `[[u, v, length], …]`, or as `[{"u": …, "v": …, "length": …}, …]`; its lengths
//! are used for the loops and the
//! refinement. Without it the Euclidean lengths of the positions are used.

use crate::util::read_surface;
use crate::util::{print_json, write_atomic, UsageError};
use indicatif::{ProgressBar, ProgressStyle};
use ricci::cut::{canonical_cut, CanonicalCut, CutOptions};
use ricci::mesh::Surface;
use ricci::metric::{Geometry, IntrinsicMetric};
use ricci_render::loops::{loops_svg, SurfaceLoop};
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (OBJ, OFF, PLY, STL).
    pub mesh: PathBuf,
    /// Base vertex (0-based id in the file's vertex order after validation); default: a
    /// central vertex.
    #[arg(long)]
    pub base: Option<u32>,
    /// Metric from `ricci flow` (geometry + edge lengths); default: Euclidean lengths.
    #[arg(long)]
    pub metric: Option<PathBuf>,
    /// Minimum valence of the base vertex after refinement (default max(4g+4, 8g−4) + b;
    /// raised 3.5× and then 5× when four attempts at it do not fit the loops).
    #[arg(long)]
    pub min_valence: Option<usize>,
    /// Output: the cut mesh with the polygon sides as `l` polylines (.obj).
    #[arg(long, short = 'o')]
    pub out: PathBuf,
    /// Optional SVG picture of the loops on the surface.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Read METRIC.json into (geometry, lengths by edge id of `s`); a metric whose flow did not
/// converge is refused (`ricci::metric::file`).
fn read_metric(path: &Path, s: &Surface) -> anyhow::Result<(Geometry, Vec<f64>)> {
    let m = ricci::metric::file::read_metric_file(path, &s.mesh)?;
    m.check_usable(&path.display().to_string())?;
    Ok((m.geometry, m.lengths))
}

/// The cut mesh with the polygon sides as named `l` polylines (also written by `ricci demo`).
pub fn cut_obj(c: &CanonicalCut) -> String {
    let mut t = String::new();
    let _ = writeln!(
        t,
        "# ricci cut: genus {}, base vertex {}, boundary word {}",
        c.genus, c.base, c.boundary_word
    );
    let pos = c
        .cut_positions()
        .unwrap_or_else(|| vec![[0.0; 3]; c.cut_mesh.n_vertices()]);
    for p in &pos {
        let _ = writeln!(t, "v {} {} {}", p[0], p[1], p[2]);
    }
    for f in c.cut_mesh.faces() {
        let _ = writeln!(t, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    for s in &c.polygon {
        let _ = writeln!(t, "g {}", s.label);
        t.push('l');
        for &v in &s.vertices {
            let _ = write!(t, " {}", v + 1);
        }
        t.push('\n');
    }
    t
}

/// Orthographic picture along the shortest bounding-box axis: front faces shaded, loops on top
/// ([`ricci_render::loops::loops_svg`]).
fn svg(c: &CanonicalCut) -> anyhow::Result<String> {
    let positions = c.refined.positions.clone().unwrap_or_default();
    let loops: Vec<SurfaceLoop<'_>> = c
        .loops
        .iter()
        .map(|l| SurfaceLoop {
            label: &l.label,
            vertices: &l.vertices,
        })
        .collect();
    Ok(loops_svg(
        &positions,
        c.refined.mesh.faces(),
        &loops,
        Some(c.base),
    )?)
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    if a.out
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.eq_ignore_ascii_case("obj"))
        != Some(true)
    {
        return Err(UsageError(format!(
            "--out {}: the cut mesh is written as .obj",
            a.out.display()
        ))
        .into());
    }
    let (s, _) = read_surface(&a.mesh)?;
    if let Some(b) = a.base {
        if b as usize >= s.mesh.n_vertices() {
            return Err(UsageError(format!(
                "--base {b}: the mesh has only {} vertices",
                s.mesh.n_vertices()
            ))
            .into());
        }
    }
    let (geometry, lengths) = match &a.metric {
        Some(p) => read_metric(p, &s)?,
        None => (Geometry::Euclidean, s.edge_lengths()),
    };
    let bar = ProgressBar::new(100);
    bar.set_style(
        ProgressStyle::with_template("{spinner} cut [{bar:30}] {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut progress = |_: &str, f: Option<f64>, msg: &str| {
        if let Some(f) = f {
            bar.set_position((100.0 * f) as u64);
        }
        bar.set_message(msg.to_string());
    };
    let opts = CutOptions {
        base: a.base,
        min_valence: a.min_valence,
        max_attempts: None,
        ..CutOptions::default()
    };
    let c = canonical_cut(
        &s.mesh,
        &IntrinsicMetric::new(geometry, lengths),
        Some(&s.positions),
        &opts,
        &mut progress,
    );
    bar.finish_and_clear();
    let c = c?;
    let obj = cut_obj(&c);
    let pic = a.svg.as_ref().map(|_| svg(&c)).transpose()?;
    write_atomic(&a.out, obj.as_bytes())?;
    if let (Some(path), Some(pic)) = (&a.svg, pic) {
        write_atomic(path, pic.as_bytes())?;
    }
    let loops: Vec<Value> = c
        .loops
        .iter()
        .map(|l| json!({"label": l.label, "length": l.length, "edges": l.halfedges.len(), "vertices": l.vertices}))
        .collect();
    let sides: Vec<Value> = c
        .polygon
        .iter()
        .map(|s| json!({"label": s.label, "edges": s.edges.len(), "partner": s.partner}))
        .collect();
    let disk = {
        let t = ricci::mesh::topology(&c.cut_mesh);
        t.components.len() == 1 && t.euler_characteristic() == 1 && t.boundary_loops() == 1
    };
    let v = json!({
        "file": a.mesh.display().to_string(),
        "genus": c.genus,
        "boundary_loops": c.boundary_loops,
        "geometry": geometry.name(),
        "base_vertex": c.base,
        "base_automatic": c.report.base_automatic,
        "loops": loops,
        "loop_lengths": c.loops.iter().map(|l| l.length).collect::<Vec<_>>(),
        "polygon_sides": sides,
        "boundary_word": c.boundary_word,
        "disk": disk,
        "intersection_matrix": c.intersection_matrix,
        "refinement": {
            "valence_before": c.report.valence_before,
            "valence_after": c.report.valence_after,
            "splits": c.report.refinement_splits,
            "vertices": c.refined.mesh.n_vertices(),
            "faces": c.refined.mesh.n_faces(),
            "attempts": c.report.attempts,
            "failed_attempts": c.report.failed_attempts,
        },
        "cut_mesh": {"vertices": c.cut_mesh.n_vertices(), "faces": c.cut_mesh.n_faces()},
        "search": c.report.search,
        "seconds": t0.elapsed().as_secs_f64(),
    });
    if a.json {
        print_json(&v);
    } else {
        println!(
            "{}: genus {}, base vertex {}",
            a.mesh.display(),
            c.genus,
            c.base
        );
        println!("  boundary word: {}", c.boundary_word);
        for l in &c.loops {
            println!(
                "  {:>4}: {} edges, length {:.6}",
                l.label,
                l.halfedges.len(),
                l.length
            );
        }
        println!(
            "  refinement: valence {} -> {}, {} splits; cut mesh {} vertices, {} faces (disk: {disk})",
            c.report.valence_before,
            c.report.valence_after,
            c.report.refinement_splits,
            c.cut_mesh.n_vertices(),
            c.cut_mesh.n_faces()
        );
        println!("  wrote {}", a.out.display());
    }
    Ok(())
}
