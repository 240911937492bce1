//! plots (todo).
