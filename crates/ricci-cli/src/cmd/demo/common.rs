//! Shared pieces of the demo's stages: the [`Ctx`] the stages hand on to each other, the
//! constants several stages use, and the picture helpers (render options, PNG/SVG writing,
//! residual plots and tables, generator colours, point markers).

use super::report::{Picture, Table};
use super::Env;
use ricci::atlas::AffineAtlas;
use ricci::flow::FlowResult;
use ricci::layout::isometry::Complex;
use ricci::layout::pipeline::CutDisk;
use ricci::layout::{DeckGroup, Layout, Mobius};
use ricci::mesh::Surface;
use ricci::metric::refine::Refined;
use ricci_render::plot::{line_plot_figure, Figure, LinePlot, Series};
use ricci_render::{color, Image, Polyline, RenderOptions, View};
use serde_json::json;

/// Tolerance of both flows: max |K − K̄| (the value `ricci layout` uses; 1e-12 stalls at
/// rounding on large meshes, 1e-11 is reached here in a few Newton steps).
pub const FLOW_TOLERANCE: f64 = 1e-11;
/// Valence the single cone's vertex is raised to (Chow–Luo needs ≥ 4 − 2K̄/π = 12 for a cone
/// of 2πχ = −4π; a few more spokes keep the Thurston angles comfortably inside the bound).
pub const CONE_VALENCE: usize = 16;
/// Copies of the fundamental polygon in the tiling picture.
pub const TILES: usize = 300;
/// Geodesic lengths listed.
pub const SPECTRUM_COUNT: usize = 8;
/// Checks per unit of Poincaré-disk coordinates in the checkerboard pictures.
pub const CHECKS: f64 = 14.0;

/// What the stages computed, for the stages after them.
pub struct Ctx {
    pub resolution: u32,
    pub surface: Option<Surface>,
    pub chi: i64,
    pub hyperbolic: Option<FlowResult>,
    pub disk: Option<CutDisk>,
    pub layout: Option<Layout<Complex>>,
    pub group: Option<DeckGroup<Mobius>>,
    /// The refined surface and flat metric with one cone (for the affine atlas stage).
    pub cone: Option<(Refined, FlowResult, u32)>,
    /// The affine atlas (for the manifold spline stage).
    pub atlas: Option<AffineAtlas>,
}

impl Ctx {
    pub fn new(resolution: u32) -> Ctx {
        Ctx {
            resolution,
            surface: None,
            chi: 0,
            hyperbolic: None,
            disk: None,
            layout: None,
            group: None,
            cone: None,
            atlas: None,
        }
    }
    /// What a stage running beside the others ([`super::BESIDE`]) may read: a copy of the
    /// surface and its Euler characteristic.
    pub(super) fn beside(&self) -> Ctx {
        let mut c = Ctx::new(self.resolution);
        c.surface = self.surface.clone();
        c.chi = self.chi;
        c
    }
    pub(super) fn surface(&self) -> anyhow::Result<&Surface> {
        self.surface
            .as_ref()
            .ok_or_else(|| anyhow::anyhow!("no surface"))
    }
}

// ---------------------------------------------------------------------------------------------
// Pictures.

/// Width and height of the surface renders (the genus-2 surface is about 5 × 3 × 0.8).
pub(super) const RENDER_W: u32 = 760;
pub(super) const RENDER_H: u32 = 520;

pub(super) fn opts(view: View) -> RenderOptions {
    RenderOptions {
        width: RENDER_W,
        height: RENDER_H,
        supersample: 3,
        view,
        ..RenderOptions::default()
    }
}

pub(super) fn back_view() -> View {
    View {
        eye_direction: [-0.4, -0.3, -1.0],
        ..View::default()
    }
}

/// Write an image as PNG and describe it.
pub(super) fn png(
    env: &mut Env,
    file: &str,
    img: &Image,
    caption: &str,
) -> anyhow::Result<Picture> {
    env.out.write(file, &img.to_png()?)?;
    Ok(Picture {
        file: file.into(),
        caption: caption.into(),
        width: img.width,
        height: img.height,
        alternatives: Vec::new(),
    })
}

/// Write a 2D figure as `stem.png` and, with `svg`, `stem.svg`.
pub(super) fn figure(
    env: &mut Env,
    stem: &str,
    fig: &Figure,
    caption: &str,
    svg: bool,
) -> anyhow::Result<Picture> {
    let img = fig.to_image(1.0)?;
    let mut p = png(env, &format!("{stem}.png"), &img, caption)?;
    if svg {
        let file = format!("{stem}.svg");
        env.out.write(&file, fig.to_svg().as_bytes())?;
        p.alternatives.push(file);
    }
    Ok(p)
}

/// Residual history (max |K − K̄| per Newton step) as a log-scale line plot.
pub(super) fn residual_plot(r: &FlowResult, title: &str) -> anyhow::Result<Figure> {
    let pts: Vec<[f64; 2]> = r
        .history
        .iter()
        .map(|h| [h.iteration as f64, h.max_curvature_error])
        .collect();
    let tol: Vec<[f64; 2]> = vec![
        [0.0, r.tolerance],
        [
            r.history.last().map_or(1, |h| h.iteration) as f64,
            r.tolerance,
        ],
    ];
    Ok(line_plot_figure(
        &[
            Series {
                name: "max |K − K̄|".into(),
                points: pts,
                color: color::categorical(0),
            },
            Series {
                name: format!("tolerance {:.0e}", r.tolerance),
                points: tol,
                color: [0.55, 0.55, 0.55],
            },
        ],
        &LinePlot {
            title: title.into(),
            x_label: "Newton step".into(),
            y_label: String::new(),
            log_y: true,
            width: 600.0,
            height: 400.0,
        },
    )?)
}

pub(super) fn history_table(r: &FlowResult) -> Table {
    let mut t = Table::new(
        "Newton steps",
        &["step", "max |K − K̄|", "largest |Δu|", "time (s)"],
    );
    for h in &r.history {
        t.row(vec![
            h.iteration.to_string(),
            format!("{:.3e}", h.max_curvature_error),
            format!("{:.3e}", h.step),
            format!("{:.4}", h.seconds),
        ]);
    }
    t
}

pub(super) fn flow_summary(r: &FlowResult) -> serde_json::Value {
    json!({
        "geometry": r.geometry,
        "scheme": r.scheme,
        "solver": r.solver,
        "target": r.target_description,
        "iterations": r.iterations,
        "converged": r.converged,
        "tolerance": r.tolerance,
        "max_curvature_error": r.max_curvature_error,
        "gauss_bonnet_error": r.gauss_bonnet_error,
        "area": r.area,
        "flow_seconds": r.seconds,
        "history": r.history.iter().map(|h| json!({
            "iteration": h.iteration, "max_curvature_error": h.max_curvature_error,
            "step": h.step, "seconds": h.seconds})).collect::<Vec<_>>(),
        "notes": r.notes,
    })
}

/// Colour of generator `letter` (a1 → 0, b1 → 1, …), the same in every picture.
pub(super) fn generator_color(letters: &[String], label: &str) -> color::Rgb {
    let base = label.trim_end_matches("^-1");
    color::categorical(letters.iter().position(|l| l == base).unwrap_or(7))
}

/// A small black ring around vertex `v` in its tangent plane (radius 2% of the bounding box
/// diagonal), to mark a point on the surface.
pub(super) fn base_marker(pos: &[[f64; 3]], tris: &[[u32; 3]], v: u32) -> Polyline {
    crate::util::ring_marker(pos, tris, v, 0.02, [0.0, 0.0, 0.0])
}
