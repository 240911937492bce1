//! Text in PNG pictures (titles, legends, axis numbers, generator names): DejaVu Sans, an
//! open-licensed font embedded in the crate (`fonts/DejaVuSans.ttf`, licence in
//! `fonts/LICENSE-DejaVu.txt`), rasterized with anti-aliasing by `ab_glyph`.
//!
//! The font covers the Unicode the pictures use (Greek, math operators such as − ≤ ≈ Σ π,
//! sub- and superscripts ² ⁻¹). There is no shaping engine: characters are placed left to
//! right with the font's kerning, and combining marks (U+0300–U+036F, e.g. the macron of
//! "K̄" = `K\u{304}`) are centred over the character before them and raised above it.
//! Sizes are in pixels (the font's em), the same number as an SVG `font-size`.

use crate::{color::Rgb, image::Image};
use ab_glyph::{point, Font, FontRef, Glyph, GlyphId, PxScale, ScaleFont};
use std::sync::OnceLock;

/// The embedded font file.
static FONT_BYTES: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");

/// CSS `font-family` for SVG text: the embedded font first, so that a browser that has it
/// draws the same glyphs as the PNG, then any sans-serif.
pub const SVG_FONT_FAMILY: &str = "DejaVu Sans, Verdana, sans-serif";

fn font() -> Option<&'static FontRef<'static>> {
    static FONT: OnceLock<Option<FontRef<'static>>> = OnceLock::new();
    FONT.get_or_init(|| FontRef::try_from_slice(FONT_BYTES).ok())
        .as_ref()
}

fn is_combining(c: char) -> bool {
    ('\u{0300}'..='\u{036F}').contains(&c) || ('\u{20D0}'..='\u{20FF}').contains(&c)
}

/// Glyphs of one line of text with their positions (origin at the top-left of the line box)
/// and the line's advance width.
fn lay_out(text: &str, px: f32) -> (Vec<Glyph>, f32) {
    let Some(f) = font() else {
        return (Vec::new(), 0.0);
    };
    let scale = PxScale::from(px.max(1.0));
    let sf = f.as_scaled(scale);
    let ascent = sf.ascent();
    let mut glyphs = Vec::with_capacity(text.len());
    let mut x = 0.0f32;
    let mut prev: Option<GlyphId> = None;
    let mut base: Option<Glyph> = None;
    for c in text.chars() {
        let id = f.glyph_id(c);
        if is_combining(c) {
            // Centre the mark over the base glyph and keep a small gap above it.
            if let Some(b) = &base {
                let mark = id.with_scale_and_position(scale, point(0.0, ascent));
                if let (Some(bo), Some(mo)) = (f.outline_glyph(b.clone()), f.outline_glyph(mark)) {
                    let (bb, mb) = (bo.px_bounds(), mo.px_bounds());
                    let dx = 0.5 * (bb.min.x + bb.max.x) - 0.5 * (mb.min.x + mb.max.x);
                    let dy = (bb.min.y - 0.08 * px - mb.max.y).min(0.0);
                    glyphs.push(id.with_scale_and_position(scale, point(dx, ascent + dy)));
                }
            }
            continue;
        }
        if let Some(p) = prev {
            x += sf.kern(p, id);
        }
        let g = id.with_scale_and_position(scale, point(x, ascent));
        glyphs.push(g.clone());
        base = Some(g);
        x += sf.h_advance(id);
        prev = Some(id);
    }
    (glyphs, x)
}

/// Advance width in pixels of `text` at size `px`.
pub fn text_width_px(text: &str, px: f32) -> f32 {
    lay_out(text, px).1
}

/// Width in pixels of `text` at size `px`, rounded up.
pub fn text_width(text: &str, px: f32) -> i64 {
    text_width_px(text, px).ceil() as i64
}

/// Height in pixels of a line of text at size `px` (ascent + descent).
pub fn text_height(px: f32) -> i64 {
    match font() {
        Some(f) => {
            let sf = f.as_scaled(PxScale::from(px.max(1.0)));
            (sf.ascent() - sf.descent()).ceil() as i64
        }
        None => px.ceil() as i64,
    }
}

/// The largest size ≤ `px` at which `text` fits in `width` pixels (at least `min_px`).
pub fn fit_size(text: &str, px: f32, width: f32, min_px: f32) -> f32 {
    let w = text_width_px(text, px);
    if w <= width || w <= 0.0 {
        px
    } else {
        (px * width / w).max(min_px)
    }
}

/// Draw `text` with the top-left corner of its line box at (x, y), anti-aliased.
pub fn draw_text(img: &mut Image, x: i64, y: i64, px: f32, text: &str, color: Rgb) {
    draw_text_alpha(img, x, y, px, text, color, 1.0);
}

