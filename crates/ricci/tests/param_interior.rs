//! Session 12 (param12) of issue 16: the greedy cone placement with the boundary held
//! (`--seams free`'s disk) solves its systems from one factorization (Woodbury identity);
//! checked against a dense direct solve of the Dirichlet problems written here from the
//! positions (cotangent weights and angle defects from the 3D triangles). (The file's other
//! test, of the opt-in harmonic interior, went with that experiment in session 13.)

use ricci::mesh::Surface;
use ricci::metric::IntrinsicMetric;
use ricci::param::cones::{free_boundary_least_squares, greedy_cones, ConeBudget};
use std::f64::consts::PI;

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross_norm(a: [f64; 3], b: [f64; 3]) -> f64 {
    let c = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    dot(c, c).sqrt()
}

/// Cotangent of the angle at `p` of triangle `p, q, r`.
fn cot(p: [f64; 3], q: [f64; 3], r: [f64; 3]) -> f64 {
    let (a, b) = (sub(q, p), sub(r, p));
    dot(a, b) / cross_norm(a, b)
}

/// A bumpy disk: a polar grid on `z = 0.3 (x² + y²) + 0.05 sin(5x) cos(4y)`.
fn bumpy_disk(rings: usize, sectors: usize) -> Surface {
    let mut pos = vec![[0.0, 0.0, 0.0]];
    for r in 1..=rings {
        for s in 0..sectors {
            let t = 2.0 * PI * s as f64 / sectors as f64 + 0.3 * r as f64;
            let rad = r as f64 / rings as f64;
            let (x, y) = (rad * t.cos(), rad * t.sin());
            pos.push([
                x,
                y,
                0.3 * (x * x + y * y) + 0.05 * (5.0 * x).sin() * (4.0 * y).cos(),
            ]);
        }
    }
    let id = |r: usize, s: usize| (1 + (r - 1) * sectors + s % sectors) as u32;
    let mut tris = Vec::new();
    for s in 0..sectors {
        tris.push([0, id(1, s), id(1, s + 1)]);
    }
    for r in 1..rings {
        for s in 0..sectors {
            tris.push([id(r, s), id(r + 1, s), id(r + 1, s + 1)]);
            tris.push([id(r, s), id(r + 1, s + 1), id(r, s + 1)]);
        }
    }
    Surface::new(pos, tris).unwrap()
}

/// Dense cotangent Laplacian (positive semi-definite) and angle defects from the positions.
fn dense_laplacian(s: &Surface) -> (Vec<Vec<f64>>, Vec<f64>, Vec<f64>) {
    let n = s.mesh.n_vertices();
    let mut l = vec![vec![0.0; n]; n];
    let mut k = vec![2.0 * PI; n];
    let mut area = vec![0.0; n];
    for t in s.mesh.faces() {
        let p = t.map(|v| s.positions[v as usize]);
        for i in 0..3 {
            let (a, b, c) = (i, (i + 1) % 3, (i + 2) % 3);
            let w = 0.5 * cot(p[c], p[a], p[b]);
            let (va, vb) = (t[a] as usize, t[b] as usize);
            l[va][vb] -= w;
            l[vb][va] -= w;
            l[va][va] += w;
            l[vb][vb] += w;
            let (x, y) = (sub(p[b], p[a]), sub(p[c], p[a]));
            k[va] -= (dot(x, y) / (dot(x, x) * dot(y, y)).sqrt()).acos();
            area[va] += 0.5 * cross_norm(x, y) / 3.0;
        }
    }
    (l, k, area)
}

/// Dense Gaussian elimination with partial pivoting.
fn dense_solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))
            .unwrap();
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..n {
            let f = a[r][c] / a[c][c];
            if f != 0.0 {
                let pivot = a[c].clone();
                for (x, p) in a[r][c..].iter_mut().zip(&pivot[c..]) {
                    *x -= f * p;
                }
                b[r] -= f * b[c];
            }
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|j| a[r][j] * x[j]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    x
}

