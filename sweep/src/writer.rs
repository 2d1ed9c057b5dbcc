//! Streaming episode rows to `episodes.csv` in sweep order, and resuming a cut file.

use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use errp_sim::task::Task;
use errp_sim::{Result, SimError};

use crate::observer::SweepObserver;
use crate::rows::run_row;
use crate::spec::{Level, SweepSpec};

/// The episodes of a slice, run on every thread of the current pool and
/// written to `episodes.csv` in sweep order as they complete: a worker takes
/// the next episode as soon as it is free (no barrier between chunks), and
/// rows that finish early wait in memory until the rows before them are
/// written, at most `window` of them.
pub(crate) struct EpisodeJob<'a, T: Task> {
    pub(crate) spec: &'a SweepSpec,
    pub(crate) levels: &'a [Level],
    pub(crate) runners: &'a [T::Runner],
    pub(crate) items: &'a [usize],
    pub(crate) cancel: &'a AtomicBool,
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
                        if self.cancel.load(Ordering::SeqCst) {
                            break;
                        }
                        let i = next.fetch_add(1, Ordering::SeqCst);
                        if i >= self.items.len() {
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
                        let (l, k) = split(self.spec, self.items[i]);
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
                        let sync = st.unsynced >= self.sync_every || st.written == self.items.len();
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
                        self.observer.episodes_done(st.written, self.items.len());
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

/// Checks the rows already in `path` against the slice and drops a last
/// line cut short by a crash. Returns how many complete rows it holds.
pub(crate) fn resume_rows(
    path: &Path,
    header: &str,
    spec: &SweepSpec,
    items: &[usize],
) -> Result<usize> {
    let file = File::open(path).map_err(|source| SimError::Input {
        path: path.to_path_buf(),
        source,
    })?;
    let mut reader = BufReader::new(file);
    let mut line = String::new();
    let mut good_bytes = 0u64;
    let mut rows = 0usize;
    let mut first = true;
    let bad = |why: String| {
        SimError::Sweep(format!(
            "{}: {why}; it does not belong to this sweep: choose another --out or delete it",
            path.display()
        ))
    };
    loop {
        line.clear();
        let n = reader
            .read_line(&mut line)
            .map_err(|source| SimError::Input {
                path: path.to_path_buf(),
                source,
            })?;
        if n == 0 || !line.ends_with('\n') {
            break; // end, or a row cut short: dropped below
        }
        let text = line.trim_end_matches('\n');
        if first {
            if text != header {
                return Err(bad("its header differs".into()));
            }
            first = false;
        } else {
            let Some(&g) = items.get(rows) else {
                return Err(bad("it has more rows than the sweep".into()));
            };
            let (level, k) = split(spec, g);
            let mut cols = text.split(',');
            let lv = cols.next().and_then(|c| c.parse::<usize>().ok());
            let ep = cols
                .nth(1 + spec.axes.len())
                .and_then(|c| c.parse::<usize>().ok());
            if lv != Some(level) || ep != Some(k) {
                return Err(bad(format!(
                    "row {} should be level {level} episode {k}",
                    rows + 1
                )));
            }
            rows += 1;
        }
        good_bytes += n as u64;
    }
    drop(reader);
    let file = OpenOptions::new()
        .write(true)
        .open(path)
        .map_err(|source| SimError::Output {
            path: path.to_path_buf(),
            source,
        })?;
    file.set_len(good_bytes)
        .map_err(|source| SimError::Output {
            path: path.to_path_buf(),
            source,
        })?;
    Ok(if first { usize::MAX } else { rows })
}
