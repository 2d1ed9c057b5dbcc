//! Streaming episode rows to `episodes.csv` in sweep order, and resuming a cut file.

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use errp_bci::stop::WindDown;
use errp_sim::task::Task;
use errp_sim::{Result, SimError};

use crate::observer::SweepObserver;
use crate::rows::{MAX_ROW_BYTES, RowCheck, RowFault, run_row};
use crate::spec::{Level, Shard, SweepSpec};

/// The episodes of a slice, run on every thread of the current pool and
/// written to `episodes.csv` in sweep order as they complete: a worker takes
/// the next episode as soon as it is free (no barrier between chunks), and
/// rows that finish early wait in memory until the rows before them are
/// written, at most `window` of them.
pub(crate) struct EpisodeJob<'a, T: Task> {
    pub(crate) spec: &'a SweepSpec,
    pub(crate) levels: &'a [Level],
    pub(crate) runners: &'a [T::Runner],
    pub(crate) items: Slice,
    pub(crate) wind_down: &'a WindDown,
    pub(crate) observer: &'a dyn SweepObserver,
    pub(crate) sync_every: usize,
    pub(crate) window: usize,
}

/// What the workers share.
pub(crate) struct Writer {
    file: File,
    /// Finished rows not yet written, by position in the slice.
    pending: std::collections::BTreeMap<usize, String>,
    /// Rows of the slice on disk.
    written: usize,
    /// Rows written since the last sync.
    unsynced: usize,
    /// The first failure; every worker stops.
    error: Option<SimError>,
}

impl<T: Task> EpisodeJob<'_, T> {
    /// Runs the episodes after the first `done` and returns how many rows of
    /// the slice are on disk (all of them unless cancelled).
    pub(crate) fn run(&self, file: File, done: usize, path: &Path) -> Result<usize> {
        let next = AtomicUsize::new(done);
        let state = Mutex::new(Writer {
            file,
            pending: Default::default(),
            written: done,
            unsynced: 0,
            error: None,
        });
        let moved = std::sync::Condvar::new();
        let io = |source| SimError::Output {
            path: path.to_path_buf(),
            source,
        };
        rayon::scope(|scope| {
            for _ in 0..rayon::current_num_threads() {
                scope.spawn(|_| {
                    loop {
                        if self.wind_down.requested() {
                            break;
                        }
                        let i = next.fetch_add(1, Ordering::SeqCst);
                        if i >= self.items.len {
                            break;
                        }
                        // Do not run too far ahead of the oldest unfinished row.
                        {
                            let mut st = state.lock().expect("a worker panicked");
                            while i >= st.written + self.window && st.error.is_none() {
                                st = moved.wait(st).expect("a worker panicked");
                            }
                            if st.error.is_some() {
                                break;
                            }
                        }
                        let (l, k) = split(self.spec, self.items.episode(i));
                        let row = run_row::<T>(self.spec, &self.levels[l], &self.runners[l], k);
                        let mut guard = state.lock().expect("a worker panicked");
                        let st = &mut *guard;
                        let row = match row {
                            Ok(row) => row,
                            Err(e) => {
                                st.error.get_or_insert(e);
                                moved.notify_all();
                                break;
                            }
                        };
                        st.pending.insert(i, row);
                        let mut text = String::new();
                        while let Some(row) = st.pending.remove(&st.written) {
                            text.push_str(&row);
                            text.push('\n');
                            st.written += 1;
                            st.unsynced += 1;
                        }
                        if text.is_empty() {
                            continue;
                        }
                        let sync = st.unsynced >= self.sync_every || st.written == self.items.len;
                        let mut result = st.file.write_all(text.as_bytes());
                        if sync && result.is_ok() {
                            result = st.file.sync_data();
                            st.unsynced = 0;
                        }
                        if let Err(e) = result {
                            st.error.get_or_insert(io(e));
                            moved.notify_all();
                            break;
                        }
                        self.observer.episodes_done(st.written, self.items.len);
                        moved.notify_all();
                    }
                });
            }
        });
        let st = state.into_inner().expect("a worker panicked");
        if let Some(e) = st.error {
            return Err(e);
        }
        st.file.sync_data().map_err(io)?;
        Ok(st.written)
    }
}

/// The (level, episode) of sweep episode `g`.
pub(crate) fn split(spec: &SweepSpec, g: usize) -> (usize, usize) {
    (g / spec.episodes, g % spec.episodes)
}

/// The episodes of one shard, in sweep order, computed rather than listed:
/// a sweep's memory does not grow with its number of episodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Slice {
    shard: Shard,
    /// Episodes of the slice.
    pub(crate) len: usize,
}

