//! Affine atlas with a single extraordinary point (paper 000 §4, paper 002 §5.2–5.3).
//!
//! * [`charts`] — the chart interface ([`charts::FlatCharts`]) shared with the manifold splines.

pub mod charts;

pub use charts::{fit_rigid, ChartId, FlatCharts};
