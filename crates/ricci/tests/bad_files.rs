//! Hand-made bad files: each gives its own clear one-sentence error naming the file and the
//! line / byte / vertex / face at fault, and nothing panics — also on every truncation and
//! on random corruption of valid files.

use ricci::mesh::io::{self, read_surface, Format};
use std::path::PathBuf;

fn temp_dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("ricci-bad-files-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Write `bytes` to a file called `name` and return the error of reading it (which must be
/// one line and name the file).
fn error_of(name: &str, bytes: &[u8]) -> String {
    let path = temp_dir().join(name);
    std::fs::write(&path, bytes).unwrap();
    let e = match read_surface(&path) {
        Ok(_) => panic!("{name} was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(e.contains(name), "the message does not name the file: {e}");
    assert!(!e.contains('\n'), "the message is not one line: {e}");
    std::fs::remove_file(&path).unwrap();
    e
}

fn assert_has(e: &str, words: &[&str]) {
    for w in words {
        assert!(e.contains(w), "expected '{w}' in: {e}");
    }
}

const TETRA_OFF: &str =
    "OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";
const TETRA_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";

fn tetra_ply_binary(count_type: &str, index_type: &str) -> Vec<u8> {
    let mut d = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
         property float z\nelement face 4\nproperty list {count_type} {index_type} vertex_indices\nend_header\n"
    )
    .into_bytes();
    for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]] {
        for x in p {
            d.extend(x.to_le_bytes());
        }
    }
    for t in [[0u32, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]] {
        match count_type {
            "uchar" => d.push(3),
            "uint" => d.extend(3u32.to_le_bytes()),
            other => panic!("count type {other} not supported by this helper"),
        }
        for v in t {
            d.extend(v.to_le_bytes());
        }
    }
    d
}

fn tetra() -> ricci::mesh::Surface {
    let soup = io::parse(TETRA_OFF.as_bytes(), Format::Off).unwrap();
    ricci::mesh::build_surface(soup).unwrap().0
}

fn tetra_stl_binary() -> Vec<u8> {
    let p = [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]];
    let mut d = vec![0u8; 80];
    d.extend(4u32.to_le_bytes());
    for t in [[0usize, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]] {
        d.extend([0u8; 12]);
        for v in t {
            for x in p[v] {
                d.extend(x.to_le_bytes());
            }
        }
        d.extend([0u8; 2]);
    }
    d
}

#[test]
fn valid_samples_are_accepted() {
    // The corrupted variants below start from these; make sure they are good to begin with.
    for (fmt, d) in [
        (Format::Off, TETRA_OFF.as_bytes().to_vec()),
        (Format::Obj, TETRA_OBJ.as_bytes().to_vec()),
        (Format::Ply, tetra_ply_binary("uchar", "int")),
        (Format::Stl, tetra_stl_binary()),
    ] {
        let s = io::parse(&d, fmt).unwrap();
        let (surface, _) = ricci::mesh::build_surface(s).unwrap();
        assert_eq!(
            (surface.mesh.n_vertices(), surface.mesh.n_faces()),
            (4, 4),
            "{fmt:?}"
        );
    }
}

#[test]
fn truncated_binary_ply_names_element_index_and_byte() {
    let d = tetra_ply_binary("uchar", "int");
    let header_len = d.len() - 4 * 12 - 4 * 13;
    // Cut inside face 2: its record starts at header + 48 + 2·13.
    let face2 = header_len + 48 + 2 * 13;
    let e = error_of("cut.ply", &d[..face2 + 6]);
    assert_has(
        &e,
        &["truncated", "'face' 2", &format!("byte {}", face2 + 5)],
    );
    // Cut inside the vertices.
    let e = error_of("cut_vertices.ply", &d[..header_len + 20]);
    assert_has(
        &e,
        &[
            "truncated",
            "'vertex' 1",
            &format!("byte {}", header_len + 20),
        ],
    );
}

