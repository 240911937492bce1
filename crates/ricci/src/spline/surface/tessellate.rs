//! The tessellation of a manifold spline surface (paper 000 §5, last paragraph): one welded,
//! consistently oriented triangle mesh, the spline part trimmed exactly at each seam and the
//! fill patches triangulated on rings whose outer ring is the seam.

use std::collections::{BTreeMap, HashMap};

use super::ManifoldSpline;
use crate::atlas::FlatCharts;
use crate::error::{Error, Result};
use crate::numeric::vec3::{dot as dot3, sub as sub3};
use crate::spline::dms::Workspace;
use crate::spline::hole::Hole;
use crate::spline::manifold::ManifoldSpace;

/// A tessellated spline surface: one welded, consistently oriented triangle mesh. The spline
/// part is trimmed exactly at the seams; each fill patch's outer ring is the spline part's
/// seam vertices, so spline and fill share those vertices and edges (no gap, no T-junction,
/// vertex normals average across the seam). A closed input gives a closed mesh.
#[derive(Debug, Clone, Default)]
pub struct Tessellation {
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// Domain face of each vertex (`-1` for the fill patches' own vertices; seam vertices
    /// are points of the spline and carry their face).
    pub vertex_face: Vec<i64>,
    /// Canonical chart of the face (`-1` for the fill).
    pub vertex_chart: Vec<i64>,
    /// Barycentric coordinates of each vertex in its `vertex_face` (`[0; 3]` for the fill).
    pub vertex_bary: Vec<[f64; 3]>,
    /// Triangles `0..spline_triangles` are spline, the rest fill.
    pub spline_triangles: usize,
    /// Patch boundaries: images of the domain edges (trimmed at the seams), then the seams.
    pub boundaries: Vec<Vec<[f64; 3]>>,
    /// The seam of each fill patch as it is in the mesh.
    pub seams: Vec<SeamLoop>,
}

/// The seam of one fill patch in a [`Tessellation`]: vertices that lie on the seam curve, in
/// the order of the spline part's boundary (spline on the left).
#[derive(Debug, Clone, Default)]
pub struct SeamLoop {
    /// Index into [`ManifoldSpline::holes`].
    pub hole: usize,
    pub vertices: Vec<u32>,
    /// Seam parameter `ψ ∈ [0, 2π)` of each vertex: its position is the spline at
    /// (`vertex_face`, `vertex_bary`) and also [`Hole::fill_point`] at `t = 1`, `ψ`.
    pub psi: Vec<f64>,
    /// Grid points moved onto the seam (crossings closer than [`SEAM_SNAP`] of a grid edge to
    /// one of its ends).
    pub snapped: usize,
}

/// A grid edge crossing the seam closer than this fraction of its length to one end moves
/// that end onto the seam instead of cutting the edge there (no sliver triangles; the move
/// is along the grid edge, so no triangle folds).
pub const SEAM_SNAP: f64 = 0.25;

/// First ring step of the fill patch's triangulation next to the seam, as a fraction of its
/// regular ring step (see [`tessellate`]).
pub const FILL_GRADING: f64 = 0.5;
/// Growth of the fill's ring steps from the seam inwards.
pub const FILL_GROWTH: f64 = 1.5;

/// A grid point of the tessellation that several faces share: a domain vertex, or the `k`-th
/// of the `m − 1` inner points of a domain edge counted from the origin of its lower-numbered
/// half-edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum GridKey {
    Vertex(u32),
    Edge(u32, usize),
}

/// The shared key of the grid point with integer barycentric weights `w` (summing to `m`) in
/// face `f`, or `None` for a point inside the face.
fn grid_key(mesh: &crate::mesh::Mesh, f: u32, w: [usize; 3]) -> Option<GridKey> {
    let zeros = w.iter().filter(|&&x| x == 0).count();
    if zeros == 2 {
        let c = (0..3).find(|&c| w[c] != 0)?;
        return Some(GridKey::Vertex(mesh.face(f)[c]));
    }
    if zeros != 1 {
        return None;
    }
    let z = (0..3).find(|&c| w[c] == 0)?;
    // The edge opposite corner z runs from corner a = z + 1 to corner b = z + 2 (half-edge
    // 3f + a goes from corner a to corner a + 1).
    let (a, b) = ((z + 1) % 3, (z + 2) % 3);
    let h = 3 * f + a as u32;
    let tw = mesh.he_twin(h);
    let k = if mesh.is_boundary_halfedge(tw) || h < tw {
        w[b]
    } else {
        w[a]
    };
    Some(GridKey::Edge(mesh.he_edge(h), k))
}

