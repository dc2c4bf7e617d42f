//! cadmorph: a CAD/NURBS geometry kernel and IGES/STEP processor for shape
//! parameterisation.
//!
//! This facade re-exports the workspace crates and opens a file of either format; it
//! is a library whose dependencies are the crates' own (the command-line tool is the
//! `cadmorph-cli` package).
//!
//! | module | crate | what |
//! |---|---|---|
//! | [`nurbs`] | `cadmorph-nurbs` | NURBS curves and surfaces |
//! | [`brep`] | `cadmorph-brep` | entity references, units, faces, the document trait |
//! | [`morph`] | `cadmorph-morph` | FFD, RBF, IDW deformations of point sets |
//! | [`iges`] | `cadmorph-iges` | lossless IGES 5.3 documents, NURBS views, edits |
//! | [`step`] | `cadmorph-step` | lossless ISO 10303-21 documents, B-rep and NURBS views, edits |
//! | [`seam`] | `cadmorph-seam` | seam measurement, seam-keeping refinement, repair |
//! | [`model`] | `cadmorph-model` | format-neutral patches, morph and save |
//!
//! Layers point down only: `nurbs` and `morph` depend on no other cadmorph crate;
//! `brep` on `nurbs`; `iges` and `step` on `brep` and `nurbs`; `seam` on `brep`,
//! `nurbs`, `morph`; `model` on `brep`, `seam`, `morph`, `nurbs` and never on a format.
//! The one place that tells the formats apart is [`read_document`] here.
//!
//! ```
//! # let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("samples/hull3.stp");
//! // let path = std::path::Path::new("hull3.stp");
//! let mut model = cadmorph::open(&path)?;
//! assert_eq!(model.format(), cadmorph::Format::Step);
//! let bow = cadmorph::morph::Affine::identity();
//! model.morph(&bow, &Default::default())?;
//! assert_eq!(model.to_bytes(), std::fs::read(&path)?); // nothing moved, nothing rewritten
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod convert;
mod loops;

use std::path::Path;

pub use cadmorph_blade as blade;
pub use cadmorph_brep as brep;
pub use cadmorph_iges as iges;
pub use cadmorph_mesh as mesh;
pub use cadmorph_model as model;
pub use cadmorph_morph as morph;
pub use cadmorph_nurbs as nurbs;
pub use cadmorph_seam as seam;
pub use cadmorph_step as step;

pub use cadmorph_brep::{CadDocument, EntityRef, Format};
pub use cadmorph_model::{Error, Model, Result};
pub use convert::{
    bounded_faces, convert, convert_with, save_as, save_as_with, BoundedFaces, ConvertOptions, IgesFaces,
};

/// The format of `bytes`: STEP when the first non-blank text is the Part 21 header line
/// `ISO-10303-21` (ISO 10303-21 §5.2), IGES when the first line has 80 columns
/// (ignoring its terminator) with a section letter `S`, `G` or `D` in column 73 (IGES
/// 5.3 §2.1.2), else `None`.
///
/// ```
/// use cadmorph::{sniff, Format};
/// assert_eq!(sniff(b"ISO-10303-21;\nHEADER;"), Some(Format::Step));
/// assert_eq!(sniff(b""), None);
/// assert_eq!(sniff(b"hello"), None);
/// ```
pub fn sniff(bytes: &[u8]) -> Option<Format> {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
    if bytes[start..].starts_with(b"ISO-10303-21") {
        return Some(Format::Step);
    }
    let end = bytes.iter().position(|&b| b == b'\n' || b == b'\r').unwrap_or(bytes.len());
    // No line terminators at all: the first 80 bytes are the first record.
    let line = if end == bytes.len() { &bytes[..bytes.len().min(80)] } else { &bytes[..end] };
    (line.len() == 80 && matches!(line[72], b'S' | b'G' | b'D')).then_some(Format::Iges)
}

/// Reads `bytes` as the document of the format [`sniff`] finds; `what` names the input
/// in errors (a path, or `bytes`).
///
/// # Errors
///
/// [`Error::NotCad`] when the input is neither format (an empty file included);
/// [`Error::Document`] with the reader's error.
pub fn read_document(bytes: &[u8], what: &str) -> Result<Box<dyn CadDocument>> {
    use cadmorph_brep::ReadDocument;
    match sniff(bytes) {
        Some(Format::Step) => Ok(Box::new(<step::Document as ReadDocument>::from_bytes(bytes)?)),
        Some(Format::Iges) => Ok(Box::new(<iges::Document as ReadDocument>::from_bytes(bytes)?)),
        None if bytes.iter().all(u8::is_ascii_whitespace) => Err(Error::NotCad { what: format!("{what} is empty") }),
        None => Err(Error::NotCad { what: what.to_owned() }),
    }
}

/// The model of `bytes`, IGES or STEP (see [`sniff`]).
///
/// # Errors
///
/// As [`read_document`], and the model's own ([`Model::new`]).
pub fn from_bytes(bytes: &[u8]) -> Result<Model> {
    Model::new(read_document(bytes, "bytes")?)
}

/// Opens the IGES or STEP file at `path` (told apart by its contents, not its name).
///
/// # Errors
///
/// [`Error::Io`] and [`Error::Read`] with the path; [`Error::NotCad`] for a file of
/// neither format.
pub fn open(path: &Path) -> Result<Model> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io { path: path.to_owned(), source })?;
    let with_path = |e: Error| match e {
        Error::Document(source) => Error::Read { path: path.to_owned(), source },
        other => other,
    };
    let doc = read_document(&bytes, &path.display().to_string()).map_err(with_path)?;
    Model::new(doc).map_err(with_path)
}
