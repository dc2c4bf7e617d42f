//! Files written whole or not at all: a temporary file beside the target, then a rename
//! (POSIX `rename(2)` is atomic within a file system), so a crash never leaves half a file
//! under the target's name. Temporary files are named `.NAME.PID-N.campaign-tmp`, one per
//! writer (the shards of a Slurm array all write the same manifest at once: a shared
//! temporary name let one shard's rename take another's file); a killed run leaves at most
//! those, and [`remove_temporaries`] clears them on the next run.

use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{io, Result};

const SUFFIX: &str = ".campaign-tmp";

/// Writes of this process so far, for unique temporary names.
static WRITES: AtomicU64 = AtomicU64::new(0);

/// Writes `bytes` to `path` through `.NAME.PID-N.campaign-tmp` (unique to this write) and a
/// rename.
///
/// # Errors
///
/// [`Error::Io`](crate::Error::Io) with the path.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let n = WRITES.fetch_add(1, Ordering::Relaxed);
    let tmp = dir.join(format!(".{name}.{}-{n}{SUFFIX}", std::process::id()));
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Many writers of one file at once (as the shards of a Slurm array write the manifest):
    /// every write succeeds, the file is one writer's whole content, no temporary is left.
    #[test]
    fn concurrent_writers_of_one_file_all_succeed() {
        let dir = std::env::temp_dir().join(format!("cadmorph-fsutil-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("manifest.json");
        let contents: Vec<String> = (0..8).map(|i| format!("writer {i}\n").repeat(4096)).collect();
        std::thread::scope(|s| {
            for c in &contents {
                let path = &path;
                s.spawn(move || {
                    for _ in 0..50 {
                        write_atomic(path, c.as_bytes()).unwrap();
                    }
                });
            }
        });
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(contents.contains(&text), "the file mixes writers");
        assert_eq!(remove_temporaries(&dir).unwrap(), 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