/// Seam level of a point: the hole whose two-ring holds it and `ln ρ − ln R` (negative inside);
/// `None` away from every hole.
type SeamLevel = Option<(usize, f64)>;

/// Where a grid edge of the tessellation crosses a seam.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    hole: usize,
    face: u32,
    bary: [f64; 3],
    psi: f64,
    /// Fraction of the edge from its lower-numbered end.
    s: f64,
}

/// Sample every active face on a grid of `m` segments per edge and weld the grid points on
/// domain vertices and edges (the spline is continuous there), so the spline part is one
/// connected mesh. Trim it at each seam: grid points get the sign of [`Hole::seam_level`];
/// grid edges that cross the seam are cut at the crossing, found on the seam in (face,
/// barycentric) coordinates through the hole's unrolled cone coordinates
/// ([`Hole::seam_crossing`]); crossings within [`SEAM_SNAP`] of a grid point move that point
/// onto the seam instead. Sub-triangles keep their part outside the seam (a triangle or a quad
/// split along its better diagonal). The boundary edges of the trimmed part form one closed
/// curve per seam, all of whose vertices lie on the seam; the fill patch is triangulated on
/// rings `t = k/n_t` of its disk whose outer ring is exactly that curve (inner rings placed
/// by the seam's arc length, consecutive rings zipped by parameter order). Unused grid points
/// are dropped.
pub fn tessellate<A: FlatCharts + Sync + ?Sized>(
    space: &ManifoldSpace<'_, A>,
    spline: &ManifoldSpline,
    m: usize,
) -> Result<Tessellation> {
    let grid = FaceGrid::new(m.max(1));
    let m = grid.m;
    let mesh = space.charts().mesh();
    let holes = &spline.holes;
    let faces: Vec<u32> = (0..mesh.n_faces() as u32)
        .filter(|&f| space.is_active(f))
        .collect();
    let Welded {
        mut t,
        mut level,
        ids,
    } = sample_welded(space, spline, &grid, &faces)?;
    let crossings = seam_crossings(&grid, &faces, &ids, &level, holes)?;
    let seam = place_seam_vertices(space, spline, &mut t, &mut level, crossings)?;
    clip(&mut t, &grid, &ids, &level, &seam)?;
    t.spline_triangles = t.triangles.len();
    t.seams = seam_loops(&t, &level, &seam, holes, m)?;
    // Fill patches whose outer rings are the seams.
    for seam in t.seams.clone() {
        fill_patch(space, spline, &seam, &mut t)?;
    }
    drop_unused(&mut t);
    t.boundaries = domain_edge_lines(space, spline, m)?;
    for seam in &t.seams {
        let mut line: Vec<[f64; 3]> = seam
            .vertices
            .iter()
            .map(|&v| t.positions[v as usize])
            .collect();
        line.push(line[0]);
        t.boundaries.push(line);
    }
    Ok(t)
}

/// The sample grid of one face: `m` segments per edge, grid points `(i, j)` with barycentric
/// coordinates `((m − i − j)/m, i/m, j/m)`, and its sub-triangles.
struct FaceGrid {
    m: usize,
    points: Vec<(usize, usize)>,
    subtri: Vec<[usize; 3]>,
}

impl FaceGrid {
    fn new(m: usize) -> FaceGrid {
        let points: Vec<(usize, usize)> = (0..=m)
            .flat_map(|i| (0..=m - i).map(move |j| (i, j)))
            .collect();
        let idx =
            |i: usize, j: usize| -> usize { points.iter().position(|&x| x == (i, j)).unwrap_or(0) };
        let mut subtri = Vec::new();
        for i in 0..m {
            for j in 0..m - i {
                subtri.push([idx(i, j), idx(i + 1, j), idx(i, j + 1)]);
                if i + j + 1 < m {
                    subtri.push([idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)]);
                }
            }
        }
        FaceGrid { m, points, subtri }
    }

    fn bary(&self, q: usize) -> [f64; 3] {
        let (m, (i, j)) = (self.m, self.points[q]);
        [
            (m - i - j) as f64 / m as f64,
            i as f64 / m as f64,
            j as f64 / m as f64,
        ]
    }
}

/// Seam level of a point: (hole, ln ρ − ln R), negative inside.
fn level_at(holes: &[Hole], f: u32, b: [f64; 3]) -> SeamLevel {
    holes
        .iter()
        .enumerate()
        .find_map(|(h, hole)| hole.seam_level(f, b).map(|l| (h, l)))
}

/// Whether a point of seam level `l` lies inside a seam.
fn inside(l: SeamLevel) -> bool {
    l.is_some_and(|(_, x)| x < 0.0)
}

