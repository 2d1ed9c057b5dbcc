//! One writer per sweep directory: `DIR/sweep.lock`.
//!
//! The lock is the file system's advisory lock (`flock`, through
//! [`File::try_lock`]) on `DIR/sweep.lock`, which also records who holds it:
//! host, process id (with its start time) and command. The operating system
//! releases the lock when the process ends, however it ends, so a lock left
//! by a killed sweep is taken over at once.
//!
//! On a network file system the lock is shared between hosts where the
//! file system shares locks (NFS v4, or v3 with lockd). Where it does not
//! (locks local to each host), the record still refuses a second writer:
//! the holder touches the file every [`HEARTBEAT`], and a record of another
//! host is trusted until it has been silent for [`STALE_AFTER`]; one of this
//! host is checked against the process table. The holder removes the file
//! when it ends.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, SystemTime};

use errp_sim::host::{host_name, process_gone, process_start, random_suffix};
use errp_sim::{
    Result, SimError, forget_if_interrupted, open_regular, open_regular_with, remove_if_interrupted,
};

/// The lock file's name in a sweep directory.
pub const LOCK: &str = "sweep.lock";

/// How often the holder shows it is alive.
pub const HEARTBEAT: Duration = Duration::from_secs(10);

/// How long another host's record is trusted without a heartbeat.
pub const STALE_AFTER: Duration = Duration::from_secs(60);

/// The wall clock, for the heartbeat and a record's age only: nothing a
/// sweep computes depends on it.
#[allow(
    clippy::disallowed_methods,
    reason = "a lock's heartbeat and age; nothing a sweep computes reads the clock"
)]
fn now() -> SystemTime {
    SystemTime::now()
}

/// Who holds a lock, as its file records it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Holder {
    /// Host name.
    pub host: String,
    /// Process id on that host.
    pub pid: u32,
    /// The process's start time (clock ticks since boot), if known.
    pub process_start: Option<u64>,
    /// A random token of this holding.
    pub token: u64,
    /// The command line.
    pub command: String,
}

impl Holder {
    fn me() -> Self {
        let pid = std::process::id();
        let command: Vec<String> = std::env::args_os()
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        let mut command = command.join(" ");
        if command.len() > 300 {
            let cut = (0..=300)
                .rev()
                .find(|&i| command.is_char_boundary(i))
                .unwrap_or(0);
            command.truncate(cut);
            command.push_str("...");
        }
        Self {
            host: host_name(),
            pid,
            process_start: process_start(pid),
            token: random_suffix(),
            command: command.replace('\n', " "),
        }
    }

    fn text(&self) -> String {
        format!(
            "# errp is writing this directory; this file goes when it ends.\n\
             host = {}\npid = {}\nprocess_start = {}\ntoken = {:016x}\ncommand = {}\n",
            self.host,
            self.pid,
            self.process_start
                .map_or("unknown".into(), |s| s.to_string()),
            self.token,
            self.command
        )
    }

    fn parse(text: &str) -> Option<Self> {
        let get = |key: &str| {
            text.lines()
                .find_map(|l| l.strip_prefix(key)?.trim_start().strip_prefix('='))
                .map(str::trim)
        };
        Some(Self {
            host: get("host")?.to_string(),
            pid: get("pid")?.parse().ok()?,
            process_start: get("process_start").and_then(|s| s.parse().ok()),
            token: u64::from_str_radix(get("token")?, 16).ok()?,
            command: get("command").unwrap_or("").to_string(),
        })
    }

    /// Whether the holder is known to be gone: a process of this host no
    /// longer running, or another host silent for [`STALE_AFTER`].
    fn gone(&self, silent: Option<Duration>) -> bool {
        if self.host == host_name() {
            process_gone(self.pid, self.process_start)
        } else {
            silent.is_some_and(|s| s > STALE_AFTER)
        }
    }
}

