//! Affine atlas with a single extraordinary point (paper 000 §4, paper 002 §5.2–5.3).