/// The welded samples of the active faces: the tessellation's vertices so far, their seam
/// levels, and per face the vertex id of each grid point.
struct Welded {
    t: Tessellation,
    level: Vec<SeamLevel>,
    ids: Vec<Vec<u32>>,
}

/// Evaluate the spline on the grid of every face in `faces` and weld: a grid point on a domain
/// vertex or edge is one vertex of the tessellation, shared by the faces around it (its value
/// and seam level are taken from the first face that reaches it), so the spline part is one
/// connected mesh and vertex normals average across patch boundaries instead of stopping at
/// them. The owners are decided first (in face order), so each shared point is evaluated once.
fn sample_welded<A: FlatCharts + Sync + ?Sized>(
    space: &ManifoldSpace<'_, A>,
    spline: &ManifoldSpline,
    grid: &FaceGrid,
    faces: &[u32],
) -> Result<Welded> {
    use rayon::prelude::*;
    let (m, mesh, control) = (grid.m, space.charts().mesh(), &spline.control);
    // Owners: a shared point is the first face's to reach it; `own[k]`: face k's new points.
    let mut shared: HashMap<GridKey, u32> = HashMap::new();
    let mut ids: Vec<Vec<u32>> = Vec::with_capacity(faces.len());
    let mut own: Vec<Vec<usize>> = Vec::with_capacity(faces.len());
    let mut n = 0u32;
    for &f in faces {
        let mut local = Vec::with_capacity(grid.points.len());
        let mut mine = Vec::with_capacity(grid.points.len());
        for (q, &(i, j)) in grid.points.iter().enumerate() {
            let id = match grid_key(mesh, f, [m - i - j, i, j]) {
                Some(key) => *shared.entry(key).or_insert(n),
                None => n,
            };
            if id == n {
                mine.push(q);
                n += 1;
            }
            local.push(id);
        }
        ids.push(local);
        own.push(mine);
    }
    #[allow(clippy::type_complexity)]
    let per: Vec<(Vec<[f64; 3]>, Vec<SeamLevel>)> = faces
        .par_iter()
        .zip(&own)
        .map(|(&f, mine)| -> Result<(Vec<[f64; 3]>, Vec<SeamLevel>)> {
            let (mut ws, mut out) = (Workspace::default(), [0.0; 3]);
            let mut p = Vec::with_capacity(mine.len());
            let mut lv = Vec::with_capacity(mine.len());
            for &q in mine {
                let b = grid.bary(q);
                space.evaluate(control, 3, f, b, 0, &mut ws, &mut out)?;
                p.push(out);
                lv.push(level_at(&spline.holes, f, b));
            }
            Ok((p, lv))
        })
        .collect::<Result<_>>()?;
    let mut t = Tessellation::default();
    let mut level: Vec<SeamLevel> = Vec::with_capacity(n as usize);
    for (k, (p, lv)) in per.into_iter().enumerate() {
        let f = faces[k];
        let chart = space.canonical_chart(f) as i64;
        for (&q, (x, l)) in own[k].iter().zip(p.into_iter().zip(lv)) {
            t.positions.push(x);
            t.vertex_face.push(f as i64);
            t.vertex_chart.push(chart);
            t.vertex_bary.push(grid.bary(q));
            level.push(l);
        }
    }
    Ok(Welded { t, level, ids })
}

/// The grid edges that cross a seam, keyed by their (lower, higher) vertex ids, with the
/// crossing found on the seam ([`Hole::seam_crossing`]).
fn seam_crossings(
    grid: &FaceGrid,
    faces: &[u32],
    ids: &[Vec<u32>],
    level: &[SeamLevel],
    holes: &[Hole],
) -> Result<BTreeMap<(u32, u32), Crossing>> {
    let mut crossings: BTreeMap<(u32, u32), Crossing> = BTreeMap::new();
    for (k, &f) in faces.iter().enumerate() {
        for s in &grid.subtri {
            for e in 0..3 {
                let (qa, qb) = (s[e], s[(e + 1) % 3]);
                let (a, b) = (ids[k][qa], ids[k][qb]);
                let (la, lb) = (level[a as usize], level[b as usize]);
                if inside(la) == inside(lb) {
                    continue;
                }
                let key = (a.min(b), a.max(b));
                if crossings.contains_key(&key) {
                    continue;
                }
                let h = la.or(lb).map(|x| x.0).unwrap_or(0);
                let (s_ab, bary, psi) = holes[h]
                    .seam_crossing(f, grid.bary(qa), grid.bary(qb))
                    .ok_or_else(|| {
                        Error::numerical(format!(
                            "tessellation: face {f} meets the seam around vertex {} but is not in \
                             its two-ring",
                            holes[h].vertex
                        ))
                    })?;
                crossings.insert(
                    key,
                    Crossing {
                        hole: h,
                        face: f,
                        bary,
                        psi,
                        s: if a < b { s_ab } else { 1.0 - s_ab },
                    },
                );
            }
        }
    }
    Ok(crossings)
}

