//! Surface and volume meshes for shape parameterisation: lossless readers and writers of
//! the CFD/FEM formats, morphs of their nodes by any [`cadmorph_morph::Deformation`],
//! RBF propagation of a boundary displacement into a volume mesh, and mesh quality as
//! OpenFOAM's `checkMesh` reports it (paper §3.1.1, §3.2, §3.3).
//!
//! This crate owns meshes. It knows nothing of CAD files; deformations come from
//! `cadmorph-morph`.
//!
//! # Formats
//!
//! | module | format | kept losslessly |
//! | --- | --- | --- |
//! | [`format::foam`] | OpenFOAM `polyMesh` (ASCII/binary, gzip or not) | every file of the directory |
//! | [`format::unv`] | I-DEAS Universal 2411/2412 | every dataset |
//! | [`format::dyna`] | LS-DYNA keyword `.k` | every keyword |
//! | [`format::mdpa`] | Kratos `.mdpa` | every block |
//! | [`format::elmer`] | Elmer `mesh.nodes` | every record |
//!
//! Writing an unchanged file gives back its bytes; after a morph only the records of
//! moved nodes are written anew. Each format also has the writer of PyGeM's handler
//! (`write_pygem`), which reproduces PyGeM's expected test outputs.
//!
//! # Crates measured
//!
//! No crates.io mesh reader was taken: none keeps unknown content, which a morph of a
//! production mesh needs (OpenFOAM zones and sets, UNV groups, LS-DYNA keywords).
//! `flate2` (gzip of OpenFOAM files) is used.
//!
//! ```
//! use cadmorph_mesh::format::elmer::ElmerNodes;
//! use cadmorph_morph::{Affine, Deformation};
//! use cadmorph_morph::math::Vector3;
//! let mut f = ElmerNodes::parse("1 -1 0 0 0\n2 -1 1 0 0\n")?;
//! Affine::translation(Vector3::new(0.0, 0.0, 0.5)).deform(&mut f.points);
//! assert_eq!(f.write(), "1 -1 0.0 0.0 0.5\n2 -1 1.0 0.0 0.5\n");
//! # Ok::<(), cadmorph_mesh::Error>(())
//! ```

pub mod atomic;
pub mod cell;
mod error;
mod file;
pub mod format;
mod from_cells;
pub mod morph;
mod nodelines;
pub mod quality;
mod text;
pub mod volume;

pub use cell::{Cell, CellKind};
pub use error::{Error, Result};
pub use file::MeshFile;
