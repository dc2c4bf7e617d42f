//! Object laws for hulls and other closed CAD models (paper section 2.2 and its closing
//! remarks): the exact enclosed volume of a closed NURBS B-rep and its derivatives
//! ([`volume`]), FFD that keeps the volume or the barycentre of a CAD model
//! ([`keep()`]), a Lackenby-style shift of the longitudinal centre of buoyancy
//! ([`lackenby`]), the planing-hull chine law ([`chine()`]), length, beam, draft and block
//! coefficient changes ([`dims`]).
//!
//! The crate works on the model's faces ([`cadmorph_model::Model::patches`]) and bounding
//! curves; the constrained solvers for point sets live in `cadmorph_morph::constrained`.

pub mod chine;
pub mod dims;
pub mod error;
pub mod gauss;
pub mod keep;
pub mod lackenby;
pub mod refine;
pub mod volume;

pub use chine::{chine, ChineLaw, ChineReport, Law, Section, Side};
pub use dims::{change_dimensions, dimensions, extent, Dimensions, DimsChange, DimsReport, Stretch};
pub use error::{Error, Result};
pub use keep::{keep, Keep, KeepReport};
pub use lackenby::{lcb_shift, section_shift, LcbReport, SectionShift};
pub use volume::{enclosed, Enclosed, FaceMethod, Moments, OnReseamed};
