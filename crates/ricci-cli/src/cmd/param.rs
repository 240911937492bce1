//! `ricci param MESH [--out UV.obj] [--svg UV.svg] [--png UV.png] [--cones auto|none|N|V=K,…|file:PATH]
//! [--max-area-distortion D] [--boundary free|round|fixed-angles] [--sphere] [--seamless]
//! [--seams rigid|free] [--cone-corrections R] [--margin M] [--json]`: a conformal UV map of the mesh in one command
//! (`ricci::param::parametrize`): conformal flow with intrinsic Delaunay flips, a cut through
//! the cones and the handles, a flat layout, UVs on the input's own faces (seams as extra
//! `vt`), charts packed into [0, 1]².
//!
//! Cones (closed components): `auto` (default for genus ≠ 1) places greedy cones until the
//! linearised log area distortion is ≤ `--max-area-distortion` (default 1.0); `N` places N;
//! `V=K,…` gives vertex ids and curvatures (`K` in radians, `pi/2`, `-pi` accepted; cone angle
//! 2π − K); `file:PATH` reads per-vertex curvatures (the `--target file:` format of
//! `ricci flow`; nonzero entries are cones); `none` (a torus).
//! Components with boundary have no cones by default; `N`, `auto` and `V=K,…` (interior
//! vertices) put cones inside them (cones by the greedy with the boundary held, least-squares
//! curvatures, a cut from each cone to the boundary: BFF's `--nCones`) under every boundary
//! condition: `free` holds `u = 0`, `round` puts the boundary on a circle turning by
//! `2πχ − ΣK̄`, `fixed-angles` keeps the boundary's corner angles (greedy cones carry the
//! interior's curvature), `--seamless` rounds cones and boundary turning to quarter turns.
//! `--seams free` (closed components of genus ≥ 1): the homology seams are free — the surface
//! cut along its homology generators is flattened as a disk with the least area distortion
//! along the cut (`u = 0`, Boundary First Flattening's kind of map) and greedy cones inside;
//! transitions across those seams are not rigid motions (cone seams stay rigid). The default
//! `rigid` gives a flat metric with cones on the closed surface (every transition a rotation),
//! what `--seamless` and quad meshing need; `free` has less area distortion at equal cone
//! count. The JSON says which (`"seams"`).
//! `--sphere` maps a closed genus-0 surface onto the unit sphere instead (UV.obj then holds
//! the sphere points as `v`).
//! When the input's own faces would fold (or the cut needs edges the flow flipped), UV.obj
//! holds the common subdivision of the input and the flat triangulation instead (points on
//! the input surface, every triangle inside one input face), and the JSON says so:
//! `uv.on` / `uv_faces` = "common_subdivision" (else "input"), with `uv.vertices`,
//! `uv.triangles`, `uv.input_flipped_faces`.
//! A disk whose own flow fails or stalls (free boundary, no cones asked for) is mapped through
//! the flow on its double instead (`"route": "double"`, `"route_reason"`; [`double`]).
//! When the map asked for would have flipped triangles (its scale factors beyond what
//! double-precision UVs resolve: camel as a flat torus, or with 3–4 free-seam cones) or its
//! flow does not converge, the chart is recomputed with rigid seams, then with up to four
//! more greedy cones, and the first map without flipped triangles is written; stderr and
//! `chart_details[].fallback` say so (given cones are never changed).
//! The JSON report: `uv_faces`, `flipped_faces` (of what is written), `qc_mean`/`qc_p95`/`qc_max`
//! (σmax/σmin per face), `log_area_sigma` (σ of log(A_uv/A_3d)), `cones`, `seam_length`,
//! per-chart details and `seconds`.

mod double;
mod picture;

