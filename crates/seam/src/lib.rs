//! Continuity of adjacent NURBS patches, refinement that keeps it under a deformation,
//! and seam repair.
//!
//! `cadmorph-seam` owns the mission's point: a morphed multi-patch model must stay
//! joined. It measures every shared edge densely (C0 gap measured two ways, G1 normal
//! angle, C1 mismatch of cross-boundary derivatives), refines patches so that moving
//! their control points follows the exact morph within a tolerance, and repairs seams
//! between iso boundaries to exact C0 (and G1). It works on NURBS patches and
//! [`Deformation`](cadmorph_morph::Deformation)s. Edges are either coinciding
//! iso-boundaries ([`shared_boundaries`], [`measure_boundary`]) or curves shared by two
//! faces that need not be iso lines of either ([`TrimEdge`], [`measure_edge`]): edges of
//! a STEP B-rep or IGES 504 list, or trimming curves that lie on each other
//! ([`shared_curves`]); which edges a file has is the model crate's business.
//!
//! ```
//! use cadmorph_nurbs::NurbsSurface;
//! use cadmorph_seam::{measure_boundary, shared_boundaries, Face};
//! // Two unit squares side by side, the second lifted by 1 mm at its far corner.
//! let a = NurbsSurface::bilinear([[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]]);
//! let b = NurbsSurface::bilinear([[1., 0., 0.], [2., 0., 0.], [1., 1., 0.], [2., 1., 0.001]]);
//! let edges = shared_boundaries(&[&a, &b], 1e-6, 32, 0.9);
//! assert_eq!(edges.len(), 1);
//! let faces = [Face { surface: &a, reversed: false }, Face { surface: &b, reversed: false }];
//! let r = measure_boundary(&faces, &edges[0], 50);
//! assert!(r.gap_closest.max < 1e-12);
//! assert!(r.g1_angle_deg.max > 0.05);
//! ```

mod adjacency;
mod area;
mod check;
mod edge;
mod error;
mod index;
mod measure;
mod refine;
mod repair;
mod seams_refine;

pub use adjacency::{closing_seams, shared_boundaries, SharedBoundary, SideRef};
pub use area::area_and_volume;
pub use check::{EdgeCheck, SeamCheck};
pub use edge::{measure_edge, measure_edge_samples, shared_curves, EdgeSample, EdgeSamples, TrimCurve, TrimEdge};
pub use error::{Error, Result};
pub use measure::{measure_boundary, EdgeEnd, EdgeReport, Face, SeamReport, Stat, SHARP_EDGE_DEG};
pub use refine::{deformed, morph_error, refine_for, refine_uniform, RefineOptions, Refinement, Scope};
pub use repair::{covers_side, make_compatible, repair, Repair};
pub use seams_refine::{refine_edges, refine_seams, RefineRound, SeamRefineOptions, SeamRefinement};
