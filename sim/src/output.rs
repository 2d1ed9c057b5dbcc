//! Output files that appear whole or not at all.

use std::fs::File;
use std::path::{Path, PathBuf};

use crate::error::{Result, SimError};

/// Creates directory `dir` and its parents (an existing one is fine).
pub fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| SimError::Output {
        path: dir.to_path_buf(),
        source,
    })
}

/// A file being written under a temporary name next to its destination. It
/// is renamed into place by [`PendingFile::commit`]; dropped uncommitted (an
/// error, a panic, Ctrl-C unwinding), the temporary is removed, so a failed
/// run never leaves a partial file behind.
#[derive(Debug)]
pub struct PendingFile {
    dest: PathBuf,
    temp: PathBuf,
    committed: bool,
}

impl PendingFile {
    /// Reserves `dest`: creates the temporary file now, so that an unwritable
    /// destination is reported before any long computation.
    pub fn create(dest: impl AsRef<Path>) -> Result<(Self, File)> {
        let dest = dest.as_ref().to_path_buf();
        let fail = |source| SimError::Output {
            path: dest.clone(),
            source,
        };
        let name = dest.file_name().ok_or_else(|| {
            fail(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "the path names a directory, not a file",
            ))
        })?;
        if dest.is_dir() {
            return Err(fail(std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                "the path is a directory",
            )));
        }
        let mut temp_name = std::ffi::OsString::from(".");
        temp_name.push(name);
        temp_name.push(format!(".partial-{}", std::process::id()));
        let temp = dest.with_file_name(temp_name);
        let file = File::create(&temp).map_err(fail)?;
        Ok((
            Self {
                dest,
                temp,
                committed: false,
            },
            file,
        ))
    }

    /// Where the data goes while it is written.
    pub fn temp_path(&self) -> &Path {
        &self.temp
    }

    /// The final path.
    pub fn path(&self) -> &Path {
        &self.dest
    }

    /// Moves the finished file into place.
    pub fn commit(mut self) -> Result<PathBuf> {
        std::fs::rename(&self.temp, &self.dest).map_err(|source| SimError::Output {
            path: self.dest.clone(),
            source,
        })?;
        self.committed = true;
        Ok(self.dest.clone())
    }
}

impl Drop for PendingFile {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.temp);
        }
    }
}

/// Writes `bytes` to `path` through a temporary file renamed into place.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    let (pending, mut file) = PendingFile::create(path)?;
    file.write_all(bytes)
        .and_then(|()| file.sync_all())
        .map_err(|source| SimError::Output {
            path: path.to_path_buf(),
            source,
        })?;
    pending.commit()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    #[test]
    fn committed_files_appear_and_dropped_ones_vanish() {
        let dir = std::env::temp_dir().join(format!("errp-pending-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (p, mut f) = PendingFile::create(dir.join("a.txt")).unwrap();
        f.write_all(b"hello").unwrap();
        assert!(!dir.join("a.txt").exists());
        p.commit().unwrap();
        assert_eq!(std::fs::read(dir.join("a.txt")).unwrap(), b"hello");

        let (p, _f) = PendingFile::create(dir.join("b.txt")).unwrap();
        let temp = p.temp_path().to_path_buf();
        assert!(temp.exists());
        drop(p);
        assert!(!temp.exists() && !dir.join("b.txt").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn unwritable_destination_fails_early_naming_the_path() {
        let err = PendingFile::create("/nonexistent-dir/x.rrd").unwrap_err();
        assert!(err.to_string().contains("/nonexistent-dir/x.rrd"), "{err}");
    }
}
