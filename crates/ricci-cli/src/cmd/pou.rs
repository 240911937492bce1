//! `ricci pou MESH [--radius R] [--local-degree D] [--smoothing L] [--tessellation K] [--out DIR]
//! [--json]`: the
//! partition-of-unity surface over the hyperbolic structure (paper 004;
//! `ricci::spline::pou`): one control point per vertex, C∞ radial bumps on hyperbolic disks
//! covering the two-rings (`--radius` scales them: larger is smoother and less local), each
//! carrying a local quadratic fitted to the mesh around its vertex (`--local-degree`),
//! control points fitted to the mesh with a thin-plate fairness term (`--smoothing`).
//! Surfaces with boundary are handled through their double cover.
//!
//! `--out DIR` writes `surface.obj` (the tessellation), `control_points.obj` (one point per
//! vertex of the domain) and `pou.json` (the report). Zebra pictures:
//! `ricci render DIR/surface.obj --zebra --out zebra.png`.

use crate::cmd::layout::spinner;
use crate::util::{print_json, write_atomic, UsageError};
use ricci::mesh::io::read_surface;
use ricci::spline::pou::fit::PouFitOptions;
use ricci::spline::pou::{run, PouOptions};
use serde_json::json;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (OBJ, OFF, PLY, STL) of a surface with χ < 0.
    pub mesh: PathBuf,
    /// Disk radius as a multiple of the two-ring radius (≥ 1).
    #[arg(long, default_value_t = 1.0)]
    pub radius: f64,
    /// Degree of the local polynomial carried by each basis (0: constant control points,
    /// 1: affine, 2: quadratic).
    #[arg(long, default_value_t = 2)]
    pub local_degree: usize,
    /// Weight of the (scale-free) thin-plate fairness term of the fit.
    #[arg(long, default_value_t = 1e-4)]
    pub smoothing: f64,
    /// Segments per domain edge in the tessellation.
    #[arg(long, default_value_t = 6)]
    pub tessellation: usize,
    /// Random points of the chart-independence check.
    #[arg(long, default_value_t = 2000)]
    pub samples: usize,
    /// Edges sampled by the continuity check, evenly spaced (0: all).
    #[arg(long, default_value_t = 3000)]
    pub continuity_edges: usize,
    /// Output directory.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

pub fn run_cmd(a: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    if !(a.radius >= 1.0 && a.radius.is_finite()) {
        return Err(UsageError(format!("--radius {} must be ≥ 1", a.radius)).into());
    }
    if !(a.smoothing >= 0.0 && a.smoothing.is_finite()) {
        return Err(UsageError(format!("--smoothing {} must be ≥ 0", a.smoothing)).into());
    }
    if a.local_degree > 2 {
        return Err(UsageError(format!(
            "--local-degree {} is not 0, 1 or 2",
            a.local_degree
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
    let (surface, _) = read_surface(&a.mesh)?;
    let mut bar = spinner(a.json);
    let opts = PouOptions {
        radius: a.radius,
        local_degree: a.local_degree,
        fit: PouFitOptions {
            smoothing: a.smoothing,
            ..PouFitOptions::default()
        },
        tessellation: a.tessellation,
        independence_samples: a.samples,
        continuity_edges: a.continuity_edges,
    };
    let (rep, tess, c) = run(&surface, &opts, &mut bar)?;
    bar.0.finish_and_clear();
    let mut out = serde_json::to_value(&rep)?;
    out["file"] = json!(a.mesh.display().to_string());
    out["tessellation"] = json!({"vertices": tess.positions.len(), "triangles": tess.triangles.len(), "segments": a.tessellation});
    if let Some(dir) = &a.out {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "# ricci pou: partition-of-unity surface, {} control points, radius factor {}",
            rep.control_points, rep.radius_factor
        );
        for p in &tess.positions {
            let _ = writeln!(s, "v {} {} {}", p[0], p[1], p[2]);
        }
        for t in &tess.triangles {
            let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
        }
        let mut cp = String::new();
        let _ = writeln!(cp, "# ricci pou control points (one per domain vertex)");
        for p in &c.control {
            let _ = writeln!(cp, "v {} {} {}", p[0], p[1], p[2]);
        }
        out["out"] = json!(dir.display().to_string());
        out["seconds_total"] = json!(t0.elapsed().as_secs_f64());
        write_atomic(&dir.join("surface.obj"), s.as_bytes())?;
        write_atomic(&dir.join("control_points.obj"), cp.as_bytes())?;
        write_atomic(
            &dir.join("pou.json"),
            serde_json::to_string_pretty(&out)?.as_bytes(),
        )?;
    }
    out["seconds_total"] = json!(t0.elapsed().as_secs_f64());
    // After the work (a failure stays one sentence on stderr), as `ricci spline` does.
    if a.out.is_none() {
        let stem = a
            .mesh
            .file_stem()
            .map_or("pou".into(), |s| s.to_string_lossy().into_owned());
        eprintln!(
            "warning: no --out: the surface was computed and only its numbers are reported; to \
             keep it, try: ricci pou {} --out {stem}-pou",
            a.mesh.display()
        );
    }
    if a.json {
        print_json(&out);
    } else {
        let j = &rep.continuity.relative_jumps;
        println!(
            "{}: {} control points, error rms {:.3}% max {:.3}% of the diagonal; {} (jumps {:.1e} {:.1e} {:.1e} {:.1e}); chart independence {:.1e} / {:.1e} / {:.1e}; {:.2} s",
            a.mesh.display(),
            rep.control_points,
            rep.rms_error_percent,
            rep.max_error_percent,
            rep.continuity.class,
            j.first().copied().unwrap_or(f64::NAN),
            j.get(1).copied().unwrap_or(f64::NAN),
            j.get(2).copied().unwrap_or(f64::NAN),
            j.get(3).copied().unwrap_or(f64::NAN),
            rep.chart_independence.relative[0],
            rep.chart_independence.relative[1],
            rep.chart_independence.relative[2],
            rep.seconds
        );
    }
    Ok(())
}
