//! The geodesic spectrum of a closed hyperbolic surface from its own triangulation
//! ([`surface_spectrum`]): the search over a compact fundamental domain grown by hyperbolic
//! distance, with a cover by balls to drop tiles (the parent module [`super`] states the
//! method and why it is complete).

use super::*;

/// What [`surface_spectrum`] did besides the lengths.
#[derive(Debug, Clone)]
pub struct CompactDomain {
    /// Radius of the compact fundamental domain around its centre (the bound of the search
    /// is `L + 2·radius`).
    pub radius: f64,
    /// Faces of the domain and edges on its boundary (each edge twice).
    pub faces: usize,
    pub boundary_edges: usize,
    /// Distinct side pairings of the domain (a generating set of the deck group).
    pub generators: usize,
    /// Balls covering the domain (the tile test of the search).
    pub balls: usize,
}

/// A cover of a fundamental domain `F` by hyperbolic balls `B(c_j, r_j)` (hyperboloid
/// centres), for the conservative test `d(F, gF) ≤ L ⇒ ∃ j, k: d(c_j, g c_k) ≤ L + r_j + r_k`.
struct BallCover {
    /// (centre on the hyperboloid, centre in the disk, radius).
    balls: Vec<([f64; 3], Complex, f64)>,
    /// Largest distance from the domain's centre to one of its points.
    radius: f64,
    centre: [f64; 3],
}

/// Thresholds of [`BallCover::may_be_within`] for one length bound, in cosh form.
struct CoverLimits {
    /// cosh(L + r_j + r_k), widened, row-major.
    pair: Vec<f64>,
    /// cosh(L + r_j + radius), widened: a ball farther than this from g o cannot be near gF.
    reach: Vec<f64>,
}

impl BallCover {
    /// Greedy farthest-point cover of the vertices `points` of a triangulated domain with
    /// balls of radius about `r`, padded by `pad` (the longest edge: a point of a triangle is
    /// within its longest side of each of its corners), at most `max_balls` balls (the
    /// radius grows when the budget is reached).
    fn of_points(points: &[Complex], centre: Complex, r: f64, pad: f64, max_balls: usize) -> Self {
        let h: Vec<[f64; 3]> = points.iter().map(|&p| poincare_to_hyperboloid(p)).collect();
        let c0 = poincare_to_hyperboloid(centre);
        let cosh_d =
            |x: &[f64; 3], y: &[f64; 3]| (x[2] * y[2] - x[0] * y[0] - x[1] * y[1]).max(1.0);
        // Nearest chosen centre per point (cosh of the distance) and its index.
        let mut near: Vec<(f64, usize)> = h.iter().map(|x| (cosh_d(x, &c0), 0)).collect();
        let radius = near.iter().map(|n| n.0).fold(1.0, f64::max).acosh() + pad;
        let mut centres = vec![c0];
        let mut disk = vec![centre];
        let target = r.cosh();
        while centres.len() < max_balls {
            let (far, &(worst, _)) = near
                .iter()
                .enumerate()
                .max_by(|a, b| a.1 .0.total_cmp(&b.1 .0))
                .unwrap_or((0, &(1.0, 0)));
            if worst <= target {
                break;
            }
            let c = h[far];
            let k = centres.len();
            centres.push(c);
            disk.push(points[far]);
            for (x, n) in h.iter().zip(near.iter_mut()) {
                let d = cosh_d(x, &c);
                if d < n.0 {
                    *n = (d, k);
                }
            }
        }
        let mut rad = vec![0.0f64; centres.len()];
        for n in &near {
            rad[n.1] = rad[n.1].max(n.0);
        }
        let balls = centres
            .into_iter()
            .zip(disk)
            .zip(rad)
            .map(|((c, z), rc)| (c, z, rc.acosh() + pad))
            .collect();
        BallCover {
            balls,
            radius,
            centre: c0,
        }
    }

