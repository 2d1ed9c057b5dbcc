//! Output files that appear whole or not at all, and what is removed when
//! the program is interrupted.
//!
//! A file is written under a temporary name beside its destination
//! (`.NAME.partial-HOST-PID-RANDOM`, created exclusively: unique across the
//! hosts that share a network directory) and renamed into place when
//! complete. Temporaries are removed when dropped, by
//! [`remove_unfinished`] (the command line calls it on Ctrl-C or SIGTERM),
//! and, when a process died without either (SIGKILL, out of memory), by
//! the next [`PendingFile::create`] in the same directory on the same host.

use std::collections::BTreeSet;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::{Result, SimError};
use crate::host::{host_name, process_gone, random_suffix};

/// Files this process removes if it is interrupted: temporaries being
/// written, locks it holds.
static UNFINISHED: Mutex<BTreeSet<PathBuf>> = Mutex::new(BTreeSet::new());

fn unfinished() -> std::sync::MutexGuard<'static, BTreeSet<PathBuf>> {
    // A panic elsewhere while the set was held leaves it usable.
    UNFINISHED.lock().unwrap_or_else(|e| e.into_inner())
}

/// Registers `path` to be removed by [`remove_unfinished`] (a directory
/// only if it is empty by then).
pub fn remove_if_interrupted(path: &Path) {
    unfinished().insert(path.to_path_buf());
}

/// Takes `path` off the list of [`remove_if_interrupted`].
pub fn forget_if_interrupted(path: &Path) {
    unfinished().remove(path);
}

/// Removes every registered temporary and lock of this process (and a
/// registered directory, if that leaves it empty), and returns how many
/// were there. For a signal handler, just before the process exits: what
/// was being written would otherwise stay behind.
pub fn remove_unfinished() -> usize {
    let mut set = unfinished();
    let n = set.len();
    // Children sort after their parents: removed first.
    for path in std::mem::take(&mut *set).into_iter().rev() {
        if std::fs::remove_file(&path).is_err() {
            let _ = std::fs::remove_dir(&path);
        }
    }
    n
}

/// Directories made by [`create_dirs`], outermost first: what to remove
/// to leave the file system as it was.
#[derive(Debug, Default)]
pub struct CreatedDirs(Vec<PathBuf>);

impl CreatedDirs {
    /// True if the directory existed already.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Has [`remove_unfinished`] remove them (each only if empty by then).
    pub fn remove_if_interrupted(&self) {
        for d in &self.0 {
            remove_if_interrupted(d);
        }
    }

    /// Takes them off [`remove_unfinished`]'s list.
    pub fn forget_if_interrupted(&self) {
        for d in &self.0 {
            forget_if_interrupted(d);
        }
    }

    /// Removes them, and what the innermost holds: the work failed.
    pub fn remove(&self) {
        if let Some(inner) = self.0.last() {
            let _ = std::fs::remove_dir_all(inner);
        }
        for d in self.0.iter().rev().skip(1) {
            let _ = std::fs::remove_dir(d);
        }
        self.forget_if_interrupted();
    }
}

/// Creates directory `dir` and its missing parents, and returns those it
/// made (none if `dir` existed), so that a run that fails or is
/// interrupted can remove every one of them.
pub fn create_dirs(dir: &Path) -> Result<CreatedDirs> {
    let fail = |source| SimError::Output {
        path: dir.to_path_buf(),
        source,
    };
    let mut missing = Vec::new();
    let mut at = Some(dir);
    while let Some(d) = at.filter(|d| !d.as_os_str().is_empty()) {
        match std::fs::symlink_metadata(d) {
            Ok(_) => break,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => missing.push(d.to_path_buf()),
            Err(e) => return Err(fail(e)),
        }
        at = d.parent();
    }
    missing.reverse();
    let mut made = CreatedDirs::default();
    for d in missing {
        match std::fs::create_dir(&d) {
            Ok(()) => made.0.push(d),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && d.is_dir() => {}
            Err(e) => {
                made.remove();
                return Err(fail(e));
            }
        }
    }
    if !dir.is_dir() {
        made.remove();
        return Err(fail(std::io::Error::new(
            std::io::ErrorKind::NotADirectory,
            "it exists and is not a directory",
        )));
    }
    Ok(made)
}

/// Creates directory `dir` and its parents (an existing one is fine).
pub fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| SimError::Output {
        path: dir.to_path_buf(),
        source,
    })
}

/// The longest file name most file systems take (NAME_MAX), in bytes.
const NAME_MAX: usize = 255;

/// The temporary's name for `name`: `.NAME.partial-HOST-PID-RANDOM`, with
/// NAME shortened (at a character boundary) so that the whole fits in
/// [`NAME_MAX`] bytes whenever it can: a destination whose own name is
/// near that limit can still be written.
fn partial_name(name: &std::ffi::OsStr, host: &str, random: u64) -> String {
    let tail = format!(".partial-{host}-{}-{random:016x}", std::process::id());
    let name = name.to_string_lossy();
    let room = NAME_MAX.saturating_sub(1 + tail.len());
    let cut = (0..=room.min(name.len()))
        .rev()
        .find(|&i| name.is_char_boundary(i))
        .unwrap_or(0);
    format!(".{}{tail}", &name[..cut])
}

