//! Isometric layouts, isometries and deck transformations (paper 001 §V Step 4 and §VI,
//! paper 002 §4.3.2–4.3.3 and §6.2.2–6.2.4).
//!
//! * [`dd`] — double-double arithmetic and Möbius maps, the working precision of hyperbolic
//!   layouts and deck groups.
//! * [`isometry`] — rigid motions of the plane, Möbius maps of the Poincaré disk (SU(1,1)),
//!   rotations of the sphere; composition, inverse, fitting from point pairs; Klein matrices.
//! * [`place`] — breadth-first isometric placement of a disk (or of a closed genus-0 surface on
//!   the sphere) with a metric, generic over the background geometry ([`Space`]).
//! * [`deck`] — fundamental polygons with paired sides, side pairings, deck transformation
//!   generators and the group relation.
//! * [`cover`] — finite portions of the universal cover: copies of the polygon by words or by
//!   radius.
//! * [`pipeline`] — surface with metric → canonical cut → layout → deck group (with the
//!   uniformization flow when no metric is given; H² metrics polished to double-double).
//! * [`svg`], [`export`] — pictures of the fundamental domain and tilings; OBJ with UVs.
//! * [`double_half`] — the map of a surface with boundary from the conformal flow on its double:
//!   the common subdivision of the surface's faces with the double's final triangulation, and
//!   its UVs.
//! * [`input_uv`] — UVs on the input's own faces from a layout of another triangulation of
//!   the surface (refined or intrinsic), mapped across the seams by the deck group.
//! * [`synthetic`] — closed surfaces with exact flat / hyperbolic metrics and known polygons
//!   (flat tori, regular 4g-gons), the references of the tests.

pub mod cover;
pub mod dd;
pub mod deck;
pub mod double_half;
pub(crate) mod error;
pub mod export;
pub mod frame;
pub mod input_uv;
pub mod isometry;
pub mod pipeline;
pub mod place;
pub mod subdivision_uv;
pub mod svg;
pub mod synthetic;

pub use deck::{deck_group, DeckGroup, Polygon, Side, SidePairing};
pub use error::LayoutError;
pub use isometry::{Isometry, Mobius, RigidMotion, Rotation};
pub use place::{align, align_layouts, layout, layout_dd, Frame, Layout, Space};
