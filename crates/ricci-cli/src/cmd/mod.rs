//! One module per subcommand; each has `Args` (clap) and `run`.

pub mod atlas;
pub mod batch;
pub mod cut;
pub mod demo;
pub mod flow;
pub mod forms;
pub mod generate;
pub mod info;
pub mod layout;
pub mod param;
pub mod pou;
pub mod render;
pub mod spectrum;
pub mod spline;
pub mod teichmuller;
pub mod tspline;
pub mod tspline_domain;
pub mod tspline_genus;
pub mod tspline_pictures;
