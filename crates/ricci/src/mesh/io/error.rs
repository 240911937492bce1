//! The readers' error: one sentence for the user, plus where it happened and which record of
//! the file it is about, as data.
//!
//! Every reader of this module returns a [`ReadError`]. It carries the place (file name once
//! known, 1-based line of a text file, byte offset of a binary file) and the [`Record`] at
//! fault (a vertex, a face, a texture coordinate, another PLY element, the header, or the file
//! as a whole), so that a caller can point at the record without parsing the message. It
//! converts into [`crate::Error::Parse`] with the same location, record and message, so its
//! `Display` and the converted error's `Display` are the same sentence (`file, line N:
//! message`), and the record survives the conversion ([`crate::Error::record`]).

pub use crate::error::Record;
use crate::error::{Error, Location};
use std::fmt;

/// A mesh file that cannot be read: what is wrong (`message`, one sentence), where
/// (`location`: file, line, byte) and which record ([`Record`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReadError {
    pub location: Location,
    pub record: Record,
    pub message: String,
}

impl ReadError {
    /// An error about the file as a whole, at no particular place.
    pub(crate) fn whole(message: impl Into<String>) -> Self {
        ReadError {
            location: Location::default(),
            record: Record::File,
            message: message.into(),
        }
    }

    /// The same error, about `record`.
    pub(crate) fn about(mut self, record: Record) -> Self {
        self.record = record;
        self
    }

    /// The same error with the file name, unless it has one already.
    pub fn in_file(mut self, file: &str) -> Self {
        if self.location.file.is_none() {
            self.location.file = Some(file.to_string());
        }
        self
    }

    /// The 1-based line of a text file, if the error has one.
    pub fn line(&self) -> Option<usize> {
        self.location.line
    }

    /// The vertex the error is about, if any.
    pub fn vertex(&self) -> Option<usize> {
        match self.record {
            Record::Vertex(i) => Some(i),
            _ => None,
        }
    }

    /// The face the error is about, if any.
    pub fn face(&self) -> Option<usize> {
        match self.record {
            Record::Face(i) => Some(i),
            _ => None,
        }
    }
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // The same sentence as the `Error::Parse` it converts into.
        write!(f, "{}: {}", self.location, self.message)
    }
}

impl std::error::Error for ReadError {}

impl From<ReadError> for Error {
    fn from(e: ReadError) -> Error {
        Error::Parse {
            location: e.location,
            record: e.record,
            message: e.message,
        }
    }
}

/// The result of a reader.
pub type ReadResult<T> = std::result::Result<T, ReadError>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn converts_into_a_parse_error_with_the_same_sentence() {
        let e = ReadError {
            location: Location::default().with_line(7),
            record: Record::Face(3),
            message: "face 3 refers to vertex 9".into(),
        }
        .in_file("a.obj");
        assert_eq!((e.face(), e.vertex(), e.line()), (Some(3), None, Some(7)));
        let shown = e.to_string();
        assert_eq!(shown, "a.obj, line 7: face 3 refers to vertex 9");
        let converted = Error::from(e.clone());
        assert!(matches!(&converted, Error::Parse { location, .. } if location.line == Some(7)));
        assert_eq!(converted.record(), Some(&Record::Face(3)));
        assert_eq!(converted.to_string(), shown);
        // A file name already there is kept.
        assert_eq!(e.in_file("b.obj").location.file.as_deref(), Some("a.obj"));
    }
}
