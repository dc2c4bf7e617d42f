//! The file formats, one module each. Every reader keeps what it does not interpret, so
//! that writing an unchanged file gives its bytes back; a morph changes node coordinates
//! only.

pub mod dyna;
pub mod elmer;
pub mod foam;
pub mod gmsh;
pub mod mdpa;
pub mod obj;
pub mod stl;
pub mod unv;
pub mod vtk;
pub mod vtu;
