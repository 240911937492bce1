//! Closed curves drawn on a surface, as an SVG sketch: an orthographic view along the
//! bounding box's shortest axis, front-facing triangles shaded by the cosine of their normal
//! with the view direction (painter's order, far to near), the curves on top as coloured
//! polylines (two consecutive curves share a colour: the `a_i`, `b_i` pairs of a canonical
//! cut) and an optional marked vertex (the cut's base point).

use crate::{input_err, Result};
use std::fmt::Write as _;

/// One curve on the surface: a label (shown as the polyline's SVG title) and its vertices.
#[derive(Debug, Clone)]
pub struct SurfaceLoop<'a> {
    pub label: &'a str,
    pub vertices: &'a [u32],
}

/// Colours of the curves, one per pair of consecutive curves.
const LOOP_COLOURS: [&str; 8] = [
    "#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
];

/// The SVG sketch of `loops` on the surface `(positions, triangles)` with the vertex `marker`
/// drawn as a dot (module docs); 900 pixels along the longer side. No positions: an empty
/// SVG. Fails on an index out of range or a non-finite position.
pub fn loops_svg(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    loops: &[SurfaceLoop<'_>],
    marker: Option<u32>,
) -> Result<String> {
    let p = positions;
    if p.is_empty() {
        return Ok("<svg xmlns=\"http://www.w3.org/2000/svg\"/>\n".into());
    }
    if let Some(k) = p.iter().position(|q| q.iter().any(|x| !x.is_finite())) {
        return input_err(format!("loops_svg: position {k} is not finite"));
    }
    let n = p.len();
    let check = |v: u32, what: &str| -> Result<()> {
        if v as usize >= n {
            return input_err(format!(
                "loops_svg: {what} names vertex {v}, but there are {n} positions"
            ));
        }
        Ok(())
    };
    for (f, t) in triangles.iter().enumerate() {
        for &v in t {
            check(v, &format!("triangle {f}"))?;
        }
    }
    for l in loops {
        for &v in l.vertices {
            check(v, &format!("loop {}", l.label))?;
        }
    }
    if let Some(v) = marker {
        check(v, "the marker")?;
    }
    let mut t = String::new();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for q in p {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let ext = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    let z = (0..3)
        .min_by(|&a, &b| ext[a].total_cmp(&ext[b]))
        .unwrap_or(2);
    let (x, y) = ((z + 1) % 3, (z + 2) % 3);
    let size = 900.0;
    let s = size / ext[x].max(ext[y]).max(1e-300);
    let (w, h) = (ext[x] * s + 20.0, ext[y] * s + 20.0);
    let proj = |q: [f64; 3]| ((q[x] - lo[x]) * s + 10.0, (hi[y] - q[y]) * s + 10.0);
    let _ = writeln!(
        t,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.0}\" height=\"{h:.0}\" viewBox=\"0 0 {w:.0} {h:.0}\">"
    );
    let _ = writeln!(t, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>");
    let mut faces: Vec<(f64, usize, f64)> = Vec::new();
    for (f, tri) in triangles.iter().enumerate() {
        let [a, b, cc] = tri.map(|v| p[v as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-300);
        if n[z] <= 0.0 {
            continue;
        }
        faces.push(((a[z] + b[z] + cc[z]) / 3.0, f, n[z] / len));
    }
    faces.sort_by(|a, b| a.0.total_cmp(&b.0));
    let points = |vs: &mut dyn Iterator<Item = u32>| -> String {
        let pts: Vec<String> = vs
            .map(|v| {
                let (px, py) = proj(p[v as usize]);
                format!("{px:.1},{py:.1}")
            })
            .collect();
        pts.join(" ")
    };
    for (_, f, shade) in faces {
        let g = (150.0 + 100.0 * shade) as u8;
        let _ = writeln!(
            t,
            "<polygon points=\"{}\" fill=\"rgb({g},{g},{g})\"/>",
            points(&mut triangles[f].iter().copied())
        );
    }
    for (i, l) in loops.iter().enumerate() {
        let _ = writeln!(
            t,
            "<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2.5\"><title>{}</title></polyline>",
            points(&mut l.vertices.iter().copied()),
            LOOP_COLOURS[(i / 2) % LOOP_COLOURS.len()],
            l.label
        );
    }
    if let Some(v) = marker {
        let (bx, by) = proj(p[v as usize]);
        let _ = writeln!(
            t,
            "<circle cx=\"{bx:.1}\" cy=\"{by:.1}\" r=\"5\" fill=\"black\"/>"
        );
    }
    t.push_str("</svg>\n");
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tetrahedron seen along z: the faces whose normal points to +z are drawn, darker the
    /// more they are tilted; the loop and the marker are drawn once each; bad indices fail.
    #[test]
    fn tetrahedron_front_faces_loop_and_marker() {
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 0.1],
        ];
        // (0,2,1) faces −z, the three others face outwards; of those, those with n_z > 0 show.
        let t = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
        let normal_z = |tri: [u32; 3]| {
            let [a, b, c] = tri.map(|v| p[v as usize]);
            (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        };
        let front = t.iter().filter(|&&tri| normal_z(tri) > 0.0).count();
        let lp = [0u32, 1, 2, 0];
        let svg = loops_svg(
            &p,
            &t,
            &[SurfaceLoop {
                label: "a1",
                vertices: &lp,
            }],
            Some(3),
        )
        .unwrap();
        assert_eq!(svg.matches("<polygon").count(), front);
        assert_eq!(svg.matches("<polyline").count(), 1);
        assert!(svg.contains("<title>a1</title>") && svg.contains("#d62728"));
        assert_eq!(svg.matches("<circle").count(), 1);
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
        assert!(loops_svg(&p, &[[0, 1, 9]], &[], None).is_err());
        assert!(loops_svg(&p, &t, &[], Some(4)).is_err());
        assert!(loops_svg(&[[f64::NAN; 3]], &[], &[], None).is_err());
        assert_eq!(
            loops_svg(&[], &[], &[], None).unwrap(),
            "<svg xmlns=\"http://www.w3.org/2000/svg\"/>\n"
        );
    }
}
