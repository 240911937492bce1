//! Stanford PLY: reader (ascii, binary little endian, binary big endian) and writer (ascii,
//! binary little endian).
//!
//! Read: the `vertex` element's `x`, `y`, `z` (any scalar type; `u v`, `s t` or `texture_u
//! texture_v` become per-vertex UVs), the `face` element's `vertex_indices` (or
//! `vertex_index`) list with any count and index types. Every other property, list or element
//! is skipped. Errors name the header line, or for data the element, its index and the line
//! (ascii) or byte offset (binary) — a truncated binary file says where it ends.

use super::text::{self, at_byte, at_line, parse_f64, parse_i64, show, tokens};
use crate::error::{Error, Result};
use crate::mesh::{PolygonSoup, Surface};
use std::io::Write;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"long" | b"int64" => Scalar::I64,
            b"ulong" | b"uint64" => Scalar::U64,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::I64 | Scalar::U64 | Scalar::F64 => 8,
        }
    }
    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Debug, Clone)]
enum Property {
    Scalar(Vec<u8>, Scalar),
    List(Vec<u8>, Scalar, Scalar),
}

impl Property {
    fn name(&self) -> &[u8] {
        match self {
            Property::Scalar(n, _) | Property::List(n, _, _) => n,
        }
    }
}

#[derive(Debug, Clone)]
struct Element {
    name: Vec<u8>,
    count: usize,
    props: Vec<Property>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Storage {
    Ascii,
    Little,
    Big,
}

/// A value read from the data: integers exactly, floats as `f64`.
#[derive(Debug, Clone, Copy)]
enum Value {
    Int(i128),
    Float(f64),
}

impl Value {
    fn as_f64(self) -> f64 {
        match self {
            Value::Int(i) => i as f64,
            Value::Float(x) => x,
        }
    }
}

/// Where the data values come from.
enum Source<'a> {
    Ascii {
        data: &'a [u8],
        pos: usize,
        line: usize,
    },
    Binary {
        data: &'a [u8],
        pos: usize,
        big: bool,
    },
}

impl Source<'_> {
    /// Location of the next value, for messages.
    fn here(&self) -> Location {
        match self {
            Source::Ascii { line, data, pos } => {
                // Report the line of the next token (skip whitespace first).
                let mut l = *line;
                let mut p = *pos;
                while p < data.len() && data[p].is_ascii_whitespace() {
                    if data[p] == b'\n' {
                        l += 1;
                    }
                    p += 1;
                }
                Location::Line(l)
            }
            Source::Binary { pos, .. } => Location::Byte(*pos),
        }
    }

    fn read(&mut self, ty: Scalar, what: &dyn Fn() -> String) -> Result<Value> {
        match self {
            Source::Ascii { data, pos, line } => {
                while *pos < data.len() && data[*pos].is_ascii_whitespace() {
                    if data[*pos] == b'\n' {
                        *line += 1;
                    }
                    *pos += 1;
                }
                let start = *pos;
                while *pos < data.len() && !data[*pos].is_ascii_whitespace() {
                    *pos += 1;
                }
                let tok = &data[start..*pos];
                if tok.is_empty() {
                    return Err(at_line(
                        *line,
                        format!("the file ends in the middle of {}", what()),
                    ));
                }
                if ty.is_integer() {
                    parse_i64(tok)
                        .map(|i| Value::Int(i as i128))
                        .ok_or_else(|| {
                            at_line(
                                *line,
                                format!("{}: '{}' is not an integer", what(), show(tok)),
                            )
                        })
                } else {
                    parse_f64(tok).map(Value::Float).ok_or_else(|| {
                        at_line(
                            *line,
                            format!("{}: '{}' is not a number", what(), show(tok)),
                        )
                    })
                }
            }
            Source::Binary { data, pos, big } => {
                let n = ty.size();
                let Some(b) = data.get(*pos..*pos + n) else {
                    return Err(at_byte(
                        *pos,
                        format!(
                            "truncated binary PLY: {} needs {n} more bytes at byte offset {}, but the file ends at byte {}",
                            what(),
                            *pos,
                            data.len()
                        ),
                    ));
                };
                *pos += n;
                let mut a = [0u8; 8];
                a[..n].copy_from_slice(b);
                if *big {
                    a[..n].reverse();
                }
                Ok(match ty {
                    Scalar::I8 => Value::Int(a[0] as i8 as i128),
                    Scalar::U8 => Value::Int(a[0] as i128),
                    Scalar::I16 => Value::Int(i16::from_le_bytes([a[0], a[1]]) as i128),
                    Scalar::U16 => Value::Int(u16::from_le_bytes([a[0], a[1]]) as i128),
                    Scalar::I32 => Value::Int(i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as i128),
                    Scalar::U32 => Value::Int(u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as i128),
                    Scalar::I64 => Value::Int(i64::from_le_bytes(a) as i128),
                    Scalar::U64 => Value::Int(u64::from_le_bytes(a) as i128),
                    Scalar::F32 => {
                        Value::Float(f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64)
                    }
                    Scalar::F64 => Value::Float(f64::from_le_bytes(a)),
                })
            }
        }
    }

    fn remaining(&self) -> usize {
        match self {
            Source::Ascii { data, pos, .. } | Source::Binary { data, pos, .. } => {
                data.len().saturating_sub(*pos)
            }
        }
    }
}

