//! Isometric layouts, isometries and deck transformations (paper 001 §V Step 4 and §VI,
//! paper 002 §4.3.2–4.3.3 and §6.2.2–6.2.4).
//!
//! * [`isometry`] — rigid motions of the plane, Möbius maps of the Poincaré disk (SU(1,1)),
//!   rotations of the sphere; composition, inverse, fitting from point pairs; Klein matrices.

pub mod isometry;

pub use isometry::{Isometry, Mobius, RigidMotion, Rotation};
