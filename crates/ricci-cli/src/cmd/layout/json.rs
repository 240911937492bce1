//! The JSON of `ricci layout`'s deck group: generators and side pairings per isometry type.

use ricci::layout::isometry::{Complex, Mobius, RigidMotion};
use ricci::layout::{DeckGroup, Isometry, Polygon};
use serde_json::{json, Value};

fn c2(z: Complex) -> Value {
    json!([z.re, z.im])
}

/// JSON of a generator (or side pairing) per isometry type.
pub trait JsonIso {
    fn to_json(&self) -> Value;
}
impl JsonIso for RigidMotion {
    fn to_json(&self) -> Value {
        json!({"kind": "rigid_motion", "angle": self.angle(), "translation": c2(self.t)})
    }
}
impl JsonIso for Mobius {
    fn to_json(&self) -> Value {
        let (theta, z0) = self.theta_center();
        json!({
            "kind": "mobius", "a": c2(self.a), "b": c2(self.b), "theta": theta, "center": c2(z0),
            "trace": self.trace(), "translation_length": self.translation_length(),
            "klein_matrix": self.klein_matrix(),
        })
    }
}
impl JsonIso for ricci::layout::Rotation {
    fn to_json(&self) -> Value {
        json!({"kind": "rotation", "matrix": self.m})
    }
}

pub(super) fn deck_json<I: Isometry + JsonIso>(g: &DeckGroup<I>, poly: &Polygon) -> Value {
    let gens: Vec<Value> = g
        .named_generators()
        .iter()
        .map(|(l, d)| {
            let mut v = d.to_json();
            v["letter"] = json!(l);
            v
        })
        .collect();
    let pairings: Vec<Value> = g
        .pairings
        .iter()
        .map(|p| {
            json!({
                "side": poly.sides[p.side].label, "partner": poly.sides[p.partner].label,
                "edge_spread": p.edge_spread, "edge_spread_matrix": p.edge_spread_matrix,
                "max_vertex_error": p.max_vertex_error,
                "map": p.map.to_json(),
            })
        })
        .collect();
    json!({"generators": gens, "side_pairings": pairings})
}
