//! `mesh::io::uv_match`: texture coordinates read back onto the mesh they were made for.
//! Files are written by hand here, so the expected UVs are the ones the test wrote.

use ricci::mesh::io::uv_match::{has_corner_uvs, uvs_from_file, MatchedUvs};
use ricci::mesh::Surface;
use std::path::PathBuf;

fn square() -> Surface {
    Surface::new(
        vec![
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .expect("square")
}

fn write(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ricci-uv-match-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write");
    p
}

const V: &str = "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";

#[test]
fn one_uv_per_vertex_comes_back_per_vertex() {
    let p = write(
        "per-vertex.obj",
        &format!(
            "{V}vt 0.1 0.2\nvt 0.3 0.4\nvt 0.5 0.6\nvt 0.7 0.8\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n"
        ),
    );
    assert!(has_corner_uvs(&p));
    let got = uvs_from_file(&p, &square()).expect("uvs");
    assert_eq!(
        got,
        MatchedUvs::PerVertex(vec![[0.1, 0.2], [0.3, 0.4], [0.5, 0.6], [0.7, 0.8]])
    );
}

#[test]
fn a_seam_gives_uvs_per_corner_matched_by_position() {
    // Vertex 3 (0-based 2) has another vt in the second face: a seam. The second face is
    // written starting at another corner, so matching must go by position, not by index.
    let p = write(
        "seam.obj",
        &format!("{V}vt 0 0\nvt 1 0\nvt 1 1\nvt 9 9\nvt 0 1\nf 1/1 2/2 3/3\nf 3/4 4/5 1/1\n"),
    );
    let got = uvs_from_file(&p, &square()).expect("uvs");
    let want = vec![
        [0.0, 0.0],
        [1.0, 0.0],
        [1.0, 1.0],
        [0.0, 0.0],
        [9.0, 9.0],
        [0.0, 1.0],
    ];
    assert_eq!(got, MatchedUvs::PerCorner(want));
}

#[test]
fn a_planar_layout_without_vt_gives_its_xy() {
    let p = write(
        "planar.obj",
        "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nf 1 2 3\nf 1 3 4\n",
    );
    assert!(!has_corner_uvs(&p));
    let got = uvs_from_file(&p, &square()).expect("uvs");
    assert_eq!(
        got,
        MatchedUvs::PerVertex(vec![[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    );
}

#[test]
fn other_faces_are_refused_with_the_file_and_both_counts() {
    let p = write(
        "one-face.obj",
        &format!("{V}vt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/3\n"),
    );
    let e = uvs_from_file(&p, &square())
        .expect_err("must refuse")
        .to_string();
    assert!(e.contains("one-face.obj"), "{e}");
    assert!(e.contains("1 faces, but the mesh has 2"), "{e}");
    let p = write(
        "not-planar.obj",
        "v 0 0 0\nv 1 0 1\nv 1 1 0\nv 0 1 2\nf 1 2 3\nf 1 3 4\n",
    );
    let e = uvs_from_file(&p, &square())
        .expect_err("must refuse")
        .to_string();
    assert!(e.contains("no texture coordinates"), "{e}");
}
