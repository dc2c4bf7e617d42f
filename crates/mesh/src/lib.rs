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
//! | module | format | read | write |
//! | --- | --- | --- | --- |
//! | [`format::foam`] | OpenFOAM `polyMesh`: ASCII and binary, gzip or not, 32-bit labels in memory | all five files (ASCII `faces`, `owner`, `neighbour` streamed, not held) | points (in the file's format); every other file copied (streamed ones from disk) |
//! | [`format::stl`] | STL ASCII (several solids) and binary | yes | lossless, VTK-style ASCII, binary |
//! | [`format::obj`] | Wavefront OBJ | `v`, `f`, `g`/`o` | lossless |
//! | [`format::vtk`] | legacy VTK ASCII (v2–v5 cell layouts) | points, cells | lossless, VTK-writer style |
//! | [`format::vtu`] | VTK XML `.vtu`/`.vtp`: ascii, base64, appended raw/base64, zlib | points, cells | lossless, fresh appended-raw grid |
//! | [`format::gmsh`] | Gmsh MSH 2.2 and 4.1 ASCII | nodes, elements | lossless |
//! | [`format::unv`] | I-DEAS Universal 2411/2412 | nodes, elements | lossless, PyGeM style |
//! | [`format::dyna`] | LS-DYNA keyword `.k` | `*NODE`, `*ELEMENT_SHELL/SOLID` | lossless |
//! | [`format::mdpa`] | Kratos `.mdpa` | nodes, elements, conditions | lossless, PyGeM style |
//! | [`format::elmer`] | Elmer `mesh.nodes` | nodes | lossless, PyGeM style |
//!
//! "Lossless": writing an unchanged file gives back its bytes, and after a morph only the
//! records of moved nodes are written anew (a whole points block for VTK, the points array
//! for VTU), so every field, comment, group and unknown section survives. The PyGeM-style
//! writers (`write_pygem`, `write_ascii_vtk`, `write_vtk_style`) reproduce the expected
//! outputs of PyGeM's handler tests byte for byte. [`MeshFile`] picks the format by name.
//! Not supported: binary MSH, binary legacy VTK, big-endian VTK XML (each refused with
//! [`Error::Unsupported`]).
//!
//! # Morph, quality, volume morph
//!
//! [`morph::morph_checked`] moves every node by any [`cadmorph_morph::Deformation`]
//! and refuses a result that fails a check it did not fail before;
//! [`quality::Quality`] is OpenFOAM `checkMesh`'s geometry report (same formulas,
//! agreeing to 1e-13 relative on the test meshes); [`volume`] carries a boundary
//! displacement into the interior with a Wendland RBF and greedy centre selection;
//! [`tessellate`] turns NURBS faces and their shared sides into a watertight triangle
//! mesh (written as an STL with one solid per face, [`format::stl::Stl::from_triangles`]);
//! [`from_cad`] does the same for trimmed faces of any IGES or STEP model (shared edges
//! sampled once, a constrained Delaunay triangulation per face in its parameters).
//!
//! # Crates measured
//!
//! Measured on PyGeM's test files and a gmsh mesh (release build, 2-core VM):
//!
//! * `stl_io` 0.11: reads ASCII and binary (the 2400-triangle sphere in 12.9 ms ASCII,
//!   0.5 ms binary, merging vertices), but writes binary only, drops solid names and the
//!   normals as stored, so an ASCII file cannot be written back. Skipped.
//! * `vtkio` 0.6: reads legacy VTK, but rewrites it in its own layout (not byte-identical)
//!   and failed on PyGeM's `points_test_true_version6.vtp` (VTK 9, appended base64 + zlib:
//!   "incomplete deflate stream"). Skipped.
//! * `mshio` 0.4: reads MSH 4.1 only (refuses 2.2: "Only the MSH file format specification
//!   of revision 4.1 is supported") and has no writer. Skipped.
//! * No crate reads OpenFOAM polyMesh, UNV, LS-DYNA, Kratos or Elmer files.
//!
//! Used: `flate2` (gzip for OpenFOAM, zlib for VTU), `base64` (VTU), `memchr` (line
//! starts of the parallel polyMesh reader), `fast-float2` (its numbers: the same correctly
//! rounded results as `str::parse`, on bytes, about twice as fast on OpenFOAM's 17-digit
//! coordinates) and `spade` (constrained Delaunay triangulation for [`from_cad`]). The
//! independent readers of the tests are Python `meshio`, `gmsh` (also UNV), Ansys PyDyna's
//! keyword deck (LS-DYNA `.k`) and OpenFOAM itself (`tests/mesh/setup.sh`); no
//! installable program or package reads Elmer's `mesh.nodes` here (ElmerGrid is not in
//! Debian or on PyPI), so Elmer files are checked against PyGeM's expected outputs only.
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
pub mod from_cad;
mod from_cells;
pub mod morph;
mod nodelines;
pub mod quality;
pub mod tessellate;
mod text;
pub mod volume;

pub use cell::{Cell, CellKind};
pub use error::{Error, Result};
pub use file::MeshFile;