enum Location {
    Line(usize),
    Byte(usize),
}

impl Location {
    fn error(&self, message: String) -> Error {
        match self {
            Location::Line(l) => at_line(*l, message),
            Location::Byte(b) => at_byte(*b, message),
        }
    }
    fn line(&self) -> Option<usize> {
        match self {
            Location::Line(l) => Some(*l),
            Location::Byte(_) => None,
        }
    }
}

struct Header {
    storage: Storage,
    elements: Vec<Element>,
    data_start: usize,
}

fn parse_header(data: &[u8]) -> Result<Header> {
    let mut lines = text::Lines::new(data);
    let bom = data.len() - lines.rest().len();
    let Some((_, first)) = lines.next() else {
        return Err(text::empty_file());
    };
    if first.trim_ascii() != b"ply" {
        if data.iter().all(|b| b.is_ascii_whitespace()) {
            return Err(text::empty_file());
        }
        return Err(at_line(
            1,
            format!(
                "not a PLY file: the first line must be 'ply', found '{}'",
                show(first)
            ),
        ));
    }
    let mut storage = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut saw_end = false;
    for (n, line) in lines.by_ref() {
        let mut t = tokens(line);
        let Some(key) = t.next() else { continue };
        match key {
            b"comment" | b"obj_info" => {}
            b"format" => {
                let kind = t.next().unwrap_or_default();
                storage = Some(match kind {
                    b"ascii" => Storage::Ascii,
                    b"binary_little_endian" => Storage::Little,
                    b"binary_big_endian" => Storage::Big,
                    _ => {
                        return Err(at_line(
                            n,
                            format!("unknown PLY format '{}'; expected ascii, binary_little_endian or binary_big_endian", show(kind)),
                        ))
                    }
                });
            }
            b"element" => {
                let name = t.next().unwrap_or_default().to_vec();
                let count = t.next().unwrap_or_default();
                let count = match parse_i64(count) {
                    Some(c) if c >= 0 && c <= u32::MAX as i64 => c as usize,
                    _ => {
                        return Err(at_line(
                            n,
                            format!(
                                "element '{}' needs a count between 0 and 2³²−1, found '{}'",
                                show(&name),
                                show(count)
                            ),
                        ))
                    }
                };
                if name.is_empty() {
                    return Err(at_line(n, "an element needs a name and a count"));
                }
                elements.push(Element {
                    name,
                    count,
                    props: Vec::new(),
                });
            }
            b"property" => {
                let Some(el) = elements.last_mut() else {
                    return Err(at_line(n, "a property appears before any element"));
                };
                let ty = t.next().unwrap_or_default();
                let bad_type = |s: &[u8]| {
                    at_line(
                        n,
                        format!(
                            "unknown property type '{}' (expected char, uchar, short, ushort, int, uint, float, double or int8…float64)",
                            show(s)
                        ),
                    )
                };
                let prop = if ty == b"list" {
                    let ct = t.next().unwrap_or_default();
                    let it = t.next().unwrap_or_default();
                    let count_ty = Scalar::parse(ct).ok_or_else(|| bad_type(ct))?;
                    let item_ty = Scalar::parse(it).ok_or_else(|| bad_type(it))?;
                    if !count_ty.is_integer() {
                        return Err(at_line(
                            n,
                            "the count type of a list property must be an integer type",
                        ));
                    }
                    Property::List(t.next().unwrap_or_default().to_vec(), count_ty, item_ty)
                } else {
                    let s = Scalar::parse(ty).ok_or_else(|| bad_type(ty))?;
                    Property::Scalar(t.next().unwrap_or_default().to_vec(), s)
                };
                if prop.name().is_empty() {
                    return Err(at_line(n, "a property needs a name"));
                }
                el.props.push(prop);
            }
            b"end_header" => {
                saw_end = true;
                break;
            }
            _ => {
                return Err(at_line(
                    n,
                    format!("unknown PLY header line starting with '{}'", show(key)),
                ))
            }
        }
    }
    if !saw_end {
        return Err(text::whole(
            "the PLY header has no 'end_header' line (truncated or not a PLY file)",
        ));
    }
    let Some(storage) = storage else {
        return Err(text::whole("the PLY header has no 'format' line"));
    };
    Ok(Header {
        storage,
        elements,
        data_start: bom + (data.len() - bom - lines.rest().len()),
    })
}

