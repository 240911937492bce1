//! `ricci cut`: one JSON object with the contract keys, a disk written to CUT.obj whose
//! polygon sides read back, bad arguments exit with code 2, bad input with code 1.

use ricci::mesh::io::read_surface;
use ricci::mesh::topology;
use std::path::PathBuf;
use std::process::Command;

fn ricci() -> Command {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ricci-cli-cut-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn cut_of_a_generated_genus2_surface() {
    let mesh = scratch("g2.off");
    let o = ricci()
        .args(["generate", "genus2", "--out"])
        .arg(&mesh)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = scratch("g2cut.obj");
    let svg = scratch("g2cut.svg");
    let o = ricci()
        .arg("cut")
        .arg(&mesh)
        .arg("--out")
        .arg(&out)
        .arg("--svg")
        .arg(&svg)
        .arg("--json")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value =
        serde_json::from_slice(&o.stdout).expect("stdout is one JSON object");
    for key in [
        "genus",
        "loops",
        "polygon_sides",
        "boundary_word",
        "disk",
        "intersection_matrix",
        "seconds",
        "base_vertex",
        "loop_lengths",
        "refinement",
    ] {
        assert!(v.get(key).is_some(), "missing key {key}");
    }
    assert_eq!(v["genus"], 2);
    assert_eq!(v["disk"], true);
    assert_eq!(v["boundary_word"], "a1 b1 a1^-1 b1^-1 a2 b2 a2^-1 b2^-1");
    assert_eq!(
        v["intersection_matrix"],
        serde_json::json!([[0, 1, 0, 0], [-1, 0, 0, 0], [0, 0, 0, 1], [0, 0, -1, 0]])
    );
    // The written cut mesh is a disk, and carries one `l` polyline per polygon side.
    let (s, _) = read_surface(&out).unwrap();
    let t = topology(&s.mesh);
    assert_eq!((t.euler_characteristic(), t.boundary_loops()), (1, 1));
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(text.lines().filter(|l| l.starts_with("l ")).count(), 8);
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<polyline"));
}

#[test]
fn bad_arguments_and_bad_input() {
    let mesh = scratch("t.off");
    let o = ricci()
        .args(["generate", "torus", "--out"])
        .arg(&mesh)
        .output()
        .unwrap();
    assert!(o.status.success());
    // --out must be .obj: usage error, nothing written.
    let bad = scratch("x.off");
    let o = ricci()
        .arg("cut")
        .arg(&mesh)
        .arg("--out")
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(!bad.exists());
    // Base vertex out of range: usage error.
    let out = scratch("t.obj");
    let o = ricci()
        .arg("cut")
        .arg(&mesh)
        .args(["--base", "99999999", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(!out.exists());
    // A missing file is bad input.
    let o = ricci()
        .arg("cut")
        .arg(scratch("missing.off"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(!out.exists());
}
