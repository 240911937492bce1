//! Stanford PLY: reader (ascii, binary little endian, binary big endian) and writer (ascii,
//! binary little endian).
//!
//! Read: the `vertex` element's `x`, `y`, `z` (any scalar type; `u v`, `s t` or `texture_u
//! texture_v` become per-vertex UVs), the `face` element's `vertex_indices` (or
//! `vertex_index`) list with any count and index types. Every other property, list or element
//! is skipped. Errors name the header line, or for data the element, its index and the line
//! (ascii) or byte offset (binary) — a truncated binary file says where it ends.

mod data;
mod header;

use super::error::{ReadResult, Record};
use super::text::{self, show};
use crate::error::{Error, Result};
use crate::mesh::{PolygonSoup, Surface};
use data::{list_count, skip_list, Item, Source, Value};
use header::{parse_header, Element, Header, Property, Storage};
use std::io::Write;

/// Parse a PLY file held in memory.
pub fn parse_ply(data: &[u8]) -> ReadResult<PolygonSoup> {
    let header = parse_header(data)?;
    let mut src = data_source(data, &header);
    let binary = header.storage != Storage::Ascii;
    let mut mesh = PlyMesh::default();
    for el in &header.elements {
        // A capacity bounded by what the rest of the file can hold.
        let min_size: usize = el
            .props
            .iter()
            .map(|p| match p {
                Property::Scalar(_, s) => s.size(),
                Property::List(_, c, _) => c.size(),
            })
            .sum::<usize>()
            .max(if binary { 1 } else { 2 });
        let cap = el.count.min(src.remaining() / min_size + 1);
        if el.name == b"vertex" && !mesh.saw_vertex {
            mesh.saw_vertex = true;
            read_vertices(&mut src, el, cap, binary, &mut mesh)?;
        } else if el.name == b"face" && !mesh.saw_face {
            mesh.saw_face = true;
            read_faces(&mut src, el, cap, &mut mesh)?;
        } else {
            skip_element(&mut src, el)?;
        }
    }
    mesh.finish(binary)
}

/// The source of the data after the header: ascii tokens with their lines, or binary bytes.
fn data_source<'a>(data: &'a [u8], header: &Header) -> Source<'a> {
    match header.storage {
        Storage::Ascii => Source::Ascii {
            data: &data[header.data_start..],
            pos: 0,
            line: data[..header.data_start]
                .iter()
                .filter(|&&b| b == b'\n')
                .count()
                + 1,
        },
        Storage::Little | Storage::Big => Source::Binary {
            data,
            pos: header.data_start,
            big: header.storage == Storage::Big,
        },
    }
}

/// What the reader keeps of a PLY file.
#[derive(Default)]
struct PlyMesh {
    soup: PolygonSoup,
    vertex_lines: Vec<usize>,
    polygon_lines: Vec<usize>,
    /// Per-vertex UVs, when the vertex element has a UV pair.
    uvs: Option<Vec<[f64; 2]>>,
    saw_vertex: bool,
    saw_face: bool,
}

impl PlyMesh {
    fn finish(mut self, binary: bool) -> ReadResult<PolygonSoup> {
        if !self.saw_vertex {
            return Err(text::whole("the PLY file has no 'vertex' element"));
        }
        if !self.saw_face {
            return Err(text::whole(
                "the PLY file has no 'face' element (a point cloud is not a surface)",
            ));
        }
        if !binary {
            self.soup.vertex_lines = Some(self.vertex_lines);
            self.soup.polygon_lines = Some(self.polygon_lines);
        }
        self.soup.uvs = self.uvs;
        Ok(self.soup)
    }
}

/// The property indices of `x`, `y`, `z` and of a UV pair, if any.
struct VertexLayout {
    xyz: [usize; 3],
    uv: Option<(usize, usize)>,
}

/// The property indices of `x`, `y`, `z` and of a UV pair (`u v`, `s t`, `texture_u
/// texture_v` or `texture_s texture_t`) in the vertex element.
fn vertex_layout(el: &Element) -> ReadResult<VertexLayout> {
    let find = |name: &[u8]| {
        el.props
            .iter()
            .position(|p| matches!(p, Property::Scalar(n, _) if n == name))
    };
    let mut xyz = [0usize; 3];
    for (k, c) in [b"x", b"y", b"z"].iter().enumerate() {
        xyz[k] = find(&c[..]).ok_or_else(|| {
            text::whole(format!(
                "the 'vertex' element has no scalar property '{}'",
                c[0] as char
            ))
            .about(Record::Header)
        })?;
    }
    let uv_pair = [
        (&b"u"[..], &b"v"[..]),
        (b"s", b"t"),
        (b"texture_u", b"texture_v"),
        (b"texture_s", b"texture_t"),
    ]
    .iter()
    .find_map(|(a, b)| Some((find(a)?, find(b)?)));
    Ok(VertexLayout { xyz, uv: uv_pair })
}