/// Parse a PLY file held in memory.
pub fn parse_ply(data: &[u8]) -> Result<PolygonSoup> {
    let header = parse_header(data)?;
    let header_lines = data[..header.data_start]
        .iter()
        .filter(|&&b| b == b'\n')
        .count();
    let mut src = match header.storage {
        Storage::Ascii => Source::Ascii {
            data: &data[header.data_start..],
            pos: 0,
            line: header_lines + 1,
        },
        Storage::Little | Storage::Big => Source::Binary {
            data,
            pos: header.data_start,
            big: header.storage == Storage::Big,
        },
    };
    let binary = header.storage != Storage::Ascii;
    let mut soup = PolygonSoup::default();
    let mut vertex_lines = Vec::new();
    let mut polygon_lines = Vec::new();
    let mut saw_vertex = false;
    let mut saw_face = false;
    let mut uvs: Vec<[f64; 2]> = Vec::new();
    let mut has_uv = false;
    for el in &header.elements {
        let ename = show(&el.name);
        // Which properties we keep.
        let find = |name: &[u8]| {
            el.props
                .iter()
                .position(|p| matches!(p, Property::Scalar(n, _) if n == name))
        };
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
        if el.name == b"vertex" && !saw_vertex {
            saw_vertex = true;
            let mut xyz = [0usize; 3];
            for (k, c) in [b"x", b"y", b"z"].iter().enumerate() {
                xyz[k] = find(&c[..]).ok_or_else(|| {
                    text::whole(format!(
                        "the 'vertex' element has no scalar property '{}'",
                        c[0] as char
                    ))
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
            has_uv = uv_pair.is_some();
            soup.positions.reserve(cap);
            if has_uv {
                uvs.reserve(cap);
            }
            for i in 0..el.count {
                let at = src.here();
                let mut p = [0.0f64; 3];
                let mut uv = [0.0f64; 2];
                for (j, prop) in el.props.iter().enumerate() {
                    let what = || format!("element 'vertex' {i} (of {})", el.count);
                    match prop {
                        Property::Scalar(_, ty) => {
                            let v = src.read(*ty, &what)?.as_f64();
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
                        Property::List(_, ct, it) => skip_list(&mut src, *ct, *it, &what)?,
                    }
                }
                if binary && p.iter().any(|x| !x.is_finite()) {
                    return Err(at.error(format!(
                        "vertex {i} has a non-finite coordinate ({}, {}, {})",
                        p[0], p[1], p[2]
                    )));
                }
                soup.positions.push(p);
                if has_uv {
                    uvs.push(uv);
                }
                if let Some(l) = at.line() {
                    vertex_lines.push(l);
                }
            }
        } else if el.name == b"face" && !saw_face {
            saw_face = true;
            let list = el
                .props
                .iter()
                .position(|p| {
                    matches!(p, Property::List(n, _, _) if n == b"vertex_indices" || n == b"vertex_index")
                })
                .ok_or_else(|| {
                    text::whole("the 'face' element has no list property 'vertex_indices' (or 'vertex_index')")
                })?;
            if let Property::List(_, _, it) = &el.props[list] {
                if !it.is_integer() {
                    return Err(text::whole(
                        "the face list 'vertex_indices' must have an integer item type",
                    ));
                }
            }
            soup.polygons.reserve(cap);
            for i in 0..el.count {
                let at = src.here();
                let what = || format!("element 'face' {i} (of {})", el.count);
                for (j, prop) in el.props.iter().enumerate() {
                    match prop {
                        Property::Scalar(_, ty) => {
                            src.read(*ty, &what)?;
                        }
                        Property::List(_, ct, it) if j == list => {
                            let k = list_count(&mut src, *ct, &what, &at)?;
                            let mut poly = Vec::with_capacity(
                                k.min(src.remaining() / it.size().max(1) + 1).min(64),
                            );
                            for _ in 0..k {
                                let loc = src.here();
                                match src.read(*it, &what)? {
                                    Value::Int(v) if (0..u32::MAX as i128).contains(&v) => {
                                        poly.push(v as u32)
                                    }
                                    Value::Int(v) => {
                                        return Err(loc.error(format!(
                                            "face {i} refers to vertex {v}, which is not a valid vertex index"
                                        )))
                                    }
                                    Value::Float(_) => {
                                        return Err(loc.error(format!(
                                            "face {i}: vertex indices must be integers"
                                        )))
                                    }
                                }
                            }
                            soup.polygons.push(poly);
                        }
                        Property::List(_, ct, it) => skip_list(&mut src, *ct, *it, &what)?,
                    }
                }
                if let Some(l) = at.line() {
                    polygon_lines.push(l);
                }
            }
        } else {
            for i in 0..el.count {
                let what = || format!("element '{ename}' {i} (of {})", el.count);
                for prop in &el.props {
                    match prop {
                        Property::Scalar(_, ty) => {
                            src.read(*ty, &what)?;
                        }
                        Property::List(_, ct, it) => skip_list(&mut src, *ct, *it, &what)?,
                    }
                }
            }
        }
    }
    if !saw_vertex {
        return Err(text::whole("the PLY file has no 'vertex' element"));
    }
    if !saw_face {
        return Err(text::whole(
            "the PLY file has no 'face' element (a point cloud is not a surface)",
        ));
    }
    if !binary {
        soup.vertex_lines = Some(vertex_lines);
        soup.polygon_lines = Some(polygon_lines);
    }
    if has_uv {
        soup.uvs = Some(uvs);
    }
    Ok(soup)
}

fn list_count(
    src: &mut Source,
    ct: Scalar,
    what: &dyn Fn() -> String,
    at: &Location,
) -> Result<usize> {
    match src.read(ct, what)? {
        Value::Int(k) if k >= 0 && k <= u32::MAX as i128 => Ok(k as usize),
        v => Err(at.error(format!(
            "{}: a list length of {} is not valid",
            what(),
            v.as_f64()
        ))),
    }
}

fn skip_list(src: &mut Source, ct: Scalar, it: Scalar, what: &dyn Fn() -> String) -> Result<()> {
    let at = src.here();
    let k = list_count(src, ct, what, &at)?;
    match src {
        Source::Binary { data, pos, .. } => {
            let need = k * it.size();
            if *pos + need > data.len() {
                return Err(at_byte(
                    *pos,
                    format!(
                        "truncated binary PLY: {} needs {need} more bytes at byte offset {}, but the file ends at byte {}",
                        what(),
                        *pos,
                        data.len()
                    ),
                ));
            }
            *pos += need;
        }
        Source::Ascii { .. } => {
            for _ in 0..k {
                src.read(it, what)?;
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
