//! All integration tests of `ricci-cli` as one binary: each `tests/NAME.rs` is the module `NAME`
//! (`autotests = false` in `crates/ricci-cli/Cargo.toml`; one compile and link of the library's
//! generic code instead of one per file, docs/notes/wave2-s13-ci13.md). One file's tests:
//! `cargo test --release -p ricci-cli --test all readme::` (a substring filter on `readme::test_name`).
//! A new test file needs its two lines below; `every_test_file_is_declared` fails until then.
//!
//! The files keep their own `mod ricci_meshes;` etc. (each reads on its own), so a helper module
//! is declared more than once.
#![allow(clippy::duplicate_mod)]

#[path = "cli_atlas.rs"]
mod cli_atlas;
#[path = "cli_atlas_progress.rs"]
mod cli_atlas_progress;
#[path = "cli_batch.rs"]
mod cli_batch;
#[path = "cli_cut.rs"]
mod cli_cut;
#[path = "cli_demo.rs"]
mod cli_demo;
#[path = "cli_first_hour.rs"]
mod cli_first_hour;
#[path = "cli_flow.rs"]
mod cli_flow;
#[path = "cli_forms.rs"]
mod cli_forms;
#[path = "cli_generate.rs"]
mod cli_generate;
#[path = "cli_info.rs"]
mod cli_info;
#[path = "cli_layout.rs"]
mod cli_layout;
#[path = "cli_layout_double.rs"]
mod cli_layout_double;
#[path = "cli_layout_round_boundary.rs"]
mod cli_layout_round_boundary;
#[path = "cli_metric_file.rs"]
mod cli_metric_file;
#[path = "cli_nonconvergence.rs"]
mod cli_nonconvergence;
#[path = "cli_param.rs"]
mod cli_param;
#[path = "cli_pou.rs"]
mod cli_pou;
#[path = "cli_refusals.rs"]
mod cli_refusals;
#[path = "cli_render.rs"]
mod cli_render;
#[path = "cli_spectrum_double.rs"]
mod cli_spectrum_double;
#[path = "cli_spectrum_reference.rs"]
mod cli_spectrum_reference;
#[path = "cli_spline.rs"]
mod cli_spline;
#[path = "cli_teichmuller.rs"]
mod cli_teichmuller;
#[path = "cli_tspline.rs"]
mod cli_tspline;
#[path = "readme.rs"]
mod readme;
#[path = "sweep_meshes.rs"]
mod sweep_meshes;
#[path = "sweep_tspline.rs"]
mod sweep_tspline;

#[path = "../../ricci/tests/test_files/mod.rs"]
mod test_files;

#[test]
fn every_test_file_is_declared() {
    test_files::assert_all_rs_declares_every_test_file(
        env!("CARGO_MANIFEST_DIR"),
        include_str!("all.rs"),
    );
}