/// The tessellation's vertices on the seams, after [`place_seam_vertices`].
struct SeamVertices {
    /// Seam parameter of the vertices on a seam (by vertex id).
    psi: Vec<Option<f64>>,
    /// Grid points moved onto each hole's seam.
    snapped: Vec<usize>,
    /// The vertex made at each remaining crossing (keyed like the crossings).
    crossing_vertex: HashMap<(u32, u32), u32>,
}

/// Put vertices on the seams: a grid point whose nearest crossing is within [`SEAM_SNAP`] of
/// it moves there; every other crossing becomes a new vertex. Both are evaluated on the
/// spline at their (face, barycentric) place on the seam.
fn place_seam_vertices<A: FlatCharts + Sync + ?Sized>(
    space: &ManifoldSpace<'_, A>,
    spline: &ManifoldSpline,
    t: &mut Tessellation,
    level: &mut Vec<SeamLevel>,
    mut crossings: BTreeMap<(u32, u32), Crossing>,
) -> Result<SeamVertices> {
    use rayon::prelude::*;
    let control = &spline.control;
    // Snap: a grid point whose nearest crossing is within SEAM_SNAP of it moves there.
    let mut snap: BTreeMap<u32, (f64, (u32, u32))> = BTreeMap::new();
    for (&key, c) in &crossings {
        for (v, d) in [(key.0, c.s), (key.1, 1.0 - c.s)] {
            if d < SEAM_SNAP && snap.get(&v).is_none_or(|x| d < x.0) {
                snap.insert(v, (d, key));
            }
        }
    }
    let mut seam_psi: Vec<Option<f64>> = vec![None; t.positions.len()];
    let mut snapped = vec![0usize; spline.holes.len()];
    let mut moved: Vec<(u32, Crossing)> = Vec::with_capacity(snap.len());
    for (&v, &(_, key)) in &snap {
        let c = crossings[&key];
        seam_psi[v as usize] = Some(c.psi);
        level[v as usize] = Some((c.hole, 0.0));
        snapped[c.hole] += 1;
        moved.push((v, c));
    }
    crossings.retain(|k, _| seam_psi[k.0 as usize].is_none() && seam_psi[k.1 as usize].is_none());
    // New vertices at the remaining crossings.
    let mut crossing_vertex: HashMap<(u32, u32), u32> = HashMap::new();
    let first_new = t.positions.len();
    for (&key, c) in &crossings {
        crossing_vertex.insert(key, t.positions.len() as u32);
        t.positions.push([0.0; 3]);
        t.vertex_face.push(c.face as i64);
        t.vertex_chart.push(space.canonical_chart(c.face) as i64);
        t.vertex_bary.push(c.bary);
        level.push(Some((c.hole, 0.0)));
        seam_psi.push(Some(c.psi));
    }
    let evaluated: Vec<[f64; 3]> = moved
        .iter()
        .map(|x| &x.1)
        .chain(crossings.values())
        .collect::<Vec<_>>()
        .par_iter()
        .map(|c| -> Result<[f64; 3]> {
            let mut ws = Workspace::default();
            let mut out = [0.0; 3];
            space.evaluate(control, 3, c.face, c.bary, 0, &mut ws, &mut out)?;
            Ok(out)
        })
        .collect::<Result<_>>()?;
    for (k, (v, c)) in moved.iter().enumerate() {
        let v = *v as usize;
        t.positions[v] = evaluated[k];
        t.vertex_face[v] = c.face as i64;
        t.vertex_chart[v] = space.canonical_chart(c.face) as i64;
        t.vertex_bary[v] = c.bary;
    }
    for (k, p) in evaluated[moved.len()..].iter().enumerate() {
        t.positions[first_new + k] = *p;
    }
    Ok(SeamVertices {
        psi: seam_psi,
        snapped,
        crossing_vertex,
    })
}

