//! `ricci forms MESH [--zeros V,...] [--triangulation delaunay|input|flat] [--base V]
//! [--out UV.obj] [--png PIC.png] [--json]`: holomorphic 1-forms of a closed surface of genus
//! ≥ 1 (paper 002 §4.2, `ricci::analysis::forms`): the basis normalized on the a-cycles, the
//! Riemann period matrix (genus 1: the modulus τ), the zeros of the integrated form, and its
//! conformal net — uv per face corner on the cut mesh (OBJ), a checkerboard picture with the
//! zeros circled in red.
//!
//! The form integrated is `ω_1` (`--form K`: `ω_K`), with `--zeros` the combination with zeros
//! at the given vertices (at most g − 1 exactly, paper 002 §4.2.4), with `--uniform` the
//! combination of least area distortion (§4.2.1). The OBJ and the picture show the
//! working triangulation: with `--triangulation delaunay` (default) it is the intrinsic
//! Delaunay triangulation of the input, drawn with the input positions (`flips` in the JSON
//! says how many edges differ from the input's); `--triangulation input` keeps the input
//! faces.

use super::layout::spinner;
use crate::util::{print_json, read_surface, write_atomic, UsageError};
use ricci::analysis::forms::placement::form_with_zeros;
use ricci::analysis::forms::uniform::uniform_combination;
use ricci::analysis::forms::{holomorphic_forms, FormsOptions, FormsTriangulation};
use ricci::cut::CutOptions;
use ricci::layout::export::obj_with_corner_uv;
use ricci::layout::isometry::Complex;
use ricci_render::render::Uvs;
use ricci_render::{Checker, Paint, Polyline, RenderOptions, Style};
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum Triangulation {
    /// Intrinsic Delaunay triangulation of the input metric (positive cotangent weights).
    Delaunay,
    /// The input triangles with their own lengths.
    Input,
    /// Genus 1: the flat metric of the conformal flow (the form is exactly dz there).
    Flat,
}

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file (a closed surface of genus ≥ 1).
    pub mesh: PathBuf,
    /// Place zeros of the integrated form at these vertices (comma-separated ids, at most g).
    #[arg(long, value_delimiter = ',')]
    pub zeros: Vec<u32>,
    /// Triangulation the forms are computed on.
    #[arg(long, value_enum, default_value = "delaunay")]
    pub triangulation: Triangulation,
    /// Base vertex of the canonical loops.
    #[arg(long)]
    pub base: Option<u32>,
    /// Integrate the combination of least area distortion (paper 002 §4.2.1) instead of ω_k.
    #[arg(long, conflicts_with = "zeros")]
    pub uniform: bool,
    /// Basis form to integrate when no --zeros are given (1-based).
    #[arg(long, default_value_t = 1)]
    pub form: usize,
    /// Write the conformal net: the surface with one uv per face corner (OBJ).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write a picture: checkerboard of the net on the surface, zeros circled.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Checks per unit period (the a-period of ω_1 is 1).
    #[arg(long, default_value_t = 12.0)]
    pub checks: f64,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    if !(a.checks > 0.0 && a.checks.is_finite()) {
        return Err(UsageError("--checks must be a positive number".into()).into());
    }
    let (surface, _) = read_surface(&a.mesh)?;
    let mut bar = spinner(a.json);
    let opts = FormsOptions {
        triangulation: match a.triangulation {
            Triangulation::Delaunay => FormsTriangulation::Delaunay,
            Triangulation::Input => FormsTriangulation::Input,
            Triangulation::Flat => FormsTriangulation::Flat,
        },
        cut: CutOptions {
            base: a.base,
            ..Default::default()
        },
    };
    let h = holomorphic_forms(
        &surface.mesh,
        &surface.edge_lengths(),
        Some(&surface.positions),
        &opts,
        &mut bar,
    )?;
    let g = h.genus;
    let mut uniform_report = None;
    let (form, coefficients, placement_residual) = if a.uniform {
        let (u, w) = uniform_combination(&h, 200)?;
        let c = u.coefficients.clone();
        uniform_report = Some(u);
        (w, c, None)
    } else if a.zeros.is_empty() {
        if a.form == 0 || a.form > g {
            return Err(UsageError(format!("--form must be between 1 and the genus {g}")).into());
        }
        let mut c = vec![Complex::new(0.0, 0.0); g];
        c[a.form - 1] = Complex::new(1.0, 0.0);
        (h.combination(&c), c, None)
    } else {
        if a.zeros.len() > g {
            return Err(UsageError(format!(
                "--zeros: at most {g} positions on a genus-{g} surface"
            ))
            .into());
        }
        if let Some(&v) = a
            .zeros
            .iter()
            .find(|&&v| v as usize >= surface.mesh.n_vertices())
        {
            return Err(UsageError(format!(
                "--zeros: vertex {v} does not exist (the mesh has {} vertices)",
                surface.mesh.n_vertices()
            ))
            .into());
        }
        let (c, w, r) = form_with_zeros(&h, &a.zeros)?;
        (w, c, Some(r))
    };
    bar.0.set_message("zeros and conformal net");
    let zeros = h.zeros(&form)?;
    let net = h.net(&form)?;
    let refined = &h.cut.refined;
    let n_work = h.working.mesh.n_vertices() as u32;
    let zero_json: Vec<_> = zeros
        .zeros
        .iter()
        .map(|z| {
            json!({
                "vertex": (z.vertex < n_work).then_some(z.vertex),
                "refined_vertex": z.vertex,
                "multiplicity": z.multiplicity,
                "position": refined.positions.as_ref().map(|p| p[z.vertex as usize]),
            })
        })
        .collect();
    let cut_mesh = &h.cut.cut_mesh;
    let corner_uv: Vec<[f64; 2]> = (0..cut_mesh.n_corners() as u32)
        .map(|c| net.uv[cut_mesh.corner_vertex(c) as usize])
        .collect();
    if let Some(path) = &a.out {
        let pos = refined.positions.as_ref().ok_or_else(|| {
            anyhow::anyhow!("the working triangulation has vertices without positions; use --triangulation input")
        })?;
        let text = obj_with_corner_uv(
            pos,
            refined.mesh.faces(),
            &corner_uv,
            &[
                format!("ricci forms: conformal net of a holomorphic 1-form, genus {g}"),
                format!("triangulation {}", h.report.triangulation.name()),
            ],
        );
        write_atomic(path, text.as_bytes())?;
    }
    if let Some(path) = &a.png {
        let pos = refined.positions.as_ref().ok_or_else(|| {
            anyhow::anyhow!("the working triangulation has vertices without positions; use --triangulation input")
        })?;
        let tris = refined.mesh.faces();
        // Scale: `checks` per unit of the a₁-period of ω_1 (per unit of |λ| otherwise).
        let scale: f64 = coefficients
            .iter()
            .map(|c| c.norm_sqr())
            .sum::<f64>()
            .sqrt();
        let freq = a.checks / scale.max(1e-300);
        let style = Style {
            paint: Paint::Checker(Checker::new(Uvs::PerCorner(&corner_uv), freq)),
            polylines: zeros
                .zeros
                .iter()
                .map(|z| marker(pos, tris, z.vertex))
                .collect(),
            ..Default::default()
        };
        let png = ricci_render::render_png(pos, tris, &style, &RenderOptions::default())?;
        write_atomic(path, &png)?;
    }
    bar.0.finish_and_clear();
    let om = &h.period_matrix;
    let r = &h.report;
    let v = json!({
        "mesh": a.mesh.display().to_string(),
        "genus": g,
        "period_matrix": {"re": om.re, "im": om.im},
        "modulus": h.modulus().map(|t| [t.0, t.1]),
        "im_eigenvalues": om.im_eigenvalues()?,
        "symmetry_error": om.asymmetry(),
        "zeros": zero_json,
        "zero_count": zeros.count,
        "spurious_singularities": zeros.spurious,
        "form": {
            "coefficients": coefficients.iter().map(|c| [c.re, c.im]).collect::<Vec<_>>(),
            "placed_zeros": a.zeros,
            "placement_residual": placement_residual,
            "uniform": uniform_report,
        },
        "quality": {
            "star_defect": r.star_defect,
            "raw_asymmetry": r.raw_asymmetry,
            "harmonic_residual": r.harmonic_residual,
            "closedness": r.closedness,
            "negative_weights": r.negative_weights,
            "integration_error": net.integration_error,
            "qc_mean": net.quality.qc_mean,
            "qc_p95": net.quality.qc_p95,
            "qc_max": net.quality.qc_max,
            "flipped_faces": net.quality.flipped_faces,
        },
        "triangulation": r.triangulation.name(),
        "flips": r.flips,
        "vertices": r.vertices,
        "faces": r.faces,
        "base_vertex": h.cut.base,
        "out": a.out.as_ref().map(|p| p.display().to_string()),
        "png": a.png.as_ref().map(|p| p.display().to_string()),
        "seconds": t0.elapsed().as_secs_f64(),
    });
    if a.json {
        print_json(&v);
    } else {
        println!(
            "genus {g}, {} vertices ({} triangulation, {} flips)",
            r.vertices,
            r.triangulation.name(),
            r.flips
        );
        for i in 0..g {
            let row: Vec<String> = (0..g)
                .map(|j| format!("{:+.6} {:+.6}i", om.re[i][j], om.im[i][j]))
                .collect();
            println!("  Ω[{}] = {}", i + 1, row.join(", "));
        }
        if let Some(t) = h.modulus() {
            println!("modulus τ = {:.6} + {:.6}i", t.0, t.1);
        }
        println!(
            "zeros ({}): {}",
            zeros.count,
            zeros
                .zeros
                .iter()
                .map(|z| format!("{}×{}", z.vertex, z.multiplicity))
                .collect::<Vec<_>>()
                .join(" ")
        );
        println!(
            "star defect {:.1e}, net angle distortion mean {:.3} p95 {:.3}; {:.2} s",
            r.star_defect,
            net.quality.qc_mean,
            net.quality.qc_p95,
            t0.elapsed().as_secs_f64()
        );
    }
    Ok(())
}

/// A small circle around vertex `v` (in the plane orthogonal to its normal).
fn marker(pos: &[[f64; 3]], tris: &[[u32; 3]], v: u32) -> Polyline {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in pos {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diag = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let r = 0.015 * diag;
    let n = ricci_render::render::vertex_normals(pos, tris)
        .get(v as usize)
        .copied()
        .unwrap_or([0.0, 0.0, 1.0]);
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
    let c = pos[v as usize];
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
        color: [0.85, 0.1, 0.1],
        width: 3.0,
        closed: true,
    }
}
