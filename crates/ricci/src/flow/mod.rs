//! Target curvatures and Ricci flow solvers (paper 001 §V, paper 000 §4 Step 3).
