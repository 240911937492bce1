//! Fairing and fitting of DMS splines (paper 000 §5).
