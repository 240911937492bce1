//! The display list of a 2D figure ([`Figure`], [`Item`]) and its two renderings: an SVG
//! document and a tiny-skia raster (text with the built-in bitmap font).

use crate::color::{self, Rgb};
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

    pub(super) fn text(
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

    pub(super) fn line(
        &mut self,
        points: Vec<[f64; 2]>,
        color: Rgb,
        width: f64,
        class: &'static str,
    ) {
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
