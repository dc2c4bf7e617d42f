//! A format-neutral model of an IGES or STEP file: every face as a NURBS patch in world
//! coordinates, tied to the entity it came from, with the shared edges between patches;
//! morphing it (with the seam-keeping refinement of `cadmorph-seam`) and saving it by
//! patching the original document, so that everything the morph did not touch stays
//! byte for byte as it was.
//!
//! This crate owns the glue between the file layers (`cadmorph-iges`, `cadmorph-step`)
//! and the geometry layers (`cadmorph-nurbs`, `cadmorph-morph`, `cadmorph-seam`); it reads
//! and writes no syntax itself.
//!
//! Edges come from two places. [`Model::edges`] are iso-boundaries of two patches that
//! lie on each other (found from geometry, so bare IGES 128 surfaces have them too);
//! seam repair makes those exact. [`Model::trim_edges`] are the other shared edges, from
//! the file's topology: STEP B-rep edges, IGES 504 edges used by the loops of two 510
//! faces, and, for IGES 144/143 files without B-rep, trimming curves of two faces that
//! lie on each other. Both are measured by [`Model::seams`] and refined for by
//! [`Model::morph`]; after a morph, IGES trimming curves and B-rep edges are traced on
//! their morphed face (control points moved where that stays within `1e-7 ×` the model
//! size, else a cubic fit broken where the curve crosses the face's knot lines).
//!
//! ```
//! use cadmorph_model::Model;
//! let bytes = std::fs::read(cadmorph_testkit::sample("hull3.igs")).unwrap();
//! let model = Model::from_bytes(&bytes).unwrap();
//! assert_eq!(model.patches().len(), 3);
//! let seams = model.seams(100);
//! assert_eq!(seams.edges.len(), 2);
//! assert!(seams.max_gap_closest < 1e-9);
//!
//! // A solid: 29 shared edges from its B-rep, 28 of them design creases.
//! let bytes = std::fs::read(cadmorph_testkit::sample("mixed_solid.stp")).unwrap();
//! let seams = Model::from_bytes(&bytes).unwrap().seams(50);
//! assert_eq!((seams.edges.len(), seams.sharp_edges), (29, 28));
//! ```

mod error;
mod model;
mod topology;

pub use error::{Error, Result};
pub use model::{Format, Info, Model, MorphOptions, MorphOutcome, Patch, PatchInfo, Progress, Silent, Source};
