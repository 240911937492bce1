//! SVG pictures of an atlas of flat charts (paper 000 §4, the affine atlas): one picture per
//! chart with its faces filled by role (the chart's home faces in its colour, faces it only
//! overlaps light grey, faces around a singular point red), and an overview: the central
//! chart with the home faces of every other chart mapped into it.
//!
//! Plain data in, SVG text out: the caller gives each face's three corners in chart
//! coordinates (e.g. `ricci::atlas::AffineAtlas::chart_faces` and `overview`).

use std::fmt::Write;

/// Colours of charts (chart `c` gets `PALETTE[c % 10]`; the same as the sides of a layout).
const PALETTE: [&str; 10] = [
    "#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
    "#bcbd22", "#7f7f7f",
];

/// The three corners of a face in chart coordinates.
pub type Corners = [[f64; 2]; 3];

/// Colour of chart `c`.
pub fn chart_colour(c: usize) -> &'static str {
    PALETTE[c % PALETTE.len()]
}

/// What a face is to the chart it is drawn in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaceRole {
    /// The chart is the face's home chart.
    Home,
    /// The face belongs to another chart's home faces.
    Other,
    /// The face has no home chart (it touches a singular point).
    Singular,
}

/// Centre and extent (longer side) of the bounding box of the corners.
fn bounds(coords: &[Corners]) -> ([f64; 2], f64) {
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

/// Maps chart coordinates to the square canvas (y up).
struct Canvas {
    centre: [f64; 2],
    scale: f64,
    size: f64,
}

impl Canvas {
    /// A canvas of `size` pixels framing `coords` with a 3% margin.
    fn framing(coords: &[Corners], size: f64) -> Canvas {
        let (centre, ext) = bounds(coords);
        Canvas {
            centre,
            scale: 0.94 * size / ext,
            size,
        }
    }

    /// One `<path>` per triangle, filled with its colour.
    fn triangles(&self, out: &mut String, tris: &[Corners], fills: &[&str], stroke: bool) {
        let xy = |p: [f64; 2]| {
            (
                0.5 * self.size + (p[0] - self.centre[0]) * self.scale,
                0.5 * self.size - (p[1] - self.centre[1]) * self.scale,
            )
        };
        for (c, fill) in tris.iter().zip(fills) {
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
}

fn header(size: f64) -> String {
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{size}\" height=\"{size}\" viewBox=\"0 0 {size} {size}\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    )
}

/// Chart `chart`: its faces (`coords`, with a role each) in its own coordinates, home faces
/// in the chart's colour, other faces light grey, singular faces red; edges drawn up to
/// 20 000 faces.
pub fn chart_svg(chart: usize, coords: &[Corners], roles: &[FaceRole], size: f64) -> String {
    let canvas = Canvas::framing(coords, size);
    let colour = chart_colour(chart);
    let fills: Vec<&str> = roles
        .iter()
        .map(|r| match r {
            FaceRole::Home => colour,
            FaceRole::Singular => "#ff4040",
            FaceRole::Other => "#dddddd",
        })
        .collect();
    let mut out = header(size);
    canvas.triangles(&mut out, coords, &fills, roles.len() <= 20_000);
    let _ = writeln!(
        out,
        "<text x=\"8\" y=\"20\" font-family=\"sans-serif\" font-size=\"14\">chart {chart}: {} faces</text>\n</svg>",
        roles.len()
    );
    out
}

/// The central chart (`central`, roles relative to it) with every other chart's home faces
/// mapped into it (`others`: chart number and its faces in the central chart's coordinates),
/// coloured by chart. `n_charts` is shown in the caption.
pub fn overview_svg(
    central: &[Corners],
    central_roles: &[FaceRole],
    others: &[(usize, Vec<Corners>)],
    n_charts: usize,
    size: f64,
) -> String {
    let canvas = Canvas::framing(central, size);
    let mut out = header(size);
    let fills: Vec<&str> = central_roles
        .iter()
        .map(|r| match r {
            FaceRole::Home => "#c8d8f0",
            FaceRole::Singular => "#ff4040",
            FaceRole::Other => "#f0f0f0",
        })
        .collect();
    canvas.triangles(&mut out, central, &fills, false);
    for (c, tris) in others {
        let fills = vec![chart_colour(*c); tris.len()];
        canvas.triangles(&mut out, tris, &fills, false);
    }
    let _ = writeln!(
        out,
        "<text x=\"8\" y=\"18\" font-family=\"sans-serif\" font-size=\"13\"><tspan x=\"8\">{n_charts} charts: central chart (blue); each cut or local chart's home faces (colours)</tspan><tspan x=\"8\" dy=\"16\">placed by its transition on one face — across the cut they appear displaced by the deck motion</tspan></text>\n</svg>",
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chart_picture_has_one_path_per_face_coloured_by_role() {
        let coords: Vec<Corners> = vec![
            [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            [[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            [[1.0, 1.0], [2.0, 1.0], [1.0, 2.0]],
        ];
        let roles = [FaceRole::Home, FaceRole::Other, FaceRole::Singular];
        let svg = chart_svg(3, &coords, &roles, 200.0);
        assert_eq!(svg.matches("<path").count(), 3);
        assert!(svg.contains(&format!("fill=\"{}\"", PALETTE[3])));
        assert!(svg.contains("fill=\"#dddddd\"") && svg.contains("fill=\"#ff4040\""));
        // The bounding box [0, 2]² spans 94% of the canvas around its centre: (0, 0) maps to
        // 100 − 94 = 6 in x and 100 + 94 = 194 in y (y up).
        assert!(svg.contains("M6.00,194.00"), "{svg}");
        let o = overview_svg(&coords[..2], &roles[..2], &[(1, vec![coords[2]])], 2, 200.0);
        assert_eq!(o.matches("<path").count(), 3);
        assert!(o.contains(&format!("fill=\"{}\"", PALETTE[1])) && o.contains("2 charts"));
    }
}
