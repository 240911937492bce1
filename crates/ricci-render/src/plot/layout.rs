//! Layout figures: copies of a triangulated domain in the plane or the Poincaré disk, sides
//! coloured by generator with labels, the unit circle and an optional colour bar.

use super::{Anchor, Figure, Item};
use crate::color::{self, Colormap, Rgb};
use crate::font;
use crate::{input_err, Result};

/// Affine map from data coordinates to pixels (uniform scale, y up in data, y down on screen).
#[derive(Debug, Clone, Copy)]
struct Frame {
    sx: f64,
    sy: f64,
    ox: f64,
    oy: f64,
}

impl Frame {
    #[inline]
    fn map(&self, p: [f64; 2]) -> [f64; 2] {
        [self.ox + self.sx * p[0], self.oy - self.sy * p[1]]
    }
}

/// One copy of a layout (the fundamental domain, or its image under a deck transformation).
#[derive(Debug, Clone)]
pub struct LayoutCopy<'a> {
    /// One 2D point per vertex (plane or Poincaré disk coordinates).
    pub uvs: &'a [[f64; 2]],
    pub triangles: &'a [[u32; 3]],
    /// Fill of every triangle (unless `face_colors` is given).
    pub fill: Rgb,
    /// Per-face fill colours (e.g. from [`face_colors`]).
    pub face_colors: Option<Vec<Rgb>>,
    /// Colour of triangle edges, `None` for no edges.
    pub edges: Option<Rgb>,
}

impl<'a> LayoutCopy<'a> {
    /// Light grey-blue triangles with thin darker edges.
    pub fn new(uvs: &'a [[f64; 2]], triangles: &'a [[u32; 3]]) -> Self {
        LayoutCopy {
            uvs,
            triangles,
            fill: [0.86, 0.90, 0.96],
            face_colors: None,
            edges: Some([0.45, 0.52, 0.62]),
        }
    }

    /// A tiling copy number `i` (i ≥ 1): a light tint of the categorical palette.
    pub fn tinted(uvs: &'a [[f64; 2]], triangles: &'a [[u32; 3]], i: usize) -> Self {
        let c = color::categorical(i);
        LayoutCopy {
            uvs,
            triangles,
            fill: color::tint(c, 0.72),
            face_colors: None,
            edges: Some(color::tint(c, 0.3)),
        }
    }
}

/// A side of a fundamental domain (or any marked curve) in layout coordinates.
#[derive(Debug, Clone)]
pub struct Side {
    pub points: Vec<[f64; 2]>,
    pub color: Rgb,
    /// Shown next to the side's midpoint ("a1", "b1⁻¹" is written "b1^-1" in PNGs).
    pub label: String,
}

/// A layout picture: copies of a triangulated domain, marked sides, the unit circle.
#[derive(Debug, Clone)]
pub struct LayoutPlot<'a> {
    pub copies: Vec<LayoutCopy<'a>>,
    pub sides: Vec<Side>,
    /// Poincaré disk: frame the unit disk and draw the unit circle.
    pub disk: bool,
    pub title: String,
    /// Size of the longer side of the picture in pixels.
    pub size: f64,
    /// A colour bar at the right for the copies' `face_colors` (the same map and range).
    pub colorbar: Option<ColorBar>,
}

/// A vertical colour bar: what the colours of a picture mean.
#[derive(Debug, Clone)]
pub struct ColorBar {
    pub colormap: Colormap,
    /// Values at the bottom and the top of the bar.
    pub range: (f64, f64),
    /// What is coloured (shown above the bar), e.g. "log(flat area / R³ area)".
    pub label: String,
}

/// Width of the strip a [`ColorBar`] adds at the right of a layout figure.
const COLORBAR_STRIP: f64 = 96.0;

