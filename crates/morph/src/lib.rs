//! Deformations of point sets: FFD, RBF, IDW and affine maps (placeholder until issue 3 lands).
