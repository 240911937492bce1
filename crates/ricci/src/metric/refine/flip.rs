//! Intrinsic edge flips ([`Refiner::flip`]): the diagonal of the quad of two faces is
//! replaced by the other one, with the length it has in the quad's development (E², H², S²),
//! so the metric is unchanged.

use super::*;

impl Refiner {
    /// The length the new edge would have if the edge of `h` were flipped ([`Refiner::flip`]),
    /// or the reason the flip is refused; changes nothing.
    pub fn flip_length(&self, h: u32) -> Result<f64> {
        if h as usize >= self.len.len() {
            return Err(Error::input(format!(
                "half-edge {h} does not exist (the mesh has {} half-edges)",
                self.len.len()
            )));
        }
        let g = self.geometry;
        let f = h / 3;
        let i = h % 3;
        let (h_ab, h_bc, h_ca) = (h, 3 * f + (i + 1) % 3, 3 * f + (i + 2) % 3);
        let (a, b, c) = (self.origin(h_ab), self.origin(h_bc), self.origin(h_ca));
        let hg = self.twin[h as usize];
        if hg == NONE {
            return Err(Error::input(format!(
                "edge ({a}, {b}) lies on the boundary and cannot be flipped"
            )));
        }
        let gf = hg / 3;
        let j = hg % 3;
        let (h_ad, h_db) = (3 * gf + (j + 1) % 3, 3 * gf + (j + 2) % 3);
        let d = self.origin(h_db);
        if c == d || self.halfedge(c, d).is_some() {
            return Err(Error::input(format!(
                "edge ({a}, {b}) cannot be flipped: its opposite vertices {c} and {d} are                  already joined"
            )));
        }
        let (l_ab, l_bc, l_ca) = (
            self.len[h_ab as usize],
            self.len[h_bc as usize],
            self.len[h_ca as usize],
        );
        let (l_ad, l_db) = (self.len[h_ad as usize], self.len[h_db as usize]);
        // Angles at a and b in both faces.
        let a1 = g.angle(l_bc, l_ab, l_ca);
        let a2 = g.angle(l_db, l_ab, l_ad);
        let b1 = g.angle(l_ca, l_ab, l_bc);
        let b2 = g.angle(l_ad, l_ab, l_db);
        const MARGIN: f64 = 1e-9;
        let (ta, tb) = (a1 + a2, b1 + b2);
        if !(ta < PI - MARGIN && tb < PI - MARGIN) {
            return Err(Error::input(format!(
                "edge ({a}, {b}) cannot be flipped: the quadrilateral is not strictly convex                  (angles {ta:.6} at {a} and {tb:.6} at {b}; both must be < π)"
            )));
        }
        // From the endpoint with the smaller angle sum (better conditioned).
        let l_cd = if ta <= tb {
            side(g, l_ca, l_ad, ta)
        } else {
            side(g, l_bc, l_db, tb)
        };
        if !(l_cd.is_finite() && l_cd > 0.0) {
            return Err(Error::numerical(format!(
                "flipping edge ({a}, {b}) gave the length {l_cd} for ({c}, {d})"
            )));
        }
        Ok(l_cd)
    }

