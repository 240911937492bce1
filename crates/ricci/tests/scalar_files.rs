//! `mesh::io::scalars`: the numbers written by the test come back, and bad files are refused
//! with the file and the line or entry.

use ricci::mesh::io::scalars::read_scalar_file;
use std::path::PathBuf;

fn write(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ricci-scalars-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write");
    p
}

#[test]
fn text_numbers_with_commas_and_comments() {
    let p = write("height.txt", "# heights\n1.5, -2\n3e-1 # third\n\n4\n");
    let s = read_scalar_file(&p, None).expect("read");
    assert_eq!(s.values, vec![1.5, -2.0, 0.3, 4.0]);
    assert_eq!(s.name, "height");
}

#[test]
fn json_arrays_by_key_with_null_as_missing() {
    let p = write("metric.json", r#"{"K": [1, 2], "u": [0.5, null, -1]}"#);
    let s = read_scalar_file(&p, None).expect("read");
    assert_eq!(s.name, "u");
    assert_eq!(s.values[0], 0.5);
    assert!(s.values[1].is_nan());
    assert_eq!(s.values[2], -1.0);
    let s = read_scalar_file(&p, Some("K")).expect("read K");
    assert_eq!((s.values, s.name.as_str()), (vec![1.0, 2.0], "K"));
}

#[test]
fn bad_files_name_the_file_and_the_place() {
    let p = write("bad.txt", "1 2\n3 x4\n");
    let e = read_scalar_file(&p, None).expect_err("refuse").to_string();
    assert!(e.contains("bad.txt, line 2: 'x4' is not a number"), "{e}");
    let p = write("bad.json", r#"{"u": [1, "a"]}"#);
    let e = read_scalar_file(&p, None).expect_err("refuse").to_string();
    assert!(
        e.contains("bad.json: entry 1 of \"u\" is not a number"),
        "{e}"
    );
    let e = read_scalar_file(&p, Some("w"))
        .expect_err("refuse")
        .to_string();
    assert!(e.contains("no array under the key w"), "{e}");
}
