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
//! ```
//! use cadmorph_model::Model;
//! let bytes = std::fs::read(cadmorph_testkit::sample("hull3.igs")).unwrap();
//! let model = Model::from_bytes(&bytes).unwrap();
//! assert_eq!(model.patches().len(), 3);
//! let seams = model.seams(100);
//! assert_eq!(seams.edges.len(), 2);
//! assert!(seams.max_gap_closest < 1e-9);
//! ```

mod error;
mod model;
mod topology;

pub use error::{Error, Result};
pub use model::{Format, Info, Model, MorphOptions, MorphOutcome, Patch, PatchInfo, Progress, Silent, Source};
