//! The legend of a scalar paint: a colour bar with min/max labels in a strip on the right.

use super::*;

/// The colour bar strip: geometry in output pixels.
pub(super) struct Legend {
    pub(super) strip_width: u32,
    pub(super) scale: u32,
    pub(super) range: (f64, f64),
    pub(super) labels: Vec<(f64, String)>,
}

impl Legend {
    pub(super) fn new(s: &Scalar, range: (f64, f64), width: u32, height: u32) -> Legend {
        let scale = (height / 400).clamp(1, 4);
        let mut labels = vec![(range.1, font::format_number(range.1))];
        if s.colormap.is_diverging() && range.0 < 0.0 && range.1 > 0.0 {
            labels.push((0.0, "0".to_string()));
        } else if range.1 > range.0 {
            let m = 0.5 * (range.0 + range.1);
            labels.push((m, font::format_number(m)));
        }
        if range.1 > range.0 {
            labels.push((range.0, font::format_number(range.0)));
        }
        let px = Legend::px(scale);
        let label_w = labels
            .iter()
            .map(|l| font::text_width(&l.1, px))
            .max()
            .unwrap_or(0);
        let bar = 14 * scale as i64;
        let title_w = font::text_width(&s.label, px);
        let want = (bar + 6 * scale as i64 + label_w).max(title_w) + 12 * scale as i64;
        let strip_width = (want as u32).min(width / 2);
        Legend {
            strip_width,
            scale,
            range,
            labels,
        }
    }

    /// Text size in pixels at a legend scale.
    pub(super) fn px(scale: u32) -> f32 {
        13.0 * scale as f32
    }

    pub(super) fn draw(&self, img: &mut Image, s: &Scalar, bg: Background) {
        let sc = self.scale as i64;
        let (w, h) = (img.width as i64, img.height as i64);
        let x0 = w - self.strip_width as i64 + 6 * sc;
        let bar_w = 14 * sc;
        let top = (h as f64 * 0.2) as i64;
        let bot = (h as f64 * 0.8) as i64;
        let text = match bg {
            Background::Color(c) if color::lightness(c) < 50.0 => [0.95, 0.95, 0.95],
            _ => [0.1, 0.1, 0.1],
        };
        let halo = if text[0] > 0.5 { [0.0; 3] } else { [1.0; 3] };
        let cmap = s.colormap;
        let constant = self.range.1 <= self.range.0;
        for y in top..=bot {
            // A constant field has one colour (the centre of the map) and one label.
            let t = if constant {
                0.5
            } else {
                (bot - y) as f64 / (bot - top).max(1) as f64
            };
            img.fill_rect(x0, y, bar_w, 1, cmap.eval(t), 1.0);
        }
        // Frame.
        let frame = [0.2, 0.2, 0.2];
        img.fill_rect(x0 - 1, top - 1, bar_w + 2, 1, frame, 1.0);
        img.fill_rect(x0 - 1, bot + 1, bar_w + 2, 1, frame, 1.0);
        img.fill_rect(x0 - 1, top - 1, 1, bot - top + 3, frame, 1.0);
        img.fill_rect(x0 + bar_w, top - 1, 1, bot - top + 3, frame, 1.0);
        let px = Legend::px(self.scale);
        let th = font::text_height(px);
        for (value, label) in &self.labels {
            let t = normalize(*value, self.range.0, self.range.1);
            let y = bot - ((bot - top) as f64 * t).round() as i64;
            img.fill_rect(x0 + bar_w, y, 4 * sc, 1.max(sc / 2), frame, 1.0);
            font::draw_text_halo(
                img,
                x0 + bar_w + 6 * sc,
                y - th / 2,
                px,
                &label.replace('-', "−"),
                text,
                halo,
            );
        }
        if !s.label.is_empty() {
            let tw = font::text_width(&s.label, px);
            let tx = (x0 - 4 * sc).min(w - tw - 2).max(0);
            font::draw_text_halo(img, tx, top - th - 8 * sc, px, &s.label, text, halo);
        }
    }
}

// f32 floor/ceil/round without a libm call (the default x86-64 target has no SSE4.1 `roundss`);
// exact for |x| < 2^31.
