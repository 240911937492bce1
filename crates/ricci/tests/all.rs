//! All integration tests of `ricci` as one binary: each `tests/NAME.rs` is the module `NAME`
//! (`autotests = false` in `crates/ricci/Cargo.toml`; one compile and link of the library's
//! generic code instead of one per file, docs/notes/wave2-s13-ci13.md). One file's tests:
//! `cargo test --release -p ricci --test all flow_meshes::` (a substring filter on `flow_meshes::test_name`).
//! A new test file needs its two lines below; `every_test_file_is_declared` fails until then.
//!
//! The files keep their own `mod ricci_meshes;` etc. (each reads on its own), so a helper module
//! is declared more than once.
#![allow(clippy::duplicate_mod)]

#[path = "atlas_candidates.rs"]
mod atlas_candidates;
#[path = "atlas_meshes.rs"]
mod atlas_meshes;
#[path = "atlas_placement.rs"]
mod atlas_placement;
#[path = "bad_files.rs"]
mod bad_files;
#[path = "common_subdivision.rs"]
mod common_subdivision;
#[path = "conformal_flow.rs"]
mod conformal_flow;
#[path = "conformal_invariance.rs"]
mod conformal_invariance;
#[path = "conformal_sphere.rs"]
mod conformal_sphere;
#[path = "cut_check.rs"]
mod cut_check;
#[path = "cut_generated.rs"]
mod cut_generated;
#[path = "cut_meshes.rs"]
mod cut_meshes;
#[path = "cut_refine.rs"]
mod cut_refine;
#[path = "double_cover.rs"]
mod double_cover;
#[path = "flow_double.rs"]
mod flow_double;
#[path = "flow_fallback.rs"]
mod flow_fallback;
#[path = "flow_meshes.rs"]
mod flow_meshes;
#[path = "flow_solvers.rs"]
mod flow_solvers;
#[path = "flow_torus.rs"]
mod flow_torus;
#[path = "forms_double.rs"]
mod forms_double;
#[path = "forms_genus1.rs"]
mod forms_genus1;
#[path = "forms_genus_g.rs"]
mod forms_genus_g;
#[path = "forms_symplectic.rs"]
mod forms_symplectic;
#[path = "forms_trajectories.rs"]
mod forms_trajectories;
#[path = "generate.rs"]
mod generate;
#[path = "layers.rs"]
mod layers;
#[path = "layout_input_uv.rs"]
mod layout_input_uv;
#[path = "layout_meshes.rs"]
mod layout_meshes;
#[path = "layout_nearest_images.rs"]
mod layout_nearest_images;
#[path = "layout_polish.rs"]
mod layout_polish;
#[path = "layout_synthetic.rs"]
mod layout_synthetic;
#[path = "mesh_edge_order.rs"]
mod mesh_edge_order;
#[path = "mesh_files.rs"]
mod mesh_files;
#[path = "metric_derivatives.rs"]
mod metric_derivatives;
#[path = "param.rs"]
mod param;
#[path = "param_boundary_cones.rs"]
mod param_boundary_cones;
#[path = "param_cone_scale_bound.rs"]
mod param_cone_scale_bound;
#[path = "param_develop.rs"]
mod param_develop;
#[path = "param_free.rs"]
mod param_free;
#[path = "param_interior.rs"]
mod param_interior;
#[path = "param_lscm.rs"]
mod param_lscm;
#[path = "param_placement.rs"]
mod param_placement;
#[path = "param_seamless.rs"]
mod param_seamless;
#[path = "param_seamless_boundary.rs"]
mod param_seamless_boundary;
#[path = "param_seamless_distortion.rs"]
mod param_seamless_distortion;
#[path = "param_sphere.rs"]
mod param_sphere;
#[path = "param_threads.rs"]
mod param_threads;
#[path = "roundtrip.rs"]
mod roundtrip;
#[path = "scalar_files.rs"]
mod scalar_files;
#[path = "spectrum_domain.rs"]
mod spectrum_domain;
#[path = "spectrum_meshes.rs"]
mod spectrum_meshes;
#[path = "spectrum_powers.rs"]
mod spectrum_powers;
#[path = "spectrum_synthetic.rs"]
mod spectrum_synthetic;
#[path = "spectrum_timing.rs"]
mod spectrum_timing;
#[path = "spectrum_words.rs"]
mod spectrum_words;
#[path = "spline_atlas.rs"]
mod spline_atlas;
#[path = "spline_dms.rs"]
mod spline_dms;
#[path = "spline_fast_paths.rs"]
mod spline_fast_paths;
#[path = "spline_fit.rs"]
mod spline_fit;
#[path = "spline_manifold.rs"]
mod spline_manifold;
#[path = "spline_pou.rs"]
mod spline_pou;
#[path = "spline_seam.rs"]
mod spline_seam;
#[path = "stage_errors.rs"]
mod stage_errors;
#[path = "subdivision_uv.rs"]
mod subdivision_uv;
#[path = "teichmuller.rs"]
mod teichmuller;
#[path = "tspline.rs"]
mod tspline;
#[path = "tspline_bezier_elements.rs"]
mod tspline_bezier_elements;
#[path = "tspline_cylinders.rs"]
mod tspline_cylinders;
#[path = "tspline_domain_blocks.rs"]
mod tspline_domain_blocks;
#[path = "tspline_domain_carry.rs"]
mod tspline_domain_carry;
#[path = "tspline_domain_genus3.rs"]
mod tspline_domain_genus3;
#[path = "tspline_domain_mesh.rs"]
mod tspline_domain_mesh;
#[path = "tspline_domain_nested.rs"]
mod tspline_domain_nested;
#[path = "tspline_domain_thin_plate.rs"]
mod tspline_domain_thin_plate;
#[path = "tspline_genus.rs"]
mod tspline_genus;
#[path = "tspline_genus0.rs"]
mod tspline_genus0;
#[path = "tspline_genus_three.rs"]
mod tspline_genus_three;
#[path = "tspline_thin_cylinders.rs"]
mod tspline_thin_cylinders;
#[path = "uv_match.rs"]
mod uv_match;

#[path = "test_files/mod.rs"]
mod test_files;

#[test]
fn every_test_file_is_declared() {
    test_files::assert_all_rs_declares_every_test_file(
        env!("CARGO_MANIFEST_DIR"),
        include_str!("all.rs"),
    );
}
