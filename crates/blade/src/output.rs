//! Writing files safely: to a temporary file beside the target, then renamed, so a
//! failed run never leaves half a file.

use std::path::Path;

use crate::{Error, Result};

/// Writes `bytes` to `path` through `path.tmp-<pid>` and a rename.
///
/// # Errors
///
/// [`Error::Io`] naming the path.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    let io = |e| Error::Io { path: path.display().to_string(), source: e };
    std::fs::write(&tmp, bytes).map_err(io)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(e)
    })
}