/// A temporary's name `.NAME.partial-HOST-PID-RANDOM` as (`.NAME`, HOST,
/// PID); `None` for any other name. The host may hold dashes itself.
fn parse_partial(name: &str) -> Option<(&str, &str, u32)> {
    let (prefix, rest) = name
        .starts_with('.')
        .then(|| name.split_once(".partial-"))??;
    let mut parts = rest.rsplitn(3, '-');
    let (random, pid, owner) = (parts.next()?, parts.next()?, parts.next()?);
    let random_ok = random.len() == 16 && random.bytes().all(|b| b.is_ascii_hexdigit());
    Some((prefix, owner, pid.parse().ok().filter(|_| random_ok)?))
}

/// Removes the temporaries in `dest`'s directory (of any file) left by
/// processes of this host that are gone (killed, or out of memory). Those
/// of other hosts, whose processes cannot be seen from here, and of live
/// processes are left alone.
fn remove_stale_partials(dest: &Path) {
    let dir = match dest.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let host = host_name();
    for entry in entries.flatten().take(100_000) {
        let file = entry.file_name();
        if let Some((_, owner, pid)) = file.to_str().and_then(parse_partial)
            && owner == host
            && process_gone(pid, None)
        {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// The process of this host (this one included) that writes the same file
/// as our temporary `temp` under another temporary of its own, if any:
/// two writers of one path would have the last one win, silently. Those of
/// other hosts cannot be seen to be alive and are left alone.
fn other_writer(temp: &Path, host: &str) -> Option<u32> {
    let ours = temp.file_name()?.to_str()?;
    let (prefix, _) = ours.split_once(".partial-")?;
    let dir = match temp.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::read_dir(dir)
        .ok()?
        .flatten()
        .take(100_000)
        .find_map(|entry| {
            let file = entry.file_name();
            let name = file.to_str().filter(|&n| n != ours)?;
            let (p, owner, pid) = parse_partial(name)?;
            (p == prefix && owner == host && !process_gone(pid, None)).then_some(pid)
        })
}

/// A file being written under a temporary name next to its destination. It
/// is renamed into place by [`PendingFile::commit`]; dropped uncommitted (an
/// error, a panic, Ctrl-C unwinding), the temporary is removed, so a failed
/// run never leaves a partial file behind.
///
/// A destination that is a symbolic link is written through: the file it
/// points to is replaced and the link stays.
#[derive(Debug)]
pub struct PendingFile {
    /// The path as given (for messages).
    dest: PathBuf,
    /// Where the file goes: `dest`, or the file its link points to.
    target: PathBuf,
    temp: PathBuf,
    committed: bool,
}

/// The file `dest` names, through a symbolic link (resolved in full) if
/// it is one; a link to nothing is an error.
fn link_target(dest: &Path) -> std::io::Result<PathBuf> {
    match std::fs::symlink_metadata(dest) {
        Ok(m) if m.file_type().is_symlink() => std::fs::canonicalize(dest).map_err(|e| {
            std::io::Error::new(
                e.kind(),
                format!("it is a symbolic link to a file that cannot be reached ({e})"),
            )
        }),
        _ => Ok(dest.to_path_buf()),
    }
}

/// Checks that the existing `target` may be replaced by this process
/// before any work: a regular file it can write (not a directory, FIFO or
/// device, not read-only, immutable or another user's in a sticky
/// directory).
fn check_replaceable(target: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(target) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
        Ok(m) if m.is_dir() => Err(std::io::Error::new(
            std::io::ErrorKind::IsADirectory,
            "the path is a directory",
        )),
        Ok(_) => crate::files::write_regular(target).map(drop),
    }
}

impl PendingFile {
    /// Reserves `dest`: creates the temporary file now, and checks that an
    /// existing `dest` can be replaced, so that an unwritable destination
    /// is reported before any long computation. Temporaries in `dest`'s
    /// directory left by dead processes of this host are removed first.
    pub fn create(dest: impl AsRef<Path>) -> Result<(Self, File)> {
        let given = dest.as_ref().to_path_buf();
        let fail = |source| SimError::Output {
            path: given.clone(),
            source,
        };
        if given.as_os_str().as_encoded_bytes().ends_with(b"/") {
            return Err(fail(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "the path ends in /, so it names a directory, not a file",
            )));
        }
        let dest = link_target(&given).map_err(fail)?;
        let name = dest.file_name().ok_or_else(|| {
            fail(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "the path names a directory, not a file",
            ))
        })?;
        check_replaceable(&dest).map_err(fail)?;
        remove_stale_partials(&dest);
        let host = host_name();
        let mut tries = 0;
        let (temp, file) = loop {
            let temp = dest.with_file_name(partial_name(name, &host, random_suffix()));
            match File::options().write(true).create_new(true).open(&temp) {
                Ok(file) => break (temp, file),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && tries < 8 => {
                    tries += 1;
                }
                Err(e) => return Err(fail(e)),
            }
        };
        remove_if_interrupted(&temp);
        Ok((
            Self {
                dest: given,
                target: dest,
                temp,
                committed: false,
            },
            file,
        ))
    }

    /// As [`PendingFile::create`], for an output that one writer at a time
    /// may hold (a recording): refused, naming the path, while another
    /// writer of this host (this process included) is writing the same
    /// file, where two would silently have the last one win.
    pub fn create_exclusive(dest: impl AsRef<Path>) -> Result<(Self, File)> {
        let (pending, file) = Self::create(dest)?;
        if let Some(pid) = other_writer(&pending.temp, &host_name()) {
            return Err(SimError::Output {
                path: pending.dest.clone(),
                source: std::io::Error::new(
                    std::io::ErrorKind::AlreadyExists,
                    if pid == std::process::id() {
                        "this process is writing the same file already (another recording or \
                         environment with this path): give each its own path"
                            .to_string()
                    } else {
                        format!(
                            "process {pid} is writing the same file now: wait for it to finish, \
                             or give another path"
                        )
                    },
                ),
            });
        }
        Ok((pending, file))
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
        std::fs::rename(&self.temp, &self.target).map_err(|source| SimError::Output {
            path: self.dest.clone(),
            source,
        })?;
        forget_if_interrupted(&self.temp);
        self.committed = true;
        Ok(self.dest.clone())
    }
}

