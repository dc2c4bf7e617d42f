//! cadmorph: a CAD/NURBS geometry kernel and IGES/STEP processor for shape
//! parameterisation.
//!
//! This facade re-exports the workspace crates and holds the command-line pipeline.
//! Until the IGES and STEP readers land, the pipeline reads surfaces from the OCCT
//! reference files shipped beside each sample (`samples/*.ref.json`).
//!
//! | module | crate | what |
//! |---|---|---|
//! | [`nurbs`] | `cadmorph-nurbs` | NURBS curves and surfaces |
//! | [`morph`] | `cadmorph-morph` | FFD, RBF, IDW deformations of point sets |
//!
//! ```
//! use cadmorph::nurbs::{NurbsSurface, Surface};
//! let s = NurbsSurface::bilinear([[0., 0., 0.], [2., 0., 0.], [0., 1., 0.], [2., 1., 0.]]);
//! assert_eq!(s.eval(0.5, 0.5).x, 1.0);
//! ```

pub use cadmorph_morph as morph;
pub use cadmorph_nurbs as nurbs;

pub mod refdata;
