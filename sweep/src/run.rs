//! Running a sweep: prepare every level's decoder, then stream episodes to
//! `episodes.csv` chunk by chunk, resuming where an earlier run stopped.

use std::collections::HashMap;
use std::fs::OpenOptions;
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use errp_bci::stop::WindDown;
use errp_sim::epuck::EpuckTask;
use errp_sim::grid::GridTask;
use errp_sim::task::{DecoderInfo, Task};
use errp_sim::{Result, SimError, create_dirs, forget_if_interrupted};

use crate::cache::TargetCache;
use crate::finish::finish_dir;
use crate::lock::{DirLock, LOCK};
use crate::manifest::{EPISODES, MANIFEST, Manifest};
use crate::observer::SweepObserver;
use crate::prepare::prepare_all;
use crate::rows::{RowCheck, episodes_header};
use crate::spec::{CheckedSweep, Level, Shard, SweepSpec};
use crate::summary::SweepReport;
use crate::writer::{EpisodeJob, Resumed, Slice, resume_rows};
use errp_sim::TaskKind;

/// The most memory a sweep's decoders may hold, bytes: what fits, with
/// the rest of the process, in the 4 GB that the Slurm job script
/// (`scripts/slurm/sweep.sbatch`) requests per job.
pub const MAX_DECODER_BYTES: usize = 3 << 30;

/// How a sweep runs (none of it changes the results).
#[derive(Debug, Clone)]
pub struct SweepOptions {
    /// Output directory.
    pub out: PathBuf,
    /// Targeting cache.
    pub cache: TargetCache,
    /// The slice to run.
    pub shard: Shard,
    /// Episodes run in parallel before each write to disk (0: a default by
    /// task).
    pub chunk: usize,
    /// On resume, drop an invalid row of `episodes.csv` and every row after
    /// it, and run them again (without it, an invalid row is an error).
    pub repair: bool,
}

/// How a call to [`run_sweep`] ended.
#[derive(Debug, Clone, PartialEq)]
pub enum SweepOutcome {
    /// Every episode of the slice is on disk.
    Complete {
        /// Episodes run by this call (the rest were already on disk).
        ran: usize,
        /// Episodes of the slice.
        total: usize,
        /// The summary of a whole sweep, whose `summary.csv`, plots and
        /// final `sweep.json` are written (none for a shard: `errp merge`
        /// writes them).
        report: Option<SweepReport>,
    },
    /// Wound down (its `WindDown` was requested); rerunning resumes.
    Interrupted {
        /// Episodes on disk.
        done: usize,
        /// Episodes of the slice.
        total: usize,
    },
}

/// Runs (or resumes) a sweep's slice into `opts.out`, holding the
/// directory's lock ([`DirLock`]) throughout; a whole sweep is also
/// finished (summary, plots, final manifest). `wind_down` is polled between
/// episodes: when it is set the rows written so far stay, and the same call
/// later resumes. Results do not depend on the thread count (run it inside
/// a rayon pool to choose one), on `opts.chunk`, or on interruptions.
///
/// A directory that does not exist is created; one that exists must hold
/// this sweep (its `sweep.json`) or nothing. Every row already on disk is
/// checked before it is kept. A refused or failed start leaves no new
/// directory behind.
pub fn run_sweep(
    sweep: &CheckedSweep,
    opts: &SweepOptions,
    wind_down: &WindDown,
    observer: &dyn SweepObserver,
) -> Result<SweepOutcome> {
    let (spec, levels) = (sweep.spec(), sweep.levels());
    let out = &opts.out;
    let created = create_dirs(out)?;
    // Undo the directories this call created, if it ends before any row.
    let undo = |e: SimError| {
        created.remove();
        e
    };
    let lock = DirLock::acquire(out, "--out").map_err(undo)?;
    let mut fresh = Manifest::new(spec, opts.shard);
    let manifest_path = out.join(MANIFEST);
    // The decoders the rows on disk were made with, if any.
    let mut made_with = Vec::new();
    if manifest_path.exists() {
        let old = Manifest::read(out)?;
        made_with = old.decoders.clone();
        if !old.spec.same_sweep(&fresh.spec) || old.shard != fresh.shard {
            return Err(SimError::Sweep(format!(
                "{} holds a different sweep (its {MANIFEST} has other parameters, scenario or \
                 shard); choose another --out, or delete the directory to start over",
                out.display()
            )));
        }
        // The same sweep, its scenario perhaps named by another path: the
        // directory keeps the first.
        fresh.spec.scenario_path = old.spec.scenario_path;
    } else {
        let others = foreign_files(out)?;
        if !others.is_empty() {
            drop(lock);
            return Err(SimError::Sweep(format!(
                "--out {} holds files that are not a sweep's ({}); give a new or empty \
                 directory",
                out.display(),
                others.join(", ")
            )));
        }
    }
    // A directory made here goes if the sweep is interrupted before its
    // first row (`sweep.json` is written once the decoders are ready).
    created.remove_if_interrupted();

    let outcome = match spec.task {
        TaskKind::Grid => {
            run_levels::<GridTask>(spec, opts, levels, fresh, &made_with, wind_down, observer)
        }
        TaskKind::Epuck => {
            run_levels::<EpuckTask>(spec, opts, levels, fresh, &made_with, wind_down, observer)
        }
    };
    // A new directory that failed before its first row goes.
    let outcome = match outcome {
        Err(e) if !out.join(EPISODES).exists() => return Err(undo(e)),
        other => other?,
    };
    let outcome = match outcome {
        SweepOutcome::Complete { ran, total, .. } if opts.shard.is_all() => {
            let manifest = Manifest::read(out)?;
            SweepOutcome::Complete {
                ran,
                total,
                report: Some(finish_dir(out, &manifest)?),
            }
        }
        other => other,
    };
    drop(lock);
    Ok(outcome)
}