/// Clip the sub-triangles: keep the part outside the seams (a triangle, or a quad split
/// along the diagonal with the larger smallest angle).
fn clip(
    t: &mut Tessellation,
    grid: &FaceGrid,
    ids: &[Vec<u32>],
    level: &[SeamLevel],
    seam: &SeamVertices,
) -> Result<()> {
    #[derive(Clone, Copy, PartialEq, Eq)]
    enum Side {
        In,
        On,
        Out,
    }
    let side = |v: u32| {
        if seam.psi[v as usize].is_some() {
            Side::On
        } else if inside(level[v as usize]) {
            Side::In
        } else {
            Side::Out
        }
    };
    for local in ids {
        for s in &grid.subtri {
            let g = s.map(|q| local[q]);
            let sides = g.map(side);
            if !sides.contains(&Side::Out) {
                continue;
            }
            if !sides.contains(&Side::In) {
                t.triangles.push(g);
                continue;
            }
            let mut poly: Vec<u32> = Vec::with_capacity(4);
            for e in 0..3 {
                let (a, b) = (g[e], g[(e + 1) % 3]);
                if sides[e] != Side::In {
                    poly.push(a);
                }
                let pair = (sides[e], sides[(e + 1) % 3]);
                if pair == (Side::In, Side::Out) || pair == (Side::Out, Side::In) {
                    let key = (a.min(b), a.max(b));
                    poly.push(*seam.crossing_vertex.get(&key).ok_or_else(|| {
                        Error::numerical(format!(
                            "tessellation: grid edge {key:?} crosses a seam but has no crossing point"
                        ))
                    })?);
                }
            }
            match poly.len() {
                3 => t.triangles.push([poly[0], poly[1], poly[2]]),
                4 => {
                    let p = |v: u32| t.positions[v as usize];
                    let q = |a: u32, b: u32, c: u32| min_angle(p(a), p(b), p(c));
                    let d02 = q(poly[0], poly[1], poly[2]).min(q(poly[0], poly[2], poly[3]));
                    let d13 = q(poly[0], poly[1], poly[3]).min(q(poly[1], poly[2], poly[3]));
                    if d02 >= d13 {
                        t.triangles.push([poly[0], poly[1], poly[2]]);
                        t.triangles.push([poly[0], poly[2], poly[3]]);
                    } else {
                        t.triangles.push([poly[0], poly[1], poly[3]]);
                        t.triangles.push([poly[1], poly[2], poly[3]]);
                    }
                }
                _ => {}
            }
        }
    }
    Ok(())
}

/// The seams as the spline part's boundary: directed edges without a reverse whose ends are
/// both on a seam, chained into one closed curve per hole (`m` only names the resolution in
/// the errors).
fn seam_loops(
    t: &Tessellation,
    level: &[SeamLevel],
    seam: &SeamVertices,
    holes: &[Hole],
    m: usize,
) -> Result<Vec<SeamLoop>> {
    let seam_psi = &seam.psi;
    // The directed edges, sorted (a set: a binary search per edge is several times cheaper
    // than hashing the half-million edges of a fine tessellation).
    let key = |a: u32, b: u32| (a as u64) << 32 | b as u64;
    let mut directed: Vec<u64> = Vec::with_capacity(3 * t.triangles.len());
    for tri in &t.triangles {
        for e in 0..3 {
            directed.push(key(tri[e], tri[(e + 1) % 3]));
        }
    }
    directed.sort_unstable();
    let mut next: Vec<BTreeMap<u32, u32>> = vec![BTreeMap::new(); holes.len()];
    for tri in &t.triangles {
        for e in 0..3 {
            let (a, b) = (tri[e], tri[(e + 1) % 3]);
            if directed.binary_search(&key(b, a)).is_ok()
                || seam_psi[a as usize].is_none()
                || seam_psi[b as usize].is_none()
            {
                continue;
            }
            let h = level[a as usize].map(|x| x.0).unwrap_or(0);
            if next[h].insert(a, b).is_some() {
                return Err(Error::numerical(format!(
                    "tessellation: the trimmed spline touches itself at a point of the seam around \
                     vertex {} (try another resolution than {m})",
                    holes[h].vertex
                )));
            }
        }
    }
    let mut seams = Vec::with_capacity(holes.len());
    for (h, hole) in holes.iter().enumerate() {
        let Some((&start, _)) = next[h].iter().next() else {
            return Err(Error::numerical(format!(
                "tessellation: the seam around vertex {} crosses no grid edge",
                hole.vertex
            )));
        };
        let mut vertices = vec![start];
        let mut v = start;
        loop {
            let Some(&w) = next[h].get(&v) else {
                return Err(Error::numerical(format!(
                    "tessellation: the seam around vertex {} is not a closed curve",
                    hole.vertex
                )));
            };
            if w == start {
                break;
            }
            if vertices.len() > next[h].len() {
                break;
            }
            vertices.push(w);
            v = w;
        }
        if vertices.len() != next[h].len() {
            return Err(Error::numerical(format!(
                "tessellation: the trimmed spline has {} boundary edges on the seam around vertex \
                 {} but they form a curve of {} (the seam is not one closed curve; try another \
                 resolution than {m})",
                next[h].len(),
                hole.vertex,
                vertices.len()
            )));
        }
        let psi = vertices
            .iter()
            .map(|&v| seam_psi[v as usize].unwrap_or(0.0))
            .collect();
        seams.push(SeamLoop {
            hole: h,
            vertices,
            psi,
            snapped: seam.snapped[h],
        });
    }
    Ok(seams)
}

