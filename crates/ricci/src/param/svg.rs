//! SVG picture of a UV map in `[0, 1]²`: faces filled (flipped faces red), seams blue, cones
//! as dots.

use crate::mesh::Mesh;
use std::fmt::Write;

/// The picture (`size` pixels square). Faces are drawn when there are at most `max_faces`
/// (otherwise only the seams, the boundary and the cones).
pub fn uv_svg(
    mesh: &Mesh,
    corner_uv: &[[f64; 2]],
    seam: &[bool],
    cones: &[u32],
    size: f64,
    max_faces: usize,
) -> String {
    let mut s = String::with_capacity(64 * mesh.n_faces().min(max_faces) + 4096);
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{size}" height="{size}" viewBox="0 0 {size} {size}">"#
    );
    let _ = writeln!(
        s,
        r##"<rect width="{size}" height="{size}" fill="#ffffff"/><rect x="0.5" y="0.5" width="{}" height="{}" fill="none" stroke="#cccccc"/>"##,
        size - 1.0,
        size - 1.0
    );
    let px = |q: [f64; 2]| (q[0] * size, (1.0 - q[1]) * size);
    if mesh.n_faces() <= max_faces {
        let mut ok = String::new();
        let mut bad = String::new();
        for f in 0..mesh.n_faces() {
            let q = [corner_uv[3 * f], corner_uv[3 * f + 1], corner_uv[3 * f + 2]];
            let area = (q[1][0] - q[0][0]) * (q[2][1] - q[0][1])
                - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]);
            let (a, b, c) = (px(q[0]), px(q[1]), px(q[2]));
            let t = if area > 0.0 { &mut ok } else { &mut bad };
            let _ = write!(
                t,
                "M{:.2} {:.2}L{:.2} {:.2}L{:.2} {:.2}Z",
                a.0, a.1, b.0, b.1, c.0, c.1
            );
        }
        let _ = writeln!(
            s,
            r##"<path d="{ok}" fill="#dde6f0" stroke="#8aa0b8" stroke-width="0.15"/>"##
        );
        if !bad.is_empty() {
            let _ = writeln!(s, r##"<path d="{bad}" fill="#e02020"/>"##);
        }
    }
    // Seams and boundary: every cut or boundary edge, on each of its sides.
    let mut d = String::new();
    for h in 0..mesh.n_corners() as u32 {
        let e = mesh.he_edge(h) as usize;
        if seam[e] || mesh.is_boundary_edge(e as u32) {
            let (a, b) = (
                px(corner_uv[h as usize]),
                px(corner_uv[mesh.he_next(h) as usize]),
            );
            let _ = write!(d, "M{:.2} {:.2}L{:.2} {:.2}", a.0, a.1, b.0, b.1);
        }
    }
    let _ = writeln!(
        s,
        r##"<path d="{d}" fill="none" stroke="#1f4e9c" stroke-width="0.8"/>"##
    );
    for h in 0..mesh.n_corners() as u32 {
        if cones.contains(&mesh.he_origin(h)) {
            let p = px(corner_uv[h as usize]);
            let _ = writeln!(
                s,
                r##"<circle cx="{:.2}" cy="{:.2}" r="2.5" fill="#d03030"/>"##,
                p.0, p.1
            );
        }
    }
    s.push_str("</svg>\n");
    s
}
