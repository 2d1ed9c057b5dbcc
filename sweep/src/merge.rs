//! Merging the directories of a sharded sweep into the files one unsharded
//! run writes, byte for byte.

use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};

use errp_sim::PendingFile;
use errp_sim::epuck::EpuckTask;
use errp_sim::grid::GridTask;
use errp_sim::task::Task;
use errp_sim::{Result, SimError, create_dirs};

use crate::finish::finish_dir;
use crate::lock::DirLock;
use crate::manifest::{EPISODES, MANIFEST, Manifest};
use crate::rows::{RowCheck, episodes_header};
use crate::run::{foreign_files, measured_levels};
use crate::spec::{Level, SweepSpec};
use crate::summary::SweepReport;
use crate::writer::read_row;
use errp_sim::{Names, TaskKind};

/// The manifests of the shard directories `dirs`, each a shard of one
/// and the same sweep with the same decoders.
fn read_shards(dirs: &[PathBuf]) -> Result<Vec<(Manifest, &Path)>> {
    let mut shards: Vec<(Manifest, &Path)> = Vec::with_capacity(dirs.len());
    for d in dirs {
        if !d.join(MANIFEST).is_file() {
            return Err(SimError::Sweep(format!(
                "{} holds no sweep (no {MANIFEST}): has its shard run? Run it (a shard \
                 resumes where it stopped), then merge",
                d.display()
            )));
        }
        let m = Manifest::read(d)?;
        if m.shard.is_none() {
            return Err(SimError::Sweep(format!(
                "{} holds a whole sweep, not a shard: there is nothing to merge",
                d.display()
            )));
        }
        shards.push((m, d));
    }
    let (first, first_dir) = &shards[0];
    let count = first.shard.expect("checked").count;
    for (m, d) in &shards[1..] {
        if !m.spec.same_sweep(&first.spec) || m.shard.expect("checked").count != count {
            return Err(SimError::Sweep(format!(
                "{} and {} are shards of different sweeps (their {MANIFEST} differ)",
                first_dir.display(),
                d.display()
            )));
        }
        if m.decoders != first.decoders {
            return Err(SimError::Sweep(format!(
                "{} and {} calibrated different decoders (the decoders in their {MANIFEST} \
                 differ): a shard run by another version of errp, or on an own EEG file \
                 changed between the shards; run the shards again from the same files",
                first_dir.join(MANIFEST).display(),
                d.join(MANIFEST).display()
            )));
        }
    }
    Ok(shards)
}

/// Merges the shard directories `dirs` (every shard of one sweep, in any
/// order) into `out`: `episodes.csv` in sweep order, then the summary, plots
/// and manifest of an unsharded run. Every row of every shard is checked
/// as a resume checks it (fields, seeds, checksum); a shard that is
/// incomplete, damaged or still being written is refused, naming the file
/// and line, and a refused merge leaves no `out` it created.
pub fn merge_sweeps(dirs: &[PathBuf], out: &Path) -> Result<SweepReport> {
    if dirs.is_empty() {
        return Err(SimError::Sweep("merge needs the shard directories".into()));
    }
    let shards = read_shards(dirs)?;
    let (first, _) = &shards[0];
    let count = first.shard.expect("checked").count;
    let mut by_index: Vec<Option<&Path>> = vec![None; count];
    for (m, d) in &shards {
        let k = m.shard.expect("checked").index;
        if let Some(other) = by_index[k - 1].replace(d) {
            return Err(SimError::Sweep(format!(
                "shard {k}/{count} is given twice: {} and {}",
                other.display(),
                d.display()
            )));
        }
    }
    let missing: Vec<String> = (1..=count)
        .filter(|k| by_index[k - 1].is_none())
        .map(|k| format!("{k}/{count}"))
        .collect();
    if !missing.is_empty() {
        return Err(SimError::Sweep(format!(
            "missing shard(s) {}: run them, then merge all {count}",
            missing.join(", ")
        )));
    }
    let spec = first.spec.clone();
    let inputs: Vec<&Path> = by_index.into_iter().map(|d| d.expect("checked")).collect();
    if inputs.iter().any(|d| same_dir(d, out)) {
        return Err(SimError::Sweep(format!(
            "the merge output {} is one of the shards; choose another --out",
            out.display()
        )));
    }
    for (k, d) in inputs.iter().enumerate() {
        if let Some(h) = DirLock::holder(d) {
            return Err(SimError::Sweep(format!(
                "shard {}/{count} in {} is still being written (errp on host {}, pid {}); \
                 merge once it has finished",
                k + 1,
                d.display(),
                h.host,
                h.pid
            )));
        }
    }
    if out.join(MANIFEST).exists() {
        return Err(SimError::Sweep(format!(
            "{} already holds a sweep; choose another --out or delete it",
            out.display()
        )));
    }
    if out.exists() {
        let others = foreign_files(out)?;
        if !others.is_empty() {
            return Err(SimError::Sweep(format!(
                "--out {} holds files that are not a sweep's ({}); give a new or empty \
                 directory",
                out.display(),
                others.join(", ")
            )));
        }
    }
    let levels = measured_levels(&spec, &spec.levels(&Names::CLI)?, &first.decoders)?;
    let created = create_dirs(out)?;
    // Go if the merge is interrupted before it is written.
    created.remove_if_interrupted();
    let result = DirLock::acquire(out, "--out").and_then(|lock| {
        let report = match spec.task {
            TaskKind::Grid => merge_rows::<GridTask>(&spec, &levels, &inputs, out),
            TaskKind::Epuck => merge_rows::<EpuckTask>(&spec, &levels, &inputs, out),
        }
        .and_then(|()| {
            let manifest = Manifest {
                shard: None,
                ..first.clone()
            };
            finish_dir(out, &manifest)
        });
        drop(lock);
        report
    });
    if result.is_err() {
        created.remove();
    }
    created.forget_if_interrupted();
    result
}

