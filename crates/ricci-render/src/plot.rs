//! 2D figures as SVG strings and PNG bytes: layouts in the plane and in the Poincaré disk
//! (triangles, boundary sides coloured by generator with labels a1, b1, …, the unit circle,
//! tilings with one colour per copy), histograms (the angle-ratio histogram of paper 001
//! Fig. 7d) and line plots (residual vs. iteration, log scale).
//!
//! A [`Figure`] is a display list in pixel coordinates (y down). Plot functions map data to
//! pixels and fill it; [`Figure::to_svg`] and [`Figure::to_png`] draw the same list (PNG through
//! tiny-skia with anti-aliasing; text with the built-in bitmap font).

mod charts;
mod figure;
mod layout;

pub use charts::{
    bin_counts, histogram_figure, line_plot_figure, nice_ticks, Histogram, LinePlot, Series,
};
pub use figure::{Anchor, Figure, Item};
pub use layout::{
    canonical_side_names, face_colors, layout_figure, ColorBar, LayoutCopy, LayoutPlot, Side,
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::{self, Colormap};
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