#[test]
fn index_out_of_range_names_face_and_line() {
    let e = error_of(
        "range.off",
        TETRA_OFF.replace("3 2 0 3", "3 2 0 7").as_bytes(),
    );
    assert_has(&e, &["face 3", "line 10", "vertex 7", "only 4 vertices"]);
    let e = error_of(
        "range.obj",
        TETRA_OBJ.replace("f 3 1 4", "f 3 1 5").as_bytes(),
    );
    assert_has(&e, &["face 3", "line 8", "vertex 5", "only 4 vertices"]);
    let e = error_of(
        "zero.obj",
        TETRA_OBJ.replace("f 3 1 4", "f 3 0 4").as_bytes(),
    );
    assert_has(&e, &["line 8", "index 0"]);
    let e = error_of(
        "relative.obj",
        TETRA_OBJ.replace("f 3 1 4", "f 3 -9 4").as_bytes(),
    );
    assert_has(&e, &["line 8", "relative", "-9"]);
    let mut d = tetra_ply_binary("uchar", "int");
    let n = d.len();
    d[n - 4..].copy_from_slice(&(-2i32).to_le_bytes());
    let e = error_of("negative.ply", &d);
    assert_has(&e, &["face 3", "vertex -2", "byte"]);
    let mut d = tetra_ply_binary("uchar", "int");
    d[n - 4..].copy_from_slice(&9i32.to_le_bytes());
    let e = error_of("range.ply", &d);
    assert_has(&e, &["face 3", "vertex 9", "only 4 vertices"]);
}

#[test]
fn non_finite_coordinates_name_the_vertex() {
    let e = error_of("nan.off", TETRA_OFF.replace("0 1 0", "0 nan 0").as_bytes());
    assert_has(&e, &["vertex 2", "line 5", "non-finite"]);
    let e = error_of(
        "inf.obj",
        TETRA_OBJ.replace("v 0 0 1", "v 0 0 inf").as_bytes(),
    );
    assert_has(&e, &["vertex 3", "line 4", "non-finite"]);
    let mut d = tetra_ply_binary("uchar", "int");
    let header_len = d.len() - 4 * 12 - 4 * 13;
    d[header_len + 12 + 4..header_len + 12 + 8].copy_from_slice(&f32::NAN.to_le_bytes());
    let e = error_of("nan.ply", &d);
    assert_has(
        &e,
        &[
            "vertex 1",
            "non-finite",
            &format!("byte {}", header_len + 12),
        ],
    );
    let mut d = tetra_stl_binary();
    d[84 + 12 + 8..84 + 12 + 12].copy_from_slice(&f32::INFINITY.to_le_bytes());
    let e = error_of("inf.stl", &d);
    assert_has(&e, &["triangle 0", "non-finite", "byte 96"]);
}

#[test]
fn empty_files_say_so() {
    for name in ["empty.obj", "empty.off", "empty.ply", "empty.stl"] {
        assert_has(&error_of(name, b""), &["empty"]);
        assert_has(&error_of(name, b"  \n\r\n\t\n"), &["empty"]);
    }
    assert_has(
        &error_of("comments.off", b"# only\n# comments\n"),
        &["empty"],
    );
    assert_has(&error_of("comments.obj", b"# only a comment\n"), &["empty"]);
    // Vertices but no faces.
    assert_has(
        &error_of("nofaces.obj", b"v 0 0 0\nv 1 0 0\n"),
        &["no faces"],
    );
    assert_has(
        &error_of("nofaces.off", b"OFF\n2 0 0\n0 0 0\n1 0 0\n"),
        &["no faces"],
    );
}

#[test]
fn wrong_off_counts_line_is_named() {
    let e = error_of(
        "counts.off",
        TETRA_OFF.replace("4 4 6", "4 four 6").as_bytes(),
    );
    assert_has(&e, &["line 2", "wrong counts line", "4 four 6"]);
    let e = error_of("counts2.off", TETRA_OFF.replace("4 4 6", "4").as_bytes());
    assert_has(&e, &["line 2", "wrong counts line"]);
    let e = error_of(
        "counts3.off",
        TETRA_OFF.replace("4 4 6", "4 -4 6").as_bytes(),
    );
    assert_has(&e, &["line 2", "wrong counts line"]);
    let e = error_of(
        "counts4.off",
        TETRA_OFF.replace("4 4 6", "4 4 6 1").as_bytes(),
    );
    assert_has(&e, &["line 2", "wrong counts line"]);
    // Counts on the header line are fine; a wrong one there is named too.
    let e = error_of(
        "counts5.off",
        TETRA_OFF.replace("OFF\n4 4 6", "OFF 4 x").as_bytes(),
    );
    assert_has(&e, &["line 1", "wrong counts line"]);
    // Too few vertices or faces for the counts.
    let e = error_of("short.off", b"OFF\n5 1 0\n0 0 0\n1 0 0\n");
    assert_has(&e, &["line 2", "declares 5 vertices", "ends after 2"]);
    let e = error_of("short2.off", TETRA_OFF.replace("4 4 6", "4 5 6").as_bytes());
    assert_has(&e, &["line 2", "declares 5 faces", "ends after 4"]);
    let e = error_of("header.off", TETRA_OFF.replace("OFF", "OBJ").as_bytes());
    assert_has(&e, &["line 1", "OFF header", "OBJ"]);
    let e = error_of("bin.off", b"OFF BINARY\n");
    assert_has(&e, &["line 1", "binary OFF"]);
    let e = error_of(
        "corners.off",
        TETRA_OFF.replace("3 2 0 3", "4 2 0 3").as_bytes(),
    );
    assert_has(&e, &["line 10", "face 3", "declares 4 corners", "only 3"]);
    let e = error_of(
        "coords.off",
        TETRA_OFF.replace("0 0 1\n", "0 0\n").as_bytes(),
    );
    assert_has(&e, &["line 6", "vertex 3", "2 coordinates"]);
}

