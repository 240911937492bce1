//! SVG pictures of the charts of an [`AffineAtlas`]: one picture per chart with its faces
//! filled (home faces of the chart darker than faces it only overlaps), or all cut and local charts
//! over the central chart after mapping them into it by their transition on a common face.
//! Plain text output, no dependencies.

use super::{AffineAtlas, ChartId, FlatCharts};
use crate::layout::isometry::Isometry;
use crate::layout::svg::letter_colour;
use std::fmt::Write;

fn bounds(coords: &[[[f64; 2]; 3]]) -> ([f64; 2], f64) {
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for c in coords {
        for p in c {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    let ext = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-300);
    ([0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])], ext)
}

fn triangles(
    out: &mut String,
    tris: &[[[f64; 2]; 3]],
    fills: &[&str],
    centre: [f64; 2],
    scale: f64,
    size: f64,
    stroke: bool,
) {
    for (c, fill) in tris.iter().zip(fills) {
        let xy = |p: [f64; 2]| {
            (
                0.5 * size + (p[0] - centre[0]) * scale,
                0.5 * size - (p[1] - centre[1]) * scale,
            )
        };
        let (a, b, d) = (xy(c[0]), xy(c[1]), xy(c[2]));
        let s = if stroke {
            "stroke=\"#333\" stroke-width=\"0.2\""
        } else {
            "stroke=\"none\""
        };
        let _ = writeln!(
            out,
            "<path d=\"M{:.2},{:.2} L{:.2},{:.2} L{:.2},{:.2} Z\" fill=\"{fill}\" fill-opacity=\"0.8\" {s}/>",
            a.0, a.1, b.0, b.1, d.0, d.1
        );
    }
}

/// One chart: home faces in the chart's colour, other faces light grey, cone faces red.
pub fn chart_svg(atlas: &AffineAtlas, c: ChartId, size: f64) -> Option<String> {
    let (faces, coords) = atlas.chart_faces(c)?;
    let (centre, ext) = bounds(coords);
    let scale = 0.94 * size / ext;
    let colour = letter_colour(c as usize);
    let fills: Vec<&str> = faces
        .iter()
        .map(|&f| match atlas.home_chart(f) {
            Some(h) if h == c => colour,
            None => "#ff4040",
            _ => "#dddddd",
        })
        .collect();
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{size}\" height=\"{size}\" viewBox=\"0 0 {size} {size}\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    );
    triangles(
        &mut out,
        coords,
        &fills,
        centre,
        scale,
        size,
        faces.len() <= 20_000,
    );
    let _ = writeln!(
        out,
        "<text x=\"8\" y=\"20\" font-family=\"sans-serif\" font-size=\"14\">chart {c}: {} faces</text>\n</svg>",
        faces.len()
    );
    Some(out)
}

/// The central chart with every other (cut or local) chart's home faces mapped into it (by the transition on
/// the chart's first face that also lies in the central chart), coloured by chart.
pub fn overview_svg(atlas: &AffineAtlas, size: f64) -> String {
    let Some((faces0, coords0)) = atlas.chart_faces(0) else {
        return String::new();
    };
    let (centre, ext) = bounds(coords0);
    let scale = 0.94 * size / ext;
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{size}\" height=\"{size}\" viewBox=\"0 0 {size} {size}\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    );
    let fills: Vec<&str> = faces0
        .iter()
        .map(|&f| match atlas.home_chart(f) {
            Some(0) => "#c8d8f0",
            None => "#ff4040",
            _ => "#f0f0f0",
        })
        .collect();
    triangles(&mut out, coords0, &fills, centre, scale, size, false);
    for c in 1..atlas.n_charts() as ChartId {
        let Some((faces, coords)) = atlas.chart_faces(c) else {
            continue;
        };
        let Some((m, _)) = faces.iter().find_map(|&f| atlas.transition(c, 0, f)) else {
            continue;
        };
        let mut tris = Vec::new();
        for (k, &f) in faces.iter().enumerate() {
            if atlas.home_chart(f) == Some(c) {
                let t = coords[k].map(|p| {
                    let z = m.apply(num_complex::Complex64::new(p[0], p[1]));
                    [z.re, z.im]
                });
                tris.push(t);
            }
        }
        let fills = vec![letter_colour(c as usize); tris.len()];
        triangles(&mut out, &tris, &fills, centre, scale, size, false);
    }
    let _ = writeln!(
        out,
        "<text x=\"8\" y=\"18\" font-family=\"sans-serif\" font-size=\"13\"><tspan x=\"8\">{} charts: central chart (blue); each cut or local chart's home faces (colours)</tspan><tspan x=\"8\" dy=\"16\">placed by its transition on one face — across the cut they appear displaced by the deck motion</tspan></text>\n</svg>",
        atlas.n_charts()
    );
    out
}
