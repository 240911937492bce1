//! `ricci generate KIND [params] --out FILE [--json]`: procedural test surfaces
//! (`ricci::mesh::generate`), written in the format of the output's extension.
//!
//! Kinds and their parameters (defaults in brackets):
//!
//! * `sphere` — icosphere; `--subdivisions S` [3] (`--resolution` is a synonym), F = 20·4^S;
//! * `torus` — torus of revolution; `--major R` [1], `--minor r` [0.5], `--resolution N` [48]
//!   segments around the major circle (conformal equilateral grid);
//! * `disk` — unit disk; `--resolution N` [64] boundary segments;
//! * `annulus` — `--inner r` [0.5] < |p| < `--outer R` [1]; `--resolution N` [64] segments on
//!   the outer circle;
//! * `pants` — unit disk minus two holes of radius 0.25 at (±0.45, 0); `--resolution N` [64];
//! * `genus2`, `genus3`, `genus4`, … or `genus --genus G` — closed surface of genus G (chain of
//!   blended tori); `--resolution N` [40] edges around each handle.

use crate::util::{print_json, write_atomic, UsageError};
use indicatif::{ProgressBar, ProgressStyle};
use ricci::mesh::generate::{generate, GeneratorKind, GeneratorParams};
use ricci::mesh::io::{write_to, Encoding, Format};
use ricci::mesh::{quality::angle_stats, topology};
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// sphere, torus, disk, annulus, pants, genus2, genus3, genus4 (any genusN), or genus with
    /// --genus G.
    pub kind: String,
    /// Genus for the kind `genus`.
    #[arg(long)]
    pub genus: Option<u32>,
    /// Resolution: segments around the major circle (torus, default 48), on the outer boundary
    /// (disk, annulus, pants, default 64), edges around each handle (genus, default 40);
    /// subdivisions for the sphere (default 3).
    #[arg(long, short = 'n')]
    pub resolution: Option<u32>,
    /// Icosphere subdivision levels (sphere only) [default: 3].
    #[arg(long)]
    pub subdivisions: Option<u32>,
    /// Major radius, centre of the tube (torus only) [default: 1].
    #[arg(long)]
    pub major: Option<f64>,
    /// Minor radius of the tube (torus only) [default: 0.5].
    #[arg(long)]
    pub minor: Option<f64>,
    /// Inner radius (annulus only) [default: 0.5].
    #[arg(long)]
    pub inner: Option<f64>,
    /// Outer radius (annulus only) [default: 1].
    #[arg(long)]
    pub outer: Option<f64>,
    /// Output mesh file (.obj, .off, .ply, .stl).
    #[arg(long, short = 'o')]
    pub out: PathBuf,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Library refusals of the parameters are bad arguments (exit code 2).
fn usage(e: ricci::Error) -> anyhow::Error {
    match e {
        ricci::Error::InvalidInput { message } => UsageError(message).into(),
        other => other.into(),
    }
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let kind = GeneratorKind::parse(&a.kind, a.genus).map_err(usage)?;
    let format = Format::from_path(&a.out).map_err(usage)?;
    let params = GeneratorParams {
        resolution: a.resolution,
        subdivisions: a.subdivisions,
        major: a.major,
        minor: a.minor,
        inner: a.inner,
        outer: a.outer,
    };
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} {elapsed} generating {prefix}: {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar.set_prefix(kind.name());
    bar.enable_steady_tick(std::time::Duration::from_millis(120));
    let start = Instant::now();
    let mut report = |stage: &str, _fraction: Option<f64>, message: &str| {
        bar.set_message(format!("{stage}: {message}"));
    };
    let generated = generate(kind, &params, &mut report);
    bar.finish_and_clear();
    let surface = generated.map_err(usage)?;
    let seconds = start.elapsed().as_secs_f64();
    let mut bytes = Vec::new();
    write_to(&mut bytes, &surface, format, Encoding::default())?;
    write_atomic(&a.out, &bytes)?;

    let m = &surface.mesh;
    let t = topology(m);
    let q = angle_stats(&surface);
    let lengths = surface.edge_lengths();
    let mean_edge = lengths.iter().sum::<f64>() / lengths.len().max(1) as f64;
    let (lo, hi) = surface.bounding_box();
    let v = json!({
        "kind": kind.name(),
        "file": a.out.display().to_string(),
        "parameters": params.with_defaults(kind),
        "vertices": m.n_vertices(),
        "edges": m.n_edges(),
        "faces": m.n_faces(),
        "components": t.components.len(),
        "genus": t.genus(),
        "euler_characteristic": t.euler_characteristic(),
        "boundary_loops": t.boundary_loops(),
        "min_angle_deg": q.min_angle_deg,
        "max_angle_deg": q.max_angle_deg,
        "mean_edge_length": mean_edge,
        "bounding_box": [lo, hi],
        "seconds": seconds,
    });
    if a.json {
        print_json(&v);
    } else {
        println!(
            "{}: {} ({} vertices, {} faces, genus {}, {} boundary loop(s), χ = {})",
            a.out.display(),
            kind.name(),
            m.n_vertices(),
            m.n_faces(),
            t.genus(),
            t.boundary_loops(),
            t.euler_characteristic()
        );
        println!(
            "  angles {:.2}°–{:.2}°, mean edge {:.4}, {:.2} s",
            q.min_angle_deg, q.max_angle_deg, mean_edge, seconds
        );
    }
    Ok(())
}