#[test]
fn garbage_is_refused_by_every_reader() {
    let garbage: Vec<u8> = (0..2000u32)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    let text = b"Lorem ipsum dolor sit amet,\nconsectetur adipiscing elit.\n";
    for (ext, words) in [
        ("obj", &["OBJ"][..]),
        ("off", &["line 1", "OFF header"][..]),
        ("ply", &["not a PLY file"][..]),
        ("stl", &["not an STL file"][..]),
    ] {
        error_of(&format!("garbage.{ext}"), &garbage);
        let e = error_of(&format!("text.{ext}"), text);
        assert_has(&e, words);
    }
    let e = error_of(
        "text2.stl",
        b"solid x\n facet normal 0 0 1\n  bogus 1 2 3\n",
    );
    assert_has(&e, &["line 3", "bogus"]);
    let e = error_of(
        "open.stl",
        b"solid x\n facet normal 0 0 1\n outer loop\n vertex 0 0 0\n",
    );
    assert_has(&e, &["facet that starts at line 2"]);
    let e = error_of(
        "noend.ply",
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n",
    );
    assert_has(&e, &["end_header"]);
    let e = error_of(
        "nox.ply",
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float y\nend_header\n0\n",
    );
    assert_has(&e, &["no scalar property 'x'"]);
    let e = error_of(
        "noface.ply",
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n",
    );
    assert_has(&e, &["no 'face' element"]);
    let e = error_of(
        "badtype.ply",
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty quaternion x\nend_header\n",
    );
    assert_has(&e, &["line 4", "quaternion"]);
    let e = error_of(
        "asciiword.ply",
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
          element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 zero\n0 1 0\n3 0 1 2\n",
    );
    assert_has(&e, &["line 11", "'vertex' 1", "zero"]);
    let e = error_of("unknown.xyz", TETRA_OFF.as_bytes());
    assert_has(&e, &["unknown mesh format", ".xyz"]);
}

#[test]
fn missing_file_names_the_path() {
    let p = temp_dir().join("does-not-exist.obj");
    let e = read_surface(&p).unwrap_err().to_string();
    assert_has(&e, &["does-not-exist.obj"]);
}