/// Drop the grid points no triangle uses (those inside the seams), renumbering the rest in
/// order of first use.
fn drop_unused(t: &mut Tessellation) {
    let mut map = vec![u32::MAX; t.positions.len()];
    let mut n = 0u32;
    for tri in &t.triangles {
        for &v in tri {
            if map[v as usize] == u32::MAX {
                map[v as usize] = n;
                n += 1;
            }
        }
    }
    let mut order = vec![0usize; n as usize];
    for (v, &w) in map.iter().enumerate() {
        if w != u32::MAX {
            order[w as usize] = v;
        }
    }
    t.positions = order.iter().map(|&v| t.positions[v]).collect();
    t.vertex_face = order.iter().map(|&v| t.vertex_face[v]).collect();
    t.vertex_chart = order.iter().map(|&v| t.vertex_chart[v]).collect();
    t.vertex_bary = order.iter().map(|&v| t.vertex_bary[v]).collect();
    for tri in &mut t.triangles {
        *tri = tri.map(|v| map[v as usize]);
    }
    for seam in &mut t.seams {
        for v in &mut seam.vertices {
            *v = map[*v as usize];
        }
    }
}

/// The domain edges as polylines of `m` segments (once per edge), trimmed at the seams.
fn domain_edge_lines<A: FlatCharts + Sync + ?Sized>(
    space: &ManifoldSpace<'_, A>,
    spline: &ManifoldSpline,
    m: usize,
) -> Result<Vec<Vec<[f64; 3]>>> {
    use rayon::prelude::*;
    let (mesh, control, holes) = (space.charts().mesh(), &spline.control, &spline.holes);
    // Each domain edge once (from its higher half-edge's active face), side by side.
    let edges: Vec<u32> = (0..mesh.n_corners() as u32)
        .filter(|&h| {
            let tw = mesh.he_twin(h);
            space.is_active(h / 3)
                && !(!mesh.is_boundary_halfedge(tw) && space.is_active(tw / 3) && tw < h)
        })
        .collect();
    let per: Vec<Vec<Vec<[f64; 3]>>> = edges
        .par_iter()
        .map_init(Workspace::default, |ws, &h| {
            edge_lines(space, control, holes, h, m, ws)
        })
        .collect::<Result<_>>()?;
    Ok(per.into_iter().flatten().collect())
}

/// The polylines of half-edge `h`'s domain edge (see [`domain_edge_lines`]).
fn edge_lines<A: FlatCharts + Sync + ?Sized>(
    space: &ManifoldSpace<'_, A>,
    control: &[f64],
    holes: &[Hole],
    h: u32,
    m: usize,
    ws: &mut Workspace,
) -> Result<Vec<Vec<[f64; 3]>>> {
    let (mut out, mut lines) = ([0.0; 3], Vec::new());
    let (f, i) = (h / 3, h as usize % 3);
    let mut line: Vec<[f64; 3]> = Vec::with_capacity(m + 1);
    let mut prev: Option<([f64; 3], SeamLevel)> = None;
    for s in 0..=m {
        let a = s as f64 / m as f64;
        let mut b = [0.0; 3];
        b[i] = 1.0 - a;
        b[(i + 1) % 3] = a;
        let lv = level_at(holes, f, b);
        if let Some((pb, pl)) = prev {
            if inside(pl) != inside(lv) {
                // The edge enters or leaves a seam between two samples: end or start the
                // polyline on the seam.
                let hh = pl.or(lv).map(|x| x.0).unwrap_or(0);
                if let Some((_, bc, _)) = holes[hh].seam_crossing(f, pb, b) {
                    space.evaluate(control, 3, f, bc, 0, ws, &mut out)?;
                    line.push(out);
                }
                if inside(lv) {
                    if line.len() >= 2 {
                        lines.push(std::mem::take(&mut line));
                    }
                    line.clear();
                }
            }
        }
        prev = Some((b, lv));
        if inside(lv) {
            continue;
        }
        space.evaluate(control, 3, f, b, 0, ws, &mut out)?;
        line.push(out);
    }
    if line.len() >= 2 {
        lines.push(line);
    }
    Ok(lines)
}