impl Slice {
    /// The episodes of `shard` among `total`.
    pub(crate) fn new(shard: Shard, total: usize) -> Self {
        let first = shard.index - 1;
        let len = if total > first {
            (total - first).div_ceil(shard.count)
        } else {
            0
        };
        Self { shard, len }
    }

    /// The sweep episode of the slice's row `i`.
    pub(crate) fn episode(&self, i: usize) -> usize {
        self.shard.index - 1 + i * self.shard.count
    }
}

/// Reads one row of at most [`MAX_ROW_BYTES`] into `line`, without its
/// newline: `None` at the end, `Some(false)` for a last row with no
/// newline (cut short by a crash), `Some(true)` for a whole row.
pub(crate) fn read_row(
    reader: &mut impl BufRead,
    line: &mut Vec<u8>,
) -> std::io::Result<Option<bool>> {
    line.clear();
    let n = reader
        .by_ref()
        .take(MAX_ROW_BYTES as u64 + 1)
        .read_until(b'\n', line)?;
    if n == 0 {
        return Ok(None);
    }
    if line.last() == Some(&b'\n') {
        line.pop();
        return Ok(Some(true));
    }
    if line.len() > MAX_ROW_BYTES {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("a line is longer than {MAX_ROW_BYTES} bytes: this is not a sweep's CSV"),
        ));
    }
    Ok(Some(false))
}

/// What [`resume_rows`] found.
pub(crate) enum Resumed {
    /// No header yet (a new file, or one cut inside its header).
    Empty,
    /// This many whole, valid rows; `dropped` rows from an invalid one on
    /// were removed (`--repair`): (line, why, rows).
    Rows {
        rows: usize,
        dropped: Option<(usize, String, usize)>,
    },
}

/// Checks every row already in `path` against the slice (each field, the
/// checksum), drops a last row cut short by a crash, and returns what it
/// holds. An invalid row is an error naming the line and the field, unless
/// `repair`: then it and every row after it are dropped, to be run again.
pub(crate) fn resume_rows<T: Task>(
    path: &Path,
    header: &str,
    check: &RowCheck<'_, T>,
    items: Slice,
    repair: bool,
) -> Result<Resumed> {
    let input = |source| SimError::Input {
        path: path.to_path_buf(),
        source,
    };
    let file = errp_sim::open_regular(path).map_err(input)?;
    let mut reader = BufReader::new(file);
    let mut line = Vec::new();
    let mut good_bytes = 0u64;
    let mut rows = 0usize;
    let mut first = true;
    let mut dropped = None;
    let not_ours = |why: String| {
        SimError::Sweep(format!(
            "{}: {why}; it does not belong to this sweep: choose another --out or delete it",
            path.display()
        ))
    };
    while let Some(whole) = read_row(&mut reader, &mut line).map_err(input)? {
        if !whole {
            break; // a row cut short by a crash: dropped below
        }
        let n = line.len() as u64 + 1;
        if first {
            if line != header.as_bytes() {
                return Err(not_ours("its header differs".into()));
            }
            first = false;
            good_bytes += n;
            continue;
        }
        let lineno = rows + 2;
        let fault = match std::str::from_utf8(&line) {
            Err(_) => Some(RowFault {
                column: String::new(),
                value: String::new(),
                expected: "it is not text (damage on disk)".into(),
            }),
            // A row past the slice's last (a duplicate of the last row,
            // say) is a fault like any other: --repair drops it.
            Ok(_) if rows >= items.len => Some(RowFault {
                column: String::new(),
                value: String::new(),
                expected: format!(
                    "the sweep's rows end at line {} ({} rows), and this one is extra",
                    items.len + 1,
                    items.len
                ),
            }),
            Ok(text) => check.check(items.episode(rows), text).err(),
        };
        if let Some(fault) = fault {
            if !repair {
                return Err(fault.error(
                    path,
                    lineno,
                    "rerun the same command with --repair to drop this row and those after \
                     it and run them again",
                ));
            }
            let mut after = 0usize;
            while read_row(&mut reader, &mut line).map_err(input)?.is_some() {
                after += 1;
            }
            let why = fault.describe();
            dropped = Some((lineno, why, after + 1));
            break;
        }
        rows += 1;
        good_bytes += n;
    }
    drop(reader);
    let output = |source| SimError::Output {
        path: path.to_path_buf(),
        source,
    };
    let file = errp_sim::write_regular(path).map_err(output)?;
    file.set_len(good_bytes).map_err(output)?;
    file.sync_all().map_err(output)?;
    Ok(if first {
        Resumed::Empty
    } else {
        Resumed::Rows { rows, dropped }
    })
}
