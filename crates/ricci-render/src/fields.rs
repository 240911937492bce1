//! fields (todo).
