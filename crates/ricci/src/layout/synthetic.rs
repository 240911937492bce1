//! Closed surfaces with **exact** constant-curvature metrics and known fundamental polygons,
//! for testing layouts, deck groups and spectra against closed forms.
//!
//! * [`flat_torus`] — the torus `C / (ω₁Z + ω₂Z)` triangulated by a jittered grid of the period
//!   parallelogram; edge lengths are Euclidean distances of the lifted points, so the metric
//!   is exactly flat and its deck group is the lattice.
//! * [`regular_polygon_surface`] — a regular `4g`-gon glued to a closed genus-`g` surface, in
//!   the hyperbolic plane with interior angles `2π/4g` (an exact hyperbolic metric; the
//!   opposite-side gluing of the octagon is the Bolza surface) or in the Euclidean plane (a
//!   flat metric with one cone point of angle `(4g − 2)π` at the identified corners). The
//!   polygon is subdivided linearly in Klein coordinates (H²) or Euclidean coordinates (E²),
//!   where geodesics are straight, so every edge is a geodesic segment and the side pairings
//!   (compositions of rotations about the centre and reflections in lines through it, both
//!   linear there) map the subdivision points of a side onto those of its partner.
//!
//! Each comes as the closed mesh with its lengths, the cut mesh (the polygon, a disk; face ids
//! are shared with the closed mesh) with its lengths and vertex map, the labelled
//! [`Polygon`], and the exact positions of the cut-mesh vertices.

// `!(x > 0.0)` is used on purpose: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::deck::Polygon;
use super::isometry::{disk_distance, klein_to_poincare, Complex};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::metric::Geometry;
use std::collections::HashMap;
use std::f64::consts::PI;

/// A closed surface with an exact metric and its cut into a fundamental polygon.
#[derive(Debug, Clone)]
pub struct SyntheticSurface {
    pub geometry: Geometry,
    pub closed: Mesh,
    pub closed_lengths: Vec<f64>,
    pub cut: Mesh,
    pub cut_lengths: Vec<f64>,
    /// Cut-mesh vertex → closed-mesh vertex.
    pub cut_to_closed: Vec<u32>,
    pub polygon: Polygon,
    /// Exact positions of the cut-mesh vertices (plane, or Poincaré disk for H²).
    pub positions: Vec<Complex>,
}

/// How the sides of a regular `4g`-gon are glued.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Gluing {
    /// `a1 b1 a1⁻¹ b1⁻¹ … ag bg ag⁻¹ bg⁻¹`.
    Canonical,
    /// Opposite sides: `x1 x2 … x2g x1⁻¹ … x2g⁻¹` (the Bolza surface for the octagon).
    Opposite,
}

fn rng(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*seed >> 11) as f64) / ((1u64 << 53) as f64)
}

/// Assemble a synthetic surface from cut-mesh data (positions, faces, labelled sides).
fn assemble(
    geometry: Geometry,
    positions: Vec<Complex>,
    faces: Vec<[u32; 3]>,
    sides: Vec<(String, Vec<u32>)>,
) -> Result<SyntheticSurface> {
    let dist = |a: Complex, b: Complex| match geometry {
        Geometry::Hyperbolic => disk_distance(a, b),
        _ => (a - b).norm(),
    };
    let polygon = Polygon::from_labelled(sides)?;
    let cut = Mesh::from_triangles(positions.len(), faces.clone())?;
    // Identify partner sides.
    let mut parent: Vec<u32> = (0..positions.len() as u32).collect();
    fn find(p: &mut [u32], x: u32) -> u32 {
        let mut r = x;
        while p[r as usize] != r {
            r = p[r as usize];
        }
        let mut y = x;
        while p[y as usize] != r {
            let n = p[y as usize];
            p[y as usize] = r;
            y = n;
        }
        r
    }
    for side in &polygon.sides {
        if let Some(m) = side.partner {
            let w = &polygon.sides[m].vertices;
            let k = w.len() - 1;
            for (t, &v) in side.vertices.iter().enumerate() {
                let (a, b) = (find(&mut parent, v), find(&mut parent, w[k - t]));
                if a != b {
                    parent[a.max(b) as usize] = a.min(b);
                }
            }
        }
    }
    let mut id = vec![u32::MAX; positions.len()];
    let mut cut_to_closed = vec![0u32; positions.len()];
    let mut n_closed = 0u32;
    for v in 0..positions.len() as u32 {
        let r = find(&mut parent, v);
        if id[r as usize] == u32::MAX {
            id[r as usize] = n_closed;
            n_closed += 1;
        }
        cut_to_closed[v as usize] = id[r as usize];
    }
    let closed_faces: Vec<[u32; 3]> = faces
        .iter()
        .map(|t| t.map(|v| cut_to_closed[v as usize]))
        .collect();
    let closed = Mesh::from_triangles(n_closed as usize, closed_faces)?;
    let cut_lengths: Vec<f64> = (0..cut.n_edges() as u32)
        .map(|e| {
            let [a, b] = cut.edge_vertices(e);
            dist(positions[a as usize], positions[b as usize])
        })
        .collect();
    let mut closed_lengths = vec![0.0; closed.n_edges()];
    for h in 0..cut.n_corners() as u32 {
        closed_lengths[closed.he_edge(h) as usize] = cut_lengths[cut.he_edge(h) as usize];
    }
    Ok(SyntheticSurface {
        geometry,
        closed,
        closed_lengths,
        cut,
        cut_lengths,
        cut_to_closed,
        polygon,
        positions,
    })
}