use crate::util::read_surface;
use crate::util::{print_json, write_atomic, UsageError};
use ricci::flow::target::{parse_angle, resolve};
use ricci::flow::TargetSpec;
use ricci::layout::export::obj_with_corner_uv;
use ricci::metric::Geometry;
use ricci::param::sphere::{sphere_map, SphereMap};
use ricci::param::{parametrize, BoundaryMode, ConeSpec, ParamOptions, SeamMode};
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (OBJ, OFF, PLY, STL).
    pub mesh: PathBuf,
    /// Output OBJ: the input's vertices and faces with texture coordinates (`f v/vt`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Output SVG picture of the UV layout (seams blue, cones red, flipped faces red).
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Output PNG picture of the UV layout (the same picture as --svg).
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Cones of closed components: auto | none | N | V=K,... | file:PATH.
    #[arg(long)]
    pub cones: Option<String>,
    /// With --cones auto: bound on the linearised max |log area ratio| (default 1.0).
    #[arg(long)]
    pub max_area_distortion: Option<f64>,
    /// Boundary condition of components with boundary: free | round | fixed-angles.
    #[arg(long, default_value = "free")]
    pub boundary: String,
    /// Closed genus-0 surfaces: map onto the unit sphere (Möbius-centred).
    #[arg(long)]
    pub sphere: bool,
    /// Cone angles multiples of π/2 (transitions across seams: rotations by k·90° on genus 0).
    #[arg(long)]
    pub seamless: bool,
    /// Homology seams of closed components of genus ≥ 1: rigid (a flat metric with cones;
    /// transitions are rotations) | free (the cut disk flattened with least area distortion
    /// along the cut; less distortion, transitions not rigid).
    #[arg(long, default_value = "rigid")]
    pub seams: String,
    /// Rounds of correcting greedy cone curvatures on the nonlinear flow (least L² norm of
    /// the log scale factor; each round runs the flow once more; kept when σ(2u) drops).
    #[arg(long, default_value_t = 0)]
    pub cone_corrections: usize,
    /// Margin of the packing in [0, 1]² (default 0.01).
    #[arg(long, default_value_t = 0.01)]
    pub margin: f64,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

