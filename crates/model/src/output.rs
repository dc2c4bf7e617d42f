//! Writing output files so that a failed run never damages anything: the bytes go to a
//! temporary file beside the target and replace it by a rename, in two steps
//! ([`Staged::new`] then [`Staged::commit`]) so that a program writing several files (a
//! morphed model and its report) can have all of them ready before any is replaced.
//!
//! What a target may be:
//! - a new path in an existing folder, or an existing regular file, whose permissions the
//!   new file keeps;
//! - a symbolic link, followed on purpose: the file it points to is replaced and the link
//!   stays a link;
//! - not a directory, a device (`/dev/null` is never replaced by a regular file), a FIFO
//!   or a socket: those are refused before anything is written.
//!
//! A staged file that is dropped without being committed (an error on the way, or a
//! failed write: disk full, file too large) is removed. Writing the output over the input
//! is safe: the input is replaced only by the complete new file, at once.

use std::fs::{self, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::{Error, Result};

/// A file written in full beside its target, waiting to replace it.
#[derive(Debug)]
pub struct Staged {
    tmp: PathBuf,
    target: PathBuf,
    /// The path as the caller gave it (for messages).
    path: PathBuf,
    committed: bool,
}

/// Distinct temporary names for several files staged by one process.
static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// The file `path` finally names: the end of its chain of symbolic links (at most 40, as
/// Linux allows), or `path` itself.
fn resolve(path: &Path) -> std::io::Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = fs::read_link(&p)?;
                p = if link.is_absolute() { link } else { p.parent().unwrap_or(Path::new(".")).join(link) };
            }
            _ => return Ok(p),
        }
    }
    Err(std::io::Error::other("too many levels of symbolic links"))
}

impl Staged {
    /// Writes `bytes` to a temporary file beside the file `path` names.
    ///
    /// # Errors
    ///
    /// [`Error::NotAFile`] when `path` is a directory, device, FIFO or socket;
    /// [`Error::Write`] when the temporary file cannot be made or written (it is removed).
    pub fn new(path: &Path, bytes: &[u8]) -> Result<Staged> {
        let err = |source| Error::Write { path: path.to_owned(), source };
        let target = resolve(path).map_err(err)?;
        let existing = match fs::metadata(&target) {
            Ok(m) if m.is_file() => Some(m),
            Ok(m) => {
                let kind = if m.is_dir() { "a directory" } else { "not a regular file (a device, FIFO or socket)" };
                return Err(Error::NotAFile { path: path.to_owned(), kind });
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(e) => return Err(err(e)),
        };
        let dir = target.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        let name = target.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = dir.join(format!(".{name}.{}.{n}.tmp", std::process::id()));
        let mut staged = Staged { tmp, target, path: path.to_owned(), committed: false };
        let mut file = OpenOptions::new().write(true).create_new(true).open(&staged.tmp).map_err(|e| {
            // Nothing was created: nothing to remove.
            staged.committed = true;
            err(e)
        })?;
        file.write_all(bytes).and_then(|()| file.flush()).map_err(err)?;
        if let Some(m) = existing {
            file.set_permissions(m.permissions()).map_err(err)?;
        }
        Ok(staged)
    }

    /// Replaces the target with the staged file.
    ///
    /// # Errors
    ///
    /// [`Error::Write`] when the rename fails (the staged file is removed).
    pub fn commit(mut self) -> Result<()> {
        fs::rename(&self.tmp, &self.target).map_err(|source| Error::Write { path: self.path.clone(), source })?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed {
            let _ = fs::remove_file(&self.tmp);
        }
    }
}

/// Writes `bytes` to `path` through a temporary file in the same folder and a rename, so a
/// failure never leaves half a file ([`Staged`] says what a target may be).
///
/// # Errors
///
/// As [`Staged::new`] and [`Staged::commit`].
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    Staged::new(path, bytes)?.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("cadmorph-output-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    fn leftovers(d: &Path) -> Vec<String> {
        fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp"))
            .collect()
    }

    #[test]
    fn devices_and_directories_are_refused() {
        let d = scratch("kinds");
        assert!(matches!(write_atomic(Path::new("/dev/null"), b"x"), Err(Error::NotAFile { .. })));
        assert!(std::os::unix::fs::FileTypeExt::is_char_device(&fs::metadata("/dev/null").unwrap().file_type()));
        assert!(matches!(write_atomic(&d, b"x"), Err(Error::NotAFile { kind: "a directory", .. })));
        assert!(leftovers(&d).is_empty());
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn links_are_followed_and_permissions_kept() {
        use std::os::unix::fs::{symlink, PermissionsExt};
        let d = scratch("links");
        let real = d.join("real.igs");
        fs::write(&real, b"old").unwrap();
        fs::set_permissions(&real, fs::Permissions::from_mode(0o640)).unwrap();
        let link = d.join("link.igs");
        symlink("real.igs", &link).unwrap();
        write_atomic(&link, b"new").unwrap();
        assert!(fs::symlink_metadata(&link).unwrap().file_type().is_symlink(), "the link stays a link");
        assert_eq!(fs::read(&real).unwrap(), b"new");
        assert_eq!(fs::metadata(&real).unwrap().permissions().mode() & 0o777, 0o640);
        assert!(leftovers(&d).is_empty());
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn an_uncommitted_file_leaves_nothing_and_the_target_untouched() {
        let d = scratch("drop");
        let out = d.join("out.stp");
        fs::write(&out, b"before").unwrap();
        let staged = Staged::new(&out, b"after").unwrap();
        assert_eq!(leftovers(&d).len(), 1);
        drop(staged);
        assert!(leftovers(&d).is_empty());
        assert_eq!(fs::read(&out).unwrap(), b"before");
        // A folder that does not exist: nothing is made.
        assert!(matches!(write_atomic(&d.join("no/such/out.stp"), b"x"), Err(Error::Write { .. })));
        fs::remove_dir_all(&d).unwrap();
    }
}
