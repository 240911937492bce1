//! Background geometries, discrete conformal schemes, curvature and Hessian (paper 001 §IV–V).