/// Smallest angle of a triangle (radians; 0 for a degenerate one).
fn min_angle(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let ang = |p: [f64; 3], q: [f64; 3], r: [f64; 3]| {
        let (u, v) = (sub3(q, p), sub3(r, p));
        let d = (dot3(u, u) * dot3(v, v)).sqrt();
        if d > 0.0 {
            (dot3(u, v) / d).clamp(-1.0, 1.0).acos()
        } else {
            0.0
        }
    };
    ang(a, b, c).min(ang(b, c, a)).min(ang(c, a, b))
}

/// Triangulate the fill patch of `seam.hole` inside its seam loop (already vertices of `t`):
/// the seam is the ring `t = 1` of the patch's disk; the regular ring step `1/n_t` makes rings
/// about as far apart as the seam's vertices. Next to the seam the steps start at
/// [`FILL_GRADING`]`/n_t` and grow by [`FILL_GROWTH`] (the patch bends more than the spline
/// there, and the spline's trimmed triangles are small), and those rings keep the seam's own
/// `ψ` (a quad strip along radial lines, which cannot fold however thin). The regular rings
/// inside have `max(5, round(n t))` points at equal steps of the seam's arc length, and the
/// centre closes the disk. Consecutive rings are zipped by arc-length order; orientation is
/// the spline's.
fn fill_patch<A: FlatCharts + Sync + ?Sized>(
    space: &ManifoldSpace<'_, A>,
    spline: &ManifoldSpline,
    seam: &SeamLoop,
    t: &mut Tessellation,
) -> Result<()> {
    use rayon::prelude::*;
    use std::f64::consts::PI;
    let hole = &spline.holes[seam.hole];
    let n = seam.vertices.len();
    if n < 3 {
        return Err(Error::numerical(format!(
            "tessellation: the seam around vertex {} has only {n} vertices",
            hole.vertex
        )));
    }
    // ψ unwrapped along the loop; the loop must wind once around the cone.
    let mut psi_u = Vec::with_capacity(n + 1);
    psi_u.push(seam.psi[0]);
    for k in 1..=n {
        let d = seam.psi[k % n] - seam.psi[k - 1];
        let d = d - 2.0 * PI * (d / (2.0 * PI)).round();
        psi_u.push(psi_u[k - 1] + d);
    }
    let total = psi_u[n] - psi_u[0];
    if (total.abs() - 2.0 * PI).abs() > 1e-6 {
        return Err(Error::numerical(format!(
            "tessellation: the seam around vertex {} winds {:.3} times around it, not once",
            hole.vertex,
            total / (2.0 * PI)
        )));
    }
    // Ring order: increasing ψ. The fill's triangles (inner, outer_j, outer_j+1) then run
    // along the seam in increasing ψ; the spline's boundary runs the other way for a
    // consistent orientation, so flip when the loop's ψ increases.
    let increasing = total > 0.0;
    // Loop index of ring position k.
    let at: Vec<usize> = (0..n)
        .map(|k| if increasing { k } else { (n - k) % n })
        .collect();
    let ring_ids: Vec<u32> = at.iter().map(|&k| seam.vertices[k]).collect();
    // Unwrapped ψ in ring order, closing value at index n.
    let mut rpsi: Vec<f64> = Vec::with_capacity(n + 1);
    rpsi.push(seam.psi[at[0]]);
    for k in 1..=n {
        let d = seam.psi[at[k % n]] - seam.psi[at[k - 1]];
        rpsi.push(rpsi[k - 1] + d - 2.0 * PI * (d / (2.0 * PI)).round());
    }
    let pos = |v: u32| t.positions[v as usize];
    // Arc length of the seam polygon, normalised to [0, 1].
    let mut arc = vec![0.0; n + 1];
    for k in 1..=n {
        let d = sub3(pos(ring_ids[k % n]), pos(ring_ids[k - 1]));
        arc[k] = arc[k - 1] + dot3(d, d).sqrt();
    }
    let length = arc[n];
    if length <= 0.0 || !length.is_finite() {
        return Err(Error::numerical(format!(
            "tessellation: the seam around vertex {} has no length",
            hole.vertex
        )));
    }
    for a in &mut arc {
        *a /= length;
    }
    let spacing = length / n as f64;
    let radius = ring_ids
        .iter()
        .map(|&v| {
            let d = sub3(pos(v), hole.center);
            dot3(d, d).sqrt()
        })
        .sum::<f64>()
        / n as f64;
    let nt = ((radius / spacing).round() as usize).clamp(1, 4 * n);
    let psi_at = |u: f64| -> f64 {
        let j = match arc.binary_search_by(|x| x.total_cmp(&u)) {
            Ok(j) => j.min(n - 1),
            Err(j) => j.saturating_sub(1).min(n - 1),
        };
        let w = (u - arc[j]) / (arc[j + 1] - arc[j]).max(1e-300);
        rpsi[j] + w.clamp(0.0, 1.0) * (rpsi[j + 1] - rpsi[j])
    };
    let ts = fill_ring_radii(nt);
    // Ring at t: (t, arc parameters, ψ). Aligned rings: the seam's; the others
    // max(5, round(n t)) points at equal steps of the seam's arc length.
    let rings: Vec<(f64, Vec<f64>, Vec<f64>)> = ts
        .iter()
        .rev()
        .map(|&(tk, aligned)| {
            if aligned {
                (tk, arc[..n].to_vec(), rpsi[..n].to_vec())
            } else {
                let c = (n as f64 * tk).round().max(5.0) as usize;
                let us: Vec<f64> = (0..c).map(|j| j as f64 / c as f64).collect();
                let ps = us.iter().map(|&u| psi_at(u)).collect();
                (tk, us, ps)
            }
        })
        .collect();
    let values: Vec<Vec<[f64; 3]>> = rings
        .par_iter()
        .map(|(tk, _, ps)| -> Result<Vec<[f64; 3]>> {
            let mut ws = Workspace::default();
            ps.iter()
                .map(|&psi| hole.fill_point(space, &spline.control, *tk, psi, &mut ws))
                .collect()
        })
        .collect::<Result<_>>()?;
    let push = |t: &mut Tessellation, p: [f64; 3]| -> u32 {
        t.positions.push(p);
        t.vertex_face.push(-1);
        t.vertex_chart.push(-1);
        t.vertex_bary.push([0.0; 3]);
        t.positions.len() as u32 - 1
    };
    let center = push(t, hole.center);
    // Each ring as (vertex ids, arc parameters).
    let mut all: Vec<(Vec<u32>, Vec<f64>)> = Vec::with_capacity(nt);
    for ((_, us, _), vals) in rings.iter().zip(&values) {
        let ids = vals.iter().map(|&p| push(t, p)).collect();
        all.push((ids, us.clone()));
    }
    all.push((ring_ids, arc[..n].to_vec()));
    let mut tris = zip_rings(center, &all);
    if increasing {
        for tri in &mut tris {
            tri.swap(1, 2);
        }
    }
    t.triangles.extend(tris);
    Ok(())
}

