//! Issue 15 (half9): are the crossings that crowd into a boundary vertex on the split disks
//! intrinsic (a flip of a boundary edge whose quad has a corner angle of π, whose new edge runs
//! through that corner) or an artefact of the overlay? For every isometric flip (to the input
//! metric's Delaunay triangulation of the double) of an edge that is a boundary edge of the
//! surface, print the quad's four corner angles minus π and the new edge's distance to the
//! two corners it separates (relative to the flipped edge's length), and the Euclidean
//! crossing parameter on the old edge.
//!
//! `cargo run --release -p ricci --example diag_split_flips [splits seed]...`

use ricci::flow::double::double_triangulation;
use ricci::mesh::{generate, Surface};
use ricci::metric::intrinsic::{length_of_lambda, IntrinsicTriangulation};
use ricci::metric::Geometry;

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let cases: Vec<(usize, u64)> = if args.len() >= 2 {
        args.chunks(2).map(|c| (c[0], c[1] as u64)).collect()
    } else {
        vec![(120, 7), (200, 3), (300, 11)]
    };
    for (count, seed) in cases {
        let s = generate::bumpy_split_disk(count, seed, 0.75, true).unwrap();
        run(&format!("split disk {count}/{seed}"), &s);
    }
}

fn run(name: &str, s: &Surface) {
    let g = Geometry::Euclidean;
    let mesh = &s.mesh;
    let (mut tri, _sigma, _origin) = double_triangulation(mesh, g, &s.edge_lengths()).unwrap();
    let ne = tri.n_edges();
    let boundary: Vec<bool> = (0..ne as u32)
        .map(|e| (e as usize) < mesh.n_edges() && mesh.is_boundary_edge(e))
        .collect();
    // Boundary angle of M at its boundary vertices (input metric), minus π.
    let mut worst_flat = f64::INFINITY;
    let mut flips = 0;
    let mut queue: std::collections::VecDeque<u32> = (0..ne as u32).collect();
    let mut queued = vec![true; ne];
    let mut min_rel = f64::INFINITY;
    let mut min_corner = f64::INFINITY;
    println!(
        "{name}: {} vertices, {} faces",
        mesh.n_vertices(),
        mesh.n_faces()
    );
    // The thinnest input face: its height over its longest side, relative to that side.
    let l = s.edge_lengths();
    let mut thin = (f64::INFINITY, 0u32);
    for f in 0..mesh.n_faces() as u32 {
        let h = [0, 1, 2].map(|i| l[mesh.he_edge(3 * f + i) as usize]);
        let a = Geometry::Euclidean.area(h[0], h[1], h[2]);
        let m = h[0].max(h[1]).max(h[2]);
        let r = 2.0 * a / (m * m);
        if r < thin.0 {
            thin = (r, f);
        }
    }
    println!(
        "  thinnest input face {} {:?}: height/side {:.3e}",
        thin.1,
        mesh.face(thin.1),
        thin.0
    );
    while let Some(e) = queue.pop_front() {
        queued[e as usize] = false;
        if tri.is_delaunay(e, &[]) || !tri.is_flippable(e) {
            continue;
        }
        let h = tri.edge_he[e as usize];
        let t = tri.twin[h as usize];
        let len = |x: u32| length_of_lambda(g, tri.lambda[tri.edge[x as usize] as usize]);
        let n = IntrinsicTriangulation::next;
        let p = IntrinsicTriangulation::prev;
        let (lij, ljk, lki) = (len(h), len(n(h)), len(p(h)));
        let (lil, llj) = (len(n(t)), len(p(t)));
        let (i, j) = (tri.origin[h as usize], tri.tip(h));
        let (k, l) = (tri.origin[p(h) as usize], tri.origin[p(t) as usize]);
        if boundary[e as usize] {
            // Quad i, l, j, k laid out: i at 0, j at (lij, 0), k above, l below.
            let ai = g.angle(ljk, lij, lki);
            let aj = g.angle(lki, lij, ljk);
            let bi = g.angle(llj, lij, lil);
            let bj = g.angle(lil, lij, llj);
            let ak = g.angle(lij, lki, ljk);
            let al = g.angle(lij, lil, llj);
            let pk = [lki * ai.cos(), lki * ai.sin()];
            let pl = [lil * bi.cos(), -lil * bi.sin()];
            // The new edge k–l meets the line ij at parameter x / lij.
            let x = pk[0] + (pl[0] - pk[0]) * pk[1] / (pk[1] - pl[1]);
            let tpar = x / lij;
            let dist = |q: [f64; 2]| {
                let d = [pl[0] - pk[0], pl[1] - pk[1]];
                ((q[0] - pk[0]) * d[1] - (q[1] - pk[1]) * d[0]).abs() / d[0].hypot(d[1])
            };
            let (di, dj) = (dist([0.0, 0.0]) / lij, dist([lij, 0.0]) / lij);
            min_rel = min_rel.min(di.min(dj));
            let corners = [
                ai + bi - std::f64::consts::PI,
                aj + bj - std::f64::consts::PI,
            ];
            min_corner = min_corner.min(corners[0].abs()).min(corners[1].abs());
            println!(
                "  flip {flips:4}: boundary edge {e} ({i}–{j}), quad {i} {l} {j} {k}: corner − π \
                 at i {:+.3e}, l {:+.3e}, j {:+.3e}, k {:+.3e}; new edge {k}–{l}: dist to i \
                 {di:.3e}, to j {dj:.3e} (× |ij|), crosses ij at t = {tpar:.6}; symmetric quad: \
                 {}",
                corners[0],
                al - std::f64::consts::PI,
                corners[1],
                ak - std::f64::consts::PI,
                (lki - lil).abs() < 1e-12 * lij && (ljk - llj).abs() < 1e-12 * lij
            );
        }
        worst_flat = worst_flat.min(1.0);
        tri.flip_isometric(e, g);
        flips += 1;
        let h = tri.edge_he[e as usize];
        let t = tri.twin[h as usize];
        for x in [n(h), p(h), n(t), p(t)] {
            let f = tri.edge[x as usize];
            if !queued[f as usize] {
                queued[f as usize] = true;
                queue.push_back(f);
            }
        }
    }
    let flipped = (0..ne).filter(|&e| boundary[e]).filter(|&e| {
        let mut a = tri.edge_vertices(e as u32);
        let mut b = mesh.edge_vertices(e as u32);
        a.sort_unstable();
        b.sort_unstable();
        a != b
    });
    println!(
        "{name}: {flips} isometric flips, {} boundary edges gone; smallest |corner − π| at the \
         flipped edge's ends {min_corner:.3e}, smallest distance of a new edge to an old end \
         {min_rel:.3e} × |ij|",
        flipped.count()
    );
}
