//! Faces the model could not convert: never passed over in silence. Every command that
//! works on faces names them on standard error; `morph` (and `refine`, which also writes)
//! refuses to run unless `--skip-unsupported` is given.

use anyhow::{bail, Result};
use cadmorph::model::Skipped;

/// Prints one warning line per skipped face.
pub fn warn(skipped: &[Skipped]) {
    for s in skipped {
        eprintln!("cadmorph: warning: face {} is not converted, left out: {}", s.entity, s.reason);
    }
}

/// Fails when faces were skipped and the user did not accept it; otherwise warns.
pub fn check(skipped: &[Skipped], accept: bool) -> Result<()> {
    if skipped.is_empty() {
        return Ok(());
    }
    if !accept {
        let list: Vec<String> = skipped.iter().map(|s| format!("{} ({})", s.entity, s.reason)).collect();
        bail!(
            "{} face(s) cannot be converted, so the morph would leave them behind and open their seams: {}; \
             nothing written (--skip-unsupported morphs the others and keeps these as they are)",
            skipped.len(),
            list.join("; ")
        );
    }
    warn(skipped);
    Ok(())
}
