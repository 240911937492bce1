//! 2D figures as SVG strings and PNG bytes: layouts in the plane and in the Poincaré disk
//! (triangles, boundary sides coloured by generator with labels a1, b1, …, the unit circle,
//! tilings with one colour per copy), histograms (the angle-ratio histogram of paper 001
//! Fig. 7d) and line plots (residual vs. iteration, log scale).
//!
//! A [`Figure`] is a display list in pixel coordinates (y down). Plot functions map data to
//! pixels and fill it; [`Figure::to_svg`] and [`Figure::to_png`] draw the same list (PNG through
//! tiny-skia with anti-aliasing; text with the built-in bitmap font).

use crate::color::{self, Colormap, Rgb};
use crate::font;
use crate::image::Image;
use crate::{input_err, Error, Result};
use std::fmt::Write;

/// Horizontal alignment of text.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    Start,
    Middle,
    End,
}

/// One element of a figure (pixel coordinates, y down).
#[derive(Debug, Clone)]
pub enum Item {
    /// Many polygons with one style (one SVG path).
    Polygons {
        polygons: Vec<Vec<[f64; 2]>>,
        fill: Option<Rgb>,
        stroke: Option<Rgb>,
        stroke_width: f64,
        class: &'static str,
    },
    Polyline {
        points: Vec<[f64; 2]>,
        color: Rgb,
        width: f64,
        dash: Option<f64>,
        closed: bool,
        class: &'static str,
    },
    Circle {
        center: [f64; 2],
        radius: f64,
        fill: Option<Rgb>,
        stroke: Option<Rgb>,
        stroke_width: f64,
        id: Option<&'static str>,
    },
    Text {
        at: [f64; 2],
        text: String,
        size: f64,
        color: Rgb,
        anchor: Anchor,
        bold: bool,
    },
}

/// A display list with a size in pixels.
#[derive(Debug, Clone)]
pub struct Figure {
    pub width: f64,
    pub height: f64,
    /// `None` = transparent.
    pub background: Option<Rgb>,
    pub items: Vec<Item>,
}

impl Figure {
    pub fn new(width: f64, height: f64) -> Figure {
        Figure {
            width,
            height,
            background: Some([1.0; 3]),
            items: Vec::new(),
        }
    }

    /// Number of items of each kind (polygons counted one by one), e.g. for checks.
    pub fn count_polygons(&self) -> usize {
        self.items
            .iter()
            .map(|i| match i {
                Item::Polygons { polygons, .. } => polygons.len(),
                _ => 0,
            })
            .sum()
    }

    fn text(
        &mut self,
        at: [f64; 2],
        text: impl Into<String>,
        size: f64,
        color: Rgb,
        anchor: Anchor,
    ) {
        self.items.push(Item::Text {
            at,
            text: text.into(),
            size,
            color,
            anchor,
            bold: false,
        });
    }

    fn line(&mut self, points: Vec<[f64; 2]>, color: Rgb, width: f64, class: &'static str) {
        self.items.push(Item::Polyline {
            points,
            color,
            width,
            dash: None,
            closed: false,
            class,
        });
    }

