//! The picture of a UV map (`ricci param --png/--svg`): the input's faces in `[0, 1]²`
//! (flipped faces red), seams and boundary blue, cones as red dots, drawn by ricci-render's
//! figure (`ricci_render::plot::Figure`: SVG and PNG from the same display list).

use ricci::mesh::Mesh;
use ricci_render::plot::{Figure, Item};

/// Faces are drawn when there are at most this many (otherwise seams, boundary and cones).
const MAX_FACES: usize = 300_000;

/// The figure (`size` pixels square) of `corner_uv` (per corner of `mesh`'s faces).
pub fn uv_figure(
    mesh: &Mesh,
    corner_uv: &[[f64; 2]],
    seam: &[bool],
    cones: &[u32],
    size: f64,
) -> Figure {
    let mut fig = Figure::new(size, size);
    let px = |q: [f64; 2]| [q[0] * size, (1.0 - q[1]) * size];
    fig.items.push(Item::Polygons {
        polygons: vec![vec![
            [0.5, 0.5],
            [size - 0.5, 0.5],
            [size - 0.5, size - 0.5],
            [0.5, size - 0.5],
        ]],
        fill: None,
        stroke: Some([0.8, 0.8, 0.8]),
        stroke_width: 1.0,
        class: "frame",
    });
    if mesh.n_faces() <= MAX_FACES {
        let (mut ok, mut bad) = (Vec::new(), Vec::new());
        for f in 0..mesh.n_faces() {
            let q = [corner_uv[3 * f], corner_uv[3 * f + 1], corner_uv[3 * f + 2]];
            let area = (q[1][0] - q[0][0]) * (q[2][1] - q[0][1])
                - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]);
            let poly = q.iter().map(|&p| px(p)).collect::<Vec<_>>();
            if area > 0.0 {
                ok.push(poly);
            } else {
                bad.push(poly);
            }
        }
        let thin = (0.6 * size / (mesh.n_faces() as f64).sqrt()).clamp(0.05, 0.5);
        fig.items.push(Item::Polygons {
            polygons: ok,
            fill: Some([0.87, 0.90, 0.94]),
            stroke: Some([0.54, 0.63, 0.72]),
            stroke_width: thin,
            class: "faces",
        });
        if !bad.is_empty() {
            fig.items.push(Item::Polygons {
                polygons: bad,
                fill: Some([0.88, 0.13, 0.13]),
                stroke: None,
                stroke_width: 0.0,
                class: "flipped",
            });
        }
    }
    // Seams and boundary: every cut or boundary edge, on each of its sides.
    let mut seams = Vec::new();
    for h in 0..mesh.n_corners() as u32 {
        let e = mesh.he_edge(h);
        if seam[e as usize] || mesh.is_boundary_edge(e) {
            let (a, b) = (corner_uv[h as usize], corner_uv[mesh.he_next(h) as usize]);
            seams.push(vec![px(a), px(b)]);
        }
    }
    fig.items.push(Item::Polygons {
        polygons: seams,
        fill: None,
        stroke: Some([0.12, 0.31, 0.61]),
        stroke_width: 1.0,
        class: "seams",
    });
    for h in 0..mesh.n_corners() as u32 {
        if cones.contains(&mesh.he_origin(h)) {
            fig.items.push(Item::Circle {
                center: px(corner_uv[h as usize]),
                radius: 3.0,
                fill: Some([0.82, 0.19, 0.19]),
                stroke: None,
                stroke_width: 0.0,
                id: None,
            });
        }
    }
    fig
}