    /// **Intrinsic edge flip** of the interior edge of half-edge `h` (metric-preserving).
    ///
    /// The edge `(a, b)` between faces `(a, b, c)` and `(b, a, d)` is replaced by `(c, d)`:
    /// the two triangles are unfolded into the background plane (sphere, hyperbolic plane)
    /// across `(a, b)` and `|cd|` is the side opposite the angle `θ_a = ∠cab + ∠bad` between
    /// `|ac|` and `|ad|` (the stable half-angle form [`side`]). The flip is legal only if the
    /// quadrilateral `a d b c` is strictly convex at `a` and at `b` intrinsically
    /// (`∠cab + ∠bad < π` and `∠abc + ∠dba < π`, with a margin of 1e-9 rad), and `c ≠ d`
    /// are not already joined (the result stays a simplicial complex); otherwise it is
    /// refused with an error naming the edge and nothing changes. The cone metric is the
    /// same (curvatures and areas unchanged up to rounding: tested after > 1000 chained random
    /// flips to 1e-12 in E², 1e-10 in H² and S²).
    ///
    /// The faces keep their ids: face `f` of `h` becomes `(c, a, d)`, the twin face `g`
    /// becomes `(d, b, c)`. Positions are unchanged. A flipped face lies in the union of the
    /// two old faces; `face_origin` keeps, for each new face, the origin of the old face
    /// with the same id (the one holding its whole corner at `c`, resp. `d`).
    pub fn flip(&mut self, h: u32) -> Result<()> {
        let l_cd = self.flip_length(h)?;
        // The flipped diagonal is computed in double: the low parts are no longer valid.
        self.len_lo = None;
        let f = h / 3;
        let i = h % 3;
        let (h_ab, h_bc, h_ca) = (h, 3 * f + (i + 1) % 3, 3 * f + (i + 2) % 3);
        let (a, b, c) = (self.origin(h_ab), self.origin(h_bc), self.origin(h_ca));
        let hg = self.twin[h as usize];
        let gf = hg / 3;
        let j = hg % 3;
        let (h_ad, h_db) = (3 * gf + (j + 1) % 3, 3 * gf + (j + 2) % 3);
        let d = self.origin(h_db);
        let (l_bc, l_ca) = (self.len[h_bc as usize], self.len[h_ca as usize]);
        let (l_ad, l_db) = (self.len[h_ad as usize], self.len[h_db as usize]);
        let (t_bc, t_ca, t_ad, t_db) = (
            self.twin[h_bc as usize],
            self.twin[h_ca as usize],
            self.twin[h_ad as usize],
            self.twin[h_db as usize],
        );
        let set = |s: &mut Self, x: u32, y: u32| {
            s.twin[x as usize] = y;
            if y != NONE {
                s.twin[y as usize] = x;
            }
        };
        // f = (c, a, d): c→a, a→d, d→c.   g = (d, b, c): d→b, b→c, c→d.
        self.faces[f as usize] = [c, a, d];
        self.faces[gf as usize] = [d, b, c];
        let (f0, g0) = (3 * f, 3 * gf);
        self.len[f0 as usize] = l_ca;
        self.len[(f0 + 1) as usize] = l_ad;
        self.len[(f0 + 2) as usize] = l_cd;
        self.len[g0 as usize] = l_db;
        self.len[(g0 + 1) as usize] = l_bc;
        self.len[(g0 + 2) as usize] = l_cd;
        set(self, f0, t_ca);
        set(self, f0 + 1, t_ad);
        set(self, f0 + 2, g0 + 2);
        set(self, g0, t_db);
        set(self, g0 + 1, t_bc);
        self.vertex_corner[c as usize] = f0;
        self.vertex_corner[a as usize] = f0 + 1;
        self.vertex_corner[d as usize] = g0;
        self.vertex_corner[b as usize] = g0 + 1;
        Ok(())
    }
}

#[cfg(test)]
mod flip_tests {
    use super::*;
    use crate::metric::{curvature, total_area};

