//! Issue 16: the distortion of `--seamless` maps carried by the common subdivision
//! (`ricci::param::seamless`, `MAX_FACE_DISTORTION`). The seamless metric of the flow's
//! triangulation `T` is the conformal one changed until the homology loops' holonomies are
//! quarter turns; the written map is the conformal map of the input onto `T`'s faces
//! followed, face by face of `T`, by the linear map from the conformal to the seamless
//! triangle. With every such linear map of distortion ≤ 8, the seamless map's distortion is
//! at most 8 times that of the conformal map on the same carrier — measured here against the
//! conformal map of the same mesh and cone count forced onto the common subdivision (its
//! cones are the greedy's unrounded ones, so the comparison is of like with like up to
//! the rounding).
//!
//! Before (main caaf258) fertility `--seamless --cones 12` had qc mean 87.4 and max 1.1e6
//! (a triangle of `T` made flat to 1e-5 by the holonomy change) against the conformal
//! map's 1.20 and 77.

#[path = "ricci_meshes/mod.rs"]
mod ricci_meshes;

use ricci::param::{parametrize, ConeSpec, ParamOptions};
use ricci::progress::NoProgress;

#[test]
fn fertility_seamless_distortion_is_bounded_by_the_conformal_map() {
    let Some(dir) = ricci_meshes::ricci_meshes() else {
        eprintln!("RICCI_MESHES not set; skipped");
        return;
    };
    let s = ricci::mesh::io::read_surface(&dir.join("fertility.off"))
        .unwrap()
        .0;
    let run = |seamless: bool, on_subdivision: bool| {
        let opts = ParamOptions {
            cones: ConeSpec::Count(12),
            seamless,
            on_subdivision,
            ..ParamOptions::default()
        };
        parametrize(&s, &opts, &mut NoProgress).unwrap()
    };
    let conformal = run(false, true);
    let seamless = run(true, false);
    assert!(conformal.subdivision.is_some());
    let (c, q) = (&conformal.stats, &seamless.stats);
    eprintln!(
        "fertility --cones 12 on {} / {}: qc mean {:.4} / {:.4}, p95 {:.4} / {:.4}, max {:.3} / \
         {:.3}",
        conformal.charts[0].uv_faces,
        seamless.charts[0].uv_faces,
        c.qc_mean,
        q.qc_mean,
        c.qc_p95,
        q.qc_p95,
        c.qc_max,
        q.qc_max
    );
    assert_eq!(q.flipped_faces, 0);
    assert!(
        q.qc_mean <= 8.0 * c.qc_mean,
        "qc mean {} vs {}",
        q.qc_mean,
        c.qc_mean
    );
    assert!(
        q.qc_p95 <= 8.0 * c.qc_p95,
        "qc p95 {} vs {}",
        q.qc_p95,
        c.qc_p95
    );
    assert!(
        q.qc_max <= 8.0 * c.qc_max,
        "qc max {} vs {}",
        q.qc_max,
        c.qc_max
    );
}