    fn limits(&self, l: f64, radius: f64) -> CoverLimits {
        // Widened by a relative 1e-9 so that rounding can only keep a tile more.
        let widen = |x: f64| x.cosh() * (1.0 + 1e-9) + 1e-9;
        let n = self.balls.len();
        CoverLimits {
            pair: (0..n * n)
                .map(|i| widen(l + self.balls[i / n].2 + self.balls[i % n].2))
                .collect(),
            reach: self.balls.iter().map(|b| widen(l + b.2 + radius)).collect(),
        }
    }

    /// False only if `d(F, gF) > L` is certain.
    fn may_be_within(&self, g: &Mobius, go: [f64; 3], lim: &CoverLimits) -> bool {
        let cosh_d = |x: &[f64; 3], y: &[f64; 3]| x[2] * y[2] - x[0] * y[0] - x[1] * y[1];
        let k = g.klein_matrix();
        let n = self.balls.len();
        let mut moved: Vec<Option<[f64; 3]>> = vec![None; n];
        for (j, bj) in self.balls.iter().enumerate() {
            if cosh_d(&bj.0, &go) > lim.reach[j] {
                continue;
            }
            let row = &lim.pair[j * n..(j + 1) * n];
            for (kk, bk) in self.balls.iter().enumerate() {
                let gk = *moved[kk].get_or_insert_with(|| apply_h(&k, bk.0));
                if cosh_d(&bj.0, &gk) <= row[kk] {
                    return true;
                }
            }
        }
        false
    }

    /// False only if the axis (the real diameter in the frame `fr`) certainly misses `F`.
    fn meets_axis(&self, fr: &Mobius) -> bool {
        self.balls.iter().any(|b| {
            let w = fr.apply(b.1);
            let sinh_d = 2.0 * w.im.abs() / (1.0 - w.norm_sqr()).max(1e-300);
            sinh_d.asinh() <= b.2 * (1.0 + 1e-9) + 1e-9
        })
    }
}

