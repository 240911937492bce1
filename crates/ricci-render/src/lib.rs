//! Pictures for ricci: a small software renderer (PNG), 2D plots (SVG/PNG) and glTF export.
//!
//! This crate does not depend on the `ricci` library: it takes plain slices (positions
//! `&[[f64; 3]]`, triangles `&[[u32; 3]]`, UVs `&[[f64; 2]]`, scalars `&[f64]`, polylines), so
//! programs that compute flows do not compile image dependencies, and anything with a triangle
//! list can be drawn.
//!
//! * [`render`] — z-buffered triangle rasterizer with supersampling, a camera that frames the
//!   mesh, Lambert + Blinn–Phong shading on smooth vertex normals, and paints: checkerboard or
//!   circle textures from UVs (conformality pictures of paper 001 Fig. 4f/7c), scalar fields
//!   through perceptual colormaps with a legend, reflection lines (zebra), wireframe and
//!   polylines on the surface.
//! * [`plot`] — 2D figures as SVG strings and PNG bytes: planar and Poincaré-disk layouts with
//!   sides coloured by generator, tilings, histograms (angle-ratio histogram of paper 001
//!   Fig. 7d) and line plots (residual vs. iteration, log scale).
//! * [`gltf`] — glTF 2.0 binary (`.glb`) with positions, normals, UVs and an embedded checker
//!   texture.
//! * [`loops`] — closed curves on a surface as an SVG sketch (the canonical cut's loops).
//! * [`atlas`] — the charts of a flat atlas as SVG (one chart, or all mapped into the
//!   central chart).
//! * [`fields`] — per-vertex and per-face quantities worth looking at (angle defect, mean
//!   curvature, area distortion, angle ratios), computed from the same plain slices.
//!
//! Every function returns [`Error`] on bad data (index out of range, NaN position, wrong
//! length) and never panics on user data.

#![allow(clippy::needless_range_loop)] // index loops over xyz read best in numeric code

pub mod atlas;
pub mod camera;
pub mod color;
pub mod fields;
mod font;
pub mod gltf;
pub mod image;
pub mod loops;
pub mod plot;
pub mod render;
pub mod shapes;

pub use camera::{Camera, Projection, View};
pub use color::{Colormap, Rgb, ScalarRange};
pub use image::Image;
pub use render::{
    render, render_png, Background, Checker, Circles, Lighting, Paint, Polyline, RenderOptions,
    Rendered, Scalar, ScalarLocation, Style, Wireframe, Zebra,
};

/// Errors of the renderer: one sentence naming the problem and where it is.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The input data is unusable (index out of range, non-finite value, wrong length, …).
    #[error("{0}")]
    Input(String),
    /// Encoding an image or a file failed.
    #[error("{0}")]
    Encode(String),
}

/// Result with this crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

pub(crate) fn input_err<T>(msg: impl Into<String>) -> Result<T> {
    Err(Error::Input(msg.into()))
}

/// Check a triangle list against a vertex count and positions for finiteness.
pub(crate) fn check_mesh(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<()> {
    if triangles.is_empty() {
        return input_err("the mesh has no triangles to draw");
    }
    for (v, p) in positions.iter().enumerate() {
        if !p.iter().all(|x| x.is_finite()) {
            return input_err(format!("vertex {v} has a non-finite position {p:?}"));
        }
    }
    let n = positions.len();
    for (f, t) in triangles.iter().enumerate() {
        for &i in t {
            if i as usize >= n {
                return input_err(format!(
                    "face {f} refers to vertex {i}, but there are only {n} vertices"
                ));
            }
        }
    }
    Ok(())
}
