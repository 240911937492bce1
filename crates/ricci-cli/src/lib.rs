//! The `ricci` command-line tool's subcommands as a library: the binary (`main.rs`) parses
//! arguments and calls them; the Python package (`crates/ricci-py`) calls the same `run`
//! functions with [`util::Capture`] active, so its results are the CLI's JSON reports.

pub mod cmd;
pub mod util;