fn cone_spec(a: &Args, surface: &ricci::mesh::Surface) -> anyhow::Result<ConeSpec> {
    let bound = a.max_area_distortion.unwrap_or(1.0);
    if bound.is_nan() || bound <= 0.0 {
        return Err(UsageError("--max-area-distortion must be positive".into()).into());
    }
    let Some(c) = a.cones.as_deref() else {
        return Ok(if a.max_area_distortion.is_some() {
            ConeSpec::Auto {
                max_area_distortion: bound,
            }
        } else {
            ConeSpec::Default
        });
    };
    let c = c.trim();
    if c == "auto" {
        return Ok(ConeSpec::Auto {
            max_area_distortion: bound,
        });
    }
    if c == "none" {
        return Ok(ConeSpec::None);
    }
    if let Ok(n) = c.parse::<usize>() {
        return Ok(ConeSpec::Count(n));
    }
    if let Some(p) = c.strip_prefix("file:") {
        let t = resolve(
            &surface.mesh,
            Geometry::Euclidean,
            &TargetSpec::File(PathBuf::from(p)),
        )?;
        let list: Vec<(u32, f64)> = t
            .curvature
            .iter()
            .enumerate()
            .filter(|(_, &k)| k != 0.0)
            .map(|(v, &k)| (v as u32, k))
            .collect();
        return Ok(ConeSpec::Given(list));
    }
    let mut list = Vec::new();
    for item in c.split(',').filter(|x| !x.trim().is_empty()) {
        let (v, k) = item.split_once('=').ok_or_else(|| {
            UsageError(format!(
                "--cones: '{item}' is not auto, none, a count, file:PATH or V=K"
            ))
        })?;
        let v: u32 = v
            .trim()
            .parse()
            .map_err(|_| UsageError(format!("--cones: '{v}' is not a vertex id")))?;
        let k = parse_angle(k)
            .ok_or_else(|| UsageError(format!("--cones: '{k}' is not a curvature")))?;
        list.push((v, k));
    }
    Ok(ConeSpec::Given(list))
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let boundary: BoundaryMode = a.boundary.parse().map_err(UsageError)?;
    let seams: SeamMode = a.seams.parse().map_err(UsageError)?;
    let (surface, _) = read_surface(&a.mesh)?;
    let mut bar = super::layout::spinner(a.json);
    let name = a.mesh.display().to_string();
    if a.sphere {
        let m = sphere_map(&surface, &mut bar).map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
        bar.0.finish_and_clear();
        if let Some(path) = &a.out {
            write_atomic(path, sphere_obj(&name, &surface, &m).as_bytes())?;
        }
        let out = json!({
            "file": name, "mode": "sphere", "vertices": surface.mesh.n_vertices(),
            "faces": surface.mesh.n_faces(), "uv_faces": m.uv_faces,
            "flipped_faces": m.stats.flipped_faces,
            "input_flipped_faces": m.input_flipped_faces, "qc_mean": m.stats.qc_mean,
            "qc_p95": m.stats.qc_p95, "qc_max": m.stats.qc_max,
            "log_area_sigma": m.stats.log_area_sigma, "sphere": m,
            "seconds": t0.elapsed().as_secs_f64(),
        });
        return report(&a, &out);
    }
    let opts = ParamOptions {
        cones: cone_spec(&a, &surface)?,
        boundary,
        seamless: a.seamless,
        margin: a.margin,
        cone_corrections: a.cone_corrections,
        seams,
        ..ParamOptions::default()
    };
    let p = match parametrize(&surface, &opts, &mut bar) {
        Ok(p) => p,
        // The surface's own flow failed or stalled: a disk is mapped through its double.
        Err(e) if double::applies(&a, boundary, &surface.mesh) => {
            bar.0.set_message("flow on the double");
            let reason = e.to_string();
            let r = double::run_double(&a, &surface, &reason, &mut bar, t0);
            bar.0.finish_and_clear();
            return r;
        }
        Err(e) => anyhow::bail!("{name}: {e}"),
    };
    bar.0.finish_and_clear();
    let cones: Vec<_> = p
        .charts
        .iter()
        .flat_map(|c| c.cones.iter().copied())
        .collect();
    // A chart recomputed with rigid seams or more cones because the map asked for would
    // have flipped triangles (`ricci::param` ladder): said on stderr, and in the JSON's
    // `chart_details[].fallback`.
    for c in &p.charts {
        if let Some(why) = &c.fallback {
            eprintln!("note: {name}: component {}: {why}", c.component);
        }
    }
    if let Some(path) = &a.out {
        let text = match &p.subdivision {
            Some(m) => obj_with_corner_uv(
                &m.positions,
                m.mesh.faces(),
                &m.corner_uv,
                &[
                    format!("ricci param of {name}"),
                    format!(
                        "the common subdivision of the input and the flat intrinsic \
                         triangulation ({} points on the input surface, {} triangles, each \
                         inside one input face; the input's own faces would have {} flipped \
                         UV triangle(s))",
                        m.positions.len(),
                        m.mesh.n_faces(),
                        m.input_stats.flipped_faces
                    ),
                    "vt: conformal UVs in [0,1]^2 per corner; several vt per vertex along the \
                     seams"
                        .to_string(),
                ],
            ),
            None => obj_with_corner_uv(
                &surface.positions,
                surface.mesh.faces(),
                &p.corner_uv,
                &[
                    format!("ricci param of {name}"),
                    "vt: conformal UVs in [0,1]^2 per corner of the input's faces; several vt \
                     per vertex along the seams"
                        .to_string(),
                ],
            ),
        };
        write_atomic(path, text.as_bytes())?;
    }
    if a.svg.is_some() || a.png.is_some() {
        let cv: Vec<u32> = cones.iter().map(|c| c.vertex).collect();
        let fig = match &p.subdivision {
            Some(m) => {
                let cv: Vec<u32> = cv.iter().map(|&v| m.input_vertex[v as usize]).collect();
                picture::uv_figure(&m.mesh, &m.corner_uv, &m.seam, &cv, 1024.0)
            }
            None => picture::uv_figure(&surface.mesh, &p.corner_uv, &p.seam, &cv, 1024.0),
        };
        if let Some(path) = &a.svg {
            write_atomic(path, fig.to_svg().as_bytes())?;
        }
        if let Some(path) = &a.png {
            write_atomic(path, &fig.to_png(1.0)?)?;
        }
    }
    let uv = match &p.subdivision {
        Some(m) => json!({
            "on": p.uv_on(), "vertices": m.positions.len(), "triangles": m.mesh.n_faces(),
            "flipped_faces": p.stats.flipped_faces,
            "input_flipped_faces": m.input_stats.flipped_faces,
        }),
        None => json!({
            "on": p.uv_on(), "vertices": surface.mesh.n_vertices(),
            "triangles": surface.mesh.n_faces(), "flipped_faces": p.stats.flipped_faces,
            "input_flipped_faces": p.stats.flipped_faces,
        }),
    };
    let seam_length: f64 = p.charts.iter().map(|c| c.seam_length).sum();
    let out = json!({
        "file": name, "mode": "plane", "vertices": surface.mesh.n_vertices(),
        "faces": surface.mesh.n_faces(), "charts": p.charts.len(), "uv_faces": p.uv_on(),
        "uv": uv,
        "flipped_faces": p.stats.flipped_faces, "qc_mean": p.stats.qc_mean,
        "qc_p95": p.stats.qc_p95, "qc_max": p.stats.qc_max,
        "log_area_sigma": p.stats.log_area_sigma, "distortion": p.stats,
        "cone_count": cones.len(), "cones": cones, "seam_length": seam_length,
        "seam_edges": p.seam.iter().filter(|&&s| s).count(),
        "seamless": a.seamless, "seams": seams, "boundary": boundary, "chart_details": p.charts,
        "seconds": t0.elapsed().as_secs_f64(),
    });
    report(&a, &out)
}