/// Draw `bar` into `fig` in the strip `[x, x + COLORBAR_STRIP] × [top, bottom]`.
fn draw_colorbar(fig: &mut Figure, bar: &ColorBar, x: f64, top: f64, bottom: f64) {
    let ink = [0.15; 3];
    let bw = 16.0;
    let (y0, y1) = (top + 30.0, bottom - 10.0);
    if y1 <= y0 {
        return;
    }
    let steps = 96;
    for k in 0..steps {
        let (a, b) = (k as f64 / steps as f64, (k + 1) as f64 / steps as f64);
        let (ya, yb) = (y1 - a * (y1 - y0), y1 - b * (y1 - y0));
        fig.items.push(Item::Polygons {
            polygons: vec![vec![
                [x, ya + 0.5],
                [x + bw, ya + 0.5],
                [x + bw, yb],
                [x, yb],
            ]],
            fill: Some(bar.colormap.eval(0.5 * (a + b))),
            stroke: None,
            stroke_width: 0.0,
            class: "colorbar",
        });
    }
    fig.items.push(Item::Polyline {
        points: vec![[x, y0], [x + bw, y0], [x + bw, y1], [x, y1]],
        color: ink,
        width: 1.0,
        dash: None,
        closed: true,
        class: "colorbar",
    });
    let (lo, hi) = bar.range;
    let mut ticks = vec![lo, hi];
    if bar.colormap.is_diverging() && lo < 0.0 && hi > 0.0 {
        ticks.push(0.0);
    } else {
        ticks.push(0.5 * (lo + hi));
    }
    for t in ticks {
        let f = if hi > lo { (t - lo) / (hi - lo) } else { 0.5 };
        let y = y1 - f * (y1 - y0);
        fig.line(vec![[x + bw, y], [x + bw + 4.0, y]], ink, 1.0, "colorbar");
        fig.text(
            [x + bw + 7.0, y],
            font::format_number(t).replace('-', "−"),
            12.0,
            ink,
            Anchor::Start,
        );
    }
    let size = font::fit_size(&bar.label, 12.0, (COLORBAR_STRIP - 6.0) as f32, 7.0) as f64;
    fig.text(
        [x + COLORBAR_STRIP - 4.0, top + 14.0],
        bar.label.clone(),
        size,
        ink,
        Anchor::End,
    );
}

impl<'a> LayoutPlot<'a> {
    pub fn new(copy: LayoutCopy<'a>) -> Self {
        LayoutPlot {
            copies: vec![copy],
            sides: Vec::new(),
            disk: false,
            title: String::new(),
            size: 800.0,
            colorbar: None,
        }
    }
}

/// Per-face colours of values through a colormap over [lo, hi] (NaN → grey).
pub fn face_colors(values: &[f64], map: Colormap, range: (f64, f64)) -> Vec<Rgb> {
    values
        .iter()
        .map(|&v| {
            if v.is_finite() {
                map.eval(color::normalize(v, range.0, range.1))
            } else {
                [0.6; 3]
            }
        })
        .collect()
}

/// The standard names of the 2g sides of a canonical fundamental domain, in the order of the
/// boundary word a1 b1 a1⁻¹ b1⁻¹ … (`["a1", "b1", "a1^-1", "b1^-1", "a2", …]`), and the
/// generator index of each (a1 → 0, b1 → 1, a2 → 2, …) for colouring.
pub fn canonical_side_names(genus: usize) -> Vec<(String, usize)> {
    let mut v = Vec::with_capacity(4 * genus);
    for k in 1..=genus {
        let (a, b) = (2 * (k - 1), 2 * (k - 1) + 1);
        v.push((format!("a{k}"), a));
        v.push((format!("b{k}"), b));
        v.push((format!("a{k}^-1"), a));
        v.push((format!("b{k}^-1"), b));
    }
    v
}

