//! The library's error type.
//!
//! Every error is one sentence that names the problem and where it is (file, line, vertex,
//! face). The library never panics on user data and never prints; the CLI prints
//! `Error`'s `Display` and exits with code 1.

use std::fmt;

/// Where in an input file something went wrong.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Location {
    /// The file (or a name standing for the data source).
    pub file: Option<String>,
    /// 1-based line number in a text file.
    pub line: Option<usize>,
    /// Byte offset in a binary file.
    pub byte: Option<u64>,
}

impl Location {
    pub fn file(file: impl Into<String>) -> Self {
        Location {
            file: Some(file.into()),
            line: None,
            byte: None,
        }
    }
    pub fn with_line(mut self, line: usize) -> Self {
        self.line = Some(line);
        self
    }
    pub fn with_byte(mut self, byte: u64) -> Self {
        self.byte = Some(byte);
        self
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        if let Some(file) = &self.file {
            parts.push(file.clone());
        }
        if let Some(line) = self.line {
            parts.push(format!("line {line}"));
        }
        if let Some(byte) = self.byte {
            parts.push(format!("byte {byte}"));
        }
        write!(f, "{}", parts.join(", "))
    }
}

/// The record of an input file an error is about (a mesh file's vertex, face, …). Indices are
/// 0-based, in the order the records appear in the file (the message may show a format's own
/// numbering, e.g. OBJ's 1-based vertices).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum Record {
    /// The file as a whole (nothing to read, a statement that is not of this format, …).
    #[default]
    File,
    /// A header line (OFF header and counts, PLY header, STL binary header).
    Header,
    /// The vertex with this index.
    Vertex(usize),
    /// The texture coordinate (`vt`) with this index.
    TextureCoordinate(usize),
    /// The face (polygon, facet, triangle) with this index.
    Face(usize),
    /// Another element of a PLY file: its name and the index of the record.
    Element { name: String, index: usize },
}

/// All errors of the library.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The operating system refused to read or write a file.
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    /// A file could not be parsed: where, which record (as data; [`Record::File`] when the
    /// error is not about one record) and what is wrong.
    #[error("{location}: {message}")]
    Parse {
        location: Location,
        record: Record,
        message: String,
    },
    /// The mesh is not a valid oriented 2-manifold triangle mesh (non-manifold, non-orientable, …).
    #[error("{}{message}", prefix(.file))]
    InvalidMesh {
        file: Option<String>,
        message: String,
    },
    /// The mesh is valid but has the wrong topology for the requested operation.
    #[error("{message}")]
    Topology { message: String },
    /// A parameter given by the user cannot be used (target curvature, vertex id, …).
    #[error("{message}")]
    InvalidInput { message: String },
    /// A numerical procedure broke down (non-finite values, singular system, …).
    #[error("{message}")]
    Numerical { message: String },
}

fn prefix(file: &Option<String>) -> String {
    match file {
        Some(f) => format!("{f}: "),
        None => String::new(),
    }
}

impl Error {
    pub fn io(path: impl Into<String>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
    pub fn parse(location: Location, message: impl Into<String>) -> Self {
        Error::Parse {
            location,
            record: Record::File,
            message: message.into(),
        }
    }
    pub fn invalid_mesh(message: impl Into<String>) -> Self {
        Error::InvalidMesh {
            file: None,
            message: message.into(),
        }
    }
    pub fn topology(message: impl Into<String>) -> Self {
        Error::Topology {
            message: message.into(),
        }
    }
    pub fn input(message: impl Into<String>) -> Self {
        Error::InvalidInput {
            message: message.into(),
        }
    }
    pub fn numerical(message: impl Into<String>) -> Self {
        Error::Numerical {
            message: message.into(),
        }
    }
    /// The record of an input file a [`Error::Parse`] is about (`None` for other errors).
    pub fn record(&self) -> Option<&Record> {
        match self {
            Error::Parse { record, .. } => Some(record),
            _ => None,
        }
    }
    /// Attach a file name to an error that does not carry one yet.
    pub fn in_file(self, file: &str) -> Self {
        match self {
            Error::InvalidMesh {
                file: None,
                message,
            } => Error::InvalidMesh {
                file: Some(file.to_string()),
                message,
            },
            Error::Parse {
                mut location,
                record,
                message,
            } if location.file.is_none() => {
                location.file = Some(file.to_string());
                Error::Parse {
                    location,
                    record,
                    message,
                }
            }
            other => other,
        }
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
