//! `ricci forms MESH [--zeros V,...] [--triangulation delaunay|input|flat] [--base V]
//! [--out UV.obj] [--png PIC.png] [--json]`: holomorphic 1-forms of a closed surface of genus
//! ≥ 1 (paper 002 §4.2, `ricci::analysis::forms`): the basis normalized on the a-cycles, the
//! Riemann period matrix (genus 1: the modulus τ), the zeros of the integrated form, and its
//! conformal net — uv per face corner on the cut mesh (OBJ, with the critical horizontal
//! trajectories through the zeros as `l` lines), a checkerboard picture with the zeros circled
//! in red and the critical trajectories in blue (`ricci::analysis::forms::trajectories`).
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
use ricci::analysis::forms::trajectories::critical_trajectories;
use ricci::analysis::forms::uniform::{uniform_combination, UniformCombination};
use ricci::analysis::forms::{
    double_forms, holomorphic_forms, ConformalNet, FormsOptions, FormsTriangulation,
    HolomorphicForm, HolomorphicForms, ZeroSet,
};
use ricci::cut::CutOptions;
use ricci::layout::export::obj_with_corner_uv;
use ricci::layout::isometry::Complex;
use ricci::metric::{Geometry, IntrinsicMetric};
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
    /// Write a picture: checkerboard of the net on the surface, zeros circled, critical
    /// horizontal trajectories through them.
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
        keep_sharp_corners: false,
    };
    // A surface with boundary: the forms of its double (paper 003 §2), genus 2g + b − 1.
    let dbl = if surface.mesh.has_boundary() {
        let metric = IntrinsicMetric::new(Geometry::Euclidean, surface.edge_lengths());
        let d = double_forms(
            &surface.mesh,
            &metric,
            Some(&surface.positions),
            &opts,
            &mut bar,
        )
        .map_err(|e| anyhow::anyhow!("{}: {e}", a.mesh.display()))?;
        Some(d)
    } else {
        None
    };
    let owned;
    let h: &HolomorphicForms = match &dbl {
        Some(d) => &d.forms,
        None => {
            owned = holomorphic_forms(
                &surface.mesh,
                &IntrinsicMetric::euclidean(surface.edge_lengths()),
                Some(&surface.positions),
                &opts,
                &mut bar,
            )?;
            &owned
        }
    };
    let chosen = choose_form(&a, h, surface.mesh.n_vertices())?;
    bar.0
        .set_message("zeros, conformal net and critical trajectories");
    let zeros = h.zeros(&chosen.form)?;
    let net = h.net(&chosen.form)?;
    let cut_mesh = &h.cut.cut_mesh;
    let corner_uv: Vec<[f64; 2]> = (0..cut_mesh.n_corners() as u32)
        .map(|c| net.uv[cut_mesh.corner_vertex(c) as usize])
        .collect();
    let scale = chosen.scale();
    let trajectories = critical_lines(h, &chosen.form, &zeros, scale);
    if let Some(path) = &a.out {
        let pos = refined_positions(h)?;
        // On a surface with boundary, the net on the surface itself (the double's faces on it).
        let (faces, uv) = match &dbl {
            Some(d) => {
                let on = d.surface_faces();
                let faces: Vec<[u32; 3]> = h
                    .cut
                    .refined
                    .mesh
                    .faces()
                    .iter()
                    .zip(&on)
                    .filter(|x| *x.1)
                    .map(|x| *x.0)
                    .collect();
                let uv: Vec<[f64; 2]> = corner_uv
                    .chunks(3)
                    .zip(&on)
                    .filter(|x| *x.1)
                    .flat_map(|x| x.0.iter().copied())
                    .collect();
                (faces, uv)
            }
            None => (h.cut.refined.mesh.faces().to_vec(), corner_uv.clone()),
        };
        let mut text = obj_with_corner_uv(
            pos,
            &faces,
            &uv,
            &[
                format!(
                    "ricci forms: conformal net of a holomorphic 1-form, genus {}",
                    h.genus
                ),
                format!("triangulation {}", h.report.triangulation.name()),
                "critical horizontal trajectories through the zeros as `l` lines".into(),
            ],
        );
        append_obj_lines(&mut text, pos.len(), &trajectories);
        write_atomic(path, text.as_bytes())?;
    }
    if let Some(path) = &a.png {
        // A surface with boundary: its half of the double only (the mirror half is folded
        // onto the same positions).
        let half = dbl.as_ref().map(|d| d.surface_faces());
        let png = net_picture(
            h,
            &zeros,
            &corner_uv,
            a.checks / scale,
            &trajectories,
            half.as_deref(),
        )?;
        write_atomic(path, &png)?;
    }
    bar.0.finish_and_clear();
    let mut v = report_json(&a, h, &chosen, &zeros, &net, trajectories.len(), t0)?;
    if let Some(d) = &dbl {
        v["double"] = json!({
            "surface_genus": d.surface_genus,
            "boundary_loops": d.boundary_loops,
            "genus": d.genus,
            "chord_splits": d.chord_splits,
            "widened_corners": d.widened,
            "reflection": d.reflection,
            "orthogonal_forms": d.orthogonal.len(),
            "orthogonal_boundary_defect": d.orthogonal_boundary_defect,
            "surface_faces": d.surface_faces().iter().filter(|&&x| x).count(),
        });
    }
    if a.json {
        print_json(&v);
    } else {
        print_text(h, &zeros, &net, t0);
    }
    Ok(())
}

