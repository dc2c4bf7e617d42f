//! Propeller blades from design tables: NACA and custom profiles, sections wrapped on
//! their cylinders, lofted NURBS faces closed into a B-rep solid, B-spline radial laws
//! driven by BladeX parameter files, propellers, and the reverse (sections from a blade).
//!
//! The crate follows BladeX (mathLab/BladeX, the Python reference of the paper §2.2.2
//! and §3.1.2) number for number where BladeX defines the numbers — profiles,
//! `_planar_to_cylindrical`, `apply_transformations`, `Deformation` — and goes beyond it
//! where BladeX stops at loose faces: the upper and lower faces come from one interpolating
//! surface split at the leading edge (so the leading edge stays round and both faces share
//! it exactly), the tip and root caps are ruled between the faces' own boundary curves,
//! and the four faces are written as one closed solid through `cadmorph-step`
//! (`MANIFOLD_SOLID_BREP`) and `cadmorph-iges` (186/514/510). It knows nothing of the
//! CLI; see the `cadmorph` binary.
//!
//! ```
//! use cadmorph_blade::{naca, NacaOptions};
//! let foil = naca("2412", NacaOptions::default()).unwrap();
//! // Four-digit 2412: 12 % thick.
//! assert!((foil.max_thickness(None).unwrap() - 0.12).abs() < 1e-3);
//! ```
//!
//! What is where: profiles (`naca`, [`Profile`], [`Profile::to_curve`]), the design
//! ([`Blade`], [`DesignTable`] in TOML), placement ([`Blade::apply_transformations`]),
//! the loft ([`loft::loft`]: P&T A9.4 with centripetal parameters averaged over the
//! sections and knots by averaging, eq. 9.6/9.8), the solid ([`BladeSolid`]: volume by
//! the divergence theorem, edge gaps, seams), files ([`export`]), radial laws
//! ([`RadialLaw`], [`Deformation`], [`ParamFile`] `.prm` and TOML), [`Propeller`] (one
//! solid per blade plus a cylinder hub; see its module for why not united),
//! [`reverse`], [`export_ppg`], [`errors_txt`].
//!
//! The crate has no feature flags.

mod blade;
mod custom;
mod error;
pub mod export;
mod linalg;
pub mod loft;
mod naca;
pub mod output;
mod ppg;
mod prm;
mod profile;
mod profile_curve;
pub mod propeller;
mod radial;
mod report;
mod reverse;
mod solid;
pub mod spline1d;
mod table;
pub mod wendland;

pub use blade::{mirror, rotation, scaling, wrap, Blade, BladeCoordinates};
pub use error::{Error, Result};
pub use naca::{naca, NacaOptions, NacaSpacing};
pub use ppg::{c_exp, export_ppg};
pub use prm::{py_float, LawParam, LawSettings, ParamFile};
pub use profile::{Convention, Profile, ProfileParameters};
pub use profile_curve::ProfileCurve;
pub use propeller::{hub_cylinder, Propeller};
pub use radial::{optimum_control_points, Deformation, RadialLaw};
pub use report::errors_txt;
pub use reverse::{reverse, RecoveredSection};
pub use solid::{face_area, face_volume, ruled, BladeSolid, EdgeGap, SectionError};
pub use table::{DesignTable, LoftSpec, ProfileSpec, PropellerSpec};
