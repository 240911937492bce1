//! `ricci param` runs independent work side by side on rayon's threads: the cone placement's
//! symbolic analysis of the Laplacian beside its values and the angle defects, the flat layout
//! beside the wedges of the input route, the layout of `T` beside the common subdivision, the
//! parallel sorts of the cut graph and of the distortion statistics. Each of these must give
//! the result of running the same steps one after the other. Checked here against the
//! sequential run itself: the whole map computed in a pool of one thread (every `join` runs
//! its halves in turn, every parallel sort and iterator runs sequentially) and in a pool of
//! four, equal bit for bit — UVs, seams, cones, statistics, and the common subdivision where
//! there is one — on the paths that use those steps: free seams (held boundary, input
//! route), rigid seams with greedy cones (closed surface), cones inside a surface with
//! boundary, and maps written on the common subdivision.

#[path = "ricci_meshes/mod.rs"]
mod ricci_meshes;

use ricci::mesh::generate::genus;
use ricci::mesh::Surface;
use ricci::param::{parametrize, ConeSpec, ParamOptions, Parametrization, SeamMode};
use ricci::progress::NoProgress;

fn in_pool(threads: usize, s: &Surface, opts: &ParamOptions) -> Parametrization {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| parametrize(s, opts, &mut NoProgress).unwrap())
}

fn bits2(x: &[[f64; 2]]) -> Vec<[u64; 2]> {
    x.iter().map(|p| p.map(f64::to_bits)).collect()
}

/// The map of one thread and of four, compared bit for bit; returns where the map lies.
fn same_with_threads(what: &str, s: &Surface, opts: &ParamOptions) -> &'static str {
    let one = in_pool(1, s, opts);
    let four = in_pool(4, s, opts);
    assert_eq!(bits2(&one.corner_uv), bits2(&four.corner_uv), "{what}: UVs");
    assert_eq!(one.seam, four.seam, "{what}: seams");
    // Debug prints every f64 in its shortest round-trip form: equal text, equal bits.
    assert_eq!(
        format!("{:?}", one.stats),
        format!("{:?}", four.stats),
        "{what}: statistics"
    );
    for (a, b) in one.charts.iter().zip(&four.charts) {
        assert_eq!(format!("{:?}", a.cones), format!("{:?}", b.cones), "{what}");
        assert_eq!(a.uv_faces, b.uv_faces, "{what}");
        assert_eq!(a.seam_length.to_bits(), b.seam_length.to_bits(), "{what}");
        assert_eq!(
            a.log_scale_sigma.to_bits(),
            b.log_scale_sigma.to_bits(),
            "{what}"
        );
    }
    match (&one.subdivision, &four.subdivision) {
        (None, None) => {}
        (Some(a), Some(b)) => {
            assert_eq!(bits2(&a.corner_uv), bits2(&b.corner_uv), "{what}");
            let pos = |m: &ricci::param::SubdivisionMap| -> Vec<[u64; 3]> {
                m.positions.iter().map(|p| p.map(f64::to_bits)).collect()
            };
            assert_eq!(pos(a), pos(b), "{what}: subdivision points");
            assert_eq!(a.mesh.faces(), b.mesh.faces(), "{what}: subdivision");
        }
        _ => panic!("{what}: one run on the common subdivision, the other not"),
    }
    assert!(!one.charts[0].cones.is_empty() || opts.cones == ConeSpec::Default);
    one.uv_on()
}

#[test]
fn generated_genus_two_free_and_rigid_seams() {
    let s = genus(2, 12).unwrap();
    let free = ParamOptions {
        cones: ConeSpec::Count(6),
        seams: SeamMode::Free,
        ..ParamOptions::default()
    };
    same_with_threads("genus 2, free seams", &s, &free);
    let rigid = ParamOptions {
        cones: ConeSpec::Count(6),
        ..ParamOptions::default()
    };
    same_with_threads("genus 2, rigid seams", &s, &rigid);
}

#[test]
fn shared_meshes_on_every_route() {
    let Some(dir) = ricci_meshes::ricci_meshes() else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    let read = |f: &str| ricci::mesh::io::read_surface(&dir.join(f)).unwrap().0;
    // A disk with cones inside (the held boundary's greedy), on the input faces.
    let face = read("face.off");
    let inside = ParamOptions {
        cones: ConeSpec::Count(4),
        ..ParamOptions::default()
    };
    same_with_threads("face, 4 cones", &face, &inside);
    // Written on the common subdivision (the layout of T beside the overlay).
    let seamless = ParamOptions {
        seamless: true,
        ..ParamOptions::default()
    };
    assert_eq!(
        same_with_threads("face, seamless", &face, &seamless),
        "common_subdivision"
    );
    // Free seams whose input route cannot cut (camel: the common subdivision, then the map
    // developed on the input faces).
    let camel = read("camel.off");
    let free = ParamOptions {
        cones: ConeSpec::Count(8),
        seams: SeamMode::Free,
        ..ParamOptions::default()
    };
    same_with_threads("camel, 8 cones, free seams", &camel, &free);
}