/// Length spectrum of a closed hyperbolic surface given by a triangulation with a hyperbolic
/// metric (`metric`, H², with or without double-double low parts, curvature 0 at every
/// vertex; `centre`: the vertex the domain grows from, default a central one), through a **compact fundamental domain** instead of the canonical polygon.
///
/// The domain `F` is the development of the surface along a spanning tree of the dual graph
/// grown in the order of the hyperbolic distance of each face's developed copy from a central
/// vertex (Prim on faces, developed in double precision for the order): the
/// surface is sliced along the edges the tree does not cross (a disk) and laid out in
/// double-double with the central face at the centre. Its side pairings (one per sliced
/// edge, deduplicated) generate the deck group. Because the faces were added nearest first,
/// `F` stays within about the surface's radius of its centre `o` (`radius`, measured on the
/// layout: the largest distance from `o` to a vertex of `F`; faces are geodesic triangles, so
/// `F ⊂ B(o, radius)`), whereas the canonical polygon of a genus-4 or genus-5 mesh reaches 12
/// or more, which made the search of [`fuchsian_spectrum`] visit millions of tiles.
///
/// Completeness (the argument of the module docs with this `F`): every class of length
/// `ℓ ≤ L` has a conjugate `γ` whose axis meets `F`; then `d(o, γo) ≤ ℓ + 2·radius`. The
/// tiles `gF` at distance ≤ L from `F` are connected under side adjacency, and all of them
/// satisfy `d(o, go) ≤ L + 2·radius`, so a breadth-first search through the side pairings
/// that keeps the tiles with `d(o, go) ≤ L + 2·radius` (widened by 1e-9 relative) finds every
/// such `γ`. Tiles are also dropped when a cover of `F` by balls `B(c_j, r_j)` of radius
/// about 1 proves `d(F, gF) > L` (`d(c_j, g c_k) > L + r_j + r_k` for all pairs), and words
/// are composed in double-double (the side pairings move `o` by up to `2·radius`; double
/// products lost the 1e-7 that tells two tiles apart). Classes are formed as in [`fuchsian_spectrum`] (the pieces of one closed geodesic
/// are linked through the sides its axis crosses). `L` starts at the shortest side pairing's
/// translation length; while fewer than `count` classes are complete it grows to the
/// `count`-th distinct length among the candidates up to `1.25 L` (certain to be enough: each
/// distinct length is a class), or to `1.25 L`. The search is grown, not redone: tiles kept
/// under a bound are kept under a larger one, and only the rejected tiles are tested again
/// (so the rounds cost about as much as the last one alone).
///
/// What the result proves: every free homotopy class of closed geodesics of length
/// `≤ complete_up_to` (= the final `L`) is among the classes found, because every tile `γF`
/// with `d(F, γF) ≤ L` was kept (the tests only drop tiles with `d(o, γo) > L + 2·radius` or
/// `d(c_j, γ c_k) > L + r_j + r_k` for all pairs of balls, each implying `d(F, γF) > L`), and
/// the kept tiles are connected to `F`; the `count` returned are the shortest of them.
///
/// Budgets: at most `max_tiles` tiles per search and 16 enlargements of `L`; exceeding either
/// is an error that says so.
pub fn surface_spectrum(
    mesh: &crate::mesh::Mesh,
    metric: &crate::metric::IntrinsicMetric,
    centre: Option<u32>,
    count: usize,
    max_tiles: usize,
) -> Result<(HyperbolicSpectrum, CompactDomain)> {
    let ne = mesh.n_edges();
    let lengths = metric.lengths();
    if metric.geometry() != crate::metric::Geometry::Hyperbolic {
        return Err(Error::input(format!(
            "the length spectrum of a surface is computed from a hyperbolic metric, this one is \
             {}",
            metric.geometry()
        )));
    }
    if lengths.len() != ne {
        return Err(Error::input(format!(
            "{} edge lengths for a mesh with {ne} edges",
            lengths.len()
        )));
    }
    if mesh.has_boundary() || mesh.n_faces() == 0 {
        return Err(Error::topology(
            "the length spectrum needs a closed surface (the mesh has a boundary or no faces)",
        ));
    }
    let o = match centre {
        Some(v) if (v as usize) < mesh.n_vertices() => v,
        Some(v) => {
            return Err(Error::input(format!(
                "centre vertex {v} does not exist (the mesh has {} vertices)",
                mesh.n_vertices()
            )))
        }
        None => crate::cut::central_vertex(mesh, lengths)?,
    };
    let (seed, crossed) = grow_domain(mesh, lengths, o)?;
    let dom = DomainPairings::new(mesh, metric, o, seed, &crossed)?;
    let max_edge = lengths.iter().copied().fold(0.0, f64::max);
    let cover = BallCover::of_points(&dom.positions, dom.centre, 1.0, max_edge, 400);
    let radius = cover.radius;
    let domain = CompactDomain {
        radius,
        faces: mesh.n_faces(),
        boundary_edges: dom.boundary.len(),
        generators: dom.generators.len(),
        balls: cover.balls.len(),
    };
    let mut l = dom
        .generators
        .iter()
        .map(|g| g.round().translation_length())
        .filter(|x| *x > 0.0)
        .fold(f64::INFINITY, f64::min);
    if !l.is_finite() {
        return Err(Error::numerical(
            "the side pairings are not hyperbolic isometries (is the metric hyperbolic?)",
        ));
    }
    let o_h = cover.centre;
    let mut search = TileSearch::new(o_h);
    for _round in 0..16 {
        let bound = ((l + 2.0 * radius) * (1.0 + 1e-9) + 1e-9).cosh();
        let limits = cover.limits(l, radius);
        let cosh_d = |x: [f64; 3], y: [f64; 3]| x[2] * y[2] - x[0] * y[0] - x[1] * y[1];
        let keep = |g: &Mobius, go: [f64; 3]| {
            cosh_d(o_h, go) <= bound && cover.may_be_within(g, go, &limits)
        };
        if !search.grow(o_h, &dom.generators, max_tiles, keep) {
            return Err(Error::numerical(format!(
                "the spectrum search exceeded its budget of {max_tiles} tiles of the \
                 universal cover at length bound {l:.3} (domain radius {radius:.2}); \
                 ask for fewer lengths"
            )));
        }
        // The axis is the real diameter in the frame: skip it when it misses every ball.
        let near = |fr: &Mobius| cover.meets_axis(fr);
        if let Some(sp) = search.spectrum(l, &dom.boundary, &dom.generators, o_h, count, near) {
            return Ok((sp, domain));
        }
        l = search.next_bound(l, &dom.boundary, count, near);
    }
    Err(Error::numerical(format!(
        "the spectrum search did not find {count} classes within its budget of 16 \
         enlargements of the length bound (last bound {l:.3})"
    )))
}

