//! Files written whole or not at all: a temporary file beside the target, then a rename
//! (POSIX `rename(2)` is atomic within a file system), so a crash never leaves half a file
//! under the target's name. Temporary files are named `.NAME.campaign-tmp`; a killed run
//! leaves at most those, and [`remove_temporaries`] clears them on the next run.

use std::path::Path;

use crate::error::{io, Result};

const SUFFIX: &str = ".campaign-tmp";

/// Writes `bytes` to `path` through `.NAME.campaign-tmp` and a rename.
///
/// # Errors
///
/// [`Error::Io`](crate::Error::Io) with the path.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = dir.join(format!(".{name}{SUFFIX}"));
    std::fs::write(&tmp, bytes).map_err(io(&tmp))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(path)(e)
    })
}

/// Whether `name` is a temporary file of [`write_atomic`].
pub fn is_temporary(name: &str) -> bool {
    name.starts_with('.') && name.ends_with(SUFFIX)
}

/// Removes the temporary files a killed run left in `dir`; returns how many.
///
/// # Errors
///
/// [`Error::Io`](crate::Error::Io) when a file cannot be removed.
pub fn remove_temporaries(dir: &Path) -> Result<usize> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Ok(0) };
    let mut n = 0;
    for e in entries.flatten() {
        if is_temporary(&e.file_name().to_string_lossy()) {
            std::fs::remove_file(e.path()).map_err(io(e.path()))?;
            n += 1;
        }
    }
    Ok(n)
}
