//! Closed genus-g surfaces as smooth implicit surfaces, polygonised by marching tetrahedra.
//!
//! **The shape.** `g` tori of major radius `R = 1` and tube radius `r = 0.4`, their centre
//! circles in the plane `z = 0` with centres `(2i − (g−1), 0)`, so consecutive circles touch.
//! With `d_i(p) = √((ρ_i − R)² + z²)` the distance to circle `i` (`ρ_i` the distance to its
//! axis), the surface is `f(p) = smin(d₍₁₎, d₍₂₎) − r = 0`, `d₍₁₎ ≤ d₍₂₎` the two smallest
//! `d_i` (only consecutive circles come close to each other), where `smin` is the cubic
//! polynomial smooth minimum with blend width `k = 0.3`:
//! `smin(a, b) = min(a, b) − k h³ / 6`, `h = max(k − |a − b|, 0) / k`.
//! It is C² near the surface, its gradient is a convex combination of the `∇d_i` (weights
//! `1 − h²/2`, `h²/2`), so `|∇f| ≤ 1`, and it equals the exact tube distance away from the
//! junctions. The union of
//! the tubes around a chain of `g` circles touching in `g − 1` points is a handlebody whose
//! boundary has genus `g`; the blend only rounds the creases where two tubes meet.
//!
//! **Marching tetrahedra.** A regular grid, each cube cut into the six tetrahedra of the
//! Kuhn/Freudenthal triangulation (all around the main diagonal, consistent across cube
//! faces), no ambiguous cases. Crossing points are shared per grid edge, so the output is a
//! closed oriented 2-manifold whenever no grid value is exactly zero (zeros count as outside).
//! Orientation is taken from a per-(tetrahedron, sign pattern) table computed once on the
//! reference cube, so it does not depend on the (possibly degenerate) crossing positions.

use super::geom::*;
use super::remesh::Implicit;
use std::collections::HashMap;

/// The genus-g "chain of tori" implicit surface of [`genus`](super::genus) (see the module docs).
pub struct ToriChain {
    pub centers: Vec<f64>,
    pub major: f64,
    pub minor: f64,
    pub blend: f64,
}

impl ToriChain {
    pub fn new(g: u32) -> ToriChain {
        let major = 1.0;
        ToriChain {
            centers: (0..g)
                .map(|i| major * (2.0 * i as f64 - (g as f64 - 1.0)))
                .collect(),
            major,
            minor: 0.4,
            blend: 0.3,
        }
    }

    /// Bounding box of the surface with a margin.
    pub fn bounds(&self, margin: f64) -> ([f64; 3], [f64; 3]) {
        let ext = self.major + self.minor + self.blend + margin;
        let zext = self.minor + self.blend + margin;
        let x0 = self.centers.first().copied().unwrap_or(0.0);
        let x1 = self.centers.last().copied().unwrap_or(0.0);
        ([x0 - ext, -ext, -zext], [x1 + ext, ext, zext])
    }

    /// `d_i` and its gradient.
    #[inline]
    fn circle_distance(&self, i: usize, p: P3) -> (f64, P3) {
        let (x, y) = (p[0] - self.centers[i], p[1]);
        let rho = (x * x + y * y).sqrt();
        let dr = rho - self.major;
        let d = (dr * dr + p[2] * p[2]).sqrt();
        if d == 0.0 || rho == 0.0 {
            return (d, [0.0, 0.0, 0.0]);
        }
        let s = dr / (rho * d);
        (d, [x * s, y * s, p[2] / d])
    }

    /// `smin(d₍₁₎, d₍₂₎) − r` and its gradient, `d₍₁₎ ≤ d₍₂₎` the two smallest circle
    /// distances. Only the circle nearest in x and its two neighbours are candidates: inside
    /// [`bounds`](Self::bounds) every other circle is at least `2R − 1.46 > k` farther than
    /// the nearest one, so it can neither be among the two smallest with an active blend nor
    /// change the value. O(1) per evaluation, whatever g.
    fn eval(&self, p: P3) -> (f64, P3) {
        let g = self.centers.len();
        let x0 = self.centers[0];
        let i0 = (((p[0] - x0) / (2.0 * self.major)).round().max(0.0) as usize).min(g - 1);
        let (lo, hi) = (i0.saturating_sub(1), (i0 + 1).min(g - 1));
        let mut best = (f64::INFINITY, [0.0; 3]);
        let mut second = (f64::INFINITY, [0.0; 3]);
        for i in lo..=hi {
            let c = self.circle_distance(i, p);
            if c.0 < best.0 {
                second = best;
                best = c;
            } else if c.0 < second.0 {
                second = c;
            }
        }
        let ((a, ga), (b, gb)) = (best, second);
        let k = self.blend;
        let diff = b - a; // ≥ 0, +∞ when g = 1
        if diff >= k {
            return (a - self.minor, ga);
        }
        let h = (k - diff) / k;
        // ∂smin/∂a = 1 − h²/2 for the smaller argument, ∂smin/∂b = h²/2.
        let (wa, wb) = (1.0 - h * h / 2.0, h * h / 2.0);
        (
            a - k * h * h * h / 6.0 - self.minor,
            add(scale(ga, wa), scale(gb, wb)),
        )
    }
}

