//! The PLY header: `format`, `element` and `property` lines, up to `end_header`.

use super::super::error::{ReadResult, Record};
use super::super::text::{self, at_line, parse_i64, show, tokens};

/// A PLY scalar type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Scalar {
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
    pub(super) fn parse(name: &[u8]) -> Option<Scalar> {
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
    pub(super) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::I64 | Scalar::U64 | Scalar::F64 => 8,
        }
    }
    pub(super) fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

/// A property of an element: a scalar (name, type) or a list (name, count type, item type).
#[derive(Debug, Clone)]
pub(super) enum Property {
    Scalar(Vec<u8>, Scalar),
    List(Vec<u8>, Scalar, Scalar),
}

impl Property {
    pub(super) fn name(&self) -> &[u8] {
        match self {
            Property::Scalar(n, _) | Property::List(n, _, _) => n,
        }
    }
}

/// An element declared by the header: its name, number of records and properties.
#[derive(Debug, Clone)]
pub(super) struct Element {
    pub(super) name: Vec<u8>,
    pub(super) count: usize,
    pub(super) props: Vec<Property>,
}

/// How the data are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Storage {
    Ascii,
    Little,
    Big,
}

/// What the header declares.
pub(super) struct Header {
    pub(super) storage: Storage,
    pub(super) elements: Vec<Element>,
    /// Byte offset of the first data byte.
    pub(super) data_start: usize,
}

/// The header of a PLY file and where its data start.
pub(super) fn parse_header(data: &[u8]) -> ReadResult<Header> {
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
    let (storage, elements) = header_lines(&mut lines).map_err(|e| e.about(Record::Header))?;
    Ok(Header {
        storage,
        elements,
        data_start: bom + (data.len() - bom - lines.rest().len()),
    })
}

/// The header lines after `ply`, up to and including `end_header`.
fn header_lines(lines: &mut text::Lines<'_>) -> ReadResult<(Storage, Vec<Element>)> {
    let mut storage = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut saw_end = false;
    for (n, line) in lines.by_ref() {
        let mut t = tokens(line);
        let Some(key) = t.next() else { continue };
        match key {
            b"comment" | b"obj_info" => {}
            b"format" => storage = Some(format_line(n, t.next().unwrap_or_default())?),
            b"element" => elements.push(element_line(n, t)?),
            b"property" => {
                let Some(el) = elements.last_mut() else {
                    return Err(at_line(n, "a property appears before any element"));
                };
                el.props.push(property_line(n, t)?);
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
    Ok((storage, elements))
}

/// `format <kind> 1.0` at line `n`.
fn format_line(n: usize, kind: &[u8]) -> ReadResult<Storage> {
    Ok(match kind {
        b"ascii" => Storage::Ascii,
        b"binary_little_endian" => Storage::Little,
        b"binary_big_endian" => Storage::Big,
        _ => {
            return Err(at_line(
                n,
                format!("unknown PLY format '{}'; expected ascii, binary_little_endian or binary_big_endian", show(kind)),
            ))
        }
    })
}

/// `element <name> <count>` at line `n` (after the keyword).
fn element_line<'a>(n: usize, mut t: impl Iterator<Item = &'a [u8]>) -> ReadResult<Element> {
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
    Ok(Element {
        name,
        count,
        props: Vec::new(),
    })
}

/// `property <type> <name>` or `property list <count type> <item type> <name>` at line `n`
/// (after the keyword).
fn property_line<'a>(n: usize, mut t: impl Iterator<Item = &'a [u8]>) -> ReadResult<Property> {
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
    Ok(prop)
}