    /// Deterministic xorshift in [0, 1).
    fn rand(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Random legal flips on a generated genus-2 surface keep every vertex's curvature and
    /// the total area (the metric is the same cone metric); refused flips change nothing.
    #[test]
    fn random_flips_preserve_the_metric() {
        let s = crate::mesh::generate::genus(2, 12).unwrap();
        let l0 = s.edge_lengths();
        for g in [
            Geometry::Euclidean,
            Geometry::Hyperbolic,
            Geometry::Spherical,
        ] {
            // Scale so that the lengths are valid (and not tiny) in every geometry.
            let scale = if g == Geometry::Euclidean {
                1.0
            } else {
                0.3 / l0.iter().cloned().fold(0.0, f64::max)
            };
            let l: Vec<f64> = l0.iter().map(|x| x * scale).collect();
            let k0 = curvature(&s.mesh, g, &l);
            let a0 = total_area(&s.mesh, g, &l);
            let mut r = Refiner::new(&s.mesh, &l, g, Some(&s.positions)).unwrap();
            let mut state = 0x9e3779b97f4a7c15u64;
            let (mut done, mut refused) = (0, 0);
            for _ in 0..3000 {
                let h = (rand(&mut state) * r.len.len() as f64) as u32;
                let before = (r.faces.clone(), r.len.clone(), r.twin.clone());
                match r.flip(h) {
                    Ok(()) => done += 1,
                    Err(_) => {
                        refused += 1;
                        assert_eq!(before, (r.faces.clone(), r.len.clone(), r.twin.clone()));
                    }
                }
            }
            assert!(
                done > 1000 && refused > 0,
                "{g:?}: {done} flips, {refused} refused"
            );
            let out = r.finish().unwrap();
            assert_eq!(out.mesh.n_vertices(), s.mesh.n_vertices());
            assert_eq!(out.mesh.n_faces(), s.mesh.n_faces());
            assert_eq!(out.positions.as_deref(), Some(&s.positions[..]));
            // E²: 1e-12 after > 1000 chained flips. H², S²: the angles come from the
            // cosine law through acos (Geometry::angle), which loses ~1e-14 per flip on these
            // short sides; the drift over > 1000 chained flips stays below 1e-10.
            let tol = if g == Geometry::Euclidean {
                1e-12
            } else {
                1e-10
            };
            let k1 = curvature(&out.mesh, g, &out.lengths);
            for v in 0..k0.len() {
                assert!(
                    (k0[v] - k1[v]).abs() < tol,
                    "{g:?}: vertex {v}: K {} → {}",
                    k0[v],
                    k1[v]
                );
            }
            let a1 = total_area(&out.mesh, g, &out.lengths);
            assert!(
                (a0 - a1).abs() < tol * a0.max(1.0),
                "{g:?}: area {a0} → {a1}"
            );
        }
    }

    /// A flip of a non-convex quadrilateral, of a boundary edge, or one that would duplicate
    /// an edge is refused.
    #[test]
    fn illegal_flips_are_refused() {
        // Quad a=0, b=1, c=2, d=3: (0,1,2) and (1,0,3); c and d far from the line ab near a,
        // so the angle sum at a is > π (not convex at a).
        let mesh = Mesh::from_triangles(4, vec![[0, 1, 2], [1, 0, 3]]).unwrap();
        let p: [[f64; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [-0.5, 0.2], [-0.5, -0.2]];
        let d =
            |i: usize, j: usize| ((p[i][0] - p[j][0]).powi(2) + (p[i][1] - p[j][1]).powi(2)).sqrt();
        let lengths: Vec<f64> = (0..mesh.n_edges() as u32)
            .map(|e| {
                let [a, b] = mesh.edge_vertices(e);
                d(a as usize, b as usize)
            })
            .collect();
        let mut r = Refiner::new(&mesh, &lengths, Geometry::Euclidean, None).unwrap();
        let h = r.halfedge(0, 1).unwrap();
        let e = r.flip(h).unwrap_err().to_string();
        assert!(e.contains("not strictly convex"), "{e}");
        // A boundary edge.
        let hb = r.halfedge(1, 2).unwrap();
        assert!(r.flip(hb).is_err());
        // A convex quad flips, and the new diagonal has the Euclidean length |cd| of the planar quad
        let p2: [[f64; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [0.5, 0.7], [0.4, -0.6]];
        let d2 = |i: usize, j: usize| {
            ((p2[i][0] - p2[j][0]).powi(2) + (p2[i][1] - p2[j][1]).powi(2)).sqrt()
        };
        let l2: Vec<f64> = (0..mesh.n_edges() as u32)
            .map(|e| {
                let [a, b] = mesh.edge_vertices(e);
                d2(a as usize, b as usize)
            })
            .collect();
        let mut r = Refiner::new(&mesh, &l2, Geometry::Euclidean, None).unwrap();
        let h = r.halfedge(0, 1).unwrap();
        r.flip(h).unwrap();
        let hcd = r.halfedge(2, 3).unwrap();
        assert!((r.length(hcd) - d2(2, 3)).abs() < 1e-14);
        assert!(r.halfedge(0, 1).is_none());
        // On a tetrahedron every edge's opposite vertices are already joined.
        let tet =
            Mesh::from_triangles(4, vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]).unwrap();
        let mut r = Refiner::new(&tet, &[1.0; 6], Geometry::Euclidean, None).unwrap();
        let e = r.flip(0).unwrap_err().to_string();
        assert!(e.contains("already joined"), "{e}");
    }
}
