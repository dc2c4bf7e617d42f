//! The plan as a manifest: `manifest.csv` and `manifest.json` (variant id, parameter
//! values, seed, content hash of the inputs), byte for byte the same for the same
//! campaign and seed.

use std::fmt::Write as _;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::space::{sha256_hex, DesignSpace, Values};

/// One variant of the plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Variant {
    /// Its id and folder name (`v0007`).
    pub id: String,
    /// Its position in the plan.
    pub index: usize,
    /// The parameter values, in the campaign's parameter order.
    pub values: Vec<f64>,
    /// SHA-256 of the campaign inputs ([`DesignSpace::hash`]) and these values: what the
    /// variant's outputs depend on.
    pub input_sha256: String,
}

/// The whole plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`DesignSpace::hash`] of the campaign it was planned from.
    pub campaign_sha256: String,
    /// The sampling method, as planned.
    pub method: String,
    /// The seed.
    pub seed: u64,
    /// Parameter names, in column order.
    pub parameters: Vec<String>,
    /// Their entries (`mu_y[1,1,1]`).
    pub entries: Vec<String>,
    /// Their ranges or sets, as text.
    pub values: Vec<String>,
    /// The variants.
    pub variants: Vec<Variant>,
}

/// A float as Rust's shortest round-trip text (`{:?}`): the same bits always print the
/// same, and read back to the same bits.
pub(crate) fn num(x: f64) -> String {
    format!("{x:?}")
}

impl Manifest {
    /// Plans `space`: its sampler's points, one variant each.
    pub fn plan(space: &DesignSpace) -> Manifest {
        let rows = crate::sampler::plan(&space.method, &space.parameters, space.seed);
        let width = rows.len().saturating_sub(1).to_string().len().max(4);
        let variants = rows
            .into_iter()
            .enumerate()
            .map(|(index, values)| {
                let mut key = space.hash.clone();
                for v in &values {
                    key.push(',');
                    key.push_str(&num(*v));
                }
                Variant { id: format!("v{index:0width$}"), index, input_sha256: sha256_hex(key.as_bytes()), values }
            })
            .collect();
        Manifest {
            campaign_sha256: space.hash.clone(),
            method: format!("{:?}", space.method),
            seed: space.seed,
            parameters: space.parameters.iter().map(|p| p.name.clone()).collect(),
            entries: space.parameters.iter().map(|p| p.entry.to_string()).collect(),
            values: space
                .parameters
                .iter()
                .map(|p| match &p.values {
                    Values::Range { lo, hi } => format!("range [{}, {}]", num(*lo), num(*hi)),
                    Values::Set(v) => format!("set [{}]", v.iter().map(|x| num(*x)).collect::<Vec<_>>().join(", ")),
                })
                .collect(),
            variants,
        }
    }

    /// The CSV form: `id,<parameter names>,seed,input_sha256`, one row per variant.
    pub fn to_csv(&self) -> String {
        let mut s = String::from("id");
        for p in &self.parameters {
            s.push(',');
            s.push_str(p);
        }
        s.push_str(",seed,input_sha256\n");
        for v in &self.variants {
            s.push_str(&v.id);
            for x in &v.values {
                let _ = write!(s, ",{}", num(*x));
            }
            let _ = writeln!(s, ",{},{}", self.seed, v.input_sha256);
        }
        s
    }

    /// The JSON form (pretty, keys in a fixed order).
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).expect("plain data serialises");
        s.push('\n');
        s
    }

    /// Writes `manifest.csv` and `manifest.json` into `dir` (each through a temporary file
    /// and a rename). An existing manifest planned from other inputs is refused.
    ///
    /// # Errors
    ///
    /// [`Error::StaleManifest`]; [`Error::Io`].
    pub fn write(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(crate::error::io(dir))?;
        let json = dir.join("manifest.json");
        if let Ok(text) = std::fs::read_to_string(&json) {
            if let Ok(old) = serde_json::from_str::<Manifest>(&text) {
                if old.campaign_sha256 != self.campaign_sha256 {
                    return Err(Error::StaleManifest {
                        path: json,
                        expected: self.campaign_sha256.clone(),
                        found: old.campaign_sha256,
                    });
                }
            }
        }
        crate::fsutil::write_atomic(&dir.join("manifest.csv"), self.to_csv().as_bytes())?;
        crate::fsutil::write_atomic(&json, self.to_json().as_bytes())
    }
}
