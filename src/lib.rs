//! cadmorph: CAD/NURBS geometry kernel and IGES/STEP processor for shape parameterisation.
pub use cadmorph_morph as morph;
pub use cadmorph_nurbs as nurbs;
