//! The working precision of layouts and deck groups ([`Frame`]): the isometries that face
//! frames are composed in and the points they produce — double precision in E² and S²,
//! double-double in H² (paper 001 §VI.b; see [`super::place`] for why).

use super::dd::{disk_distance_dd, disk_orientation_dd, MobiusDd};
use super::isometry::{Complex, Isometry, Mobius, RigidMotion, Rotation};
use super::place::Space;
use crate::error::Result;
use crate::metric::{Euclidean, Spherical};
use crate::numeric::dd::Cdd;

/// The working precision of layouts and deck groups: the isometries face frames are composed
/// in and the points they produce. E² and S² work in double precision (rounding grows only
/// linearly with the size of the layout there): the frame is the isometry itself. H² works
/// in double-double ([`super::dd`]), because frames and coordinates far from the centre of
/// the Poincaré disk lose digits exponentially (`~1e-16·e^r` at distance `r`).
pub trait Frame: Copy + std::fmt::Debug + Send + Sync + 'static {
    /// The double-precision isometry this frame rounds to.
    type Iso: Isometry;
    /// A point in the working precision.
    type Ext: Copy + std::fmt::Debug + Send + Sync + 'static;
    /// Whether points carry a low-order part ([`Layout::positions_lo`]).
    const EXTENDED: bool;
    fn identity() -> Self;
    fn from_iso(i: &Self::Iso) -> Self;
    /// Rounded to double precision.
    fn round(&self) -> Self::Iso;
    /// `self ∘ other`.
    fn compose(&self, o: &Self) -> Self;
    fn inverse(&self) -> Self;
    fn normalized(&self) -> Self;
    fn apply(&self, p: Self::Ext) -> Self::Ext;
    /// A working-precision point from its high and low parts (the low part is ignored when
    /// not [`Frame::EXTENDED`]).
    fn ext(hi: IsoPoint<Self>, lo: Option<IsoPoint<Self>>) -> Self::Ext;
    /// High and low parts (`None` when not [`Frame::EXTENDED`]).
    fn split(p: Self::Ext) -> (IsoPoint<Self>, Option<IsoPoint<Self>>);
    /// [`Isometry::from_pairs`] in the working precision.
    fn from_pairs(p0: Self::Ext, q0: Self::Ext, p1: Self::Ext, q1: Self::Ext) -> Self;
    /// [`Isometry::fit`] in the working precision.
    fn fit(pairs: &[(Self::Ext, Self::Ext)]) -> Result<Self>;
    /// Geodesic distance.
    fn point_distance(a: Self::Ext, b: Self::Ext) -> f64;
    /// [`Space::orientation`].
    fn orientation(a: Self::Ext, b: Self::Ext, c: Self::Ext) -> f64;
    /// [`Isometry::distance`], evaluated in the working precision.
    fn distance(&self, o: &Self) -> f64;
}

/// The point type of a frame's isometry.
pub type IsoPoint<F> = <<F as Frame>::Iso as Isometry>::Point;

macro_rules! plain_frame {
    ($iso:ty, $space:ty) => {
        impl Frame for $iso {
            type Iso = $iso;
            type Ext = <$iso as Isometry>::Point;
            const EXTENDED: bool = false;
            fn identity() -> Self {
                <$iso as Isometry>::identity()
            }
            fn from_iso(i: &Self) -> Self {
                *i
            }
            fn round(&self) -> Self {
                *self
            }
            fn compose(&self, o: &Self) -> Self {
                Isometry::compose(self, o)
            }
            fn inverse(&self) -> Self {
                Isometry::inverse(self)
            }
            fn normalized(&self) -> Self {
                Isometry::normalized(self)
            }
            fn apply(&self, p: Self::Ext) -> Self::Ext {
                Isometry::apply(self, p)
            }
            fn ext(hi: Self::Ext, _lo: Option<Self::Ext>) -> Self::Ext {
                hi
            }
            fn split(p: Self::Ext) -> (Self::Ext, Option<Self::Ext>) {
                (p, None)
            }
            fn from_pairs(p0: Self::Ext, q0: Self::Ext, p1: Self::Ext, q1: Self::Ext) -> Self {
                <$iso as Isometry>::from_pairs(p0, q0, p1, q1)
            }
            fn fit(pairs: &[(Self::Ext, Self::Ext)]) -> Result<Self> {
                <$iso as Isometry>::fit(pairs)
            }
            fn point_distance(a: Self::Ext, b: Self::Ext) -> f64 {
                <$space as Space>::distance(a, b)
            }
            fn orientation(a: Self::Ext, b: Self::Ext, c: Self::Ext) -> f64 {
                <$space as Space>::orientation(a, b, c)
            }
            fn distance(&self, o: &Self) -> f64 {
                Isometry::distance(self, o)
            }
        }
    };
}
plain_frame!(RigidMotion, Euclidean);
plain_frame!(Rotation, Spherical);

impl Frame for MobiusDd {
    type Iso = Mobius;
    type Ext = Cdd;
    const EXTENDED: bool = true;
    fn identity() -> Self {
        MobiusDd::IDENTITY
    }
    fn from_iso(i: &Mobius) -> Self {
        MobiusDd::from(*i)
    }
    fn round(&self) -> Mobius {
        MobiusDd::round(self)
    }
    fn compose(&self, o: &Self) -> Self {
        MobiusDd::compose(self, o)
    }
    fn inverse(&self) -> Self {
        MobiusDd::inverse(self)
    }
    fn normalized(&self) -> Self {
        MobiusDd::normalized(self)
    }
    fn apply(&self, p: Cdd) -> Cdd {
        MobiusDd::apply(self, p)
    }
    fn ext(hi: Complex, lo: Option<Complex>) -> Cdd {
        Cdd::from_parts(hi, lo.unwrap_or_default())
    }
    fn split(p: Cdd) -> (Complex, Option<Complex>) {
        (p.hi(), Some(p.lo()))
    }
    fn from_pairs(p0: Cdd, q0: Cdd, p1: Cdd, q1: Cdd) -> Self {
        MobiusDd::from_pairs(p0, q0, p1, q1)
    }
    fn fit(pairs: &[(Cdd, Cdd)]) -> Result<Self> {
        MobiusDd::fit(pairs)
    }
    fn point_distance(a: Cdd, b: Cdd) -> f64 {
        disk_distance_dd(a, b)
    }
    fn orientation(a: Cdd, b: Cdd, c: Cdd) -> f64 {
        disk_orientation_dd(a, b, c)
    }
    fn distance(&self, o: &Self) -> f64 {
        MobiusDd::distance(self, o)
    }
}