/// The records of the vertex element: positions, UVs, and (ascii) their lines.
fn read_vertices(
    src: &mut Source,
    el: &Element,
    cap: usize,
    binary: bool,
    mesh: &mut PlyMesh,
) -> ReadResult<()> {
    let VertexLayout { xyz, uv: uv_pair } = vertex_layout(el)?;
    mesh.soup.positions.reserve(cap);
    if uv_pair.is_some() {
        mesh.uvs = Some(Vec::with_capacity(cap));
    }
    for i in 0..el.count {
        let at = src.here();
        let item = Item {
            element: "vertex",
            index: i,
            count: el.count,
            kept: true,
        };
        let mut p = [0.0f64; 3];
        let mut uv = [0.0f64; 2];
        for (j, prop) in el.props.iter().enumerate() {
            match prop {
                Property::Scalar(_, ty) => {
                    let v = src.read(*ty, &item)?.as_f64();
                    if let Some(k) = xyz.iter().position(|&x| x == j) {
                        p[k] = v;
                    }
                    if let Some((a, b)) = uv_pair {
                        if j == a {
                            uv[0] = v;
                        } else if j == b {
                            uv[1] = v;
                        }
                    }
                }
                Property::List(_, ct, it) => skip_list(src, *ct, *it, &item)?,
            }
        }
        if binary && p.iter().any(|x| !x.is_finite()) {
            return Err(at
                .error(format!(
                    "vertex {i} has a non-finite coordinate ({}, {}, {})",
                    p[0], p[1], p[2]
                ))
                .about(Record::Vertex(i)));
        }
        mesh.soup.positions.push(p);
        if let Some(uvs) = &mut mesh.uvs {
            uvs.push(uv);
        }
        if let Some(l) = at.line() {
            mesh.vertex_lines.push(l);
        }
    }
    Ok(())
}

/// The records of the face element: the `vertex_indices` list of each, and (ascii) its line.
fn read_faces(src: &mut Source, el: &Element, cap: usize, mesh: &mut PlyMesh) -> ReadResult<()> {
    let list = el
        .props
        .iter()
        .position(|p| {
            matches!(p, Property::List(n, _, _) if n == b"vertex_indices" || n == b"vertex_index")
        })
        .ok_or_else(|| {
            text::whole("the 'face' element has no list property 'vertex_indices' (or 'vertex_index')")
                .about(Record::Header)
        })?;
    if let Property::List(_, _, it) = &el.props[list] {
        if !it.is_integer() {
            return Err(text::whole(
                "the face list 'vertex_indices' must have an integer item type",
            )
            .about(Record::Header));
        }
    }
    mesh.soup.polygons.reserve(cap);
    for i in 0..el.count {
        let at = src.here();
        let item = Item {
            element: "face",
            index: i,
            count: el.count,
            kept: true,
        };
        for (j, prop) in el.props.iter().enumerate() {
            match prop {
                Property::Scalar(_, ty) => {
                    src.read(*ty, &item)?;
                }
                Property::List(_, ct, it) if j == list => {
                    let k = list_count(src, *ct, &item, &at)?;
                    mesh.soup.polygons.push(face_indices(src, *it, k, &item)?);
                }
                Property::List(_, ct, it) => skip_list(src, *ct, *it, &item)?,
            }
        }
        if let Some(l) = at.line() {
            mesh.polygon_lines.push(l);
        }
    }
    Ok(())
}

/// The `k` vertex indices (item type `it`) of face `item.index`.
fn face_indices(
    src: &mut Source,
    it: header::Scalar,
    k: usize,
    item: &Item,
) -> ReadResult<Vec<u32>> {
    let i = item.index;
    let mut poly = Vec::with_capacity(k.min(src.remaining() / it.size().max(1) + 1).min(64));
    for _ in 0..k {
        let loc = src.here();
        match src.read(it, item)? {
            Value::Int(v) if (0..u32::MAX as i128).contains(&v) => poly.push(v as u32),
            Value::Int(v) => {
                return Err(loc
                    .error(format!(
                        "face {i} refers to vertex {v}, which is not a valid vertex index"
                    ))
                    .about(Record::Face(i)))
            }
            Value::Float(_) => {
                return Err(loc
                    .error(format!("face {i}: vertex indices must be integers"))
                    .about(Record::Face(i)))
            }
        }
    }
    Ok(poly)
}

/// Read past every record of an element this reader does not keep.
fn skip_element(src: &mut Source, el: &Element) -> ReadResult<()> {
    let ename = show(&el.name);
    for i in 0..el.count {
        let item = Item {
            element: &ename,
            index: i,
            count: el.count,
            kept: false,
        };
        for prop in &el.props {
            match prop {
                Property::Scalar(_, ty) => {
                    src.read(*ty, &item)?;
                }
                Property::List(_, ct, it) => skip_list(src, *ct, *it, &item)?,
            }
        }
    }
    Ok(())
}

