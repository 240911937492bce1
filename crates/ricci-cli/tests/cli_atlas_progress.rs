//! `ricci atlas --singularity auto`: one stderr line per candidate flow of the placement,
//! consistent with the placement the JSON reports (the same vertices, in order, and the
//! chosen vertex among the converged ones with the least distortion).

use std::path::PathBuf;
use std::process::Command;

fn ricci() -> Command {
    Command::new(env!("CARGO_BIN_EXE_ricci"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ricci-cli-atlas-progress-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn placement_prints_one_line_per_candidate() {
    let mesh = scratch("g2.off");
    let o = ricci()
        .args(["generate", "genus2", "-n", "24", "--out"])
        .arg(&mesh)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = scratch("g2-atlas");
    let o = ricci()
        .arg("atlas")
        .arg(&mesh)
        .args(["--out"])
        .arg(&out)
        .arg("--json")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let p = &v["placement"];
    let confirmed = p["confirmed"].as_array().unwrap();
    let rejected = p["rejected"].as_array().unwrap();
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("placement: candidate "))
        .collect();
    assert_eq!(lines.len(), confirmed.len() + rejected.len(), "{err}");
    for c in confirmed {
        let needle = format!("(vertex {}) converged: distortion ", c["vertex"]);
        assert!(lines.iter().any(|l| l.contains(&needle)), "{needle}\n{err}");
    }
    for r in rejected {
        let needle = format!("(vertex {}) did not converge", r["vertex"]);
        assert!(lines.iter().any(|l| l.contains(&needle)), "{needle}\n{err}");
    }
    let best = confirmed
        .iter()
        .min_by(|a, b| {
            a["measured"]
                .as_f64()
                .unwrap()
                .total_cmp(&b["measured"].as_f64().unwrap())
        })
        .unwrap();
    assert_eq!(v["singular_vertex"], best["vertex"]);
}
