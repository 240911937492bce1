//! A tiny bitmap font for labels in PNG pictures (legends, axis numbers, generator names):
//! the public-domain 8×8 glyphs of the `font8x8` crate, drawn at an integer scale.

use crate::{color::Rgb, image::Image};

/// Glyph rows (top to bottom; bit 0 is the leftmost pixel) for an ASCII character; other
/// characters draw as '?'.
fn glyph(c: char) -> [u8; 8] {
    let i = if c.is_ascii() {
        c as usize
    } else {
        '?' as usize
    };
    font8x8::legacy::BASIC_LEGACY[i]
}

/// Advance of one character at scale 1 (the glyphs have one column of spacing built in for
/// most characters; 7 px keeps digits readable and compact).
const ADVANCE: i64 = 7;

/// Width in pixels of `text` at `scale`.
pub fn text_width(text: &str, scale: u32) -> i64 {
    text.chars().count() as i64 * ADVANCE * scale as i64
}

/// Height in pixels of a line of text at `scale`.
pub fn text_height(scale: u32) -> i64 {
    8 * scale as i64
}

/// Draw `text` with its top-left corner at (x, y).
pub fn draw_text(img: &mut Image, x: i64, y: i64, scale: u32, text: &str, color: Rgb) {
    let s = scale as i64;
    for (k, c) in text.chars().enumerate() {
        let g = glyph(c);
        let ox = x + k as i64 * ADVANCE * s;
        for (row, bits) in g.iter().enumerate() {
            for col in 0..8 {
                if bits & (1 << col) != 0 {
                    img.fill_rect(ox + col * s, y + row as i64 * s, s, s, color, 1.0);
                }
            }
        }
    }
}

/// Draw `text` over a soft halo of `halo` colour so it stays readable on any background.
pub fn draw_text_halo(
    img: &mut Image,
    x: i64,
    y: i64,
    scale: u32,
    text: &str,
    color: Rgb,
    halo: Rgb,
) {
    let s = scale as i64;
    for (dx, dy) in [(-1, 0), (1, 0), (0, -1), (0, 1)] {
        draw_text(img, x + dx * s.max(1), y + dy * s.max(1), scale, text, halo);
    }
    draw_text(img, x, y, scale, text, color);
}

/// A short human-readable number: 3 significant digits, plain notation for moderate
/// magnitudes and scientific notation otherwise ("0.0123", "-3.14", "1.2e-05").
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
}