impl Implicit for ToriChain {
    fn value(&self, p: [f64; 3]) -> f64 {
        self.eval(p).0
    }
    fn gradient(&self, p: [f64; 3]) -> [f64; 3] {
        self.eval(p).1
    }
}

/// Corner offsets of the unit cube, corner `c` at `(c & 1, c >> 1 & 1, c >> 2 & 1)`.
fn corner(c: usize) -> [usize; 3] {
    [c & 1, (c >> 1) & 1, (c >> 2) & 1]
}

/// The six Kuhn tetrahedra of the unit cube: for each permutation of the axes, the path
/// 0 → e_π0 → e_π0 + e_π1 → (1,1,1), as cube-corner indices.
fn kuhn_tets() -> [[usize; 4]; 6] {
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut out = [[0usize; 4]; 6];
    for (t, p) in perms.iter().enumerate() {
        let mut c = 0usize;
        out[t][0] = c;
        for (s, &axis) in p.iter().enumerate() {
            c |= 1 << axis;
            out[t][s + 1] = c;
        }
    }
    out
}

/// For a tetrahedron (corner indices) and a sign mask (bit i set = corner i inside), the
/// triangles as triples of tetrahedron edges `(i, j)` (local corner indices), oriented so the
/// normal points from the inside corners to the outside ones. Computed on the reference
/// geometry with crossings at edge midpoints.
fn tet_table(tet: [usize; 4]) -> Vec<Vec<[(usize, usize); 3]>> {
    let pt = |c: usize| {
        let k = corner(tet[c]);
        [k[0] as f64, k[1] as f64, k[2] as f64]
    };
    let mut table = Vec::with_capacity(16);
    for mask in 0..16usize {
        let inside: Vec<usize> = (0..4).filter(|&i| mask >> i & 1 == 1).collect();
        let outside: Vec<usize> = (0..4).filter(|&i| mask >> i & 1 == 0).collect();
        let mut tris: Vec<[(usize, usize); 3]> = Vec::new();
        let polygon: Vec<(usize, usize)> = match (inside.len(), outside.len()) {
            (1, 3) => outside.iter().map(|&o| (inside[0], o)).collect(),
            (3, 1) => inside.iter().map(|&i| (i, outside[0])).collect(),
            (2, 2) => {
                let (i, j, k, l) = (inside[0], inside[1], outside[0], outside[1]);
                vec![(i, k), (i, l), (j, l), (j, k)]
            }
            _ => Vec::new(),
        };
        if polygon.len() >= 3 {
            let mid = |e: (usize, usize)| lerp(pt(e.0), pt(e.1), 0.5);
            let centroid = |s: &[usize]| {
                let mut c = [0.0; 3];
                for &i in s {
                    c = add(c, pt(i));
                }
                scale(c, 1.0 / s.len() as f64)
            };
            let dir = sub(centroid(&outside), centroid(&inside));
            let (a, b, c) = (mid(polygon[0]), mid(polygon[1]), mid(polygon[2]));
            let flip = dot(tri_normal(a, b, c), dir) < 0.0;
            let mut poly = polygon.clone();
            if flip {
                poly.reverse();
            }
            tris.push([poly[0], poly[1], poly[2]]);
            if poly.len() == 4 {
                tris.push([poly[0], poly[2], poly[3]]);
            }
        }
        table.push(tris);
    }
    table
}