/// Dirichlet-like growth of a fundamental domain around vertex `o`: develop the faces in the
/// hyperbolic plane (double precision, for the order only) from a face at `o`, attaching next
/// the face whose developed copy lies nearest to `o` (largest |z| of its corners: the
/// hyperbolic distance 2 atanh|z| is monotone in |z|). Returns the seed face and the edges
/// the spanning tree of the dual graph crosses.
fn grow_domain(mesh: &crate::mesh::Mesh, lengths: &[f64], o: u32) -> Result<(u32, Vec<bool>)> {
    use crate::layout::place::Space;
    use crate::metric::Hyperbolic;
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let (nf, ne) = (mesh.n_faces(), mesh.n_edges());
    let seed = mesh
        .outgoing(o)
        .map(|h| mesh.he_face(h))
        .find(|&f| f != crate::mesh::NONE)
        .ok_or_else(|| Error::topology(format!("vertex {o} has no face")))?;
    let mut developed = vec![false; nf];
    let mut crossed = vec![false; ne];
    let mut corner = vec![Complex::new(0.0, 0.0); 3 * nf];
    let len = |h: u32| lengths[mesh.he_edge(h) as usize];
    {
        let hs = mesh.face_halfedges(seed);
        // Rotate the seed so that `o` is its first corner (at the centre of the disk).
        let i0 = mesh.face(seed).iter().position(|&v| v == o).unwrap_or(0);
        let p = Hyperbolic::seed(len(hs[i0]), len(hs[(i0 + 1) % 3]), len(hs[(i0 + 2) % 3]));
        for r in 0..3 {
            corner[3 * seed as usize + (i0 + r) % 3] = p[r];
        }
    }
    // Entries: (key = max |z|² of the copy's corners, face, half-edge of the face on the
    // shared edge, position of the corner opposite).
    type Entry = (Reverse<u64>, u32, u32, (u64, u64));
    let mut heap: BinaryHeap<Entry> = BinaryHeap::new();
    let push_neighbours =
        |f: u32, corner: &[Complex], developed: &[bool], heap: &mut BinaryHeap<Entry>| {
            for h in mesh.face_halfedges(f) {
                let t = mesh.he_twin(h);
                let g = mesh.he_face(t);
                if g == crate::mesh::NONE || developed[g as usize] {
                    continue;
                }
                // t runs b → a in g = (b, a, c).
                let pa = corner[h as usize];
                let pb = corner[mesh.he_next(h) as usize];
                let tn = mesh.he_next(t);
                let pc = Hyperbolic::third(pb, pa, len(t), len(tn), len(mesh.he_next(tn)));
                if pc.norm_sqr().is_nan() || pc.norm_sqr() >= 1.0 {
                    continue; // numerically outside the disk: never the nearest copy
                }
                let key = pa.norm_sqr().max(pb.norm_sqr()).max(pc.norm_sqr());
                let pc_bits = (pc.re.to_bits(), pc.im.to_bits());
                heap.push((Reverse(key.to_bits()), g, t, pc_bits));
            }
        };
    developed[seed as usize] = true;
    push_neighbours(seed, &corner, &developed, &mut heap);
    while let Some((_, g, t, (cre, cim))) = heap.pop() {
        if developed[g as usize] {
            continue;
        }
        developed[g as usize] = true;
        crossed[mesh.he_edge(t) as usize] = true;
        let h = mesh.he_twin(t);
        let tn = mesh.he_next(t);
        corner[t as usize] = corner[mesh.he_next(h) as usize];
        corner[tn as usize] = corner[h as usize];
        corner[mesh.he_next(tn) as usize] = Complex::new(f64::from_bits(cre), f64::from_bits(cim));
        push_neighbours(g, &corner, &developed, &mut heap);
    }
    if developed.iter().any(|&d| !d) {
        return Err(Error::topology("the surface is not connected"));
    }
    Ok((seed, crossed))
}

