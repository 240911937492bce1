//! Canonical cuts of generated surfaces of genus 1..4 (always run, no shared meshes needed):
//! disk, canonical word read from the cut mesh, standard symplectic intersection matrix,
//! and the word/homology utilities on the generators.

#[path = "cut_check.rs"]
mod cut_check;

use ricci::cut::{canonical_cut, CutOptions, Generator};
use ricci::metric::Geometry;
use ricci::metric::IntrinsicMetric;
use ricci::progress::NoProgress;

#[test]
fn generated_surfaces_of_genus_1_to_4() {
    for g in 1..=4u32 {
        let s = ricci::mesh::generate::genus(g, 24).unwrap();
        let lengths = s.edge_lengths();
        let c = canonical_cut(
            &s.mesh,
            &IntrinsicMetric::new(Geometry::Euclidean, lengths.to_vec()),
            Some(&s.positions),
            &CutOptions::default(),
            &mut NoProgress,
        )
        .unwrap_or_else(|e| panic!("genus {g}: {e}"));
        cut_check::verify(&c, g as usize, 0, &format!("generated genus {g}"));
        // Homology classes of the generators are the unit vectors, and the exponent sums of
        // their words (read from polygon crossings) agree with them.
        for (i, l) in c.loops.iter().enumerate().take(2 * g as usize) {
            let h = c.homology_class(&l.halfedges).unwrap();
            let mut e = vec![0i64; 2 * g as usize];
            e[i] = 1;
            assert_eq!(h, e, "genus {g}: class of {}", l.label);
            let mut sums = vec![0i64; 2 * g as usize];
            for (gen, s) in c.word(&l.halfedges).unwrap() {
                match gen {
                    Generator::A { handle } => sums[2 * (handle - 1)] += s as i64,
                    Generator::B { handle } => sums[2 * (handle - 1) + 1] += s as i64,
                    _ => {}
                }
            }
            assert_eq!(sums, e, "genus {g}: word of {}", l.label);
        }
        // The reported matrix and the metric are consistent.
        assert_eq!(c.intersection_matrix, cut_check::symplectic(g as usize));
    }
}
