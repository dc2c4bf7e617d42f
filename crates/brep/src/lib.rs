//! The shared vocabulary of CAD documents, and the document trait IGES and STEP
//! implement.
//!
//! `cadmorph-brep` sits between the geometry kernel (`cadmorph-nurbs`) and the file
//! formats (`cadmorph-iges`, `cadmorph-step`). It owns no syntax: it names what both
//! formats have in common so that the format-neutral layers above (`cadmorph-model`,
//! `cadmorph-seam`) and a converter author's code are written once:
//!
//! * [`EntityRef`]: an entity of a file (format, numeric id, assembly occurrence),
//!   displayed as the format writes it (`DE 5` in IGES, `#12` in STEP). No entity
//!   reference travels as a string.
//! * [`Units`]: metres per model unit, the unit's name, the file's distance uncertainty.
//! * [`Face`]: a face as an exact NURBS patch in world coordinates and model units, with
//!   its entities, parameter box, orientation, trim flag and [`SurfaceKind`].
//! * [`BoundCurve`] and [`FreeCurve`]: the model-space curves that bound faces (trims,
//!   B-rep edges) and the other model-space curves.
//! * [`CadDocument`]: what a document gives (format, units, counts, faces, bound and free
//!   curves) and the edits it takes (a face's surface, a curve), with the contract every
//!   implementation keeps (see its docs).
//! * [`BoundedFace`] and [`Shell`]: faces with their loops of model-space curves and the
//!   shared vertices and edges a writer makes of them; [`pcurve`]: their parameter-space
//!   curves; [`orient_outward`]: the faces of a closed piece turned so their normals
//!   point out (conversion writes these to the other format).
//! * [`real`]: reals as text, the shortest round-trip digits with the point and exponent
//!   both formats want.
//!
//! ```
//! use cadmorph_brep::{EntityRef, Format};
//! assert_eq!(EntityRef::new(Format::Iges, 5).to_string(), "DE 5");
//! assert_eq!(EntityRef::new(Format::Step, 12).to_string(), "#12");
//! assert_eq!(EntityRef::new(Format::Step, 12).with_occurrence(1).to_string(), "#12 (occurrence 2)");
//! ```
//!
//! The crate has no feature flags.

mod curve;
mod document;
mod entity;
mod error;
mod face;
mod orient;
pub mod pcurve;
pub mod real;
mod shell;
mod units;

pub use curve::{BoundCurve, FreeCurve};
pub use document::{CadDocument, ReadDocument};
pub use entity::{EntityRef, Format};
pub use error::{chain, Error, Result};
pub use face::{Face, FaceSet, Skipped, SurfaceKind};
pub use orient::orient_outward;
pub use shell::{BoundedFace, Shell, ShellEdge, PCURVE_TOLS};
pub use units::Units;

/// Vectors and matrices (nalgebra), as `cadmorph_nurbs::math`.
pub use cadmorph_nurbs::math;
