//! One module per subcommand; each has `Args` (clap) and `run`.

pub mod cut;
pub mod generate;
pub mod info;