/// The radii `t` of the fill's rings inside the seam (`t = 1`), from the seam inwards, with
/// whether each keeps the seam's own `ψ`: steps of [`FILL_GRADING`]`/nt` next to the seam,
/// growing by [`FILL_GROWTH`] up to `1/nt` (the patch bends more than the spline next to the
/// seam, and the spline's trimmed triangles are small there); rings whose step is below
/// `1/nt` are aligned (radial lines through the seam vertices: a quad strip that cannot fold
/// however thin it is).
fn fill_ring_radii(nt: usize) -> Vec<(f64, bool)> {
    let (beta, growth) = (FILL_GRADING, FILL_GROWTH);
    let full = 1.0 / nt as f64;
    let mut ts: Vec<(f64, bool)> = Vec::new();
    let (mut tk, mut step) = (1.0, beta * full);
    loop {
        tk -= step;
        if tk < 0.5 * full {
            break;
        }
        ts.push((tk, step < full));
        step = (step * growth).min(full);
    }
    ts
}

/// Triangles of a disk: a fan from `center` to the first ring, then consecutive rings
/// `(vertex ids, arc parameters in [0, 1))` zipped by arc-parameter order.
fn zip_rings(center: u32, all: &[(Vec<u32>, Vec<f64>)]) -> Vec<[u32; 3]> {
    let mut tris: Vec<[u32; 3]> = Vec::new();
    let (first, _) = &all[0];
    for j in 0..first.len() {
        tris.push([center, first[j], first[(j + 1) % first.len()]]);
    }
    for w in all.windows(2) {
        let (a, ua) = (&w[0].0, &w[0].1);
        let (b, ub) = (&w[1].0, &w[1].1);
        let (p, q) = (a.len(), b.len());
        let (mut i, mut j) = (0, 0);
        while i < p || j < q {
            let na = if i + 1 < p { ua[i + 1] } else { 1.0 };
            let nb = if j + 1 < q { ub[j + 1] } else { 1.0 };
            if j < q && (i == p || nb <= na) {
                tris.push([a[i % p], b[j], b[(j + 1) % q]]);
                j += 1;
            } else {
                tris.push([a[i], b[j % q], a[(i + 1) % p]]);
                i += 1;
            }
        }
    }
    tris
}