impl Drop for PendingFile {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.temp);
            forget_if_interrupted(&self.temp);
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

    /// A destination whose name is 255 bytes long can be written: its
    /// temporary's name is shortened to fit (it was ~35 bytes over).
    #[test]
    fn a_name_at_the_file_system_limit_is_written() {
        let dir = std::env::temp_dir().join(format!("errp-name-max-{:x}", random_suffix()));
        create_dir(&dir).unwrap();
        for name in ["x".repeat(255), format!("{}.rrd", "é".repeat(125))] {
            let dest = dir.join(&name);
            write_atomic(&dest, b"whole").unwrap();
            assert_eq!(
                std::fs::read(&dest).unwrap(),
                b"whole",
                "{} bytes",
                name.len()
            );
            let temp = partial_name(std::ffi::OsStr::new(&name), &host_name(), 7);
            assert!(
                temp.len() <= NAME_MAX && temp.contains(".partial-"),
                "{temp}"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

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
    fn a_dead_processs_temporary_is_removed_and_the_others_are_kept() {
        let dir = std::env::temp_dir().join(format!("errp-stale-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let host = host_name();
        // Pids above the kernel's pid_max (at most 2^22) run nothing.
        let r = "0123456789abcdef";
        let dead = dir.join(format!(".a.txt.partial-{host}-9999999-{r}"));
        let dead_other_file = dir.join(format!(".b.rrd.partial-{host}-9999999-{r}"));
        let live = dir.join(format!(".a.txt.partial-{host}-{}-{r}", std::process::id()));
        let elsewhere = dir.join(format!(".a.txt.partial-another-host-9999999-{r}"));
        let not_ours = dir.join(".a.txt.partial-notes");
        for p in [&dead, &dead_other_file, &live, &elsewhere, &not_ours] {
            std::fs::write(p, b"partial").unwrap();
        }
        write_atomic(&dir.join("a.txt"), b"whole").unwrap();
        assert!(!dead.exists() && !dead_other_file.exists());
        assert!(live.exists() && elsewhere.exists() && not_ours.exists());
        assert_eq!(std::fs::read(dir.join("a.txt")).unwrap(), b"whole");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_exclusive_output_refuses_a_second_writer_while_the_first_writes() {
        let dir = std::env::temp_dir().join(format!("errp-exclusive-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (first, _f) = PendingFile::create_exclusive(dir.join("r.rrd")).unwrap();
        let e = PendingFile::create_exclusive(dir.join("r.rrd"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("r.rrd") && e.contains("writing the same file"),
            "{e}"
        );
        // The refused one left nothing; the first still writes, then commits.
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        first.commit().unwrap();
        let (again, _g) = PendingFile::create_exclusive(dir.join("r.rrd")).unwrap();
        drop(again);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn temporaries_are_named_by_host_and_process() {
        let dir = std::env::temp_dir().join(format!("errp-names-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (a, _fa) = PendingFile::create(dir.join("x.csv")).unwrap();
        let (b, _fb) = PendingFile::create(dir.join("x.csv")).unwrap();
        let name = a
            .temp_path()
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let want = format!(".x.csv.partial-{}-{}-", host_name(), std::process::id());
        assert!(name.starts_with(&want), "{name}");
        assert_ne!(a.temp_path(), b.temp_path());
        drop((a, b));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn unwritable_destination_fails_early_naming_the_path() {
        let err = PendingFile::create("/nonexistent-dir/x.rrd").unwrap_err();
        assert!(err.to_string().contains("/nonexistent-dir/x.rrd"), "{err}");
    }
}