fn draw_text_alpha(img: &mut Image, x: i64, y: i64, px: f32, text: &str, color: Rgb, a: f32) {
    let Some(f) = font() else { return };
    for g in lay_out(text, px).0 {
        if let Some(o) = f.outline_glyph(g) {
            let b = o.px_bounds();
            let (ox, oy) = (x + b.min.x as i64, y + b.min.y as i64);
            o.draw(|gx, gy, cov| {
                img.blend(ox + gx as i64, oy + gy as i64, color, cov * a);
            });
        }
    }
}

/// Draw `text` over a soft halo of `halo` colour so it stays readable on any background.
pub fn draw_text_halo(img: &mut Image, x: i64, y: i64, px: f32, text: &str, color: Rgb, halo: Rgb) {
    let r = (px / 12.0).round().max(1.0) as i64;
    for (dx, dy) in [
        (-r, 0),
        (r, 0),
        (0, -r),
        (0, r),
        (-r, -r),
        (r, r),
        (-r, r),
        (r, -r),
    ] {
        draw_text_alpha(img, x + dx, y + dy, px, text, halo, 0.8);
    }
    draw_text(img, x, y, px, text, color);
}

/// A short human-readable number: 3 significant digits, plain notation for moderate
/// magnitudes and scientific notation otherwise ("0.0123", "-3.14", "1.2e-5").
pub fn format_number(x: f64) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    if x == 0.0 {
        return "0".into();
    }
    let a = x.abs();
    if (1e-3..1e5).contains(&a) {
        let digits = (2 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{x:.digits$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        let s = format!("{x:.2e}");
        // "1.20e-5" -> "1.2e-5"
        match s.split_once('e') {
            Some((m, e)) => {
                let m = if m.contains('.') {
                    m.trim_end_matches('0').trim_end_matches('.')
                } else {
                    m
                };
                format!("{m}e{e}")
            }
            None => s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_short() {
        assert_eq!(format_number(0.0), "0");
        assert_eq!(format_number(4.56789), "4.57");
        assert_eq!(format_number(-0.012345), "-0.0123");
        assert_eq!(format_number(1234.7), "1235");
        assert_eq!(format_number(2.0), "2");
        assert_eq!(format_number(1.2e-5), "1.2e-5");
        assert_eq!(format_number(6.02e23), "6.02e23");
    }

    /// Every character the pictures use has a glyph of its own in the embedded font (no
    /// `.notdef` box): the test that fails with a bitmap ASCII font.
    #[test]
    fn math_symbols_have_glyphs() {
        let f = font().expect("the embedded font parses");
        for c in "|K − K̄| ≤ ≥ ≈ π Σ ∞ θ κ λ χ ² ³ ⁻¹ Δ° × · → ∈ H² E² S² 0123456789".chars()
        {
            if c == ' ' {
                continue;
            }
            assert_ne!(
                f.glyph_id(c).0,
                0,
                "no glyph for {c:?} (U+{:04X})",
                c as u32
            );
        }
    }

    /// Anti-aliased: a rendered line has intermediate grey levels, not only ink and paper;
    /// and the combining macron of K̄ lands above the K (ink in rows above the K's top).
    #[test]
    fn text_is_anti_aliased_and_marks_sit_above() {
        let mut img = Image::new(200, 40, [1.0; 3], 255);
        draw_text(&mut img, 4, 4, 20.0, "|K − K̄| ≤ π", [0.0; 3]);
        let mut levels = std::collections::BTreeSet::new();
        for y in 0..40 {
            for x in 0..200 {
                levels.insert(img.pixel(x, y)[0]);
            }
        }
        assert!(levels.len() > 20, "only {} grey levels", levels.len());
        // K alone vs K̄: the macron adds ink above the K's first inked row.
        let ink_top = |t: &str| {
            let mut im = Image::new(60, 50, [1.0; 3], 255);
            draw_text(&mut im, 10, 12, 24.0, t, [0.0; 3]);
            (0..50u32)
                .find(|&y| (0..60u32).any(|x| im.pixel(x, y)[0] < 128))
                .unwrap_or(50)
        };
        assert!(
            ink_top("K\u{304}") + 2 < ink_top("K"),
            "macron not above the K: {} vs {}",
            ink_top("K\u{304}"),
            ink_top("K")
        );
        // Widths grow with the text and the size.
        assert!(text_width("ab", 12.0) < text_width("abc", 12.0));
        assert!(text_width("abc", 12.0) < text_width("abc", 24.0));
        let s = fit_size("a long title that is too wide", 20.0, 100.0, 6.0);
        assert!(s < 20.0 && text_width_px("a long title that is too wide", s) <= 100.5);
    }
}
