//! Design-of-experiments campaigns over cadmorph's morphs (issue 16; the paper's
//! campaigns of §3.1.2: 130 DTMB-5415 hulls by FFD, then active subspaces over the
//! results): a design space ([`DesignSpace`], `campaign.toml`), seeded samplers
//! ([`sampler`]), a reproducible manifest ([`Manifest`]), idempotent and resumable runs
//! sharded by hand or by a Slurm job array ([`run()`], [`Shard`], [`slurm`]), one table of
//! the results ([`collect()`], CSV and [`parquet`]), exact sensitivities ([`sensitivity`]) and active subspaces
//! ([`active`]).
//!
//! The paper's offline/online split is used (§2.1.1): the deformation's basis at the
//! base geometry's control points is built once per process, and each variant's control
//! points are one matrix product ([`online`]).
//!
//! This crate drives the `cadmorph` facade (open, morph, convert, save); it schedules
//! nothing itself: one machine runs the variants of a share in parallel with rayon, and
//! many machines run shares as Slurm array tasks.
//!
//! ```
//! use cadmorph_campaign::{DesignSpace, Manifest};
//! # let dir = std::env::temp_dir().join(format!("campaign-doc-{}", std::process::id()));
//! # std::fs::create_dir_all(&dir)?;
//! # let samples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples");
//! # let samples = samples.display();
//! let toml = format!(r#"
//! [base]
//! geometry = "{samples}/hull3.igs"
//! [deformation]
//! ffd = "{samples}/prm/bow_dome.prm"
//! [sampling]
//! method = "lhs"
//! n = 8
//! seed = 1
//! [[parameter]]
//! name = "dome"
//! entry = "mu_y[1,1,1]"
//! range = [0.0, 0.08]
//! "#);
//! # let path = dir.join("c.toml");
//! # std::fs::write(&path, &toml)?;
//! let space = DesignSpace::parse(&path, &toml)?;
//! let plan = Manifest::plan(&space);
//! assert_eq!(plan.variants.len(), 8);
//! // Latin hypercube: each eighth of the range holds one value.
//! let mut strata: Vec<usize> = plan.variants.iter().map(|v| (v.values[0] / 0.01) as usize).collect();
//! strata.sort();
//! assert_eq!(strata, (0..8).collect::<Vec<_>>());
//! assert_eq!(Manifest::plan(&space).to_csv(), plan.to_csv()); // the same seed, the same bytes
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod active;
pub mod collect;
pub mod entry;
mod error;
pub mod fsutil;
pub mod manifest;
pub mod online;
pub mod parquet;
pub mod report;
pub mod run;
pub mod sampler;
pub mod sensitivity;
pub mod shard;
pub mod slurm;
pub mod space;

pub use collect::{collect, status, table, State, Status, Table};
pub use entry::Entry;
pub use error::{Error, Result};
pub use manifest::{Manifest, Variant};
pub use report::Report;
pub use run::{run, Prepared, RunSummary};
pub use shard::Shard;
pub use space::{DesignSpace, Parameter, Values};
