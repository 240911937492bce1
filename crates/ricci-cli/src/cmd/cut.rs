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
use ricci::metric::Geometry;
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

/// Orthographic picture along the shortest bounding-box axis: front faces shaded, loops on top.
fn svg(c: &CanonicalCut) -> String {
    let m = &c.refined.mesh;
    let p = c.refined.positions.clone().unwrap_or_default();
    let mut t = String::new();
    if p.is_empty() {
        return "<svg xmlns=\"http://www.w3.org/2000/svg\"/>\n".into();
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for q in &p {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let ext = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    let z = (0..3)
        .min_by(|&a, &b| ext[a].total_cmp(&ext[b]))
        .unwrap_or(2);
    let (x, y) = ((z + 1) % 3, (z + 2) % 3);
    let size = 900.0;
    let s = size / ext[x].max(ext[y]).max(1e-300);
    let (w, h) = (ext[x] * s + 20.0, ext[y] * s + 20.0);
    let proj = |q: [f64; 3]| ((q[x] - lo[x]) * s + 10.0, (hi[y] - q[y]) * s + 10.0);
    let _ = writeln!(
        t,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.0}\" height=\"{h:.0}\" viewBox=\"0 0 {w:.0} {h:.0}\">"
    );
    let _ = writeln!(t, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>");
    let mut faces: Vec<(f64, u32, f64)> = Vec::new();
    for f in 0..m.n_faces() as u32 {
        let [a, b, cc] = m.face(f).map(|v| p[v as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-300);
        if n[z] <= 0.0 {
            continue;
        }
        faces.push(((a[z] + b[z] + cc[z]) / 3.0, f, n[z] / len));
    }
    faces.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (_, f, shade) in faces {
        let g = (150.0 + 100.0 * shade) as u8;
        let pts: Vec<String> = m
            .face(f)
            .iter()
            .map(|&v| {
                let (px, py) = proj(p[v as usize]);
                format!("{px:.1},{py:.1}")
            })
            .collect();
        let _ = writeln!(
            t,
            "<polygon points=\"{}\" fill=\"rgb({g},{g},{g})\"/>",
            pts.join(" ")
        );
    }
    let colours = [
        "#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
    ];
    for (i, l) in c.loops.iter().enumerate() {
        let pts: Vec<String> = l
            .vertices
            .iter()
            .map(|&v| {
                let (px, py) = proj(p[v as usize]);
                format!("{px:.1},{py:.1}")
            })
            .collect();
        let _ = writeln!(
            t,
            "<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2.5\"><title>{}</title></polyline>",
            pts.join(" "),
            colours[(i / 2) % colours.len()],
            l.label
        );
    }
    let (bx, by) = proj(p[c.base as usize]);
    let _ = writeln!(
        t,
        "<circle cx=\"{bx:.1}\" cy=\"{by:.1}\" r=\"5\" fill=\"black\"/>"
    );
    t.push_str("</svg>\n");
    t
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
        &lengths,
        geometry,
        Some(&s.positions),
        &opts,
        &mut progress,
    );
    bar.finish_and_clear();
    let c = c?;
    let obj = cut_obj(&c);
    let pic = a.svg.as_ref().map(|_| svg(&c));
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
