//! Triangular B-splines (DMS) and manifold splines (paper 000 §5).
