//! A format-neutral model of a CAD document: every face as a NURBS patch in world
//! coordinates, tied to the entity it came from, with the shared edges between patches;
//! morphing it (with the seam-keeping refinement of `cadmorph-seam`) and saving it by
//! patching the original document, so that everything the morph did not touch stays
//! byte for byte as it was.
//!
//! [`Model`] is generic over [`cadmorph_brep::CadDocument`], the trait
//! `cadmorph-iges` and `cadmorph-step` implement: it reads and writes no syntax and names
//! no format, so one code path morphs, refines and measures both. The facade crate
//! `cadmorph` opens a file of either format (`cadmorph::open`); with one format in hand,
//! `Model::<cadmorph_iges::Document>::open(path)` does.
//!
//! Edges come from two places. [`Model::edges`] are iso-boundaries of two patches that
//! lie on each other (found from geometry, so bare IGES 128 surfaces have them too);
//! seam repair makes those exact. [`Model::trim_edges`] are the other shared edges, from
//! the document's [`BoundCurve`](cadmorph_brep::BoundCurve)s: STEP B-rep edges, IGES 504
//! edges used by the loops of two 510 faces, and, for IGES 144/143 files without B-rep,
//! trimming curves of two faces that lie on each other. Both are measured by
//! [`Model::seams`] and refined for by [`Model::morph`]; after a morph, each bound curve
//! is traced once on its morphed face (control points moved where that stays within
//! `1e-7 ×` the model size, else a cubic fit broken where the curve crosses the face's
//! knot lines).
//!
//! ```
//! use cadmorph_model::Model;
//! # let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/hull3.igs");
//! // let path = "hull3.igs";
//! let model = Model::<cadmorph_iges::Document>::open(path.as_ref())?;
//! assert_eq!(model.patches().len(), 3);
//! let seams = model.seams(100);
//! assert_eq!(seams.edges.len(), 2);
//! assert!(seams.max_gap_closest < 1e-9);
//!
//! // A solid: 29 shared edges from its B-rep, 28 of them design creases, and the
//! // closing seam of its cylinder.
//! let bytes = std::fs::read(path.with_file_name("mixed_solid.stp"))?;
//! let seams = Model::<cadmorph_step::Document>::from_bytes(&bytes)?.seams(50);
//! assert_eq!((seams.edges.len(), seams.sharp_edges), (30, 28));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod edges;
mod error;
mod exact;
mod model;
mod morph;
mod output;
mod trace;

pub use cadmorph_brep::{CadDocument, EntityRef, Face, Format, ReadDocument, Skipped, Units};
pub use error::{Error, Result};
pub use exact::{ExactFfd, ExactReport};
pub use model::{Info, Model, Patch, PatchInfo, Progress, Silent, Verification};
pub use morph::{MorphOptions, MorphOutcome, RepairOutcome};
pub use output::{write_atomic, Staged};
