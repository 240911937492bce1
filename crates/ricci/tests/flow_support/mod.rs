//! Small procedural surfaces and a minimal mesh reader for the flow and metric tests (the
//! library's own generators and readers live in other modules; these keep the tests
//! self-contained).
#![allow(dead_code, clippy::needless_range_loop)]

use ricci::mesh::Surface;
use ricci::metric::IntrinsicMetric;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::path::PathBuf;

/// Subdivided icosahedron on the unit sphere (`level` 4-to-1 subdivisions): the library's
/// generator.
pub fn icosphere(level: usize) -> Surface {
    ricci::mesh::generate::icosphere(level as u32).unwrap()
}

/// Torus of revolution with radii `(big_r, r)`, `n` segments around the axis and `m` around
/// the tube; vertex `(i, j)` is `j * n + i` at angles `θ = 2πi/n`, `φ = 2πj/m`.
pub fn torus(big_r: f64, r: f64, n: usize, m: usize) -> Surface {
    let mut p = Vec::with_capacity(n * m);
    for j in 0..m {
        for i in 0..n {
            let (th, ph) = (
                2.0 * PI * i as f64 / n as f64,
                2.0 * PI * j as f64 / m as f64,
            );
            let rr = big_r + r * ph.cos();
            p.push([rr * th.cos(), rr * th.sin(), r * ph.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((j % m) * n + (i % n)) as u32;
    let mut f = Vec::with_capacity(2 * n * m);
    for j in 0..m {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            // Alternate diagonals for a less biased triangulation.
            if (i + j) % 2 == 0 {
                f.push([a, b, c]);
                f.push([a, c, d]);
            } else {
                f.push([a, b, d]);
                f.push([b, c, d]);
            }
        }
    }
    Surface::new(p, f).unwrap()
}

/// Unit disk triangulated by `rings` concentric rings (ring k has 6k vertices).
pub fn disk(rings: usize) -> Surface {
    let mut p = vec![[0.0, 0.0, 0.0]];
    let mut start = vec![0usize];
    for k in 1..=rings {
        start.push(p.len());
        for s in 0..6 * k {
            let a = 2.0 * PI * s as f64 / (6 * k) as f64;
            let r = k as f64 / rings as f64;
            // A little height makes it a curved cap (non-trivial metric).
            p.push([r * a.cos(), r * a.sin(), 0.3 * (1.0 - r * r)]);
        }
    }
    let mut f = Vec::new();
    for k in 1..=rings {
        let inner = |s: usize| -> u32 {
            if k == 1 {
                0
            } else {
                (start[k - 1] + s % (6 * (k - 1))) as u32
            }
        };
        let outer = |s: usize| (start[k] + s % (6 * k)) as u32;
        // Walk the 6 sectors; sector q has k outer edges and k−1 inner edges.
        for q in 0..6 {
            for s in 0..k {
                let o = q * k + s;
                let i = q * (k - 1) + s;
                f.push([outer(o), outer(o + 1), inner(i)]);
                if s + 1 < k {
                    f.push([inner(i), outer(o + 1), inner(i + 1)]);
                }
            }
        }
    }
    Surface::new(p, f).unwrap()
}

/// Closed surface of genus `g`: the boundary of a plate of voxels with `g` square holes,
/// every voxel face split into `k × k` squares, each cut into two triangles.
pub fn plate(g: usize, k: usize) -> Surface {
    // Voxels: x in 0..2g+1, y in 0..3, z in 0..1; holes at (2h+1, 1).
    let nx = 2 * g + 1;
    let solid = |x: i64, y: i64, z: i64| -> bool {
        if x < 0 || y < 0 || z != 0 || x >= nx as i64 || y >= 3 {
            return false;
        }
        !(y == 1 && x % 2 == 1)
    };
    let mut index: HashMap<[i64; 3], u32> = HashMap::new();
    let mut p: Vec<[f64; 3]> = Vec::new();
    let mut f: Vec<[u32; 3]> = Vec::new();
    let mut vid = |q: [i64; 3], p: &mut Vec<[f64; 3]>| -> u32 {
        *index.entry(q).or_insert_with(|| {
            p.push([
                q[0] as f64 / k as f64,
                q[1] as f64 / k as f64,
                q[2] as f64 / k as f64,
            ]);
            (p.len() - 1) as u32
        })
    };
    let ki = k as i64;
    for x in 0..nx as i64 {
        for y in 0..3 {
            if !solid(x, y, 0) {
                continue;
            }
            for axis in 0..3 {
                for dir in [-1i64, 1] {
                    let mut nb = [x, y, 0];
                    nb[axis] += dir;
                    if solid(nb[0], nb[1], nb[2]) {
                        continue;
                    }
                    // Face at coordinate c along axis, spanned by the two other axes (a, b)
                    // in an order that makes the normal point outwards.
                    let c = if dir > 0 {
                        [x, y, 0][axis] + 1
                    } else {
                        [x, y, 0][axis]
                    };
                    let (mut a, mut b) = ((axis + 1) % 3, (axis + 2) % 3);
                    if dir < 0 {
                        std::mem::swap(&mut a, &mut b);
                    }
                    let base = [x * ki, y * ki, 0];
                    for s in 0..ki {
                        for t in 0..ki {
                            let corner = |ds: i64, dt: i64| {
                                let mut q = base;
                                q[axis] = c * ki;
                                q[a] = base[a] + s + ds;
                                q[b] = base[b] + t + dt;
                                q
                            };
                            let q00 = vid(corner(0, 0), &mut p);
                            let q10 = vid(corner(1, 0), &mut p);
                            let q11 = vid(corner(1, 1), &mut p);
                            let q01 = vid(corner(0, 1), &mut p);
                            if (s + t) % 2 == 0 {
                                f.push([q00, q10, q11]);
                                f.push([q00, q11, q01]);
                            } else {
                                f.push([q00, q10, q01]);
                                f.push([q10, q11, q01]);
                            }
                        }
                    }
                }
            }
        }
    }
    Surface::new(p, f).unwrap()
}

/// The meshes folder from `RICCI_MESHES`, or `None` (with a note on stderr).
pub fn meshes_dir() -> Option<PathBuf> {
    match ricci_meshes() {
        Some(d) if d.is_dir() => Some(d),
        _ => {
            eprintln!("note: RICCI_MESHES is not set or missing; skipping the real-mesh part");
            None
        }
    }
}

/// Read a mesh with the library's readers (panics with the file's error message).
pub fn read_mesh(path: &std::path::Path) -> Surface {
    ricci::mesh::io::read_surface(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .0
}

/// Upper hemisphere of the unit sphere from `disk(rings)`: the point at radius ρ and angle α
/// of the disk goes to polar angle ρ·π/2, so the boundary ring lies exactly on the equator.
pub fn hemisphere(rings: usize) -> Surface {
    let mut s = disk(rings);
    for p in s.positions.iter_mut() {
        let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
        let a = p[1].atan2(p[0]);
        let t = rho * PI / 2.0;
        *p = [t.sin() * a.cos(), t.sin() * a.sin(), t.cos()];
    }
    s
}

#[path = "../ricci_meshes/mod.rs"]
mod ricci_meshes;
use ricci_meshes::ricci_meshes;

/// Spread `(max r − min r)/max r` of the distances of each boundary loop's vertices from the
/// least-squares (Kåsa) circle through them, in an independent E² layout of `lengths`
/// (`ricci::layout`); the worst over the loops.
pub fn boundary_circle_spread(mesh: &ricci::mesh::Mesh, lengths: &[f64]) -> f64 {
    use ricci::metric::geometry::Euclidean;
    let lay = ricci::layout::layout::<Euclidean>(
        mesh,
        &IntrinsicMetric::new(ricci::metric::Geometry::Euclidean, lengths.to_vec()),
        None,
    )
    .unwrap();
    assert!(lay.flipped_faces.is_empty() && lay.degenerate_faces.is_empty());
    let mut worst = 0.0f64;
    for lp in mesh.boundary_loops() {
        let pts: Vec<[f64; 2]> = lp
            .iter()
            .map(|&v| {
                let z = lay.positions[v as usize];
                [z.re, z.im]
            })
            .collect();
        let n = pts.len() as f64;
        let c0 = pts
            .iter()
            .fold([0.0, 0.0], |a, p| [a[0] + p[0] / n, a[1] + p[1] / n]);
        // Kåsa fit: x² + y² + a x + b y + c = 0 in least squares (exact for concyclic points).
        let mut m = [[0.0f64; 3]; 3];
        let mut r = [0.0f64; 3];
        for p in &pts {
            let (x, y) = (p[0] - c0[0], p[1] - c0[1]);
            let row = [x, y, 1.0];
            for i in 0..3 {
                for j in 0..3 {
                    m[i][j] += row[i] * row[j];
                }
                r[i] -= row[i] * (x * x + y * y);
            }
        }
        for c in 0..3 {
            for i in c + 1..3 {
                let f = m[i][c] / m[c][c];
                for j in 0..3 {
                    m[i][j] -= f * m[c][j];
                }
                r[i] -= f * r[c];
            }
        }
        let mut s = [0.0; 3];
        for i in (0..3).rev() {
            let mut a = r[i];
            for j in i + 1..3 {
                a -= m[i][j] * s[j];
            }
            s[i] = a / m[i][i];
        }
        let centre = [c0[0] - 0.5 * s[0], c0[1] - 0.5 * s[1]];
        let radii: Vec<f64> = pts
            .iter()
            .map(|p| ((p[0] - centre[0]).powi(2) + (p[1] - centre[1]).powi(2)).sqrt())
            .collect();
        let rmax = radii.iter().cloned().fold(0.0, f64::max);
        let rmin = radii.iter().cloned().fold(f64::INFINITY, f64::min);
        worst = worst.max((rmax - rmin) / rmax);
    }
    worst
}