/// An exclusive lock on a directory, held until dropped.
#[derive(Debug)]
pub struct DirLock {
    path: PathBuf,
    file: File,
    stop: Arc<(Mutex<bool>, Condvar)>,
    heartbeat: Option<JoinHandle<()>>,
}

/// The error for a directory another process is writing.
fn busy(dir: &Path, holder: Option<&Holder>, silent: Option<Duration>, what: &str) -> SimError {
    let who = match holder {
        Some(h) => {
            format!(
                "errp on host {}, pid {} ({})",
                h.host,
                h.pid,
                if h.command.is_empty() {
                    "command unknown"
                } else {
                    &h.command
                }
            )
        }
        None => "another process".to_string(),
    };
    let alive = match (holder, silent) {
        (Some(h), Some(s)) if h.host != host_name() => format!(
            " It was last seen alive {} s ago, and is taken to be gone once silent for {} s.",
            s.as_secs(),
            STALE_AFTER.as_secs()
        ),
        _ => String::new(),
    };
    SimError::Sweep(format!(
        "{} is in use: {who} is writing it ({}).{alive} Wait for it to end, or choose another \
         {what}; a lock left by a process that is gone is taken over by itself",
        dir.display(),
        dir.join(LOCK).display()
    ))
}

/// The same file: `file` is still the one at `path` (not removed and
/// replaced since it was opened).
#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_: &File, path: &Path) -> bool {
    path.exists()
}

impl DirLock {
    /// Takes the lock of directory `dir` (which must exist), or says who
    /// holds it; `what` names the flag that chose the directory (`--out`).
    pub fn acquire(dir: &Path, what: &str) -> Result<Self> {
        let path = dir.join(LOCK);
        let io = |source| SimError::Output {
            path: path.clone(),
            source,
        };
        for _ in 0..8 {
            let mut file = open_regular_with(
                OpenOptions::new()
                    .read(true)
                    .write(true)
                    .create(true)
                    .truncate(false),
                &path,
            )
            .map_err(io)?;
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    let text = read_small(&mut file);
                    let silent = silence(&file);
                    return Err(busy(dir, Holder::parse(&text).as_ref(), silent, what));
                }
                // A file system without locks: the record decides alone.
                Err(std::fs::TryLockError::Error(e))
                    if e.kind() == std::io::ErrorKind::Unsupported => {}
                Err(std::fs::TryLockError::Error(e)) => return Err(io(e)),
            }
            if !same_file(&file, &path) {
                // The holder removed it as we opened it: take the new one.
                continue;
            }
            let text = read_small(&mut file);
            if let Some(h) = Holder::parse(&text) {
                let silent = silence(&file);
                if !h.gone(silent) {
                    return Err(busy(dir, Some(&h), silent, what));
                }
            }
            let me = Holder::me();
            file.set_len(0)
                .and_then(|()| file.rewind())
                .and_then(|()| file.write_all(me.text().as_bytes()))
                .and_then(|()| file.sync_all())
                .map_err(io)?;
            remove_if_interrupted(&path);
            let stop = Arc::new((Mutex::new(false), Condvar::new()));
            let heartbeat = {
                let stop = stop.clone();
                let beat = file.try_clone().map_err(io)?;
                std::thread::Builder::new()
                    .name("errp-lock-heartbeat".into())
                    .spawn(move || {
                        let (lock, cvar) = &*stop;
                        let mut done = lock.lock().unwrap_or_else(|e| e.into_inner());
                        while !*done {
                            let _ = beat.set_modified(now());
                            done = cvar
                                .wait_timeout(done, HEARTBEAT)
                                .unwrap_or_else(|e| e.into_inner())
                                .0;
                        }
                    })
                    .map_err(io)?
            };
            return Ok(Self {
                path,
                file,
                stop,
                heartbeat: Some(heartbeat),
            });
        }
        Err(busy(dir, None, None, what))
    }

    /// Who holds `dir`'s lock, if a live process does (without taking it).
    pub fn holder(dir: &Path) -> Option<Holder> {
        let path = dir.join(LOCK);
        let mut file = open_regular(&path).ok()?;
        let text = read_small(&mut file);
        let h = Holder::parse(&text)?;
        (!h.gone(silence(&file))).then_some(h)
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        {
            let (lock, cvar) = &*self.stop;
            *lock.lock().unwrap_or_else(|e| e.into_inner()) = true;
            cvar.notify_all();
        }
        if let Some(h) = self.heartbeat.take() {
            let _ = h.join();
        }
        // Removed while still locked; whoever opened it meanwhile sees it
        // is no longer the file at the path, and starts again.
        let _ = std::fs::remove_file(&self.path);
        forget_if_interrupted(&self.path);
        let _ = self.file.unlock();
    }
}

