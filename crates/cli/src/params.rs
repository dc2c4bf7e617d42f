//! Morph parameter files (PyGeM `.prm` or TOML) to deformations.

use std::path::Path;

use anyhow::{bail, Context, Result};
use cadmorph::morph::{Deformation, Parameters};

/// The parameters in `path` (TOML by the `.toml` extension, else PyGeM `.prm`).
pub fn read(path: &Path) -> Result<Parameters> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let is_toml = path.extension().is_some_and(|e| e == "toml");
    let params = if is_toml { Parameters::from_toml(&text) } else { Parameters::from_prm(&text) };
    params.with_context(|| format!("reading {}", path.display()))
}

/// `ffd`, `rbf` or `idw`.
pub fn kind_of(p: &Parameters) -> &'static str {
    match p {
        Parameters::Ffd(_) => "ffd",
        Parameters::Rbf(_) => "rbf",
        Parameters::Idw(_) => "idw",
    }
}

/// The parameters of `path`, which must be of kind `expect` (`None`: any kind).
pub fn read_as(path: &Path, expect: Option<&str>) -> Result<Parameters> {
    let params = read(path)?;
    let found = kind_of(&params);
    if let Some(expect) = expect.filter(|e| *e != found) {
        bail!("{} holds {found} parameters, but --{expect} was given", path.display());
    }
    Ok(params)
}

/// The deformation of `path`, which must hold parameters of kind `expect`
/// (`None`: any kind).
pub fn deformation(path: &Path, expect: Option<&str>) -> Result<Box<dyn Deformation + Send>> {
    read_as(path, expect)?.build().with_context(|| format!("building the morph of {}", path.display()))
}

/// The FFD of `params` (read from `path`, overrides applied), for `morph --exact`, which
/// needs the lattice itself.
pub fn ffd(path: &Path, params: &Parameters) -> Result<cadmorph::morph::Ffd> {
    match params {
        Parameters::Ffd(f) => Ok(f.clone()),
        other => bail!(
            "--exact composes an FFD's Bernstein volume with the faces; {} holds {} parameters",
            path.display(),
            kind_of(other)
        ),
    }
}
