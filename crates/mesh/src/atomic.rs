//! Writing files and directories so that a failure leaves no half-written output: the
//! bytes go to a temporary sibling, which is renamed over the target once complete.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::io;
use crate::Result;

/// A temporary path beside `path` (same directory, so the rename is atomic).
fn temp_sibling(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.cadmorph-tmp{}", std::process::id()))
}

/// Write `bytes` to `path` through a temporary file and a rename.
///
/// # Errors
///
/// [`crate::Error::Io`] naming the path; the temporary file is removed on failure.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = temp_sibling(path);
    let result = (|| {
        let mut f = fs::File::create(&tmp).map_err(io(&tmp))?;
        f.write_all(bytes).map_err(io(&tmp))?;
        f.sync_all().map_err(io(&tmp))?;
        drop(f);
        fs::rename(&tmp, path).map_err(io(path))
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Write a set of files (relative path → bytes) as the directory `dir`: all of them go
/// into a temporary sibling directory first, which then replaces `dir` (an existing `dir`
/// is moved aside and removed only after the new one is in place).
///
/// # Errors
///
/// [`crate::Error::Io`] naming the path; the temporary directory is removed on failure.
pub fn write_dir_atomic(dir: &Path, files: &[(PathBuf, Vec<u8>)]) -> Result<()> {
    let tmp = temp_sibling(dir);
    let _ = fs::remove_dir_all(&tmp);
    let result = (|| {
        for (rel, bytes) in files {
            let p = tmp.join(rel);
            if let Some(parent) = p.parent() {
                fs::create_dir_all(parent).map_err(io(parent))?;
            }
            fs::write(&p, bytes).map_err(io(&p))?;
        }
        if dir.exists() {
            let old = dir.with_file_name(format!(
                ".{}.cadmorph-old{}",
                dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default(),
                std::process::id()
            ));
            fs::rename(dir, &old).map_err(io(dir))?;
            if let Err(e) = fs::rename(&tmp, dir) {
                let _ = fs::rename(&old, dir);
                return Err(io(dir)(e));
            }
            fs::remove_dir_all(&old).map_err(io(&old))?;
            Ok(())
        } else {
            if let Some(parent) = dir.parent() {
                if !parent.as_os_str().is_empty() {
                    fs::create_dir_all(parent).map_err(io(parent))?;
                }
            }
            fs::rename(&tmp, dir).map_err(io(dir))
        }
    })();
    if result.is_err() {
        let _ = fs::remove_dir_all(&tmp);
    }
    result
}
