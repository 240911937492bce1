//! Simple SVG pictures of layouts: the fundamental domain with its sides coloured by
//! generator and labelled, and a tiling of the universal cover (with the unit circle for the
//! Poincaré disk). Plain text output, no dependencies; the `ricci-render` crate draws fancier
//! pictures.

use super::deck::Polygon;
use super::isometry::Complex;
use crate::mesh::Mesh;
use crate::metric::Geometry;
use std::fmt::Write;

const PALETTE: [&str; 10] = [
    "#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
    "#bcbd22", "#7f7f7f",
];

/// Colour of a letter (a side and its partner share it).
pub fn letter_colour(letter: usize) -> &'static str {
    PALETTE[letter % PALETTE.len()]
}

/// Maps model coordinates to the SVG canvas (y up).
struct View {
    cx: f64,
    cy: f64,
    scale: f64,
    size: f64,
}

impl View {
    fn fit(points: impl Iterator<Item = Complex>, geometry: Geometry, size: f64) -> View {
        if geometry == Geometry::Hyperbolic {
            return View {
                cx: 0.0,
                cy: 0.0,
                scale: 0.47 * size,
                size,
            };
        }
        let (mut lo, mut hi) = (
            Complex::new(f64::MAX, f64::MAX),
            Complex::new(f64::MIN, f64::MIN),
        );
        for p in points {
            lo = Complex::new(lo.re.min(p.re), lo.im.min(p.im));
            hi = Complex::new(hi.re.max(p.re), hi.im.max(p.im));
        }
        let ext = (hi.re - lo.re).max(hi.im - lo.im).max(1e-300);
        View {
            cx: 0.5 * (lo.re + hi.re),
            cy: 0.5 * (lo.im + hi.im),
            scale: 0.94 * size / ext,
            size,
        }
    }
    fn xy(&self, p: Complex) -> (f64, f64) {
        (
            0.5 * self.size + (p.re - self.cx) * self.scale,
            0.5 * self.size - (p.im - self.cy) * self.scale,
        )
    }
}

fn header(size: f64) -> String {
    format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{size}\" height=\"{size}\" viewBox=\"0 0 {size} {size}\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    )
}

fn polyline(
    out: &mut String,
    view: &View,
    pts: &[Complex],
    colour: &str,
    width: f64,
    opacity: f64,
) {
    let mut d = String::new();
    for (i, p) in pts.iter().enumerate() {
        let (x, y) = view.xy(*p);
        let _ = write!(d, "{}{:.2},{:.2}", if i == 0 { "M" } else { " L" }, x, y);
    }
    let _ = writeln!(
        out,
        "<path d=\"{d}\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"{width}\" stroke-opacity=\"{opacity}\" stroke-linejoin=\"round\"/>"
    );
}

fn unit_circle(out: &mut String, view: &View) {
    let (x, y) = view.xy(Complex::new(0.0, 0.0));
    let _ = writeln!(
        out,
        "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"{:.2}\" fill=\"none\" stroke=\"black\" stroke-width=\"1.5\"/>",
        view.scale
    );
}

/// The laid-out cut mesh (plane or Poincaré disk): mesh edges in grey when there are at most
/// `max_edges` of them, polygon sides coloured by letter and labelled at their middles.
pub fn fundamental_domain_svg(
    mesh: &Mesh,
    positions: &[Complex],
    poly: Option<&Polygon>,
    geometry: Geometry,
    max_edges: usize,
) -> String {
    let size = 800.0;
    let view = View::fit(positions.iter().copied(), geometry, size);
    let mut out = header(size);
    if geometry == Geometry::Hyperbolic {
        unit_circle(&mut out, &view);
    }
    if mesh.n_edges() <= max_edges {
        let mut d = String::new();
        for e in 0..mesh.n_edges() as u32 {
            let [a, b] = mesh.edge_vertices(e);
            let (x0, y0) = view.xy(positions[a as usize]);
            let (x1, y1) = view.xy(positions[b as usize]);
            let _ = write!(d, "M{x0:.2},{y0:.2} L{x1:.2},{y1:.2} ");
        }
        let _ = writeln!(
            out,
            "<path d=\"{d}\" fill=\"none\" stroke=\"#999\" stroke-width=\"0.3\"/>"
        );
    } else {
        for lp in mesh.boundary_loops() {
            let mut pts: Vec<Complex> = lp.iter().map(|&v| positions[v as usize]).collect();
            pts.push(pts[0]);
            polyline(&mut out, &view, &pts, "#333", 1.0, 1.0);
        }
    }
    if let Some(poly) = poly {
        for side in &poly.sides {
            let pts: Vec<Complex> = side
                .vertices
                .iter()
                .map(|&v| positions[v as usize])
                .collect();
            let colour = side.letter.map(letter_colour).unwrap_or("black");
            polyline(&mut out, &view, &pts, colour, 3.0, 1.0);
            let mid = pts[pts.len() / 2];
            let (x, y) = view.xy(mid);
            let _ = writeln!(
                out,
                "<text x=\"{x:.1}\" y=\"{y:.1}\" font-family=\"sans-serif\" font-size=\"16\" fill=\"{colour}\" stroke=\"white\" stroke-width=\"3\" paint-order=\"stroke\">{}</text>",
                side.label.replace("^-1", "⁻¹")
            );
        }
    }
    out.push_str("</svg>\n");
    out
}

/// Copies of the fundamental polygon (each given by its boundary sides, already mapped),
/// the first one emphasized; for H² the unit circle is drawn and the view is the whole disk.
pub fn tiling_svg(tiles: &[Vec<(Option<usize>, Vec<Complex>)>], geometry: Geometry) -> String {
    let size = 800.0;
    let all = tiles.iter().flatten().flat_map(|s| s.1.iter().copied());
    let view = if geometry == Geometry::Hyperbolic {
        View::fit(std::iter::empty(), geometry, size)
    } else {
        View::fit(all, geometry, size)
    };
    let mut out = header(size);
    if geometry == Geometry::Hyperbolic {
        unit_circle(&mut out, &view);
    }
    for (t, sides) in tiles.iter().enumerate().rev() {
        for (letter, pts) in sides {
            let colour = letter.map(letter_colour).unwrap_or("black");
            if t == 0 {
                polyline(&mut out, &view, pts, colour, 2.5, 1.0);
            } else {
                polyline(&mut out, &view, pts, colour, 0.8, 0.6);
            }
        }
    }
    out.push_str("</svg>\n");
    out
}

/// Orthographic view of a mesh on the unit sphere from +z (faces facing the viewer).
pub fn sphere_svg(mesh: &Mesh, positions: &[[f64; 3]]) -> String {
    let size = 800.0;
    let view = View {
        cx: 0.0,
        cy: 0.0,
        scale: 0.47 * size,
        size,
    };
    let mut out = header(size);
    unit_circle(&mut out, &view);
    let mut d = String::new();
    for f in 0..mesh.n_faces() as u32 {
        let t = mesh.face(f).map(|v| positions[v as usize]);
        if t.iter().all(|p| p[2] > 0.0) {
            for i in 0..3 {
                let (x0, y0) = view.xy(Complex::new(t[i][0], t[i][1]));
                let (x1, y1) = view.xy(Complex::new(t[(i + 1) % 3][0], t[(i + 1) % 3][1]));
                let _ = write!(d, "M{x0:.2},{y0:.2} L{x1:.2},{y1:.2} ");
            }
        }
    }
    let _ = writeln!(
        out,
        "<path d=\"{d}\" fill=\"none\" stroke=\"#555\" stroke-width=\"0.3\"/>"
    );
    out.push_str("</svg>\n");
    out
}
