//! Pictures and reports of cadmorph models: see the morph, the seams and the campaign.
//!
//! - [`html::report_html`]: one self-contained HTML page per model or morph: an
//!   interactive 3D view of the faces before and after, toggles for the control nets and
//!   the FFD lattice (original and moved), the seam edges coloured by C0 gap or G1 angle
//!   on a logarithmic scale with a legend ([`colour`]), hover or click on an edge for its
//!   numbers and the two faces it joins; the seam tables, the refinement and its growth
//!   per round ([`growth`]: a table and an inline SVG plot), the timings, and a static
//!   PNG of each view for printing and for browsers without WebGL.
//! - [`render`]: those PNG pictures, drawn by [`raster`], a small deterministic software
//!   rasterizer of this crate (orthographic, depth-buffered, no anti-aliasing), so that
//!   pictures of a model before and after a morph can be compared pixel by pixel; PNG
//!   encoding is the `png` crate's.
//! - [`gltf::to_glb`]: glTF 2.0 binary with one named node per face and the seam
//!   colouring as vertex colours; [`vtk`]: `.vtu` grids of the control nets and the
//!   lattice for ParaView.
//! - [`campaign`]: the index page of a campaign: a thumbnail per variant, the results
//!   table (sortable), failed and out-of-tolerance variants marked, and scatter plots of
//!   each parameter against each result ([`plots`], inline SVG through the `plotters`
//!   crate; PNG too).
//! - Blade and mesh plots (SVG or PNG, `plotters`, one drawing code for both through
//!   [`chart`]): [`radial`] the radial laws of a blade, original and deformed, with
//!   their control points (the BladeX paper's Figure 7); [`profiles`] the 2D sections;
//!   [`histogram`] mesh quality before and after (non-orthogonality, aspect ratio, cell
//!   volume, skewness).
//!
//! # Why a hand-written WebGL viewer
//!
//! The page's viewer (`assets/viewer.js`, about 400 lines, WebGL 1) is written for
//! cadmorph instead of inlining three.js. What the page draws is small: opaque
//! triangles with a head light, lines, an orthographic orbit camera, and picking of
//! seam edges in screen space. three.js (MIT) would add several hundred kB of minified script
//! to every report, a vendored copy to keep up to date with its licence, and a scene
//! graph the page does not use; the hand-written viewer is about 15 kB, has no
//! dependency to update, opens offline like the rest of the page, and its colour scale
//! is the same code path as [`colour`]'s (the browser test checks the "bad" colour at a
//! known defect). The page exposes `window.cadmorph.project(p)` (the pixel of a model
//! point) so that tests can check what is drawn where.
//!
//! Faces are drawn on a fixed parameter grid ([`grid`]); a trimmed face keeps only the
//! grid triangles inside its trim ([`trim`]: its bound curves projected onto its
//! surface, and a point-in-face test on them).

mod error;

pub mod camera;
pub mod campaign;
pub mod chart;
pub mod colour;
pub mod gltf;
pub mod grid;
pub mod growth;
pub mod histogram;
pub mod html;
pub mod page;
pub mod plots;
pub mod profiles;
pub mod radial;
pub mod raster;
pub mod render;
pub mod scene;
pub mod seamline;
pub mod trim;
pub mod vtk;

pub use error::{Error, Result};
pub use scene::{Input, Lattice, ModelView, Scene};