/// The entries of `dir` that no sweep writes (the first few, by name).
pub(crate) fn foreign_files(dir: &Path) -> Result<Vec<String>> {
    let entries = std::fs::read_dir(dir).map_err(|source| SimError::Input {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut names: Vec<String> = entries
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != LOCK && !(n.starts_with('.') && n.contains(".partial-")))
        .take(1000)
        .collect();
    names.sort();
    if names.len() > 5 {
        let more = names.len() - 5;
        names.truncate(5);
        names.push(format!("and {more} more"));
    }
    Ok(names)
}

/// The decoders a sweep's levels need: each distinct one once.
struct Plan<'a, T: Task> {
    levels: &'a [Level],
    /// Every level's scenario.
    scenarios: Vec<&'a T::Scenario>,
    /// The first level of each distinct decoder.
    first: Vec<usize>,
    /// Each level's distinct decoder.
    key_of: Vec<usize>,
}

impl<'a, T: Task> Plan<'a, T> {
    /// The distinct decoders of `levels`, refused if they would hold more
    /// memory than a sweep may take.
    fn new(spec: &SweepSpec, levels: &'a [Level]) -> Result<Self> {
        let scenarios: Vec<&T::Scenario> = levels
            .iter()
            .map(|level| {
                level.scenario.get::<T::Scenario>().ok_or_else(|| {
                    SimError::Sweep(format!(
                        "the sweep is of the {} task, but {} is not a scenario of it",
                        T::INFO.kind,
                        spec.scenario_path.display()
                    ))
                })
            })
            .collect::<Result<_>>()?;
        let mut first: Vec<usize> = Vec::new();
        let mut key_of = Vec::with_capacity(levels.len());
        let mut index: HashMap<String, usize> = HashMap::new();
        for (i, s) in scenarios.iter().enumerate() {
            let d = *index.entry(T::decoder_key(s)).or_insert_with(|| {
                first.push(i);
                first.len() - 1
            });
            key_of.push(d);
        }
        // What the decoders will hold (their shared parts about as much as
        // the largest), refused before the work if it is more than a sweep
        // may take.
        let bytes: Vec<usize> = first
            .iter()
            .map(|&i| T::decoder_bytes(scenarios[i]))
            .collect();
        let total = bytes.iter().sum::<usize>() + 2 * bytes.iter().max().unwrap_or(&0);
        if total > MAX_DECODER_BYTES {
            return Err(SimError::Sweep(format!(
                "the sweep's {} decoders would hold about {:.1} GiB (their epoch banks), more \
                 than the {} GiB a sweep may take (what fits in the 4 GB a Slurm job of \
                 scripts/slurm/sweep.sbatch requests): sweep fewer levels at once, lower \
                 bank_per_class, or stream the EEG (--eeg stream)",
                first.len(),
                total as f64 / (1u64 << 30) as f64,
                MAX_DECODER_BYTES >> 30
            )));
        }
        Ok(Self {
            levels,
            scenarios,
            first,
            key_of,
        })
    }