#[test]
fn huge_counts_in_tiny_files_fail_fast() {
    let e = error_of("huge.off", b"OFF\n2000000000 2000000000 0\n0 0 0\n");
    assert_has(
        &e,
        &["line 2", "declares 2000000000 vertices", "ends after 1"],
    );
    let e = error_of(
        "huge.ply",
        b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty double x\n\
          property double y\nproperty double z\nelement face 4000000000\nproperty list uint uint vertex_indices\nend_header\n\0\0\0\0",
    );
    assert_has(&e, &["truncated", "'vertex' 0", "byte"]);
    let mut d = tetra_ply_binary("uint", "int");
    // A face claiming 4 billion corners.
    let n = d.len();
    let last_face = n - 4 - 12;
    d[last_face..last_face + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = error_of("hugelist.ply", &d);
    assert_has(&e, &["truncated", "'face' 3"]);
    let mut d = tetra_stl_binary();
    d[80..84].copy_from_slice(&3_000_000_000u32.to_le_bytes());
    let e = error_of("huge.stl", &d);
    assert_has(
        &e,
        &["truncated binary STL", "3000000000 triangles", "triangle 4"],
    );
}

#[test]
fn invalid_surfaces_name_the_culprit() {
    // Three triangles on one edge.
    let e = error_of(
        "fin.off",
        b"OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n",
    );
    assert_has(
        &e,
        &[
            "non-manifold edge",
            "vertices 0 (line 3) and 1 (line 4)",
            "3 faces",
        ],
    );
    // Two triangles touching at a vertex (bow tie).
    let e = error_of(
        "bowtie.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n",
    );
    assert_has(&e, &["non-manifold vertex 0", "line 1"]);
    // Two closed tetrahedra sharing one vertex: pinched without boundary (like cow.obj).
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nv -1 0 0\nv 0 -1 0\nv -1 -1 -1\n\
               f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\nf 1 6 5\nf 1 5 7\nf 5 6 7\nf 6 1 7\n";
    let e = error_of("pinch.obj", obj.as_bytes());
    assert_has(&e, &["non-manifold vertex 0 (line 1)", "more than one fan"]);
    // A Möbius strip.
    let mut obj = String::new();
    for i in 0..6 {
        obj += &format!("v {i} 0 0\nv {i} 1 0\n");
    }
    for i in 0..5 {
        let (a, b) = (2 * i + 1, 2 * i + 3);
        obj += &format!("f {a} {b} {} {}\n", b + 1, a + 1);
    }
    obj += "f 11 2 1 12\n";
    let e = error_of("moebius.obj", obj.as_bytes());
    assert_has(&e, &["not orientable"]);
    // Duplicate faces (same vertices, either orientation).
    let e = error_of(
        "dup.off",
        (TETRA_OFF.replace("4 4 6", "4 5 6") + "3 1 0 2\n").as_bytes(),
    );
    assert_has(&e, &["faces 0 (line 7) and 4 (line 11) are duplicates"]);
    // Repeated vertex in a face; too few corners.
    let e = error_of(
        "repeat.obj",
        TETRA_OBJ.replace("f 2 3 4", "f 2 3 2").as_bytes(),
    );
    assert_has(&e, &["face 2 (line 7)", "vertex 1 more than once"]);
    let e = error_of("two.off", TETRA_OFF.replace("3 2 0 3", "2 2 0").as_bytes());
    assert_has(&e, &["face 3 (line 10)", "only 2 corners"]);
}

#[test]
fn accepted_with_notes() {
    // A quad, a face against the quad's orientation, a zero-area face (vertex 6 lies on
    // the edge 0–1), an unreferenced vertex (5).
    let d = "OFF\n7 3 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n9 9 9\n0.5 0 0\n\
             4 0 1 2 3\n3 1 2 4\n3 1 0 6\n";
    let path = temp_dir().join("notes.off");
    std::fs::write(&path, d).unwrap();
    let (s, r) = read_surface(&path).unwrap();
    assert_eq!(r.triangulated_polygons, 1);
    assert_eq!(r.dropped_vertices, vec![5]);
    assert_eq!(r.reoriented_faces, 1); // "1 2 4" runs along the quad's edge 1→2
    assert_eq!(r.zero_area_faces.len(), 1);
    assert_eq!(s.mesh.n_faces(), 4);
    let notes = r.notes.join(" | ");
    assert_has(
        &notes,
        &["fan-triangulated", "dropped", "flipped", "zero area"],
    );
}

/// Every prefix of valid files of every format, and random byte corruptions, give an error
/// or a surface, never a panic.
#[test]
fn truncations_and_corruptions_never_panic() {
    let samples: Vec<(Format, Vec<u8>)> = vec![
        (Format::Off, TETRA_OFF.as_bytes().to_vec()),
        (
            Format::Obj,
            TETRA_OBJ
                .replace("f 1 3 2", "vt 0 0\nf 1/1 3/1 2/1")
                .into_bytes(),
        ),
        (Format::Ply, tetra_ply_binary("uchar", "int")),
        (Format::Ply, {
            let mut out = Vec::new();
            io::write_ply(&mut out, &tetra(), false).unwrap();
            out
        }),
        (Format::Stl, tetra_stl_binary()),
        (Format::Stl, {
            let mut out = Vec::new();
            io::write_stl(&mut out, &tetra(), false).unwrap();
            out
        }),
    ];
    let mut x: u64 = 0x2545_F491_4F6C_DD1D;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut runs = 0;
    for (fmt, d) in &samples {
        for cut in 0..=d.len() {
            if let Ok(s) = io::parse(&d[..cut], *fmt) {
                let _ = ricci::mesh::build_surface(s);
            }
            runs += 1;
        }
        for _ in 0..300 {
            let mut c = d.clone();
            for _ in 0..1 + next() % 4 {
                let i = (next() % c.len() as u64) as usize;
                c[i] = next() as u8;
            }
            if let Ok(s) = io::parse(&c, *fmt) {
                let _ = ricci::mesh::build_surface(s);
            }
            runs += 1;
        }
    }
    assert!(runs > 2000);
}

/// Fuzzing regression (fuzz_stl, crash-480a1253): an ascii STL coordinate of 3.3e110 is a
/// fine `f64` but overflows the `f32` of binary STL; the binary writer wrote `inf`, which the
/// reader (rightly) refused. The writer now refuses instead, and ascii STL keeps the value.
#[test]
fn fuzz_regression_binary_stl_refuses_coordinates_beyond_f32() {
    let big = format!("{}0", "3".repeat(110));
    let mut stl = String::from("solid t\n");
    let tris = [
        ["0 0 0", "0 1 0", "1 0 0"],
        ["0 0 0", "1 0 0", "0 0 1"],
        ["1 0 0", &format!("0 1 {big}"), "0 0 1"],
        ["0 1 0", "0 0 0", "0 0 1"],
    ];
    for t in tris {
        stl += " facet normal 0 0 0\n  outer loop\n";
        for v in t {
            stl += &format!("   vertex {v}\n");
        }
        stl += "  endloop\n endfacet\n";
    }
    stl += "endsolid t\n";
    let (s, _) =
        ricci::mesh::build_surface(io::parse(stl.as_bytes(), Format::Stl).unwrap()).unwrap();
    let mut out = Vec::new();
    let e = io::write_stl(&mut out, &s, true).unwrap_err().to_string();
    assert_has(&e, &["32-bit", "ascii STL"]);
    let mut out = Vec::new();
    io::write_stl(&mut out, &s, false).unwrap();
    let (back, _) = ricci::mesh::build_surface(io::parse(&out, Format::Stl).unwrap()).unwrap();
    assert!(back
        .positions
        .iter()
        .flatten()
        .any(|&x| x == 3.333333333333333e110));
}

#[test]
fn read_errors_carry_the_record_and_its_place_as_data() {
    use ricci::mesh::io::{parse_soup, Record};
    // The records and lines below are those of the corrupted sample, counted by hand.
    let off = TETRA_OFF.replace("3 2 0 3", "3 2 0 -1");
    let e = parse_soup(off.as_bytes(), Format::Off).unwrap_err();
    assert_eq!(
        (&e.record, e.face(), e.line()),
        (&Record::Face(3), Some(3), Some(10))
    );
    let obj = TETRA_OBJ.replace("v 0 1 0", "v 0 x 0");
    let e = parse_soup(obj.as_bytes(), Format::Obj).unwrap_err();
    assert_eq!((e.vertex(), e.line()), (Some(2), Some(3)), "{e}");
    let obj = TETRA_OBJ.replace("f 3 1 4", "f 3 1 5");
    let e = parse_soup(obj.as_bytes(), Format::Obj).unwrap_err();
    assert_eq!((e.face(), e.line()), (Some(3), Some(8)), "{e}");
    let obj = TETRA_OBJ.replace("f 1 2 4", "vt 0 0\nf 1/2 2 4");
    let e = parse_soup(obj.as_bytes(), Format::Obj).unwrap_err();
    assert_eq!((e.face(), e.line()), (Some(1), Some(7)), "{e}");
    // Binary PLY cut inside face 2: the face and the byte where the data end.
    let d = tetra_ply_binary("uchar", "int");
    let header_len = d.len() - 4 * 12 - 4 * 13;
    let face2 = header_len + 48 + 2 * 13;
    let e = parse_soup(&d[..face2 + 6], Format::Ply).unwrap_err();
    assert_eq!(e.face(), Some(2), "{e}");
    assert_eq!(e.location.byte, Some(face2 as u64 + 5), "{e}");
    // A bad property type is about the header, at its line (5).
    let bad = String::from_utf8_lossy(&d[..header_len]).replace("float y", "real y");
    let e = parse_soup(bad.as_bytes(), Format::Ply).unwrap_err();
    assert_eq!((&e.record, e.line()), (&Record::Header, Some(5)), "{e}");
    // Another element's record: named, with its index.
    let ascii = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                 property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                 element edge 2\nproperty int a\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n5\nq\n";
    let e = parse_soup(ascii.as_bytes(), Format::Ply).unwrap_err();
    assert_eq!(
        (&e.record, e.line()),
        (
            &Record::Element {
                name: "edge".into(),
                index: 1
            },
            Some(17)
        ),
        "{e}"
    );
    // The conversion into ricci::Error keeps the sentence and the record.
    assert_eq!(ricci::Error::from(e.clone()).to_string(), e.to_string());
    assert_eq!(ricci::Error::from(e.clone()).record(), Some(&e.record));
    // So does the library's reader that returns ricci::Error (the OFF face 3 above).
    let off = TETRA_OFF.replace("3 2 0 3", "3 2 0 -1");
    let e = ricci::mesh::io::parse(off.as_bytes(), Format::Off).unwrap_err();
    assert_eq!(e.record(), Some(&Record::Face(3)), "{e}");
}
