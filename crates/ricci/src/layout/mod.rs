//! Isometric layouts, isometries and deck transformations (paper 001 §V Step 4, 002 §6.2.2).
