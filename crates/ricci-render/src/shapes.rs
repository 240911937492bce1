//! Small procedural meshes for examples, tests and demos: a grid on the unit square, a torus
//! of revolution and an icosphere. Positions and triangles as plain vectors (CCW, outward).

use std::collections::HashMap;
use std::f64::consts::PI;

/// A mesh as plain arrays.
#[derive(Debug, Clone, Default)]
pub struct Shape {
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

/// The square [0, size]² in the plane z = 0 split into `n × n` cells of two triangles each;
/// vertex `j * (n + 1) + i` is at (i, j) · size / n.
pub fn grid(n: usize, size: f64) -> Shape {
    let n = n.max(1);
    let mut s = Shape::default();
    for j in 0..=n {
        for i in 0..=n {
            s.positions
                .push([i as f64 * size / n as f64, j as f64 * size / n as f64, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    for j in 0..n {
        for i in 0..n {
            s.triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            s.triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    s
}

/// A torus of revolution around the z axis with radii `big` > `small`, `n × m` quads split
/// into triangles (2 n m faces). Vertex `i * m + j` has angles (2π i / n, 2π j / m).
pub fn torus(big: f64, small: f64, n: usize, m: usize) -> Shape {
    let (n, m) = (n.max(3), m.max(3));
    let mut s = Shape::default();
    for i in 0..n {
        let u = 2.0 * PI * i as f64 / n as f64;
        for j in 0..m {
            let v = 2.0 * PI * j as f64 / m as f64;
            let r = big + small * v.cos();
            s.positions
                .push([r * u.cos(), r * u.sin(), small * v.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    for i in 0..n {
        for j in 0..m {
            s.triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            s.triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    s
}

/// The unit sphere as a subdivided icosahedron (`level` times 1:4 subdivision,
/// 20 · 4^level faces).
pub fn icosphere(level: u32) -> Shape {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut p: Vec<[f64; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let unit = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|c| c / l)
    };
    for v in &mut p {
        *v = unit(*v);
    }
    for _ in 0..level {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut nf = Vec::with_capacity(4 * f.len());
        for t in &f {
            let mut m = [0u32; 3];
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                let key = (a.min(b), a.max(b));
                m[i] = *mid.entry(key).or_insert_with(|| {
                    let (pa, pb) = (p[a as usize], p[b as usize]);
                    p.push(unit([pa[0] + pb[0], pa[1] + pb[1], pa[2] + pb[2]]));
                    (p.len() - 1) as u32
                });
            }
            nf.push([t[0], m[0], m[2]]);
            nf.push([t[1], m[1], m[0]]);
            nf.push([t[2], m[2], m[1]]);
            nf.push(m);
        }
        f = nf;
    }
    Shape {
        positions: p,
        triangles: f,
    }
}
