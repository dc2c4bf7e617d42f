//! ISO 10303-21 (STEP) lossless reader/writer with B-rep and NURBS views.
//!
//! cadmorph-step owns the STEP side of cadmorph: a [`Document`] that keeps every byte of
//! the file, typed views that turn AP203/AP214/AP242 geometry and topology into
//! [`cadmorph_nurbs`] curves and surfaces in world coordinates and model units, in-place
//! edits (control points, weights, analytic surfaces replaced by their exact B-spline
//! form) that rewrite only the instances they touch, and a [`DocumentBuilder`] for new
//! files. [`Document`] implements `cadmorph_brep::CadDocument`: its face write
//! ([`Document::write_surface_shared`]) keeps the file's sharing of points (a point
//! shared by two faces moves once), its edge write ([`Document::set_edge_curve`]) moves
//! the edge's vertices with the new curve. A part that an assembly or `MAPPED_ITEM`s
//! place more than once can be given a copy per placement ([`Document::unshare`]: the
//! geometry, the product definition and the styles), so that each placement can be
//! edited alone. It does not morph, check seams or know about IGES; see
//! `cadmorph-model`, `cadmorph-seam` and `cadmorph-iges`.
//!
//! ```
//! use cadmorph_step::Document;
//! let bytes = std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/bspline_surface.stp")).unwrap();
//! let doc = Document::parse(&bytes).unwrap();
//! assert_eq!(doc.write(), bytes); // lossless
//! let faces = doc.faces().unwrap();
//! let s = doc.face_nurbs(&faces[0]).unwrap().surface;
//! assert_eq!((s.u_degree(), s.v_degree(), s.n_u(), s.n_v()), (3, 3, 6, 5));
//! ```
//!
//! # Why the Part 21 layer is written here
//!
//! The exchange structure is parsed by hand (tokens included) instead of through
//! `truck-stepio` or `ruststep` because a shape-parameterisation run must give the user
//! back *their* file: same ids, same comments, same product structure, same names and
//! colours, with only the moved geometry changed. truck-stepio renumbers entities and
//! writes only the shapes it understood (a 6,470-entity OCCT file comes back as 1,024
//! entities). Here every instance keeps its original text, parameters are converted
//! only when a view asks, and unknown entities are never touched. truck-stepio is used
//! in the tests as a second, independent reader of what this crate writes.
//!
//! The views read the records they need from the bytes where a record has the plain
//! shape most writers give it (a point's three numbers, a placement's or an edge's
//! references and flags: `views::flat`), and through the general parameter reader
//! otherwise; each shortcut is property-tested against that reader, which also gives
//! every error. No crate reads Part 21 records lazily like this: the general reader
//! builds a parameter tree, several allocations per record, and on a small file that was
//! most of the time of the faces' conversion.
//!
//! Dependencies beyond the workspace's: `fast-float2` reads the coordinates of the
//! `CARTESIAN_POINT`s of a pole net straight from the bytes (the same correctly rounded
//! value as `str::parse`, without the UTF-8 check and about twice as fast), `rayon`
//! reads large pole nets on all cores, `memchr` finds entity names in instance texts,
//! and `rustc-hash` hashes the views' caches (keyed by instance position, which the
//! reader assigns, so a file cannot choose colliding keys).
//!
//! The crate has no feature flags.

mod cad;
mod document;
mod edit;
mod error;
mod read;
mod unshare;
mod views;
mod write;

use std::fmt;

pub use document::{Document, InstanceRef};
pub use error::{Error, Position, Result};
pub use read::param::{decode_string, encode_string, Body, Param, Record, Value};
pub use views::{Edge, Face, LengthUnit, SurfaceKind, Units, WorldCurve, WorldSurface};
pub use write::{format_real, DocumentBuilder, Schema};

/// An instance name `#n`.
///
/// ```
/// assert_eq!(cadmorph_step::EntityId(42).to_string(), "#42");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EntityId(pub u64);

impl fmt::Display for EntityId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "#{}", self.0)
    }
}