/// The flat torus `C/(ω₁Z + ω₂Z)` (`Im(ω₂/ω₁) > 0`) on an `n × m` grid whose vertices are
/// displaced by up to `jitter` times the cell size (periodically, seeded), so that the
/// triangulation is irregular but the metric exactly flat.
pub fn flat_torus(
    omega1: Complex,
    omega2: Complex,
    n: usize,
    m: usize,
    jitter: f64,
    seed: u64,
) -> Result<SyntheticSurface> {
    if n < 3 || m < 3 {
        return Err(Error::input("a grid torus needs at least 3 × 3 cells"));
    }
    if !((omega2 / omega1).im > 0.0) {
        return Err(Error::input(
            "the periods must be positively oriented (Im(ω₂/ω₁) > 0)",
        ));
    }
    if !(0.0..0.3).contains(&jitter) {
        return Err(Error::input("jitter must be in [0, 0.3)"));
    }
    let mut s = seed;
    let cell = (omega1.norm() / n as f64).min(omega2.norm() / m as f64)
        * ((omega2 / omega1).im / (omega2 / omega1).norm());
    let jit: Vec<Complex> = (0..n * m)
        .map(|_| Complex::from_polar(jitter * cell * rng(&mut s).sqrt(), 2.0 * PI * rng(&mut s)))
        .collect();
    let vid = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut positions = Vec::with_capacity((n + 1) * (m + 1));
    for j in 0..=m {
        for i in 0..=n {
            positions.push(
                omega1 * (i as f64 / n as f64)
                    + omega2 * (j as f64 / m as f64)
                    + jit[(j % m) * n + (i % n)],
            );
        }
    }
    let mut faces = Vec::with_capacity(2 * n * m);
    for j in 0..m {
        for i in 0..n {
            let (a, b, c, d) = (vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1));
            if (i + j) % 2 == 0 {
                faces.push([a, b, c]);
                faces.push([a, c, d]);
            } else {
                faces.push([a, b, d]);
                faces.push([b, c, d]);
            }
        }
    }
    let sides = vec![
        ("a".to_string(), (0..=n).map(|i| vid(i, 0)).collect()),
        ("b".to_string(), (0..=m).map(|j| vid(n, j)).collect()),
        (
            "a^-1".to_string(),
            (0..=n).rev().map(|i| vid(i, m)).collect(),
        ),
        (
            "b^-1".to_string(),
            (0..=m).rev().map(|j| vid(0, j)).collect(),
        ),
    ];
    assemble(Geometry::Euclidean, positions, faces, sides)
}