/// The OBJ of `--sphere`: the input's faces on the sphere, or the common subdivision's.
fn sphere_obj(name: &str, surface: &ricci::mesh::Surface, m: &SphereMap) -> String {
    let (points, faces, what) = match &m.subdivision {
        Some((_, p, t)) => (
            &p[..],
            &t[..],
            "the common subdivision of the input and the flow's triangulation",
        ),
        None => (&m.positions[..], surface.mesh.faces(), "the input's faces"),
    };
    let mut text = format!("# ricci param --sphere of {name}: {what} on the unit sphere\n");
    for p in points {
        text.push_str(&format!("v {:e} {:e} {:e}\n", p[0], p[1], p[2]));
    }
    for t in faces {
        text.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    text
}

fn report(a: &Args, out: &serde_json::Value) -> anyhow::Result<()> {
    let flipped = out["flipped_faces"].as_u64().unwrap_or(0);
    if flipped > 0 {
        // Issue 16 asks for 0 flipped faces every time; when the map has some (e.g. very few
        // cones with free seams: scale factors beyond what the layout resolves), say so on
        // stderr as well as in the report, so that scripts do not take the UVs on trust.
        eprintln!(
            "warning: {}: the UV map has {flipped} flipped triangle(s) (σ(log area ratio) {:.3}); \
             try more cones (--cones N) or --seams rigid",
            a.mesh.display(),
            out["log_area_sigma"].as_f64().unwrap_or(f64::NAN)
        );
    }
    if a.json {
        print_json(out);
    } else {
        println!(
            "{}: {} map",
            a.mesh.display(),
            out["mode"].as_str().unwrap_or("")
        );
        println!("  flipped faces: {}", out["flipped_faces"]);
        println!(
            "  qc mean / p95 / max: {:.4} / {:.4} / {:.4}",
            out["qc_mean"].as_f64().unwrap_or(f64::NAN),
            out["qc_p95"].as_f64().unwrap_or(f64::NAN),
            out["qc_max"].as_f64().unwrap_or(f64::NAN)
        );
        println!(
            "  σ(log area ratio): {:.4}",
            out["log_area_sigma"].as_f64().unwrap_or(f64::NAN)
        );
        if let Some(c) = out.get("cone_count") {
            println!(
                "  cones: {c}, seam length {:.4}",
                out["seam_length"].as_f64().unwrap_or(0.0)
            );
        }
        println!("  seconds: {:.3}", out["seconds"].as_f64().unwrap_or(0.0));
    }
    Ok(())
}
