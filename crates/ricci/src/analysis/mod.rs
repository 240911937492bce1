//! Distortion statistics, geodesic length spectrum (papers 000 §4, 002 §6.3.3).
//!
//! * [`distortion`] — per-face quasi-conformal ratio and area ratio of a UV map, flipped
//!   faces, summary statistics (used by [`crate::param`]).
//! * [`forms`] — holomorphic 1-forms, the Riemann period matrix, zeros and the conformal net
//!   (paper 002 §4.2, §6.3).
//! * [`spectrum`] — geodesic length spectra of flat tori (translation lattices) and of
//!   hyperbolic surfaces (Fuchsian groups), with a completeness guarantee.
//! * [`teichmuller`] — Fenchel–Nielsen and length coordinates of a closed hyperbolic surface
//!   from its marked Fuchsian group (paper 002 §6.3.4).

pub mod distortion;
pub mod forms;
pub mod spectrum;
pub mod teichmuller;
