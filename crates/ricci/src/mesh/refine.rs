//! Intrinsic refinement: metric-preserving edge splits in E², H², S² (for raising vertex valence).
