//! `ricci generate`: the written file reads back with the topology the JSON report claims;
//! bad arguments exit with code 2 and write nothing.

use ricci::mesh::io::read_surface;
use ricci::mesh::topology;
use std::path::PathBuf;
use std::process::Command;

fn ricci() -> Command {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ricci-cli-generate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn genus2_off_reads_back_with_genus_2() {
    let out = scratch("g2.off");
    let o = ricci()
        .args(["generate", "genus2", "--out"])
        .arg(&out)
        .arg("--json")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // stdout is exactly one JSON object.
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("stdout is JSON");
    for key in [
        "vertices",
        "faces",
        "genus",
        "min_angle_deg",
        "max_angle_deg",
        "euler_characteristic",
        "boundary_loops",
    ] {
        assert!(v.get(key).is_some(), "missing key {key}");
    }
    let (s, report) = read_surface(&out).unwrap();
    assert!(report.notes.is_empty(), "{:?}", report.notes);
    let t = topology(&s.mesh);
    assert_eq!(t.components.len(), 1);
    assert_eq!(t.components[0].genus, 2);
    assert_eq!(t.boundary_loops(), 0);
    assert_eq!(v["genus"], 2);
    assert_eq!(v["euler_characteristic"], -2);
    assert_eq!(v["vertices"], s.mesh.n_vertices());
    assert_eq!(v["faces"], s.mesh.n_faces());
    let faces = s.mesh.n_faces();
    assert!(
        (2000..=4000).contains(&faces),
        "{faces} faces at the default resolution"
    );
    assert!(v["min_angle_deg"].as_f64().unwrap() >= 30.0);
    let _ = std::fs::remove_file(out);
}

#[test]
fn every_kind_writes_a_mesh_with_its_topology() {
    for (args, genus, loops, ext) in [
        (vec!["sphere", "--subdivisions", "2"], 0, 0, "ply"),
        (
            vec!["torus", "--major", "2", "--minor", "0.5", "-n", "20"],
            1,
            0,
            "obj",
        ),
        (vec!["disk", "-n", "24"], 0, 1, "stl"),
        (
            vec!["annulus", "--inner", "0.3", "--outer", "1", "-n", "24"],
            0,
            2,
            "off",
        ),
        (vec!["pants", "-n", "32"], 0, 3, "ply"),
        (vec!["genus", "--genus", "3", "-n", "14"], 3, 0, "off"),
    ] {
        let out = scratch(&format!("{}.{ext}", args[0]));
        let o = ricci()
            .arg("generate")
            .args(&args)
            .arg("--out")
            .arg(&out)
            .arg("--json")
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let (s, _) = read_surface(&out).unwrap();
        let t = topology(&s.mesh);
        assert_eq!(t.components.len(), 1, "{args:?}");
        assert_eq!(t.components[0].genus, genus, "{args:?}");
        assert_eq!(t.boundary_loops(), loops, "{args:?}");
        assert_eq!(v["genus"], genus, "{args:?}");
        assert_eq!(v["boundary_loops"], loops, "{args:?}");
        let _ = std::fs::remove_file(out);
    }
}

#[test]
fn bad_arguments_exit_2_and_write_nothing() {
    for args in [
        vec!["torus", "--major", "0.5", "--minor", "1"],
        vec!["cube"],
        vec!["genus"],
        vec!["sphere", "--major", "2"],
        vec!["genus2", "-n", "3"],
    ] {
        let out = scratch("bad.off");
        let o = ricci()
            .arg("generate")
            .args(&args)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(o.stdout.is_empty());
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.starts_with("error: ") && err.trim().lines().count() == 1,
            "{err}"
        );
        assert!(!out.exists(), "{args:?} wrote a file");
    }
    let o = ricci()
        .args(["generate", "disk", "--out"])
        .arg(scratch("disk.xyz"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    // An output path that cannot be created is an I/O failure: exit code 1.
    let blocker = scratch("a-file");
    std::fs::write(&blocker, b"x").unwrap();
    let o = ricci()
        .args(["generate", "disk", "--out"])
        .arg(blocker.join("disk.off"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
}
