//! Deformations of point sets for shape parameterisation: free-form deformation (FFD),
//! radial basis functions (RBF), inverse distance weighting (IDW), affine maps and their
//! compositions, with PyGeM's parameter files.
//!
//! This crate owns the general-purpose morphs of the paper (§2.1, eq. (1)–(10)) and the
//! [`Deformation`] trait the rest of cadmorph uses to move points. It sees points only: it
//! knows nothing of NURBS (`cadmorph-nurbs`), CAD files (`cadmorph-iges`, `cadmorph-step`)
//! or file systems. Parameter files are read from and written to strings ([`prm`] for
//! PyGeM's `.prm` format, [`Parameters`] for TOML).
//!
//! Results equal PyGeM's (GitHub mathLab/PyGeM) on the same inputs to 1e-10 or better;
//! where PyGeM's behaviour is a bug (face points left behind by FFD, silently wrong
//! ill-conditioned RBF systems), this crate differs on purpose and says so.
//!
//! ```
//! use cadmorph_morph::{prm, Deformation, Ffd, LinearInParameters};
//! use cadmorph_morph::math::Point3;
//!
//! // A 3×2×2 lattice on the unit cube; push the middle nodes up by a fifth of the box.
//! let mut ffd = Ffd::unit([3, 2, 2]);
//! for j in 0..2 {
//!     for k in 0..2 {
//!         ffd.mu_mut().set(1, j, k, [0.0, 0.0, 0.2]);
//!     }
//! }
//! let mut pts = vec![Point3::new(0.5, 0.5, 0.5), Point3::new(0.0, 0.3, 0.3), Point3::new(4.0, 0.0, 0.0)];
//! ffd.deform(&mut pts);
//! assert!((pts[0].z - 0.6).abs() < 1e-15);       // b₁(½) = ½ of the 0.2 lift
//! assert_eq!(pts[1], Point3::new(0.0, 0.3, 0.3)); // the x = 0 face nodes did not move
//! assert_eq!(pts[2], Point3::new(4.0, 0.0, 0.0)); // outside the box
//!
//! // The same parameters as a PyGeM .prm file, and the Jacobian for an optimiser.
//! let text = ffd.to_prm();
//! assert_eq!(Ffd::from_prm(&text)?, ffd);
//! assert_eq!(ffd.param_jacobian(&Point3::new(0.5, 0.5, 0.5)).shape(), (3, 36));
//! # Ok::<(), cadmorph_morph::Error>(())
//! ```
//!
//! # Feature flags
//!
//! None. Large point sets are deformed in parallel with rayon; the inner loops are compiled
//! for AVX2/FMA at run time when the CPU has them (through `pulp`, without `unsafe` here).
//!
//! # Threads
//!
//! The crate uses rayon's global pool and leaves its set-up to the program. A morph of 10⁶
//! points by FFD takes a few milliseconds, and on small VMs the scheduler may put the
//! workers a sleeping main thread wakes on one CPU for that long (one run in three took
//! single-core time on the 2-vCPU bench machine). A program that morphs from its main
//! thread avoids that by making it worker 0, as the `cadmorph` CLI does:
//!
//! ```
//! // At start-up, before any parallel work (an existing pool is kept).
//! let _ = rayon::ThreadPoolBuilder::new().use_current_thread().build_global();
//! ```

pub mod affine;
pub mod budget;
pub mod cffd;
pub mod constrained;
mod deformation;
mod error;
pub mod ffd;
mod from_fn;
pub mod idw;
pub mod params;
pub mod prm;
pub mod rbf;
mod simd;

pub use affine::Affine;
pub use deformation::{
    checked_by_chunks, first_non_finite, for_each_chunk, ChunkHook, Deformation, LinearInParameters, ParamWeights,
    Then, PARALLEL_CHUNK, PARALLEL_MIN_POINTS,
};
pub use error::{Error, Result};
pub use ffd::{BoundFfd, Displacements, Ffd};
pub use from_fn::{from_fn, FromFn};
pub use idw::{Idw, IdwParameters, IdwVariant};
pub use params::Parameters;
pub use rbf::{Rbf, RbfParameters};

/// The vocabulary types, from nalgebra.
pub mod math {
    pub use nalgebra::{DMatrix, DVector, Matrix3, Point3, Vector3};
}
