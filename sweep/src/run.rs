//! Running a sweep: prepare every level's decoder, then stream episodes to
//! `episodes.csv` chunk by chunk, resuming where an earlier run stopped.

use std::collections::HashMap;
use std::fs::OpenOptions;
use std::io::{Seek, SeekFrom, Write};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use errp_sim::epuck::EpuckTask;
use errp_sim::grid::GridTask;
use errp_sim::task::Task;
use errp_sim::{Result, SimError, create_dir};

use crate::cache::TargetCache;
use crate::manifest::{EPISODES, MANIFEST, Manifest};
use crate::observer::SweepObserver;
use crate::prepare::prepare_all;
use crate::rows::episodes_header;
use crate::spec::{Level, Shard, SweepSpec, SweepTask};
use crate::writer::{EpisodeJob, resume_rows};

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
    },
    /// Stopped by the cancel flag; rerunning resumes.
    Interrupted {
        /// Episodes on disk.
        done: usize,
        /// Episodes of the slice.
        total: usize,
    },
}

/// Runs (or resumes) a sweep's slice into `opts.out`. `cancel` is polled
/// between chunks: when it is set the rows written so far stay, and the same
/// call later resumes. Results do not depend on the thread count (run it
/// inside a rayon pool to choose one), on `opts.chunk`, or on interruptions.
pub fn run_sweep(
    spec: &SweepSpec,
    opts: &SweepOptions,
    cancel: &AtomicBool,
    observer: &dyn SweepObserver,
) -> Result<SweepOutcome> {
    if spec.episodes == 0 {
        return Err(SimError::Sweep("--episodes must be at least 1".into()));
    }
    if spec.accuracies.is_empty() {
        return Err(SimError::Sweep("--accuracy gives no level".into()));
    }
    let levels = spec.levels()?;
    let out = &opts.out;
    let fresh = Manifest::new(spec, opts.shard);
    let manifest_path = out.join(MANIFEST);
    let episodes_path = out.join(EPISODES);
    if manifest_path.exists() {
        let old = Manifest::read(out)?;
        if old.spec != fresh.spec || old.shard != fresh.shard {
            return Err(SimError::Sweep(format!(
                "{} holds a different sweep (its {MANIFEST} has other parameters, scenario or \
                 shard); choose another --out, or delete the directory to start over",
                out.display()
            )));
        }
    } else {
        if episodes_path.exists() {
            return Err(SimError::Sweep(format!(
                "{} has an {EPISODES} but no {MANIFEST}; choose another --out",
                out.display()
            )));
        }
        create_dir(out)?;
        fresh.write(out)?;
    }

    match spec.task {
        SweepTask::Grid => run_levels::<GridTask>(spec, opts, &levels, fresh, cancel, observer),
        SweepTask::Epuck => run_levels::<EpuckTask>(spec, opts, &levels, fresh, cancel, observer),
    }
}

/// Prepares the levels' decoders (one per distinct calibration, in
/// parallel), lists them in the manifest, then runs the slice's episodes.
fn run_levels<T: Task>(
    spec: &SweepSpec,
    opts: &SweepOptions,
    levels: &[Level],
    fresh: Manifest,
    cancel: &AtomicBool,
    observer: &dyn SweepObserver,
) -> Result<SweepOutcome> {
    let out = &opts.out;
    let episodes_path = out.join(EPISODES);
    let scenarios: Vec<&T::Scenario> = levels
        .iter()
        .map(|level| {
            T::scenario(&level.scenario).ok_or_else(|| {
                SimError::Sweep(format!(
                    "the sweep is of the {} task, but {} is not a scenario of it",
                    T::INFO.name,
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
    let distinct: Vec<&T::Scenario> = first.iter().map(|&i| scenarios[i]).collect();
    let shared = T::shared(&scenarios)?;
    let prepared = prepare_all::<T>(
        &distinct,
        |d| (levels[first[d]].accuracy - 0.75).abs(),
        &opts.cache,
        &shared,
        observer,
    )?;
    let (decoders, infos): (Vec<_>, Vec<_>) = prepared
        .into_iter()
        .map(|(decoder, info)| (Arc::new(decoder), info))
        .unzip();
    let manifest = Manifest {
        decoders: infos,
        ..fresh
    };
    manifest.write(out)?;
    let runners: Vec<T::Runner> = scenarios
        .iter()
        .zip(&key_of)
        .map(|(s, &d)| T::runner(s, decoders[d].clone()))
        .collect::<Result<_>>()?;

    // Episodes of this slice, in sweep order.
    let items: Vec<usize> = (0..spec.total_episodes())
        .filter(|&g| opts.shard.owns(g))
        .collect();
    let header = episodes_header(spec);
    let mut done = if episodes_path.exists() {
        resume_rows(&episodes_path, &header, spec, &items)?
    } else {
        usize::MAX
    };
    let mut file = OpenOptions::new()
        .create(true)
        .append(true)
        .open(&episodes_path)
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
    observer.episodes_done(done, items.len());
    let sync_every = if opts.chunk > 0 {
        opts.chunk
    } else {
        T::INFO.rows_per_sync
    };
    let job = EpisodeJob::<T> {
        spec,
        levels,
        runners: &runners,
        items: &items,
        cancel,
        observer,
        sync_every,
        window: 64 * rayon::current_num_threads(),
    };
    done = job.run(file, done, &episodes_path)?;
    if done < items.len() {
        return Ok(SweepOutcome::Interrupted {
            done,
            total: items.len(),
        });
    }
    Ok(SweepOutcome::Complete {
        ran: done - already,
        total: items.len(),
    })
}