/// Marching tetrahedra on the grid with spacing `h` over `bounds`. Returns positions (on grid
/// edges, crossing parameter clamped to [0.02, 0.98] so no two vertices coincide) and faces.
pub(crate) fn marching_tetrahedra<F: Implicit>(
    field: &F,
    bounds: (P3, P3),
    h: f64,
) -> (Vec<P3>, Vec<[u32; 3]>) {
    let (lo, hi) = bounds;
    let n = [0, 1, 2].map(|k| (((hi[k] - lo[k]) / h).ceil() as usize).max(1));
    let (nx, ny, nz) = (n[0] + 1, n[1] + 1, n[2] + 1);
    let node = |i: usize, j: usize, k: usize| i + nx * (j + ny * k);
    let node_pos = |i: usize, j: usize, k: usize| {
        [
            lo[0] + i as f64 * h,
            lo[1] + j as f64 * h,
            lo[2] + k as f64 * h,
        ]
    };
    let mut values = vec![0.0; nx * ny * nz];
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                values[node(i, j, k)] = field.value(node_pos(i, j, k));
            }
        }
    }
    let tets = kuhn_tets();
    let tables: Vec<_> = tets.iter().map(|&t| tet_table(t)).collect();
    let mut vertex_of_edge: HashMap<(usize, usize), u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    for k in 0..nz - 1 {
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let cube: [usize; 8] = std::array::from_fn(|c| {
                    let o = corner(c);
                    node(i + o[0], j + o[1], k + o[2])
                });
                let inside = cube.map(|g| values[g] < 0.0);
                if inside.iter().all(|&s| s) || inside.iter().all(|&s| !s) {
                    continue;
                }
                for (t, tet) in tets.iter().enumerate() {
                    let mask = (0..4).fold(0, |m, c| m | ((inside[tet[c]] as usize) << c));
                    for tri in &tables[t][mask] {
                        let mut f = [0u32; 3];
                        for (s, &(a, b)) in tri.iter().enumerate() {
                            let (ga, gb) = (cube[tet[a]], cube[tet[b]]);
                            let key = (ga.min(gb), ga.max(gb));
                            f[s] = *vertex_of_edge.entry(key).or_insert_with(|| {
                                let (fa, fb) = (values[ga], values[gb]);
                                let tt = (fa / (fa - fb)).clamp(0.02, 0.98);
                                let pa = node_pos(ga % nx, (ga / nx) % ny, ga / (nx * ny));
                                let pb = node_pos(gb % nx, (gb / nx) % ny, gb / (nx * ny));
                                positions.push(lerp(pa, pb, tt));
                                (positions.len() - 1) as u32
                            });
                        }
                        faces.push(f);
                    }
                }
            }
        }
    }
    (positions, faces)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{topology, Surface};

    struct Sphere(f64);
    impl Implicit for Sphere {
        fn value(&self, p: [f64; 3]) -> f64 {
            norm(p) - self.0
        }
        fn gradient(&self, p: [f64; 3]) -> [f64; 3] {
            scale(p, 1.0 / norm(p))
        }
    }

    fn volume(s: &Surface) -> f64 {
        s.mesh
            .faces()
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| s.positions[v as usize]);
                dot(a, cross(b, c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn marching_tetrahedra_gives_a_closed_outward_sphere() {
        let h = 0.1;
        let (pos, faces) = marching_tetrahedra(&Sphere(1.0), ([-1.3; 3], [1.3; 3]), h);
        let s = Surface::new(pos, faces).unwrap();
        let t = topology(&s.mesh);
        assert_eq!(t.components.len(), 1);
        assert_eq!(t.components[0].genus, 0);
        assert!(!s.mesh.has_boundary());
        // Vertices on grid edges within one cell of the sphere; volume outward ≈ 4π/3.
        for p in &s.positions {
            assert!((norm(*p) - 1.0).abs() < h * 3f64.sqrt());
        }
        let v = volume(&s);
        assert!((v - 4.0 * std::f64::consts::PI / 3.0).abs() < 0.05, "{v}");
    }

    #[test]
    fn the_chain_field_has_genus_g_and_an_exact_gradient() {
        for g in [1u32, 2, 3] {
            let f = ToriChain::new(g);
            let (pos, faces) = marching_tetrahedra(&f, f.bounds(0.2), 0.08);
            let s = Surface::new(pos, faces).unwrap();
            let t = topology(&s.mesh);
            assert_eq!(t.components.len(), 1);
            assert_eq!(t.components[0].genus, g as i64);
            assert!(volume(&s) > 0.0);
        }
        // Gradient against central differences, also inside the blends.
        let f = ToriChain::new(3);
        let eps = 1e-6;
        for p in [
            [0.1, 0.9, 0.2],
            [-1.0, 1.3, 0.1],
            [0.05, -0.95, -0.3],
            [2.3, 0.2, 0.35],
        ] {
            let g = f.gradient(p);
            for k in 0..3 {
                let (mut a, mut b) = (p, p);
                a[k] += eps;
                b[k] -= eps;
                let fd = (f.value(a) - f.value(b)) / (2.0 * eps);
                assert!((fd - g[k]).abs() < 1e-7, "{p:?} axis {k}: {fd} vs {}", g[k]);
            }
        }
    }
}
