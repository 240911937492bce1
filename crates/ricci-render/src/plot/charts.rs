//! Charts on axes: histograms (the angle-ratio histogram of paper 001 Fig. 7d) and line plots
//! (residual vs. iteration, log scale), with "nice" ticks.

use super::{Anchor, Figure, Item};
use crate::color::{self, Rgb};
use crate::font;
use crate::{input_err, Result};
use std::fmt::Write;

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