    /// The levels, on recordings each with the accuracy its decoder gives
    /// (`infos`, one per distinct decoder in the order of their first
    /// levels); otherwise as they are.
    fn measured(&self, spec: &SweepSpec, infos: &[DecoderInfo]) -> Result<Vec<Level>> {
        if infos.len() != self.first.len() {
            return Err(SimError::Sweep(format!(
                "the sweep's {MANIFEST} lists {} decoders; its levels have {}",
                infos.len(),
                self.first.len()
            )));
        }
        Ok(self
            .levels
            .iter()
            .zip(&self.key_of)
            .map(|(level, &d)| {
                let mut level = level.clone();
                if spec.accuracies.is_empty() {
                    level.accuracy = infos[d].accuracy;
                }
                level
            })
            .collect())
    }

    /// Prepares each distinct decoder (in parallel, with `cache` for the
    /// targeting), in the order of their first levels.
    fn prepare(
        &self,
        cache: &TargetCache,
        observer: &dyn SweepObserver,
    ) -> Result<Vec<(T::Decoder, DecoderInfo)>> {
        let distinct: Vec<&T::Scenario> = self.first.iter().map(|&i| self.scenarios[i]).collect();
        let shared = T::shared(&self.scenarios)?;
        prepare_all::<T>(
            &distinct,
            |d| (self.levels[self.first[d]].accuracy - 0.75).abs(),
            cache,
            &shared,
            observer,
        )
    }
}

/// Prepares every distinct decoder of `spec`'s levels, as a sweep would,
/// and keeps nothing but what `cache` stores: the targeting of each. Run it
/// once before the shards of a sweep start (`errp sweep --prepare-only`), so
/// that none of them searches the targeting again. Returns what each decoder
/// reached.
pub fn prepare_sweep(
    sweep: &CheckedSweep,
    cache: &TargetCache,
    observer: &dyn SweepObserver,
) -> Result<Vec<DecoderInfo>> {
    let (spec, levels) = (sweep.spec(), sweep.levels());
    if cache.dir().is_none() {
        return Err(SimError::Sweep(
            "preparing a sweep keeps its targeting in the cache: give --cache DIR (not \
             --no-cache)"
                .into(),
        ));
    }
    fn infos<T: Task>(
        spec: &SweepSpec,
        levels: &[Level],
        cache: &TargetCache,
        observer: &dyn SweepObserver,
    ) -> Result<Vec<DecoderInfo>> {
        let plan = Plan::<T>::new(spec, levels)?;
        Ok(plan
            .prepare(cache, observer)?
            .into_iter()
            .map(|(_, info)| info)
            .collect())
    }
    match spec.task {
        TaskKind::Grid => infos::<GridTask>(spec, levels, cache, observer),
        TaskKind::Epuck => infos::<EpuckTask>(spec, levels, cache, observer),
    }
}

/// `levels` of `spec`, on recordings each with the accuracy its decoder
/// gave (`infos`, from `sweep.json`): the levels its rows were written
/// with.
pub(crate) fn measured_levels(
    spec: &SweepSpec,
    levels: &[Level],
    infos: &[DecoderInfo],
) -> Result<Vec<Level>> {
    match spec.task {
        TaskKind::Grid => Plan::<GridTask>::new(spec, levels)?.measured(spec, infos),
        TaskKind::Epuck => Plan::<EpuckTask>::new(spec, levels)?.measured(spec, infos),
    }
}

/// Refuses to resume rows made with decoders (`made_with`, from
/// `sweep.json`) other than the ones this run prepared (`infos`): a cache
/// that changed between the runs, another version. The file would mix two
/// sweeps.
fn check_made_with(out: &Path, made_with: &[DecoderInfo], infos: &[DecoderInfo]) -> Result<()> {
    if !made_with.is_empty()
        && let Some(i) = (0..infos.len().max(made_with.len())).find(|&i| {
            let now = infos.get(i).map(|d| DecoderInfo {
                cached: false,
                ..d.clone()
            });
            made_with.get(i) != now.as_ref()
        })
    {
        let show = |d: Option<&DecoderInfo>| {
            d.map_or("none".to_string(), |d| match &d.own_eeg {
                Some(r) => format!(
                    "recording {} ({} bytes, SHA-256 {})",
                    r.name, r.bytes, r.sha256
                ),
                None => format!(
                    "accuracy {} at ErrP-to-noise {}",
                    d.accuracy,
                    d.errp_to_noise.map_or("-".into(), |r| r.to_string())
                ),
            })
        };
        return Err(SimError::Sweep(format!(
            "{} holds rows made with other decoders than this run prepared (decoder {}: {} \
             then, {} now; was the targeting cache or a recording changed between the \
             runs?): resuming would mix them. Resume with the cache and the recordings the \
             sweep started with, or choose another --out",
            out.display(),
            i + 1,
            show(made_with.get(i)),
            show(infos.get(i)),
        )));
    }
    Ok(())
}

