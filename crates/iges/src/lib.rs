//! IGES 5.3 lossless reader/writer with NURBS views of every surface.
//!
//! `cadmorph-iges` owns the IGES file format for cadmorph:
//!
//! * [`Document::parse`] reads the fixed 80-column ASCII form (Start, Global, Directory
//!   Entry, Parameter Data and Terminate sections) with custom parameter and record
//!   delimiters, Hollerith strings (which may hold the delimiters or span lines), LF,
//!   CRLF, CR or no line terminators, every integer and real form (`1.0D3`, `.5`, `-0.`),
//!   and defaulted parameters. Every line is kept, so [`Document::write`] of an unchanged
//!   document gives back the input byte for byte.
//! * [`Document::view`] gives typed [`View`]s of entities 100–144, 186, 190–198, 308, 314,
//!   402, 406, 408 and 502–514; any other entity is kept verbatim and listed by
//!   [`Document::unknown_entities`].
//! * [`Document::faces`], [`Document::face_surface`], [`Document::surface`] and
//!   [`Document::curve`] convert geometry to exact `cadmorph_nurbs` curves and surfaces in
//!   model units (124 transformation chains applied), in OpenCASCADE's parameterisation
//!   (see [`convert`]); the one approximation is an offset surface (140) over a free-form
//!   base, which no NURBS represents exactly: it is fitted within a stated tolerance. [`Document::surfaces`] summarises every face's surface.
//!   Faces inside 308 subfigure definitions come once per 408 singular subfigure instance
//!   that places them, each with its placement and occurrence ([`Document::try_faces`]).
//! * Edits rewrite only the records they change: [`Document::set_control_points`],
//!   [`Document::set_bspline_surface`], [`Document::set_bspline_curve`],
//!   [`Document::replace_with_bspline`] and the raw [`Document::set_values`]. Sequence
//!   numbers, directory pointers and line counts and the Terminate record follow.
//!   [`Document::unshare_subfigures`] gives the 408 instances on a moved placement their
//!   own copies of the 308 definitions they share (appended entities, pointers
//!   renumbered), so that each placement of a part can be morphed its own way.
//! * [`write::DocumentBuilder`] writes new files from NURBS curves and surfaces.
//! * [`Document::face_bounds`] is the one walk over what bounds a face (144 → 142,
//!   143 → 141, 510 → 508 → 504), and [`Document::reversed_faces`] the orientation from
//!   186/514 shells; on them [`Document`] implements `cadmorph_brep::CadDocument`
//!   (faces, bound curves, free curves, face and curve edits), so the format-neutral
//!   model (`cadmorph-model`) never walks IGES topology itself.
//!
//! It does not own geometry algorithms (`cadmorph-nurbs`), deformations
//! (`cadmorph-morph`) or the format-neutral model of patches and adjacency
//! (`cadmorph-model`), and it does not read binary or compressed IGES.
//!
//! ```
//! use cadmorph_iges::{Document, Units};
//! use cadmorph_nurbs::Surface;
//!
//! let bytes = std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/hull3.igs")).unwrap();
//! let mut doc = Document::parse(&bytes)?;
//! assert_eq!(doc.global().units(), Some(Units::Metre));
//! assert_eq!(doc.write(), bytes); // lossless
//!
//! // Every face as a NURBS surface in model units.
//! let face = doc.faces()[0];
//! let exact = doc.face_surface(&face)?;
//! let p = exact.surface.eval(0.5, 0.5);
//!
//! // Move the poles up by 1 cm; only that 128 record is rewritten.
//! let moved: Vec<_> = exact.surface.control_points().iter().map(|q| q + nalgebra::Vector3::z() * 0.01).collect();
//! doc.set_control_points(face.surface, &moved, None)?;
//! let edited = Document::parse(&doc.write())?;
//! let q = edited.face_surface(&face)?.surface.eval(0.5, 0.5);
//! assert!((q.z - p.z - 0.01).abs() < 1e-12);
//! # Ok::<(), cadmorph_iges::Error>(())
//! ```
//!
//! # Why it is written here
//!
//! No maintained Rust crate reads IGES (the few on crates.io are unmaintained stubs that
//! parse a handful of entities and drop the rest), and cadmorph needs what a converter
//! rarely offers: a byte-faithful document that can be patched in place, positions in
//! every error, and conversions that agree with OpenCASCADE to 1e-9. The reader is
//! written with `nom` for the number grammar and plain byte loops elsewhere; it never
//! panics on input and never allocates from a count in the file before checking the count
//! against the input left (a `cargo fuzz` target, `fuzz/fuzz_targets/iges_document.rs`,
//! holds it to that).
//!
//! The crate has one feature flag, `bench-internals` (off by default), which adds the
//! `bench` module: the tokenizer alone, for its criterion bench. It is not part of the
//! stable API.

#[cfg(feature = "bench-internals")]
pub mod bench;
mod bounds;
mod cad;
pub mod convert;
mod document;
mod edit;
pub mod entity;
mod error;
mod global;
mod read;
mod unshare;
pub mod write;

pub use bounds::FaceBound;
pub use convert::{FaceRef, NurbsInfo, SurfaceInfo};
pub use document::{Directory, Document, Entity, EntityId, Param, Status, Value};
pub use entity::View;
pub use error::{Error, Position, Result, Warning};
pub use global::{Global, Units};
