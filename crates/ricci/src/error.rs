//! The library's error type.
//!
//! Every error is one sentence that names the problem and where it is (file, line, vertex,
//! face). The library never panics on user data and never prints; the CLI prints
//! `Error`'s `Display` and exits with code 1.
//!
//! Where the fault has a place, the place is also data: [`Error::Parse`] keeps the [`Record`]
//! of the file (from the mesh readers' `ReadError`), and [`Error::Stage`] keeps a stage's own
//! error enum ([`StageError`]: `metric::MetricError`, `flow::FlowError`, `cut::CutError`,
//! `layout::LayoutError`) with the vertex, face or edge; [`Error::stage_error`] gives it back.

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

/// What kind of problem a pipeline stage's error is: the same three kinds as
/// [`Error::Topology`], [`Error::InvalidInput`] and [`Error::Numerical`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// The mesh has the wrong topology for the operation.
    Topology,
    /// A parameter or an input metric cannot be used (a refusal: every scheme would refuse it).
    InvalidInput,
    /// A numerical procedure broke down or did not converge.
    Numerical,
}

/// A pipeline stage's error enum (`metric::MetricError`, `flow::FlowError`,
/// `cut::CutError`, `layout::LayoutError`): one sentence (`Display`) and its [`Kind`], with
/// the vertex, face, edge or loop it is about kept as data in the enum. It converts into
/// [`Error::Stage`] (`Error::from` in each stage), and [`Error::stage_error`] gives it back.
pub trait StageError: std::error::Error + Send + Sync + 'static {
    /// The kind of problem.
    fn kind(&self) -> Kind;
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
    /// A pipeline stage's error with its data: the stage's enum ([`StageError`]), whose
    /// `Display` is the sentence; [`Error::stage_error`] gives it back.
    #[error("{detail}")]
    Stage {
        kind: Kind,
        detail: Box<dyn std::error::Error + Send + Sync>,
    },
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
    /// A stage's error enum kept whole ([`Error::Stage`]).
    pub fn stage<E: StageError>(error: E) -> Self {
        Error::Stage {
            kind: error.kind(),
            detail: Box::new(error),
        }
    }
    /// The stage error of type `E` this error carries (`None` for other errors), e.g.
    /// `e.stage_error::<ricci::flow::FlowError>()`.
    pub fn stage_error<E: StageError>(&self) -> Option<&E> {
        match self {
            Error::Stage { detail, .. } => detail.downcast_ref::<E>(),
            _ => None,
        }
    }
    /// The kind of a topology, input, numerical or stage error (`None` for I/O, parse and
    /// invalid-mesh errors).
    pub fn kind(&self) -> Option<Kind> {
        match self {
            Error::Topology { .. } => Some(Kind::Topology),
            Error::InvalidInput { .. } => Some(Kind::InvalidInput),
            Error::Numerical { .. } => Some(Kind::Numerical),
            Error::Stage { kind, .. } => Some(*kind),
            _ => None,
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
