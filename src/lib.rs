//! cadmorph: a CAD/NURBS geometry kernel and IGES/STEP processor for shape
//! parameterisation.
//!
//! This facade re-exports the workspace crates and holds the command-line pipeline
//! (`cadmorph info | sample | seams | morph | refine | eval`).
//!
//! | module | crate | what |
//! |---|---|---|
//! | [`nurbs`] | `cadmorph-nurbs` | NURBS curves and surfaces |
//! | [`morph`] | `cadmorph-morph` | FFD, RBF, IDW deformations of point sets |
//! | [`iges`] | `cadmorph-iges` | lossless IGES 5.3 documents, NURBS views, edits |
//! | [`step`] | `cadmorph-step` | lossless ISO 10303-21 documents, B-rep and NURBS views, edits |
//! | [`seam`] | `cadmorph-seam` | seam measurement, seam-keeping refinement, repair |
//! | [`model`] | `cadmorph-model` | format-neutral patches, morph and save |
//!
//! ```
//! use cadmorph::nurbs::{NurbsSurface, Surface};
//! let s = NurbsSurface::bilinear([[0., 0., 0.], [2., 0., 0.], [0., 1., 0.], [2., 1., 0.]]);
//! assert_eq!(s.eval(0.5, 0.5).x, 1.0);
//! ```

pub use cadmorph_iges as iges;
pub use cadmorph_model as model;
pub use cadmorph_morph as morph;
pub use cadmorph_nurbs as nurbs;
pub use cadmorph_seam as seam;
pub use cadmorph_step as step;

pub mod refdata;
