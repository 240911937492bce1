//! glTF export (todo).