/// The rows of this slice already in `episodes.csv` (`usize::MAX` for a
/// new file), telling `observer` what `--repair` dropped.
fn resumed_count(
    resumed: Resumed,
    slice_len: usize,
    episodes_path: &Path,
    observer: &dyn SweepObserver,
) -> usize {
    match resumed {
        Resumed::Empty => usize::MAX,
        Resumed::Rows { rows, dropped } => {
            if let Some((line, why, n)) = dropped {
                let after = match n - 1 {
                    0 => String::new(),
                    k => format!(" and the {k} row(s) after it"),
                };
                let again = if rows < slice_len {
                    ", to run again what the sweep needs"
                } else {
                    ""
                };
                observer.note(&format!(
                    "--repair: {} line {line}: {why}; dropped it{after}{again}",
                    episodes_path.display(),
                ));
            }
            rows
        }
    }
}

/// Prepares the levels' decoders (one per distinct calibration, in
/// parallel), lists them in the manifest, then runs the slice's episodes.
fn run_levels<T: Task>(
    spec: &SweepSpec,
    opts: &SweepOptions,
    levels: &[Level],
    fresh: Manifest,
    made_with: &[DecoderInfo],
    wind_down: &WindDown,
    observer: &dyn SweepObserver,
) -> Result<SweepOutcome> {
    let out = &opts.out;
    let episodes_path = out.join(EPISODES);
    let plan = Plan::<T>::new(spec, levels)?;
    let prepared = plan.prepare(&opts.cache, observer)?;
    let (decoders, infos): (Vec<_>, Vec<_>) = prepared
        .into_iter()
        .map(|(decoder, info)| (Arc::new(decoder), info))
        .unzip();
    // Rows already on disk were made with the decoders `sweep.json` lists:
    // the rest must be made with the same.
    if episodes_path.exists() {
        check_made_with(out, made_with, &infos)?;
    }
    let measured = plan.measured(spec, &infos)?;
    let levels = measured.as_slice();
    let manifest = Manifest {
        decoders: infos,
        ..fresh
    };
    manifest.write(out)?;
    let runners: Vec<T::Runner> = plan
        .scenarios
        .iter()
        .zip(&plan.key_of)
        .map(|(s, &d)| T::runner(s, decoders[d].clone()))
        .collect::<Result<_>>()?;

    // Episodes of this slice, in sweep order.
    let items = Slice::new(opts.shard, spec.total_episodes());
    let header = episodes_header(spec);
    let check = RowCheck::<T>::new(spec, levels)?;
    let resumed = if episodes_path.exists() {
        resume_rows(&episodes_path, &header, &check, items, opts.repair)?
    } else {
        Resumed::Empty
    };
    let mut done = resumed_count(resumed, items.len, &episodes_path, observer);
    forget_if_interrupted(out);
    let mut file =
        errp_sim::open_regular_with(OpenOptions::new().create(true).append(true), &episodes_path)
            .map_err(|source| SimError::Output {
            path: episodes_path.clone(),
            source,
        })?;
    let io = |source| SimError::Output {
        path: episodes_path.clone(),
        source,
    };
    if done == usize::MAX {
        // A new file (or one cut inside its header).
        file.seek(SeekFrom::End(0)).map_err(io)?;
        writeln!(file, "{header}").map_err(io)?;
        done = 0;
    }
    let already = done;
    observer.episodes_done(done, items.len);
    let sync_every = if opts.chunk > 0 {
        opts.chunk
    } else {
        T::INFO.rows_per_sync
    };
    let job = EpisodeJob::<T> {
        spec,
        levels,
        runners: &runners,
        items,
        wind_down,
        observer,
        sync_every,
        window: 64 * rayon::current_num_threads(),
    };
    done = job.run(file, done, &episodes_path)?;
    if done < items.len {
        return Ok(SweepOutcome::Interrupted {
            done,
            total: items.len,
        });
    }
    Ok(SweepOutcome::Complete {
        ran: done - already,
        total: items.len,
        report: None,
    })
}
