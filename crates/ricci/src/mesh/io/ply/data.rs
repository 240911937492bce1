//! The PLY data section: values read one by one from ascii tokens or from binary bytes
//! (little or big endian), with the place (line or byte offset) of each for messages.

use super::super::error::{ReadError, ReadResult, Record};
use super::super::text::{at_byte, at_line, parse_f64, parse_i64, show};
use super::header::Scalar;

/// A value read from the data: integers exactly, floats as `f64`.
#[derive(Debug, Clone, Copy)]
pub(super) enum Value {
    Int(i128),
    Float(f64),
}

impl Value {
    pub(super) fn as_f64(self) -> f64 {
        match self {
            Value::Int(i) => i as f64,
            Value::Float(x) => x,
        }
    }
}

/// The record being read, for messages: `element 'face' 3 (of 10)`, and its [`Record`].
#[derive(Debug, Clone, Copy)]
pub(super) struct Item<'a> {
    /// The element's name as shown in messages.
    pub(super) element: &'a str,
    pub(super) index: usize,
    pub(super) count: usize,
    /// Whether the element is the one read as the mesh's vertices or faces (a second `vertex`
    /// element is skipped like any other).
    pub(super) kept: bool,
}

impl Item<'_> {
    pub(super) fn describe(&self) -> String {
        format!(
            "element '{}' {} (of {})",
            self.element, self.index, self.count
        )
    }

    pub(super) fn record(&self) -> Record {
        match self.element {
            "vertex" if self.kept => Record::Vertex(self.index),
            "face" if self.kept => Record::Face(self.index),
            name => Record::Element {
                name: name.to_string(),
                index: self.index,
            },
        }
    }
}

/// Where the data values come from.
pub(super) enum Source<'a> {
    /// The ascii data after the header; `line` is the 1-based line of the file at `pos`.
    Ascii {
        data: &'a [u8],
        pos: usize,
        line: usize,
    },
    /// The whole file; `pos` is the byte offset of the next value.
    Binary {
        data: &'a [u8],
        pos: usize,
        big: bool,
    },
}

impl Source<'_> {
    /// Location of the next value, for messages.
    pub(super) fn here(&self) -> Place {
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
                Place::Line(l)
            }
            Source::Binary { pos, .. } => Place::Byte(*pos),
        }
    }

    /// The next value, of type `ty`, of the record `item`.
    pub(super) fn read(&mut self, ty: Scalar, item: &Item) -> ReadResult<Value> {
        match self {
            Source::Ascii { data, pos, line } => read_ascii(data, pos, line, ty, item),
            Source::Binary { data, pos, big } => read_binary(data, pos, *big, ty, item),
        }
        .map_err(|e| e.about(item.record()))
    }

    /// Bytes left after the current position.
    pub(super) fn remaining(&self) -> usize {
        match self {
            Source::Ascii { data, pos, .. } | Source::Binary { data, pos, .. } => {
                data.len().saturating_sub(*pos)
            }
        }
    }
}

/// The next whitespace-separated token of ascii data at `pos`, parsed as `ty`.
fn read_ascii(
    data: &[u8],
    pos: &mut usize,
    line: &mut usize,
    ty: Scalar,
    item: &Item,
) -> ReadResult<Value> {
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
            format!("the file ends in the middle of {}", item.describe()),
        ));
    }
    if ty.is_integer() {
        parse_i64(tok)
            .map(|i| Value::Int(i as i128))
            .ok_or_else(|| {
                at_line(
                    *line,
                    format!("{}: '{}' is not an integer", item.describe(), show(tok)),
                )
            })
    } else {
        parse_f64(tok).map(Value::Float).ok_or_else(|| {
            at_line(
                *line,
                format!("{}: '{}' is not a number", item.describe(), show(tok)),
            )
        })
    }
}

/// The value of type `ty` in the binary data at byte `pos`.
fn read_binary(
    data: &[u8],
    pos: &mut usize,
    big: bool,
    ty: Scalar,
    item: &Item,
) -> ReadResult<Value> {
    let n = ty.size();
    let Some(b) = data.get(*pos..*pos + n) else {
        return Err(truncated(data, *pos, n, item));
    };
    *pos += n;
    let mut a = [0u8; 8];
    a[..n].copy_from_slice(b);
    if big {
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
        Scalar::F32 => Value::Float(f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64),
        Scalar::F64 => Value::Float(f64::from_le_bytes(a)),
    })
}

/// The error for binary data that end before the `need` bytes at `pos` of `item`.
fn truncated(data: &[u8], pos: usize, need: usize, item: &Item) -> ReadError {
    at_byte(
        pos,
        format!(
            "truncated binary PLY: {} needs {need} more bytes at byte offset {pos}, but the file ends at byte {}",
            item.describe(),
            data.len()
        ),
    )
}

/// Where a value is: a line of an ascii file or a byte offset of a binary one.
pub(super) enum Place {
    Line(usize),
    Byte(usize),
}

impl Place {
    pub(super) fn error(&self, message: String) -> ReadError {
        match self {
            Place::Line(l) => at_line(*l, message),
            Place::Byte(b) => at_byte(*b, message),
        }
    }
    pub(super) fn line(&self) -> Option<usize> {
        match self {
            Place::Line(l) => Some(*l),
            Place::Byte(_) => None,
        }
    }
}

/// The length of a list property, read with count type `ct`; `at` is where the record starts.
pub(super) fn list_count(
    src: &mut Source,
    ct: Scalar,
    item: &Item,
    at: &Place,
) -> ReadResult<usize> {
    match src.read(ct, item)? {
        Value::Int(k) if k >= 0 && k <= u32::MAX as i128 => Ok(k as usize),
        v => Err(at
            .error(format!(
                "{}: a list length of {} is not valid",
                item.describe(),
                v.as_f64()
            ))
            .about(item.record())),
    }
}

/// Skip a list property (count type `ct`, item type `it`).
pub(super) fn skip_list(src: &mut Source, ct: Scalar, it: Scalar, item: &Item) -> ReadResult<()> {
    let at = src.here();
    let k = list_count(src, ct, item, &at)?;
    match src {
        Source::Binary { data, pos, .. } => {
            let need = k * it.size();
            if *pos + need > data.len() {
                return Err(truncated(data, *pos, need, item).about(item.record()));
            }
            *pos += need;
        }
        Source::Ascii { .. } => {
            for _ in 0..k {
                src.read(it, item)?;
            }
        }
    }
    Ok(())
}