/// Circumradius (in the model's flat coordinates: Klein radius for H², Euclidean radius 1 for
/// E²) of the regular `4g`-gon used by [`regular_polygon_surface`].
pub fn regular_polygon_radius(geometry: Geometry, genus: usize) -> f64 {
    let n = 4.0 * genus as f64;
    match geometry {
        Geometry::Hyperbolic => {
            // cosh R = cot(π/N) cot(α/2), α = 2π/N.
            let c = 1.0 / (PI / n).tan() / (PI / n).tan();
            c.acosh().tanh()
        }
        _ => 1.0,
    }
}

/// A regular `4g`-gon (`g ≥ 1`; corners at angles `2πk/4g`) with sides glued as `gluing`,
/// each of the `4g` sectors (centre, `V_k`, `V_{k+1}`) subdivided into `n²` triangles.
/// Geometry: `Hyperbolic` (interior angles 2π/4g, an exact hyperbolic metric for g ≥ 2) or
/// `Euclidean` (one cone point of angle (4g − 2)π).
pub fn regular_polygon_surface(
    geometry: Geometry,
    genus: usize,
    gluing: Gluing,
    n: usize,
) -> Result<SyntheticSurface> {
    if genus == 0 || n < 2 {
        return Err(Error::input(
            "a regular polygon surface needs genus ≥ 1 and at least 2 subdivisions",
        ));
    }
    if geometry == Geometry::Spherical || (geometry == Geometry::Hyperbolic && genus < 2) {
        return Err(Error::input(
            "regular polygon surfaces are hyperbolic (genus ≥ 2) or Euclidean",
        ));
    }
    let nn = 4 * genus;
    let rho = regular_polygon_radius(geometry, genus);
    let corner = |k: usize| Complex::from_polar(rho, 2.0 * PI * (k % nn) as f64 / nn as f64);
    let to_model = |p: Complex| match geometry {
        Geometry::Hyperbolic => klein_to_poincare(p),
        _ => p,
    };
    let mut index: HashMap<(i64, i64), u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut vertex = |p: Complex, positions: &mut Vec<Complex>| -> u32 {
        let key = ((p.re * 1e9).round() as i64, (p.im * 1e9).round() as i64);
        *index.entry(key).or_insert_with(|| {
            positions.push(to_model(p));
            (positions.len() - 1) as u32
        })
    };
    let mut faces = Vec::new();
    let mut sides = Vec::new();
    let o = Complex::new(0.0, 0.0);
    for k in 0..nn {
        let (vk, vk1) = (corner(k), corner(k + 1));
        let pt = |i: usize, j: usize| {
            o * (1.0 - i as f64 / n as f64)
                + vk * ((i - j) as f64 / n as f64)
                + vk1 * (j as f64 / n as f64)
        };
        let mut ids = vec![vec![0u32; n + 1]; n + 1];
        for (i, row) in ids.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate().take(i + 1) {
                *x = vertex(pt(i, j), &mut positions);
            }
        }
        for i in 0..n {
            for j in 0..=i {
                faces.push([ids[i][j], ids[i + 1][j], ids[i + 1][j + 1]]);
                if j < i {
                    faces.push([ids[i][j], ids[i + 1][j + 1], ids[i][j + 1]]);
                }
            }
        }
        sides.push((0..=n).map(|j| ids[n][j]).collect::<Vec<u32>>());
    }
    // Orient every face counter-clockwise (in flat coordinates the subdivision is linear).
    for f in faces.iter_mut() {
        let [a, b, c] = f.map(|v| positions[v as usize]);
        if ((b - a).conj() * (c - a)).im < 0.0 {
            f.swap(1, 2);
        }
    }
    let labels: Vec<String> = match gluing {
        Gluing::Canonical => (0..genus)
            .flat_map(|i| {
                let (a, b) = (format!("a{}", i + 1), format!("b{}", i + 1));
                [a.clone(), b.clone(), format!("{a}^-1"), format!("{b}^-1")]
            })
            .collect(),
        Gluing::Opposite => {
            let h = nn / 2;
            (0..nn)
                .map(|s| {
                    if s < h {
                        format!("x{}", s + 1)
                    } else {
                        format!("x{}^-1", s - h + 1)
                    }
                })
                .collect()
        }
    };
    let sides = labels.into_iter().zip(sides).collect();
    assemble(geometry, positions, faces, sides)
}
