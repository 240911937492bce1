//! The intrinsic metric of a triangulated surface as one value ([`IntrinsicMetric`]): the
//! background geometry (E², H², S²) and a length per edge, with the double-double tail of the
//! lengths where one was computed.
//!
//! A discrete metric is an assignment of lengths to the edges that makes every face a triangle
//! of the background geometry (paper 001 §IV); the flow produces one
//! ([`crate::flow::FlowResult::metric`]), the double-double polish ([`crate::flow::polish`])
//! refines it to ~32 digits, and the cut, the layout, the deck group, the atlas and the spline
//! consume it. The tail is optional: edge `e` has length `lengths[e] + lengths_lo[e]` when
//! [`IntrinsicMetric::lengths_lo`] is `Some`, else `lengths[e]`. Stages that compute in double
//! precision read the leading parts only ([`IntrinsicMetric::lengths`], also through `Deref`
//! to `[f64]`), stages that compute in double-double (the hyperbolic layout, the compact
//! fundamental domain) read [`IntrinsicMetric::length_dd`].
//!
//! The type does not check the lengths against a mesh (it does not know one); the stages that
//! take it do, naming the edge, as before.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::metric::Geometry;
use crate::numeric::dd::Dd;

/// Edge lengths (by edge id) in a background geometry, optionally to double-double precision.
#[derive(Debug, Clone, PartialEq)]
pub struct IntrinsicMetric {
    geometry: Geometry,
    lengths: Vec<f64>,
    lengths_lo: Option<Vec<f64>>,
}

impl IntrinsicMetric {
    /// A metric given in double precision.
    pub fn new(geometry: Geometry, lengths: Vec<f64>) -> IntrinsicMetric {
        IntrinsicMetric {
            geometry,
            lengths,
            lengths_lo: None,
        }
    }

    /// A Euclidean metric given in double precision (the input of the flows: edge lengths of
    /// a mesh in R³, [`crate::mesh::Surface::edge_lengths`]).
    pub fn euclidean(lengths: Vec<f64>) -> IntrinsicMetric {
        IntrinsicMetric::new(Geometry::Euclidean, lengths)
    }

    /// A metric given to double-double precision: edge `e` has length
    /// `lengths[e] + lengths_lo[e]`. Errors when there is not one low part per length.
    pub fn with_low_parts(
        geometry: Geometry,
        lengths: Vec<f64>,
        lengths_lo: Vec<f64>,
    ) -> Result<IntrinsicMetric> {
        if lengths_lo.len() != lengths.len() {
            return Err(Error::input(format!(
                "{} low parts of edge lengths given for {} lengths",
                lengths_lo.len(),
                lengths.len()
            )));
        }
        Ok(IntrinsicMetric {
            geometry,
            lengths,
            lengths_lo: Some(lengths_lo),
        })
    }

    /// The background geometry.
    pub fn geometry(&self) -> Geometry {
        self.geometry
    }

    /// Errors unless the metric is of `geometry`; `consumer` names what needs it ("the
    /// uniformization flow").
    pub fn require(&self, geometry: Geometry, consumer: &str) -> Result<()> {
        if self.geometry == geometry {
            return Ok(());
        }
        Err(Error::input(format!(
            "{consumer} takes a {} metric, this one is {}",
            geometry.name(),
            self.geometry.name()
        )))
    }

    /// The lengths (leading parts), by edge id.
    pub fn lengths(&self) -> &[f64] {
        &self.lengths
    }

    /// The low parts of the lengths when the metric is given to double-double precision.
    pub fn lengths_lo(&self) -> Option<&[f64]> {
        self.lengths_lo.as_deref()
    }

    /// Whether the metric carries low parts (double-double precision).
    pub fn is_double_double(&self) -> bool {
        self.lengths_lo.is_some()
    }

    /// The low part of edge `e`'s length (0 when the metric has none).
    pub fn low_part(&self, e: usize) -> f64 {
        self.lengths_lo.as_ref().map_or(0.0, |l| l[e])
    }

    /// Edge `e`'s length in double-double.
    pub fn length_dd(&self, e: usize) -> Dd {
        Dd::new(self.lengths[e]) + Dd::new(self.low_part(e))
    }

    /// The parts: geometry, leading parts, low parts.
    pub fn into_parts(self) -> (Geometry, Vec<f64>, Option<Vec<f64>>) {
        (self.geometry, self.lengths, self.lengths_lo)
    }

    /// The metric carried to `target`, a mesh whose corners are those of `source` (the mesh
    /// of this metric) with some edges split in two (a cut or a slice of `source`): the edge
    /// of corner `h` of `target` gets the length of the edge of corner `h` of `source`. Low
    /// parts are carried when present.
    pub fn carried_to(&self, source: &Mesh, target: &Mesh) -> IntrinsicMetric {
        let mut l = vec![0.0; target.n_edges()];
        let mut lo = self
            .lengths_lo
            .as_ref()
            .map(|_| vec![0.0; target.n_edges()]);
        for h in 0..target.n_corners() as u32 {
            let (e, t) = (source.he_edge(h) as usize, target.he_edge(h) as usize);
            l[t] = self.lengths[e];
            if let (Some(lo), Some(from)) = (lo.as_mut(), self.lengths_lo.as_ref()) {
                lo[t] = from[e];
            }
        }
        IntrinsicMetric {
            geometry: self.geometry,
            lengths: l,
            lengths_lo: lo,
        }
    }
}

/// The metric reads as its leading lengths wherever double precision is enough (`&metric` is
/// a `&[f64]` by edge id).
impl std::ops::Deref for IntrinsicMetric {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.lengths
    }
}

impl AsRef<[f64]> for IntrinsicMetric {
    fn as_ref(&self) -> &[f64] {
        &self.lengths
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn low_parts_must_match_the_lengths() {
        let e = IntrinsicMetric::with_low_parts(Geometry::Hyperbolic, vec![1.0; 3], vec![0.0; 2]);
        assert!(e.is_err());
        let m = IntrinsicMetric::with_low_parts(
            Geometry::Hyperbolic,
            vec![1.0, 2.0],
            vec![1e-20, -1e-20],
        )
        .unwrap();
        assert_eq!(m.length_dd(0).hi, 1.0);
        assert_eq!(m.length_dd(0).lo, 1e-20);
        assert_eq!(m.low_part(1), -1e-20);
        assert_eq!(
            IntrinsicMetric::new(Geometry::Euclidean, vec![1.0]).low_part(0),
            0.0
        );
        assert_eq!(&m[..], &[1.0, 2.0]);
    }

    #[test]
    fn carried_to_a_copy_keeps_every_length() {
        // Two triangles sharing an edge; the "cut" here is the same mesh, so every edge keeps
        // its length and its low part.
        let mesh = Mesh::from_triangles(4, vec![[0, 1, 2], [0, 2, 3]]).unwrap();
        let ne = mesh.n_edges();
        let l: Vec<f64> = (0..ne).map(|e| 1.0 + e as f64).collect();
        let lo: Vec<f64> = (0..ne).map(|e| e as f64 * 1e-18).collect();
        let m =
            IntrinsicMetric::with_low_parts(Geometry::Euclidean, l.clone(), lo.clone()).unwrap();
        let c = m.carried_to(&mesh, &mesh);
        assert_eq!(c, m);
    }
}
