//! Which process on which host: the names of temporary files and the
//! holders of locks, so that files written from several hosts into one
//! shared (network) directory never collide, and what a dead process left
//! behind can be told from what a live one is still writing.

use std::hash::{BuildHasher, Hasher};

/// The environment variable that overrides the host name (for tests that
/// simulate several hosts on one machine, or clusters whose nodes share a
/// host name).
pub const HOST_VAR: &str = "ERRP_HOST";

/// This machine's host name: `$ERRP_HOST` if set, else the kernel's
/// (`/proc/sys/kernel/hostname`), else `$HOSTNAME`, else `localhost`.
/// Only the characters `[A-Za-z0-9._-]` are kept (others become `_`), at
/// most 64, so that the name can go into a file name.
pub fn host_name() -> String {
    let raw = std::env::var(HOST_VAR)
        .ok()
        .filter(|h| !h.trim().is_empty())
        .or_else(|| std::fs::read_to_string("/proc/sys/kernel/hostname").ok())
        .or_else(|| std::env::var("HOSTNAME").ok())
        .unwrap_or_default();
    let clean: String = raw
        .trim()
        .chars()
        .take(64)
        .map(|c| {
            if c.is_ascii_alphanumeric() || ".-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    if clean.is_empty() {
        "localhost".into()
    } else {
        clean
    }
}

/// A random 64-bit number for unique file names: from the standard
/// library's per-process random hash keys, so no generator is seeded and
/// nothing computed depends on it.
pub fn random_suffix() -> u64 {
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u32(std::process::id());
    h.finish()
}

/// When process `pid` of this host started, in clock ticks since boot
/// (`/proc/PID/stat`), or `None` if no such process runs (or this is not
/// Linux). With the start time, a process is told apart from a later one
/// that was given the same pid.
pub fn process_start(pid: u32) -> Option<u64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name (field 2) may hold spaces and parentheses: fields
    // are counted after its closing parenthesis, which is field 3's start.
    let rest = &stat[stat.rfind(')')? + 1..];
    rest.split_whitespace().nth(19)?.parse().ok()
}

/// Whether a process of this host is known to be gone: `pid` runs no
/// process, or a process started at another time (`start`, if known).
/// `false` when it cannot be told (no `/proc`): a live process's files are
/// never taken for a dead one's.
pub fn process_gone(pid: u32, start: Option<u64>) -> bool {
    if !std::path::Path::new("/proc/self/stat").exists() {
        return false;
    }
    match (process_start(pid), start) {
        (None, _) => true,
        (Some(now), Some(then)) => now != then,
        (Some(_), None) => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn this_process_is_alive_and_a_made_up_one_is_gone() {
        let me = std::process::id();
        let start = process_start(me);
        assert!(start.is_some());
        assert!(!process_gone(me, start));
        assert!(process_gone(me, start.map(|s| s + 1)));
        // Above the kernel's pid_max (at most 2^22).
        assert!(process_gone(9_999_999, None));
    }

    #[test]
    fn host_names_are_file_name_safe() {
        let h = host_name();
        assert!(!h.is_empty());
        assert!(
            h.chars()
                .all(|c| c.is_ascii_alphanumeric() || "._-".contains(c)),
            "{h}"
        );
        assert_ne!(random_suffix(), random_suffix());
    }
}
