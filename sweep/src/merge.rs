//! Merging the directories of a sharded sweep into the files one unsharded
//! run writes, byte for byte.

use std::fs::File;
use std::io::{BufRead, BufReader, BufWriter, Lines, Write};
use std::path::{Path, PathBuf};

use errp_sim::PendingFile;
use errp_sim::{Result, SimError, create_dir};

use crate::finish::finish_dir;
use crate::manifest::{EPISODES, MANIFEST, Manifest};
use crate::rows::episodes_header;
use crate::summary::SweepReport;

/// Merges the shard directories `dirs` (every shard of one sweep, in any
/// order) into `out`: `episodes.csv` in sweep order, then the summary, plots
/// and manifest of an unsharded run.
pub fn merge_sweeps(dirs: &[PathBuf], out: &Path) -> Result<SweepReport> {
    if dirs.is_empty() {
        return Err(SimError::Sweep("merge needs the shard directories".into()));
    }
    let mut shards: Vec<(Manifest, &Path)> = Vec::with_capacity(dirs.len());
    for d in dirs {
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
        if m.spec != first.spec || m.shard.expect("checked").count != count {
            return Err(SimError::Sweep(format!(
                "{} and {} are shards of different sweeps (their {MANIFEST} differ)",
                first_dir.display(),
                d.display()
            )));
        }
        if m.decoders != first.decoders {
            return Err(SimError::Sweep(format!(
                "{} and {} calibrated different decoders; were they run by different versions?",
                first_dir.display(),
                d.display()
            )));
        }
    }
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
    if out.join(MANIFEST).exists() {
        return Err(SimError::Sweep(format!(
            "{} already holds a sweep; choose another --out or delete it",
            out.display()
        )));
    }
    create_dir(out)?;

    // Episode g of the sweep is row g / count of shard g % count + 1.
    let header = episodes_header(&spec);
    let mut readers: Vec<(Lines<BufReader<File>>, PathBuf)> = Vec::with_capacity(count);
    for d in &inputs {
        let path = d.join(EPISODES);
        let file = File::open(&path).map_err(|source| SimError::Input {
            path: path.clone(),
            source,
        })?;
        let mut lines = BufReader::new(file).lines();
        let h = lines.next().transpose().map_err(|source| SimError::Input {
            path: path.clone(),
            source,
        })?;
        if h.as_deref() != Some(header.as_str()) {
            return Err(SimError::Sweep(format!(
                "{}: its header is not this sweep's",
                path.display()
            )));
        }
        readers.push((lines, path));
    }
    let dest = out.join(EPISODES);
    let (pending, file) = PendingFile::create(&dest)?;
    let io = |source| SimError::Output {
        path: dest.clone(),
        source,
    };
    let mut w = BufWriter::new(file);
    writeln!(w, "{header}").map_err(io)?;
    for g in 0..spec.total_episodes() {
        let (lines, path) = &mut readers[g % count];
        let line = lines
            .next()
            .transpose()
            .map_err(|source| SimError::Input {
                path: path.clone(),
                source,
            })?
            .ok_or_else(|| {
                SimError::Sweep(format!(
                    "{} is incomplete: rerun that shard's command to finish it, then merge",
                    path.display()
                ))
            })?;
        writeln!(w, "{line}").map_err(io)?;
    }
    for (lines, path) in &mut readers {
        if lines.next().is_some() {
            return Err(SimError::Sweep(format!(
                "{} has more rows than its shard of the sweep",
                path.display()
            )));
        }
    }
    let file = w.into_inner().map_err(|e| io(e.into_error()))?;
    file.sync_all().map_err(io)?;
    pending.commit()?;
    let manifest = Manifest {
        shard: None,
        ..first.clone()
    };
    finish_dir(out, &manifest)
}

/// True if `a` and `b` name the same existing directory.
fn same_dir(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}
