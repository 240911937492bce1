//! How far the input faces are from their images when the flip log starts with isometric
//! flips: the input edges flipped away isometrically (to the input's intrinsic Delaunay
//! triangulation Tb) are straightened in Tb's hyperbolic structure; their λ-lengths there
//! (Ptolemy flips back from Tb) differ from the input lengths. Prints, per mesh, the number of
//! isometric flips, the input edges concerned and the largest |log(l_straightened / l_input)|.
//!
//! `RICCI_MESHES=/work/shared/meshes cargo run --release -p ricci --example diag_overlay_prefix`

use ricci::mesh::io::read_surface;
use ricci::metric::intrinsic::IntrinsicTriangulation;
use ricci::metric::Geometry;

fn main() {
    let dir = match std::env::var_os("RICCI_MESHES") {
        Some(d) => std::path::PathBuf::from(d),
        None => {
            eprintln!("set RICCI_MESHES to the shared mesh folder");
            return;
        }
    };
    for file in [
        "face.off",
        "kitten.nf20k.off",
        "bunny.off",
        "eight.off",
        "fertility.off",
    ] {
        let (s, _) = match read_surface(&dir.join(file)) {
            Ok(x) => x,
            Err(e) => {
                println!("{file}: {e}");
                continue;
            }
        };
        let l = s.edge_lengths();
        let mut tri = IntrinsicTriangulation::from_mesh(&s.mesh, Geometry::Euclidean, &l).unwrap();
        let rep = tri.make_delaunay_isometric(Geometry::Euclidean, 1_000_000);
        let log = tri.flip_log.clone();
        for &e in log.iter().rev() {
            tri.flip(e);
        }
        let mut worst = 0.0f64;
        let mut changed = 0usize;
        for (lam, len) in tri.lambda.iter().zip(&l) {
            let d = 0.5 * (lam - 2.0 * len.ln());
            if d.abs() > 1e-12 {
                changed += 1;
            }
            worst = worst.max(d.abs());
        }
        println!(
            "{file:<18} edges {:>7}  isometric flips {:>6}  input edges off {:>6}  max |log ratio| {:.3e}",
            l.len(),
            rep.flips,
            changed,
            worst
        );
    }
}