/// Write a surface as PLY: `binary` selects binary little endian, otherwise ascii. Vertices
/// are written as `double` x, y, z (and u, v when the surface has UVs), faces as
/// `list uchar int vertex_indices`, so a file reads back exactly.
pub fn write_ply<W: Write>(w: W, s: &Surface, binary: bool) -> Result<()> {
    super::check_finite(s)?;
    let mut w = std::io::BufWriter::new(w);
    let io = |e| Error::io("PLY output", e);
    let uvs = s.uvs.as_ref().filter(|u| u.len() == s.positions.len());
    let mut h = String::from("ply\n");
    h += if binary {
        "format binary_little_endian 1.0\n"
    } else {
        "format ascii 1.0\n"
    };
    h += "comment written by ricci\n";
    h += &format!("element vertex {}\n", s.positions.len());
    h += "property double x\nproperty double y\nproperty double z\n";
    if uvs.is_some() {
        h += "property double u\nproperty double v\n";
    }
    h += &format!("element face {}\n", s.mesh.n_faces());
    h += "property list uchar int vertex_indices\nend_header\n";
    w.write_all(h.as_bytes()).map_err(io)?;
    if binary {
        for (i, p) in s.positions.iter().enumerate() {
            for x in p {
                w.write_all(&x.to_le_bytes()).map_err(io)?;
            }
            if let Some(uv) = uvs {
                for x in uv[i] {
                    w.write_all(&x.to_le_bytes()).map_err(io)?;
                }
            }
        }
        for t in s.mesh.faces() {
            w.write_all(&[3u8]).map_err(io)?;
            for v in t {
                w.write_all(&(*v as i32).to_le_bytes()).map_err(io)?;
            }
        }
    } else {
        for (i, p) in s.positions.iter().enumerate() {
            write!(w, "{:?} {:?} {:?}", p[0], p[1], p[2]).map_err(io)?;
            if let Some(uv) = uvs {
                write!(w, " {:?} {:?}", uv[i][0], uv[i][1]).map_err(io)?;
            }
            writeln!(w).map_err(io)?;
        }
        for t in s.mesh.faces() {
            writeln!(w, "3 {} {} {}", t[0], t[1], t[2]).map_err(io)?;
        }
    }
    w.flush().map_err(io)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(format: &str, extra: &str) -> String {
        format!(
            "ply\nformat {format} 1.0\ncomment c\nelement vertex 3\nproperty float x\nproperty float y\n\
             property float z\nproperty uchar red\n{extra}element face 1\nproperty uchar flags\n\
             property list uchar uint vertex_indices\nelement edge 1\nproperty list int int ends\nend_header\n"
        )
    }

    #[test]
    fn ascii_with_skipped_properties_and_elements() {
        let d = header("ascii", "") + "0 0 0 255\n1 0 0 255\n0 1 0 255\n7 3 0 1 2\n2 0 1\n";
        let s = parse_ply(d.as_bytes()).unwrap();
        assert_eq!(s.positions[1], [1.0, 0.0, 0.0]);
        assert_eq!(s.polygons, vec![vec![0, 1, 2]]);
        assert_eq!(s.vertex_lines, Some(vec![15, 16, 17]));
        assert_eq!(s.polygon_lines, Some(vec![18]));
    }

    #[test]
    fn both_endiannesses_agree() {
        for (fmt, big) in [("binary_little_endian", false), ("binary_big_endian", true)] {
            let mut d = header(fmt, "").into_bytes();
            let f = |x: f32| {
                if big {
                    x.to_be_bytes()
                } else {
                    x.to_le_bytes()
                }
            };
            let u = |x: u32| {
                if big {
                    x.to_be_bytes()
                } else {
                    x.to_le_bytes()
                }
            };
            let i = |x: i32| {
                if big {
                    x.to_be_bytes()
                } else {
                    x.to_le_bytes()
                }
            };
            for p in [[0.0, 0.0, 0.0], [1.5, 0.0, 0.0], [0.0, -2.25, 0.0]] {
                for x in p {
                    d.extend(f(x));
                }
                d.push(255);
            }
            d.push(9);
            d.push(3);
            for v in [0, 1, 2] {
                d.extend(u(v));
            }
            d.extend(i(2));
            d.extend(i(0));
            d.extend(i(1));
            let s = parse_ply(&d).unwrap();
            assert_eq!(s.positions[2], [0.0, -2.25, 0.0], "{fmt}");
            assert_eq!(s.polygons, vec![vec![0, 1, 2]], "{fmt}");
            // Cut inside the face: the error names the element and the byte offset.
            let cut = d.len() - 14;
            let e = parse_ply(&d[..cut]).unwrap_err().to_string();
            assert!(e.contains("truncated") && e.contains("'face' 0"), "{e}");
            assert!(e.contains(&format!("byte {}", cut - 2)), "{e}");
        }
    }
}