/// The compact fundamental domain laid out in double-double and its side pairings.
struct DomainPairings {
    /// Layout of the sliced surface (double part).
    positions: Vec<Complex>,
    /// The copy of the centre vertex in the seed face.
    centre: Complex,
    /// Distinct side pairings (a generating set of the deck group).
    generators: Vec<MobiusDd>,
    /// Boundary cycle: (position, generator of the side starting there).
    boundary: Vec<(Complex, usize)>,
}

impl DomainPairings {
    /// Slice `mesh` along the edges the tree does not cross, lay the disk out in double-double
    /// from `seed`, and read the side pairings: the sliced edge h (face f) and its twin t (face
    /// f') are two sides; the map S_h takes F onto the tile across h, i.e. t's copy onto h's
    /// copy, reversed.
    fn new(
        mesh: &crate::mesh::Mesh,
        metric: &crate::metric::IntrinsicMetric,
        o: u32,
        seed: u32,
        crossed: &[bool],
    ) -> Result<Self> {
        use crate::layout::place::layout_dd;
        use crate::metric::Hyperbolic;
        use crate::numeric::dd::Cdd;
        let cut: Vec<bool> = crossed.iter().map(|&c| !c).collect();
        let (cm, origin) = crate::cut::slice(mesh, &cut)?;
        let lay = layout_dd::<Hyperbolic>(&cm, &metric.carried_to(mesh, &cm), Some(seed))?;
        if !lay.flipped_faces.is_empty() {
            return Err(Error::numerical(format!(
                "the compact fundamental domain has {} flipped faces (face {}); is the metric \
                 hyperbolic and converged?",
                lay.flipped_faces.len(),
                lay.flipped_faces[0]
            )));
        }
        let pos = |v: u32| Cdd::from_parts(lay.positions[v as usize], lay.positions_lo[v as usize]);
        let loops = cm.boundary_loop_halfedges();
        if loops.len() != 1 {
            return Err(Error::numerical(format!(
                "internal error: the sliced surface has {} boundary loops",
                loops.len()
            )));
        }
        let i0 = cm
            .face(seed)
            .iter()
            .position(|&v| origin[v as usize] == o)
            .unwrap_or(0);
        let centre = lay.positions[cm.face(seed)[i0] as usize];
        let o_h = poincare_to_hyperboloid(centre);
        let mut generators: Vec<MobiusDd> = Vec::new();
        let mut gen_index = TileIndex::new();
        let mut boundary: Vec<(Complex, usize)> = Vec::with_capacity(loops[0].len());
        for &h in &loops[0] {
            let t = mesh.he_twin(h);
            let m = MobiusDd::from_pairs(
                pos(cm.he_origin(t)),
                pos(cm.he_tip(t)),
                pos(cm.he_tip(h)),
                pos(cm.he_origin(h)),
            )
            .normalized();
            let go = apply_h(&m.round().klein_matrix(), o_h);
            let k = match gen_index.find(go) {
                Some(k) => k,
                None => {
                    generators.push(m);
                    gen_index.insert(go)
                }
            };
            boundary.push((lay.positions[cm.he_origin(h) as usize], k));
        }
        Ok(DomainPairings {
            positions: lay.positions,
            centre,
            generators,
            boundary,
        })
    }
}
