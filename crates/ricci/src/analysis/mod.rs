//! Distortion statistics, geodesic length spectrum (papers 000 §4, 002 §6.3.3).
