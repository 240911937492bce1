use ricci::layout::deck_group;
use ricci::layout::pipeline::{cut_disk, uniformization_metric};
use ricci::layout::place::{layout, ext_position};
use ricci::layout::dd::MobiusDd;
use ricci::mesh::io::read_surface;
use ricci::metric::{Geometry, Hyperbolic, Scheme};
use ricci::progress::NoProgress;
use std::path::PathBuf;
fn main() {
    let dir = PathBuf::from(std::env::var("RICCI_MESHES").unwrap());
    let args: Vec<String> = std::env::args().skip(1).collect();
    let tol: f64 = args[0].parse().unwrap();
    for f in &args[1..] {
        let (s, _) = read_surface(&dir.join(f)).unwrap();
        let flow = uniformization_metric(&s.mesh, &s.edge_lengths(), Geometry::Hyperbolic, Scheme::Thurston, tol, &mut NoProgress).unwrap();
        println!("{f}: converged {} it {} maxK {:e}", flow.converged, flow.iterations, flow.max_curvature_error);
        for h in &flow.history { print!(" {:.1e}", h.max_curvature_error); }
        println!();
        let bases: Vec<Option<u32>> = std::env::var("BASES").ok().map(|b| b.split(',').map(|x| x.parse().ok()).collect()).unwrap_or(vec![None]);
        let mut disk = None;
        for b in bases {
            match cut_disk(&s.mesh, &flow.lengths, Geometry::Hyperbolic, Some(&s.positions), b, &mut NoProgress) {
                Ok(d) => { println!("  base {b:?} ok"); disk = Some(d); break; }
                Err(e) => println!("  base {b:?}: {e}"),
            }
        }
        let Some(disk) = disk else { continue };
        let nf = disk.mesh.n_faces() as u32;
        let mut ls = Vec::new();
        for seed in [None, Some(nf / 3), Some(nf - 1)] {
            let l = layout::<Hyperbolic>(&disk.mesh, &disk.lengths, seed).unwrap();
            if let Some(first) = ls.first() {
                let (_, d) = ricci::layout::align_layouts::<Hyperbolic>(first, &l).unwrap();
                println!("  seed {:?}: dev {:e} radius {:.1} depth {}", seed, d, l.max_radius, l.depth);
            }
            ls.push(l);
        }
        let g = deck_group::<Hyperbolic>(&ls[0], &disk.polygon).unwrap();
        println!("  relation {:e} cond {:e} spread {:e} verr {:e} lenerr {:e} flipped {}", g.relation_error.unwrap(), g.relation_condition, g.max_edge_spread, g.max_vertex_error, ls[0].max_length_error, ls[0].flipped_faces.len());
        for p in &g.pairings {
            let side = &disk.polygon.sides[p.side];
            let part = &disk.polygon.sides[p.partner];
            let v: Vec<_> = side.vertices.iter().map(|&x| ext_position::<Hyperbolic>(&ls[0], x as usize)).collect();
            let w: Vec<_> = part.vertices.iter().rev().map(|&x| ext_position::<Hyperbolic>(&ls[0], x as usize)).collect();
            let k = v.len() - 1;
            let e0 = MobiusDd::from_pairs(w[0], w[k], v[0], v[k]);
            let (mut fro, mut th, mut z0, mut org) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
            let (th0, c0) = e0.round().theta_center();
            for t in 0..k {
                let e = MobiusDd::from_pairs(w[t], w[t + 1], v[t], v[t + 1]);
                fro = fro.max(e.distance(&e0));
                let (th1, c1) = e.round().theta_center();
                th = th.max((th1 - th0).abs()); z0 = z0.max((c1 - c0).norm());
                let o = e0.inverse().apply(ricci::layout::dd::Cdd::ZERO);
                org = org.max(ricci::layout::dd::disk_distance_dd(e.apply(o), ricci::layout::dd::Cdd::ZERO));
            }
            println!("   frob {fro:.1e} theta {th:.1e} z0 {z0:.1e} origin {org:.1e}"); println!("   side {} ({}) len {} spread {:e} verr {:e} tl {:.2}", p.side, disk.polygon.sides[p.side].label, disk.polygon.sides[p.side].vertices.len(), p.edge_spread, p.max_vertex_error, ricci::layout::Isometry::size(&p.map)); }
    }
}