/// The bounding box `(lo, hi)` of every copy's points and every side (the unit disk
/// included when `plot.disk`), after checking the copies' indices, colours and points.
fn checked_bounds(plot: &LayoutPlot) -> Result<([f64; 2], [f64; 2])> {
    if plot.copies.is_empty() {
        return input_err("a layout plot needs at least one copy of the domain");
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for (k, c) in plot.copies.iter().enumerate() {
        for (f, t) in c.triangles.iter().enumerate() {
            for &i in t {
                if i as usize >= c.uvs.len() {
                    return input_err(format!(
                        "copy {k}: face {f} refers to vertex {i}, but there are only {} points",
                        c.uvs.len()
                    ));
                }
            }
        }
        if let Some(fc) = &c.face_colors {
            if fc.len() != c.triangles.len() {
                return input_err(format!(
                    "copy {k}: {} face colours for {} faces",
                    fc.len(),
                    c.triangles.len()
                ));
            }
        }
        for (v, p) in c.uvs.iter().enumerate() {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return input_err(format!("copy {k}: point {v} is not finite"));
            }
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
    }
    for s in &plot.sides {
        for p in &s.points {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
    }
    if plot.disk {
        lo = [lo[0].min(-1.0), lo[1].min(-1.0)];
        hi = [hi[0].max(1.0), hi[1].max(1.0)];
    }
    if !(lo[0].is_finite() && lo[1].is_finite()) {
        return input_err("the layout has no points");
    }
    Ok((lo, hi))
}

/// Draw a layout: triangles of every copy, then sides with labels, then the unit circle.
pub fn layout_figure(plot: &LayoutPlot) -> Result<Figure> {
    let (lo, hi) = checked_bounds(plot)?;
    let ext = [(hi[0] - lo[0]).max(1e-12), (hi[1] - lo[1]).max(1e-12)];
    let title_h = if plot.title.is_empty() { 0.0 } else { 34.0 };
    let pad = 36.0; // room for labels
    let size = plot.size.max(64.0);
    let (w, h) = if ext[0] >= ext[1] {
        (
            size,
            (size - 2.0 * pad) * ext[1] / ext[0] + 2.0 * pad + title_h,
        )
    } else {
        (
            (size - 2.0 * pad - title_h) * ext[0] / ext[1] + 2.0 * pad,
            size,
        )
    };
    let scale = ((w - 2.0 * pad) / ext[0]).min((h - 2.0 * pad - title_h) / ext[1]);
    let cx = 0.5 * (lo[0] + hi[0]);
    let cy = 0.5 * (lo[1] + hi[1]);
    let frame = Frame {
        sx: scale,
        sy: scale,
        ox: 0.5 * w - scale * cx,
        oy: title_h + 0.5 * (h - title_h) + scale * cy,
    };
    let strip = if plot.colorbar.is_some() {
        COLORBAR_STRIP
    } else {
        0.0
    };
    let mut fig = Figure::new((w + strip).round(), h.round());
    if plot.disk {
        fig.items.push(Item::Circle {
            center: frame.map([0.0, 0.0]),
            radius: scale,
            fill: Some([0.975, 0.975, 0.98]),
            stroke: None,
            stroke_width: 0.0,
            id: None,
        });
    }
    draw_copies(&mut fig, plot, &frame);
    draw_sides(&mut fig, plot, &frame);
    if plot.disk {
        fig.items.push(Item::Circle {
            center: frame.map([0.0, 0.0]),
            radius: scale,
            fill: None,
            stroke: Some([0.1, 0.1, 0.1]),
            stroke_width: 1.6,
            id: Some("unit-circle"),
        });
    }
    if let Some(bar) = &plot.colorbar {
        draw_colorbar(&mut fig, bar, w, title_h, h - pad);
    }
    if !plot.title.is_empty() {
        // Fitted to the figure's width (a narrow chart must not clip its title).
        let fw = (w + strip - 16.0) as f32;
        fig.text(
            [0.5 * (w + strip), 20.0],
            plot.title.clone(),
            font::fit_size(&plot.title, 16.0, fw, 8.0) as f64,
            [0.1; 3],
            Anchor::Middle,
        );
    }
    Ok(fig)
}

/// The triangles of every copy: one polygon list per copy, or per colour when the copy has
/// face colours (then its edges as a separate list).
fn draw_copies(fig: &mut Figure, plot: &LayoutPlot, frame: &Frame) {
    let edge_width =
        (0.6f64).min(0.25 + 40.0 / (1.0 + (plot.copies[0].triangles.len() as f64).sqrt()));
    for c in &plot.copies {
        let tri = |t: &[u32; 3]| {
            t.iter()
                .map(|&i| frame.map(c.uvs[i as usize]))
                .collect::<Vec<_>>()
        };
        match &c.face_colors {
            None => fig.items.push(Item::Polygons {
                polygons: c.triangles.iter().map(tri).collect(),
                fill: Some(c.fill),
                stroke: c.edges,
                stroke_width: edge_width,
                class: "faces",
            }),
            Some(fc) => {
                // Group faces by colour to keep the SVG small.
                let mut groups: std::collections::BTreeMap<[u8; 3], Vec<Vec<[f64; 2]>>> =
                    Default::default();
                for (f, t) in c.triangles.iter().enumerate() {
                    groups
                        .entry(crate::image::to8(fc[f]))
                        .or_default()
                        .push(tri(t));
                }
                for (col, polys) in groups {
                    fig.items.push(Item::Polygons {
                        polygons: polys,
                        fill: Some(col.map(|v| v as f32 / 255.0)),
                        stroke: None,
                        stroke_width: 0.0,
                        class: "faces",
                    });
                }
                if let Some(e) = c.edges {
                    fig.items.push(Item::Polygons {
                        polygons: c.triangles.iter().map(tri).collect(),
                        fill: None,
                        stroke: Some(e),
                        stroke_width: edge_width,
                        class: "edges",
                    });
                }
            }
        }
    }
}

/// The sides and their labels, pushed outwards from the centroid of the first copy.
fn draw_sides(fig: &mut Figure, plot: &LayoutPlot, frame: &Frame) {
    let centroid = {
        let u = plot.copies[0].uvs;
        let n = u.len().max(1) as f64;
        let s = u.iter().fold([0.0, 0.0], |a, p| [a[0] + p[0], a[1] + p[1]]);
        frame.map([s[0] / n, s[1] / n])
    };
    for s in &plot.sides {
        if s.points.len() < 2 {
            continue;
        }
        let pts: Vec<[f64; 2]> = s.points.iter().map(|p| frame.map(*p)).collect();
        fig.items.push(Item::Polyline {
            points: pts.clone(),
            color: s.color,
            width: 2.6,
            dash: None,
            closed: false,
            class: "side",
        });
        if !s.label.is_empty() {
            let mid = polyline_midpoint(&pts);
            let d = [mid[0] - centroid[0], mid[1] - centroid[1]];
            let l = (d[0] * d[0] + d[1] * d[1]).sqrt().max(1e-9);
            let at = [mid[0] + 16.0 * d[0] / l, mid[1] + 16.0 * d[1] / l];
            fig.items.push(Item::Text {
                at,
                text: s.label.clone(),
                size: 16.0,
                color: s.color,
                anchor: Anchor::Middle,
                bold: true,
            });
        }
    }
}

fn polyline_midpoint(p: &[[f64; 2]]) -> [f64; 2] {
    let seg = |i: usize| ((p[i + 1][0] - p[i][0]).powi(2) + (p[i + 1][1] - p[i][1]).powi(2)).sqrt();
    let total: f64 = (0..p.len() - 1).map(seg).sum();
    let mut acc = 0.0;
    for i in 0..p.len() - 1 {
        let l = seg(i);
        if acc + l >= 0.5 * total && l > 0.0 {
            let t = (0.5 * total - acc) / l;
            return [
                p[i][0] + t * (p[i + 1][0] - p[i][0]),
                p[i][1] + t * (p[i + 1][1] - p[i][1]),
            ];
        }
        acc += l;
    }
    p[p.len() / 2]
}