/// How long since the holder last touched the lock file. A time ahead of
/// this host's clock by less than [`STALE_AFTER`] is clock skew between
/// hosts (silent for no time); one further ahead was not written by a
/// heartbeat, and counts as silent since ever.
fn silence(file: &File) -> Option<Duration> {
    let modified = file.metadata().ok()?.modified().ok()?;
    Some(match now().duration_since(modified) {
        Ok(age) => age,
        Err(ahead) if ahead.duration() <= STALE_AFTER => Duration::ZERO,
        Err(_) => Duration::MAX,
    })
}

/// The first 4 KiB of the lock file (a record is a few lines).
fn read_small(file: &mut File) -> String {
    let mut text = String::new();
    let _ = file.rewind();
    let _ = Read::by_ref(file).take(4096).read_to_string(&mut text);
    text
}

/// A unique name for a temporary beside `dir`'s files (tests).
#[cfg(test)]
fn scratch(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("errp-lock-{name}-{:x}", random_suffix()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_is_refused_naming_the_holder_and_freed_on_drop() {
        let dir = scratch("busy");
        std::fs::create_dir_all(&dir).unwrap();
        let lock = DirLock::acquire(&dir, "--out").unwrap();
        let text = std::fs::read_to_string(dir.join(LOCK)).unwrap();
        assert!(
            text.contains(&format!("pid = {}", std::process::id())),
            "{text}"
        );
        let e = DirLock::acquire(&dir, "--out").unwrap_err().to_string();
        assert!(
            e.contains("is in use")
                && e.contains(&host_name())
                && e.contains(&std::process::id().to_string())
                && e.contains("--out"),
            "{e}"
        );
        assert_eq!(
            DirLock::holder(&dir).map(|h| h.pid),
            Some(std::process::id())
        );
        drop(lock);
        assert!(!dir.join(LOCK).exists());
        assert!(DirLock::holder(&dir).is_none());
        drop(DirLock::acquire(&dir, "--out").unwrap());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_dead_processs_record_is_taken_over_and_a_live_hosts_is_not() {
        let dir = scratch("stale");
        std::fs::create_dir_all(&dir).unwrap();
        let record = |host: &str, pid: u32| {
            Holder {
                host: host.into(),
                pid,
                process_start: None,
                token: 1,
                command: "errp sweep".into(),
            }
            .text()
        };
        // A process of this host that is gone (above pid_max).
        std::fs::write(dir.join(LOCK), record(&host_name(), 9_999_999)).unwrap();
        drop(DirLock::acquire(&dir, "--out").unwrap());
        // Another host, alive a moment ago (its lock not shared with us).
        std::fs::write(dir.join(LOCK), record("another-node", 42)).unwrap();
        let e = DirLock::acquire(&dir, "--out").unwrap_err().to_string();
        assert!(
            e.contains("another-node") && e.contains("alive 0 s ago"),
            "{e}"
        );
        // ... silent for longer than STALE_AFTER: gone.
        let f = File::options().write(true).open(dir.join(LOCK)).unwrap();
        f.set_modified(now() - STALE_AFTER - Duration::from_secs(5))
            .unwrap();
        drop(f);
        drop(DirLock::acquire(&dir, "--out").unwrap());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