/// The form integrated and how it was chosen.
struct ChosenForm {
    form: HolomorphicForm,
    coefficients: Vec<Complex>,
    placement_residual: Option<f64>,
    uniform: Option<UniformCombination>,
}

impl ChosenForm {
    /// `|λ|`: the length of the coefficients (1 for a basis form).
    fn scale(&self) -> f64 {
        let s: f64 = self.coefficients.iter().map(|c| c.norm_sqr()).sum();
        s.sqrt().max(1e-300)
    }
}

/// `--uniform`, `--zeros` or `--form`.
fn choose_form(a: &Args, h: &HolomorphicForms, n_vertices: usize) -> anyhow::Result<ChosenForm> {
    let g = h.genus;
    if a.uniform {
        let (u, w) = uniform_combination(h, 200)?;
        return Ok(ChosenForm {
            form: w,
            coefficients: u.coefficients.clone(),
            placement_residual: None,
            uniform: Some(u),
        });
    }
    if a.zeros.is_empty() {
        if a.form == 0 || a.form > g {
            return Err(UsageError(format!("--form must be between 1 and the genus {g}")).into());
        }
        let mut c = vec![Complex::new(0.0, 0.0); g];
        c[a.form - 1] = Complex::new(1.0, 0.0);
        return Ok(ChosenForm {
            form: h.combination(&c),
            coefficients: c,
            placement_residual: None,
            uniform: None,
        });
    }
    if a.zeros.len() > g {
        return Err(UsageError(format!(
            "--zeros: at most {g} positions on a genus-{g} surface"
        ))
        .into());
    }
    if let Some(&v) = a.zeros.iter().find(|&&v| v as usize >= n_vertices) {
        return Err(UsageError(format!(
            "--zeros: vertex {v} does not exist (the mesh has {n_vertices} vertices)"
        ))
        .into());
    }
    let (c, w, r) = form_with_zeros(h, &a.zeros)?;
    Ok(ChosenForm {
        form: w,
        coefficients: c,
        placement_residual: Some(r),
        uniform: None,
    })
}

fn refined_positions(h: &HolomorphicForms) -> anyhow::Result<&[[f64; 3]]> {
    h.cut.refined.positions.as_deref().ok_or_else(|| {
        anyhow::anyhow!(
            "the working triangulation has vertices without positions; use --triangulation input"
        )
    })
}

/// The critical horizontal trajectories of `form` through its zeros, each traced for 1.5
/// times `scale` (the a-period of a basis form is 1), as polylines on the refined surface.
pub fn critical_lines(
    h: &HolomorphicForms,
    form: &HolomorphicForm,
    zeros: &ZeroSet,
    scale: f64,
) -> Vec<Vec<[f64; 3]>> {
    let Some(pos) = h.cut.refined.positions.as_deref() else {
        return Vec::new();
    };
    let at: Vec<u32> = zeros.zeros.iter().map(|z| z.vertex).collect();
    critical_trajectories(h.mesh(), &h.metric(), form, &at, 1.5 * scale, 200_000)
        .iter()
        .map(|t| t.points.iter().map(|p| p.position(pos)).collect())
        .collect()
}