/// Writes `out/episodes.csv` from the shards' rows in sweep order, checking
/// every row as a resume does; nothing is left if one fails.
fn merge_rows<T: Task>(
    spec: &SweepSpec,
    levels: &[Level],
    inputs: &[&Path],
    out: &Path,
) -> Result<()> {
    let count = inputs.len();
    let check = RowCheck::<T>::new(spec, levels)?;
    // Episode g of the sweep is row g / count of shard g % count + 1.
    let header = episodes_header(spec);
    let mut readers: Vec<(BufReader<File>, PathBuf)> = Vec::with_capacity(count);
    let mut line = Vec::new();
    for d in inputs {
        let path = d.join(EPISODES);
        let input = |source| SimError::Input {
            path: path.clone(),
            source,
        };
        let mut reader = BufReader::new(errp_sim::open_regular(&path).map_err(input)?);
        let whole = read_row(&mut reader, &mut line).map_err(input)?;
        if whole != Some(true) || line != header.as_bytes() {
            return Err(SimError::Sweep(format!(
                "{}: its header is not this sweep's",
                path.display()
            )));
        }
        readers.push((reader, path));
    }
    let dest = out.join(EPISODES);
    let (pending, file) = PendingFile::create(&dest)?;
    let io = |source| SimError::Output {
        path: dest.clone(),
        source,
    };
    let mut w = BufWriter::new(file);
    writeln!(w, "{header}").map_err(io)?;
    let rerun = "rerun that shard's command (it resumes; add --repair to run the bad rows \
                 again), then merge";
    for g in 0..spec.total_episodes() {
        let (reader, path) = &mut readers[g % count];
        let lineno = g / count + 2;
        let whole = read_row(reader, &mut line).map_err(|source| SimError::Input {
            path: path.clone(),
            source,
        })?;
        match whole {
            None => {
                return Err(SimError::Sweep(format!(
                    "{} is incomplete: it ends before line {lineno} (episode {g} of the \
                     sweep); {rerun}",
                    path.display()
                )));
            }
            Some(false) => {
                return Err(SimError::Sweep(format!(
                    "{} is incomplete: line {lineno} is cut short (no end of line); {rerun}",
                    path.display()
                )));
            }
            Some(true) => {}
        }
        let text = std::str::from_utf8(&line).map_err(|_| {
            SimError::Sweep(format!(
                "{} line {lineno}: the row is not text (damage on disk); {rerun}",
                path.display()
            ))
        })?;
        check
            .check(g, text)
            .map_err(|fault| fault.error(path, lineno, rerun))?;
        writeln!(w, "{text}").map_err(io)?;
    }
    for (reader, path) in &mut readers {
        if read_row(reader, &mut line)
            .map_err(|source| SimError::Input {
                path: path.clone(),
                source,
            })?
            .is_some()
        {
            return Err(SimError::Sweep(format!(
                "{} has more rows than its shard of the sweep",
                path.display()
            )));
        }
    }
    let file = w.into_inner().map_err(|e| io(e.into_error()))?;
    file.sync_all().map_err(io)?;
    pending.commit()?;
    Ok(())
}

/// True if `a` and `b` name the same existing directory.
fn same_dir(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}