/// `u` with `u = 0` on `held` and `(L u)_i = rhs_i` elsewhere (exact Dirichlet problem).
fn dirichlet(l: &[Vec<f64>], held: &[bool], rhs: &[f64]) -> Vec<f64> {
    let free: Vec<usize> = (0..l.len()).filter(|&v| !held[v]).collect();
    let a: Vec<Vec<f64>> = free
        .iter()
        .map(|&i| free.iter().map(|&j| l[i][j]).collect())
        .collect();
    let x = dense_solve(a, free.iter().map(|&i| rhs[i]).collect());
    let mut u = vec![0.0; l.len()];
    for (k, &v) in free.iter().enumerate() {
        u[v] = x[k];
    }
    u
}

/// The held greedy (largest `|u − ū|` becomes a cone) and its curvatures `K⁰ + (L u)` at
/// the cones, and the least-squares curvatures at the same positions, by dense solves.
#[test]
fn held_greedy_matches_a_dense_direct_solve() {
    let s = bumpy_disk(9, 24);
    let n = s.mesh.n_vertices();
    let (l, k0, area) = dense_laplacian(&s);
    let boundary: Vec<bool> = (0..n as u32)
        .map(|v| s.mesh.is_boundary_vertex(v))
        .collect();
    let rhs: Vec<f64> = k0.iter().map(|k| -k).collect();
    let total: f64 = area.iter().sum();
    let mut held = boundary.clone();
    let mut cones = Vec::new();
    let mut u = dirichlet(&l, &held, &rhs);
    for _ in 0..5 {
        let mean = (0..n).map(|v| u[v] * area[v]).sum::<f64>() / total;
        let c = (0..n)
            .filter(|&v| !held[v])
            .max_by(|&a, &b| (u[a] - mean).abs().total_cmp(&(u[b] - mean).abs()))
            .unwrap();
        cones.push(c);
        held[c] = true;
        u = dirichlet(&l, &held, &rhs);
    }
    let reference: Vec<(u32, f64)> = cones
        .iter()
        .map(|&c| {
            (
                c as u32,
                k0[c] + (0..n).map(|j| l[c][j] * u[j]).sum::<f64>(),
            )
        })
        .collect();
    let metric = IntrinsicMetric::euclidean(s.edge_lengths());
    let ours = greedy_cones(&s.mesh, &metric, ConeBudget::Count(5)).unwrap();
    assert_eq!(ours.distortion_history.len(), 5);
    for (a, b) in ours.cones.iter().zip(&reference) {
        assert_eq!(
            a.0, b.0,
            "cone positions {:?} vs {:?}",
            ours.cones, reference
        );
        assert!((a.1 - b.1).abs() < 1e-7, "curvature {} vs {}", a.1, b.1);
    }
    // Least squares at these positions: u = u₀ + Σ k_c g_c (Dirichlet Green's functions of
    // the boundary, unit load at c), least area-weighted variance.
    let centred = |x: Vec<f64>| -> Vec<f64> {
        let m = (0..n).map(|v| x[v] * area[v]).sum::<f64>() / total;
        x.iter().map(|y| y - m).collect()
    };
    let u0 = centred(dirichlet(&l, &boundary, &rhs));
    let g: Vec<Vec<f64>> = cones
        .iter()
        .map(|&c| {
            let mut e = vec![0.0; n];
            e[c] = 1.0;
            centred(dirichlet(&l, &boundary, &e))
        })
        .collect();
    let ip = |a: &[f64], b: &[f64]| (0..n).map(|v| area[v] * a[v] * b[v]).sum::<f64>();
    let m: Vec<Vec<f64>> = g
        .iter()
        .map(|a| g.iter().map(|b| ip(a, b)).collect())
        .collect();
    let k = dense_solve(m, g.iter().map(|a| -ip(a, &u0)).collect());
    let at: Vec<u32> = cones.iter().map(|&c| c as u32).collect();
    let (lsq, _) = free_boundary_least_squares(&s.mesh, &metric, &at).unwrap();
    for (a, b) in lsq.iter().zip(&k) {
        assert!((a.1 - b).abs() < 1e-6 * (1.0 + b.abs()), "{} vs {b}", a.1);
    }
}