    /// The figure as an SVG document (UTF-8 text).
    pub fn to_svg(&self) -> String {
        let mut s = String::with_capacity(4096);
        let _ = writeln!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="Helvetica, Arial, sans-serif">"#,
            w = num(self.width),
            h = num(self.height)
        );
        if let Some(bg) = self.background {
            let _ = writeln!(
                s,
                r#"<rect x="0" y="0" width="{}" height="{}" fill="{}"/>"#,
                num(self.width),
                num(self.height),
                color::to_hex(bg)
            );
        }
        for item in &self.items {
            match item {
                Item::Polygons {
                    polygons,
                    fill,
                    stroke,
                    stroke_width,
                    class,
                } => {
                    let mut d = String::with_capacity(polygons.len() * 40);
                    for poly in polygons {
                        for (k, p) in poly.iter().enumerate() {
                            let _ = write!(
                                d,
                                "{}{} {}",
                                if k == 0 { "M" } else { "L" },
                                num(p[0]),
                                num(p[1])
                            );
                        }
                        d.push('Z');
                    }
                    let _ = writeln!(
                        s,
                        r#"<path class="{class}" d="{d}" fill="{}" stroke="{}" stroke-width="{}" stroke-linejoin="round"/>"#,
                        fill.map_or("none".into(), color::to_hex),
                        stroke.map_or("none".into(), color::to_hex),
                        num(*stroke_width)
                    );
                }
                Item::Polyline {
                    points,
                    color: c,
                    width,
                    dash,
                    closed,
                    class,
                } => {
                    let pts: Vec<String> = points
                        .iter()
                        .map(|p| format!("{},{}", num(p[0]), num(p[1])))
                        .collect();
                    let dash = dash.map_or(String::new(), |d| {
                        format!(r#" stroke-dasharray="{} {}""#, num(d), num(d))
                    });
                    let _ = writeln!(
                        s,
                        r#"<{tag} class="{class}" points="{}" fill="none" stroke="{}" stroke-width="{}" stroke-linejoin="round" stroke-linecap="round"{dash}/>"#,
                        pts.join(" "),
                        color::to_hex(*c),
                        num(*width),
                        tag = if *closed { "polygon" } else { "polyline" }
                    );
                }
                Item::Circle {
                    center,
                    radius,
                    fill,
                    stroke,
                    stroke_width,
                    id,
                } => {
                    let id = id.map_or(String::new(), |i| format!(r#" id="{i}""#));
                    let _ = writeln!(
                        s,
                        r#"<circle{id} cx="{}" cy="{}" r="{}" fill="{}" stroke="{}" stroke-width="{}"/>"#,
                        num(center[0]),
                        num(center[1]),
                        num(*radius),
                        fill.map_or("none".into(), color::to_hex),
                        stroke.map_or("none".into(), color::to_hex),
                        num(*stroke_width)
                    );
                }
                Item::Text {
                    at,
                    text,
                    size,
                    color: c,
                    anchor,
                    bold,
                } => {
                    let anchor = match anchor {
                        Anchor::Start => "start",
                        Anchor::Middle => "middle",
                        Anchor::End => "end",
                    };
                    let _ = writeln!(
                        s,
                        r#"<text x="{}" y="{}" font-size="{}" font-family="{}" fill="{}" text-anchor="{anchor}" dominant-baseline="middle"{}>{}</text>"#,
                        num(at[0]),
                        num(at[1]),
                        num(*size),
                        font::SVG_FONT_FAMILY,
                        color::to_hex(*c),
                        if *bold { r#" font-weight="bold""# } else { "" },
                        escape(text)
                    );
                }
            }
        }
        s.push_str("</svg>\n");
        s
    }

    /// The figure rasterized (anti-aliased) as PNG bytes; `scale` multiplies the pixel size
    /// (2 for high-DPI screens).
    pub fn to_png(&self, scale: f64) -> Result<Vec<u8>> {
        self.to_image(scale)?.to_png()
    }

    /// The figure rasterized as an [`Image`].
    pub fn to_image(&self, scale: f64) -> Result<Image> {
        use tiny_skia::{
            FillRule, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Stroke, StrokeDash, Transform,
        };
        if !(scale > 0.0 && scale <= 16.0) {
            return input_err(format!("the PNG scale {scale} must be in (0, 16]"));
        }
        let (w, h) = (
            (self.width * scale).round() as u32,
            (self.height * scale).round() as u32,
        );
        let mut pm = Pixmap::new(w.max(1), h.max(1))
            .ok_or_else(|| Error::Input(format!("cannot allocate a {w}x{h} picture")))?;
        if let Some(bg) = self.background {
            let c = crate::image::to8(bg);
            pm.fill(tiny_skia::Color::from_rgba8(c[0], c[1], c[2], 255));
        }
        let tr = Transform::from_scale(scale as f32, scale as f32);
        let paint_of = |c: Rgb| {
            let mut p = Paint::default();
            let c = crate::image::to8(c);
            p.set_color_rgba8(c[0], c[1], c[2], 255);
            p.anti_alias = true;
            p
        };
        let stroke_of = |width: f64| Stroke {
            width: width as f32,
            line_cap: LineCap::Round,
            line_join: LineJoin::Round,
            ..Stroke::default()
        };
        let mut texts = Vec::new();
        for item in &self.items {
            match item {
                Item::Polygons {
                    polygons,
                    fill,
                    stroke,
                    stroke_width,
                    ..
                } => {
                    let mut pb = PathBuilder::new();
                    for poly in polygons {
                        for (k, p) in poly.iter().enumerate() {
                            if k == 0 {
                                pb.move_to(p[0] as f32, p[1] as f32);
                            } else {
                                pb.line_to(p[0] as f32, p[1] as f32);
                            }
                        }
                        pb.close();
                    }
                    let Some(path) = pb.finish() else { continue };
                    if let Some(f) = fill {
                        pm.fill_path(&path, &paint_of(*f), FillRule::Winding, tr, None);
                        if stroke.is_none() {
                            // Hide anti-aliasing seams between adjacent polygons.
                            pm.stroke_path(&path, &paint_of(*f), &stroke_of(0.5), tr, None);
                        }
                    }
                    if let Some(s) = stroke {
                        pm.stroke_path(&path, &paint_of(*s), &stroke_of(*stroke_width), tr, None);
                    }
                }
                Item::Polyline {
                    points,
                    color: c,
                    width,
                    dash,
                    closed,
                    ..
                } => {
                    let mut pb = PathBuilder::new();
                    for (k, p) in points.iter().enumerate() {
                        if k == 0 {
                            pb.move_to(p[0] as f32, p[1] as f32);
                        } else {
                            pb.line_to(p[0] as f32, p[1] as f32);
                        }
                    }
                    if *closed {
                        pb.close();
                    }
                    let Some(path) = pb.finish() else { continue };
                    let mut st = stroke_of(*width);
                    if let Some(d) = dash {
                        st.dash = StrokeDash::new(vec![*d as f32, *d as f32], 0.0);
                        st.line_cap = LineCap::Butt;
                    }
                    pm.stroke_path(&path, &paint_of(*c), &st, tr, None);
                }
                Item::Circle {
                    center,
                    radius,
                    fill,
                    stroke,
                    stroke_width,
                    ..
                } => {
                    let Some(path) = PathBuilder::from_circle(
                        center[0] as f32,
                        center[1] as f32,
                        *radius as f32,
                    ) else {
                        continue;
                    };
                    if let Some(f) = fill {
                        pm.fill_path(&path, &paint_of(*f), FillRule::Winding, tr, None);
                    }
                    if let Some(s) = stroke {
                        pm.stroke_path(&path, &paint_of(*s), &stroke_of(*stroke_width), tr, None);
                    }
                }
                Item::Text { .. } => texts.push(item),
            }
        }
        let mut img = Image::from_pixmap(pm);
        for t in texts {
            if let Item::Text {
                at,
                text,
                size,
                color: c,
                anchor,
                bold,
            } = t
            {
                let fs = (size * scale) as f32;
                let tw = font::text_width(text, fs);
                let x = (at[0] * scale).round() as i64
                    - match anchor {
                        Anchor::Start => 0,
                        Anchor::Middle => tw / 2,
                        Anchor::End => tw,
                    };
                let y = (at[1] * scale).round() as i64 - font::text_height(fs) / 2;
                font::draw_text(&mut img, x, y, fs, text, *c);
                if *bold {
                    // No bold face is embedded: a second pass one pixel to the right.
                    font::draw_text(&mut img, x + 1, y, fs, text, *c);
                }
            }
        }
        Ok(img)
    }
}

fn num(x: f64) -> String {
    let r = (x * 100.0).round() / 100.0;
    if r == r.trunc() {
        format!("{}", r as i64)
    } else {
        format!("{r}")
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

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

// ---------------------------------------------------------------------------------------------
// Layouts.

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

/// Draw a layout: triangles of every copy, then sides with labels, then the unit circle.
pub fn layout_figure(plot: &LayoutPlot) -> Result<Figure> {
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
    // Sides and their labels, pushed outwards from the centroid of the first copy.
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

/// `10⁻¹¹`-style label of a power of ten (superscript digits, U+2212 minus).
fn power_of_ten(k: i32) -> String {
    const SUP: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::from("10");
    if k < 0 {
        s.push('⁻');
    }
    for d in k.unsigned_abs().to_string().bytes() {
        s.push(SUP[(d - b'0') as usize]);
    }
    s
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

// ---------------------------------------------------------------------------------------------
// Axes, histograms, line plots.

/// "Nice" tick positions covering [lo, hi]: multiples of 1, 2 or 5 × 10^k, about `target` of
/// them.
pub fn nice_ticks(lo: f64, hi: f64, target: usize) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return vec![lo];
    }
    let raw = (hi - lo) / target.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let count = |step: f64| ((hi / step).floor() - (lo / step).ceil() + 1.0).max(0.0);
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .min_by(|a, b| {
            let da = (count(*a) - target as f64).abs();
            let db = (count(*b) - target as f64).abs();
            da.total_cmp(&db)
        })
        .unwrap_or(mag);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    // Round to the step's decimals so 3 × 0.2 prints as 0.6.
    let dec = 10f64.powi((-step.log10().floor()).max(0.0) as i32);
    (first..=last)
        .map(|k| (k as f64 * step * dec).round() / dec)
        .collect()
}

/// Plot area inside a figure, with data ranges and (optionally) logarithmic y.
struct Axes {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    xr: (f64, f64),
    yr: (f64, f64),
    log_y: bool,
}

impl Axes {
    fn px(&self, x: f64) -> f64 {
        self.x0 + (x - self.xr.0) / (self.xr.1 - self.xr.0) * (self.x1 - self.x0)
    }
    fn py(&self, y: f64) -> f64 {
        let (y, lo, hi) = if self.log_y {
            (y.log10(), self.yr.0.log10(), self.yr.1.log10())
        } else {
            (y, self.yr.0, self.yr.1)
        };
        self.y1 - (y - lo) / (hi - lo) * (self.y1 - self.y0)
    }

    fn draw(&self, fig: &mut Figure, title: &str, xlabel: &str, ylabel: &str) {
        let ink = [0.15; 3];
        let grid = [0.9; 3];
        let xt = nice_ticks(self.xr.0, self.xr.1, 6);
        let yt: Vec<f64> = if self.log_y {
            let (a, b) = (
                self.yr.0.log10().ceil() as i32,
                self.yr.1.log10().floor() as i32,
            );
            let every = ((b - a) / 8 + 1).max(1);
            (a..=b)
                .filter(|k| (k - a) % every == 0)
                .map(|k| 10f64.powi(k))
                .collect()
        } else {
            nice_ticks(self.yr.0, self.yr.1, 5)
        };
        for &y in &yt {
            let p = self.py(y);
            fig.line(vec![[self.x0, p], [self.x1, p]], grid, 1.0, "grid");
            let label = if self.log_y {
                power_of_ten(y.log10().round() as i32)
            } else {
                font::format_number(y)
            };
            fig.text([self.x0 - 6.0, p], label, 12.0, ink, Anchor::End);
        }
        for &x in &xt {
            let p = self.px(x);
            fig.line(vec![[p, self.y1], [p, self.y1 + 5.0]], ink, 1.0, "tick");
            fig.text(
                [p, self.y1 + 14.0],
                font::format_number(x),
                12.0,
                ink,
                Anchor::Middle,
            );
        }
        fig.items.push(Item::Polyline {
            points: vec![[self.x0, self.y0], [self.x0, self.y1], [self.x1, self.y1]],
            color: ink,
            width: 1.2,
            dash: None,
            closed: false,
            class: "axes",
        });
        if !title.is_empty() {
            let fw = (fig.width - 12.0) as f32;
            fig.text(
                [0.5 * fig.width, 18.0],
                title,
                font::fit_size(title, 15.0, fw, 8.0) as f64,
                [0.05; 3],
                Anchor::Middle,
            );
        }
        if !xlabel.is_empty() {
            fig.text(
                [0.5 * (self.x0 + self.x1), self.y1 + 34.0],
                xlabel,
                13.0,
                ink,
                Anchor::Middle,
            );
        }
        if !ylabel.is_empty() {
            fig.text([self.x0, self.y0 - 12.0], ylabel, 13.0, ink, Anchor::Middle);
        }
    }
}

/// A histogram.
#[derive(Debug, Clone)]
pub struct Histogram {
    pub bins: usize,
    /// Range of the bins; `None` = min..max of the finite values.
    pub range: Option<(f64, f64)>,
    pub title: String,
    pub x_label: String,
    pub color: Rgb,
    /// Vertical reference line (e.g. at 1 for angle ratios).
    pub reference: Option<f64>,
    pub width: f64,
    pub height: f64,
}

impl Default for Histogram {
    fn default() -> Self {
        Histogram {
            bins: 50,
            range: None,
            title: String::new(),
            x_label: String::new(),
            color: [0.23, 0.42, 0.70],
            reference: None,
            width: 640.0,
            height: 400.0,
        }
    }
}

/// Counts per bin of the finite values in [lo, hi] (values outside are not counted); the last
/// bin includes hi.
pub fn bin_counts(values: &[f64], bins: usize, lo: f64, hi: f64) -> Vec<usize> {
    let mut c = vec![0usize; bins.max(1)];
    let n = c.len();
    for &v in values {
        if !v.is_finite() || v < lo || v > hi {
            continue;
        }
        let k = if hi > lo {
            (((v - lo) / (hi - lo)) * n as f64) as usize
        } else {
            0
        };
        c[k.min(n - 1)] += 1;
    }
    c
}

/// Draw a histogram of `values` (non-finite values are skipped; the count is in the title).
pub fn histogram_figure(values: &[f64], h: &Histogram) -> Result<Figure> {
    let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if finite.is_empty() {
        return input_err("the histogram has no finite value");
    }
    if h.bins == 0 || h.bins > 100_000 {
        return input_err(format!("{} bins: use between 1 and 100000", h.bins));
    }
    let (lo, hi) = match h.range {
        Some((a, b)) if a.is_finite() && b.is_finite() && b > a => (a, b),
        Some((a, b)) => return input_err(format!("the histogram range [{a}, {b}] is empty")),
        None => {
            let lo = finite.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if hi > lo {
                (lo, hi)
            } else {
                (lo - 0.5, hi + 0.5)
            }
        }
    };
    let counts = bin_counts(&finite, h.bins, lo, hi);
    let cmax = counts.iter().copied().max().unwrap_or(1).max(1);
    let mut fig = Figure::new(h.width, h.height);
    let ytop = nice_ticks(0.0, cmax as f64 * 1.05, 5)
        .last()
        .copied()
        .unwrap_or(1.0)
        .max(cmax as f64);
    let ax = Axes {
        x0: 64.0,
        x1: h.width - 20.0,
        y0: 40.0,
        y1: h.height - 50.0,
        xr: (lo, hi),
        yr: (0.0, ytop * 1.02),
        log_y: false,
    };
    let bw = (hi - lo) / counts.len() as f64;
    let bars: Vec<Vec<[f64; 2]>> = counts
        .iter()
        .enumerate()
        .filter(|(_, &c)| c > 0)
        .map(|(k, &c)| {
            let (a, b) = (ax.px(lo + k as f64 * bw), ax.px(lo + (k + 1) as f64 * bw));
            let (y, y0) = (ax.py(c as f64), ax.py(0.0));
            vec![[a, y0], [b, y0], [b, y], [a, y]]
        })
        .collect();
    let outside = finite.len() - counts.iter().sum::<usize>();
    let mut title = h.title.clone();
    if outside > 0 || finite.len() < values.len() {
        let _ = write!(title, " ({} values", finite.len());
        if outside > 0 {
            let _ = write!(title, ", {outside} outside the range");
        }
        title.push(')');
    }
    ax.draw(&mut fig, &title, &h.x_label, "count");
    fig.items.push(Item::Polygons {
        polygons: bars,
        fill: Some(h.color),
        stroke: Some(color::tint(h.color, -0.0).map(|c| c * 0.7)),
        stroke_width: 0.5,
        class: "bars",
    });
    if let Some(r) = h.reference.filter(|r| *r >= lo && *r <= hi) {
        fig.items.push(Item::Polyline {
            points: vec![[ax.px(r), ax.y0], [ax.px(r), ax.y1]],
            color: [0.8, 0.1, 0.1],
            width: 1.4,
            dash: Some(5.0),
            closed: false,
            class: "reference",
        });
    }
    Ok(fig)
}

/// One curve of a line plot.
#[derive(Debug, Clone)]
pub struct Series {
    pub name: String,
    pub points: Vec<[f64; 2]>,
    pub color: Rgb,
}

/// A line plot (e.g. curvature residual against Newton iteration, log scale).
#[derive(Debug, Clone)]
pub struct LinePlot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub log_y: bool,
    pub width: f64,
    pub height: f64,
}

impl Default for LinePlot {
    fn default() -> Self {
        LinePlot {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            log_y: false,
            width: 640.0,
            height: 400.0,
        }
    }
}

/// Draw line plots; with `log_y`, points with y ≤ 0 are left out.
pub fn line_plot_figure(series: &[Series], lp: &LinePlot) -> Result<Figure> {
    let usable = |p: &[f64; 2]| p[0].is_finite() && p[1].is_finite() && (!lp.log_y || p[1] > 0.0);
    let (mut xr, mut yr) = (
        (f64::INFINITY, f64::NEG_INFINITY),
        (f64::INFINITY, f64::NEG_INFINITY),
    );
    for s in series {
        for p in s.points.iter().filter(|p| usable(p)) {
            xr = (xr.0.min(p[0]), xr.1.max(p[0]));
            yr = (yr.0.min(p[1]), yr.1.max(p[1]));
        }
    }
    if !xr.0.is_finite() {
        return input_err("the line plot has no point to draw");
    }
    if xr.1 <= xr.0 {
        xr = (xr.0 - 0.5, xr.1 + 0.5);
    }
    if lp.log_y {
        yr = (
            10f64.powf(yr.0.log10().floor()),
            10f64.powf(yr.1.log10().ceil().max(yr.0.log10().floor() + 1.0)),
        );
    } else {
        if yr.1 <= yr.0 {
            yr = (yr.0 - 0.5, yr.1 + 0.5);
        }
        let t = nice_ticks(yr.0, yr.1, 5);
        let step = if t.len() > 1 { t[1] - t[0] } else { 0.0 };
        yr = (
            yr.0.min(t[0]),
            yr.1.max(t.last().copied().unwrap_or(yr.1) + 0.0 * step),
        );
    }
    let mut fig = Figure::new(lp.width, lp.height);
    let ax = Axes {
        x0: 64.0,
        x1: lp.width - 20.0,
        y0: 40.0,
        y1: lp.height - 50.0,
        xr,
        yr,
        log_y: lp.log_y,
    };
    ax.draw(&mut fig, &lp.title, &lp.x_label, &lp.y_label);
    for s in series {
        let pts: Vec<[f64; 2]> = s
            .points
            .iter()
            .filter(|p| usable(p))
            .map(|p| [ax.px(p[0]), ax.py(p[1])])
            .collect();
        if pts.is_empty() {
            continue;
        }
        fig.line(pts.clone(), s.color, 2.0, "series");
        if pts.len() <= 60 {
            for p in &pts {
                fig.items.push(Item::Circle {
                    center: *p,
                    radius: 2.8,
                    fill: Some(s.color),
                    stroke: Some([1.0; 3]),
                    stroke_width: 0.8,
                    id: None,
                });
            }
        }
    }
    // Legend (top right) when more than one series or a named one.
    let named: Vec<&Series> = series.iter().filter(|s| !s.name.is_empty()).collect();
    for (k, s) in named.iter().enumerate() {
        let y = ax.y0 + 12.0 + 18.0 * k as f64;
        let longest = named
            .iter()
            .map(|s| s.name.chars().count())
            .max()
            .unwrap_or(0) as f64;
        let x = ax.x1 - 36.0 - 7.5 * longest;
        fig.line(vec![[x, y], [x + 22.0, y]], s.color, 2.5, "legend");
        fig.text(
            [x + 28.0, y],
            s.name.clone(),
            12.0,
            [0.15; 3],
            Anchor::Start,
        );
    }
    Ok(fig)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;

    fn parse(svg: &str) -> roxmltree::Document<'_> {
        roxmltree::Document::parse(svg).expect("well-formed SVG")
    }

    #[test]
    fn nice_ticks_are_round_and_cover() {
        assert_eq!(nice_ticks(0.0, 1.0, 5), vec![0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
        let t = nice_ticks(-3.7, 12.2, 6);
        assert!(
            t.iter()
                .all(|x| (x / 2.0 - (x / 2.0).round()).abs() < 1e-12),
            "{t:?}"
        );
        assert!(t[0] >= -3.7 && *t.last().unwrap() <= 12.2 && t.len() >= 5);
    }

    #[test]
    fn disk_layout_svg_is_well_formed_and_has_the_unit_circle() {
        // A disk of radius 0.9 triangulated as a fan.
        let n = 24;
        let mut uv = vec![[0.0, 0.0]];
        let mut tri = Vec::new();
        for k in 0..n {
            let a = k as f64 * std::f64::consts::TAU / n as f64;
            uv.push([0.9 * a.cos(), 0.9 * a.sin()]);
            tri.push([0, 1 + k as u32, 1 + ((k + 1) % n) as u32]);
        }
        let mut plot = LayoutPlot::new(LayoutCopy::new(&uv, &tri));
        plot.disk = true;
        plot.title = "Poincaré disk <test>".into();
        for (i, (name, g)) in canonical_side_names(2).into_iter().enumerate() {
            let pts = (0..=3).map(|j| uv[1 + (3 * i + j) % n]).collect();
            plot.sides.push(Side {
                points: pts,
                color: color::categorical(g),
                label: name,
            });
        }
        let fig = layout_figure(&plot).unwrap();
        let svg = fig.to_svg();
        let doc = parse(&svg);
        let circle = doc
            .descendants()
            .find(|e| e.attribute("id") == Some("unit-circle"))
            .expect("unit circle");
        // Its radius is the image of 1, and its centre the image of 0: the fan's rim points
        // (radius 0.9) must lie at 0.9 of that radius from the centre.
        let r: f64 = circle.attribute("r").unwrap().parse().unwrap();
        let cx: f64 = circle.attribute("cx").unwrap().parse().unwrap();
        let cy: f64 = circle.attribute("cy").unwrap().parse().unwrap();
        let path = doc
            .descendants()
            .find(|e| e.attribute("class") == Some("faces"))
            .unwrap();
        let d = path.attribute("d").unwrap();
        let first = d[1..].split('L').nth(1).unwrap(); // second vertex of the first triangle
        let xy: Vec<f64> = first
            .split(' ')
            .map(|s| s.trim_end_matches('Z').parse().unwrap())
            .collect();
        let dist = ((xy[0] - cx).powi(2) + (xy[1] - cy).powi(2)).sqrt();
        assert!((dist / r - 0.9).abs() < 0.01, "rim at {dist} of radius {r}");
        assert_eq!(d.matches('M').count(), n);
        let labels: Vec<&str> = doc
            .descendants()
            .filter(|e| e.has_tag_name("text"))
            .filter_map(|e| e.text())
            .collect();
        assert!(
            labels.contains(&"a1") && labels.contains(&"b2^-1"),
            "{labels:?}"
        );
        assert!(labels.iter().any(|l| l.contains("<test>")));
        // The PNG version draws the circle: pixels on it are dark.
        let img = fig.to_image(1.0).unwrap();
        let (x, y) = ((cx + r) as u32, cy as u32);
        let dark =
            (x.saturating_sub(1)..=x + 1).any(|xx| img.pixel(xx.min(img.width - 1), y)[0] < 100);
        assert!(dark, "no unit circle at ({x}, {y}) in the PNG");
    }

    #[test]
    fn tiling_with_face_colors_groups_by_colour() {
        let g = shapes::grid(4, 1.0);
        let uv: Vec<[f64; 2]> = g.positions.iter().map(|p| [p[0], p[1]]).collect();
        let uv2: Vec<[f64; 2]> = uv.iter().map(|p| [p[0] + 1.0, p[1]]).collect();
        let vals: Vec<f64> = (0..g.triangles.len()).map(|f| (f % 2) as f64).collect();
        let mut first = LayoutCopy::new(&uv, &g.triangles);
        first.face_colors = Some(face_colors(&vals, Colormap::Viridis, (0.0, 1.0)));
        let mut plot = LayoutPlot::new(first);
        plot.copies.push(LayoutCopy::tinted(&uv2, &g.triangles, 1));
        let fig = layout_figure(&plot).unwrap();
        assert_eq!(fig.count_polygons(), 3 * g.triangles.len()); // 2 colour groups + edges + copy
        let svg = fig.to_svg();
        let doc = parse(&svg);
        let fills: std::collections::BTreeSet<&str> = doc
            .descendants()
            .filter(|e| e.attribute("class") == Some("faces"))
            .filter_map(|e| e.attribute("fill"))
            .collect();
        assert_eq!(fills.len(), 3, "{fills:?}");
        // Landscape picture for a 2:1 layout.
        assert!(fig.width > 1.5 * fig.height);
    }

    #[test]
    fn histogram_counts_and_svg() {
        let v: Vec<f64> = (0..1000).map(|i| 0.9 + 0.2 * (i as f64 / 999.0)).collect();
        let c = bin_counts(&v, 10, 0.9, 1.1);
        assert_eq!(c.iter().sum::<usize>(), 1000);
        assert!(c.iter().all(|&k| (99..=101).contains(&k)), "{c:?}");
        let mut vals = v.clone();
        vals.push(f64::NAN);
        let fig = histogram_figure(
            &vals,
            &Histogram {
                bins: 10,
                range: Some((0.9, 1.1)),
                reference: Some(1.0),
                title: "angle ratio".into(),
                ..Default::default()
            },
        )
        .unwrap();
        let svg = fig.to_svg();
        let doc = parse(&svg);
        let bars = doc
            .descendants()
            .find(|e| e.attribute("class") == Some("bars"))
            .unwrap();
        assert_eq!(bars.attribute("d").unwrap().matches('M').count(), 10);
        assert!(doc
            .descendants()
            .any(|e| e.attribute("class") == Some("reference")));
        assert!(histogram_figure(&[f64::NAN], &Histogram::default()).is_err());
        assert!(fig.to_png(1.0).unwrap().starts_with(b"\x89PNG"));
    }

    #[test]
    fn log_line_plot_places_decades_evenly() {
        let pts: Vec<[f64; 2]> = (0..8).map(|k| [k as f64, 10f64.powi(-2 * k)]).collect();
        let fig = line_plot_figure(
            &[Series {
                name: "residual".into(),
                points: pts,
                color: color::categorical(0),
            }],
            &LinePlot {
                log_y: true,
                title: "Newton".into(),
                ..Default::default()
            },
        )
        .unwrap();
        // The markers of a geometric sequence are equally spaced vertically.
        let ys: Vec<f64> = fig
            .items
            .iter()
            .filter_map(|i| match i {
                Item::Circle { center, .. } => Some(center[1]),
                _ => None,
            })
            .collect();
        assert_eq!(ys.len(), 8);
        let d0 = ys[1] - ys[0];
        assert!(d0 > 0.0);
        for k in 1..7 {
            assert!(((ys[k + 1] - ys[k]) - d0).abs() < 1e-9);
        }
        parse(&fig.to_svg());
        assert!(line_plot_figure(&[], &LinePlot::default()).is_err());
    }
}
