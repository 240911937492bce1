//! The flow's options that name a method: the optimizer ([`Solver`]: Newton or gradient flow)
//! and how genus-0 closed surfaces reach the sphere ([`SphereRoute`]).

use serde::Serialize;
use std::fmt;
use std::str::FromStr;

/// The optimizer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Solver {
    Newton,
    Gradient,
}

impl Solver {
    pub fn name(self) -> &'static str {
        match self {
            Solver::Newton => "newton",
            Solver::Gradient => "gradient",
        }
    }
}

impl fmt::Display for Solver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Solver {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "newton" => Ok(Solver::Newton),
            "gradient" | "gradient-descent" | "flow" => Ok(Solver::Gradient),
            _ => Err(format!(
                "unknown solver '{s}' (expected newton or gradient)"
            )),
        }
    }
}

/// How genus-0 closed surfaces reach the sphere.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SphereRoute {
    /// Spherical Newton first, the puncture route if it fails.
    Auto,
    /// Spherical Newton only.
    Newton,
    /// The puncture route directly.
    Puncture,
}