/// Append polylines to an OBJ text as new vertices and `l` elements (`first` vertices are
/// already written).
fn append_obj_lines(text: &mut String, first: usize, lines: &[Vec<[f64; 3]>]) {
    use std::fmt::Write;
    let mut next = first + 1;
    for l in lines.iter().filter(|l| l.len() >= 2) {
        for p in l {
            let _ = writeln!(text, "v {} {} {}", p[0], p[1], p[2]);
        }
        let ids: Vec<String> = (next..next + l.len()).map(|i| i.to_string()).collect();
        let _ = writeln!(text, "l {}", ids.join(" "));
        next += l.len();
    }
}

/// Checkerboard of the net on the surface (`freq` checks per unit of uv), the zeros circled
/// in red, the critical trajectories in dark blue; PNG bytes. With `faces`, only the refined
/// faces marked `true` are drawn (a surface with boundary: its half of the double).
pub fn net_picture(
    h: &HolomorphicForms,
    zeros: &ZeroSet,
    corner_uv: &[[f64; 2]],
    freq: f64,
    trajectories: &[Vec<[f64; 3]>],
    faces: Option<&[bool]>,
) -> anyhow::Result<Vec<u8>> {
    let pos = refined_positions(h)?;
    let all = h.cut.refined.mesh.faces();
    let keep = |f: usize| faces.is_none_or(|m| m.get(f).copied().unwrap_or(false));
    let tris: Vec<[u32; 3]> = (0..all.len())
        .filter(|&f| keep(f))
        .map(|f| all[f])
        .collect();
    let corner_uv: Vec<[f64; 2]> = (0..all.len())
        .filter(|&f| keep(f))
        .flat_map(|f| corner_uv[3 * f..3 * f + 3].iter().copied())
        .collect();
    let tris = tris.as_slice();
    let mut polylines: Vec<Polyline> = trajectories
        .iter()
        .map(|l| Polyline {
            points: l.clone(),
            color: [0.05, 0.15, 0.6],
            width: 2.5,
            closed: false,
        })
        .collect();
    polylines.extend(zeros.zeros.iter().map(|z| marker(pos, tris, z.vertex)));
    let style = Style {
        paint: Paint::Checker(Checker::new(Uvs::PerCorner(&corner_uv), freq)),
        polylines,
        ..Default::default()
    };
    Ok(ricci_render::render_png(
        pos,
        tris,
        &style,
        &RenderOptions::default(),
    )?)
}

fn report_json(
    a: &Args,
    h: &HolomorphicForms,
    chosen: &ChosenForm,
    zeros: &ZeroSet,
    net: &ConformalNet,
    trajectories: usize,
    t0: Instant,
) -> anyhow::Result<serde_json::Value> {
    let n_work = h.working.mesh.n_vertices() as u32;
    let refined = &h.cut.refined;
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
    let om = &h.period_matrix;
    let r = &h.report;
    Ok(json!({
        "mesh": a.mesh.display().to_string(),
        "genus": h.genus,
        "period_matrix": {"re": om.re, "im": om.im},
        "modulus": h.modulus().map(|t| [t.0, t.1]),
        "im_eigenvalues": om.im_eigenvalues()?,
        "symmetry_error": om.asymmetry(),
        "zeros": zero_json,
        "zero_count": zeros.count,
        "spurious_singularities": zeros.spurious,
        "critical_trajectories": trajectories,
        "form": {
            "coefficients": chosen.coefficients.iter().map(|c| [c.re, c.im]).collect::<Vec<_>>(),
            "placed_zeros": a.zeros,
            "placement_residual": chosen.placement_residual,
            "uniform": chosen.uniform,
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
    }))
}

fn print_text(h: &HolomorphicForms, zeros: &ZeroSet, net: &ConformalNet, t0: Instant) {
    let (g, r, om) = (h.genus, &h.report, &h.period_matrix);
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

/// A small red circle around vertex `v` (radius 1.5 % of the bounding box diagonal).
pub fn marker(pos: &[[f64; 3]], tris: &[[u32; 3]], v: u32) -> Polyline {
    crate::util::ring_marker(pos, tris, v, 0.015, [0.85, 0.1, 0.1])
}
