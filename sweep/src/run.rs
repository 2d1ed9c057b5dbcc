//! Running a sweep: prepare every level's decoder, then stream episodes to
//! `episodes.csv` chunk by chunk, resuming where an earlier run stopped.

use std::collections::HashMap;
use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use errp_bci::{
    GeneratorParams, LdaDecoder, SessionParts, SvmDecoder, calibrate_session, target_accuracy_on,
    target_continuous_accuracy,
};
use errp_robot::{Cell, Grid, QTable};
use serde::{Deserialize, Serialize};

use errp_sim::AnyScenario;
use errp_sim::calibration::{CalibrationReport, CalibrationRequest};
use errp_sim::epuck::EpuckScenario;
use errp_sim::epuck::finish_continuous_decoder;
use errp_sim::epuck::run_epuck_episode;
use errp_sim::epuck::{ContinuousDecoder, ContinuousRequest, calibrate_continuous_at};
use errp_sim::grid::decoder_from_calibration;
use errp_sim::grid::{AssessmentDecoder, EegDecoder, EegSource, EpochBankParts, run_grid_episode};
use errp_sim::grid::{DecoderChoice, EegMode, GridScenario};
use errp_sim::write_atomic;
use errp_sim::{Result, SimError};

use crate::cache::TargetCache;
use crate::spec::{Level, Shard, SweepSpec, SweepTask, format_number, value_text};

/// The calibrated decoder behind one or more levels, as `sweep.json` lists it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DecoderInfo {
    /// Requested accuracy.
    pub accuracy: f64,
    /// `lda` (grid EEG), `svm` (e-puck) or `oracle`.
    pub kind: String,
    /// Seed of its calibration session.
    pub calibration_seed: u64,
    /// ErrP-to-noise ratio found by targeting.
    pub errp_to_noise: Option<f64>,
    /// Cross-validated correct-class rate of the calibration session.
    pub cv_correct: Option<f64>,
    /// Cross-validated error-class rate.
    pub cv_error: Option<f64>,
    /// Their mean: the accuracy reached.
    pub cv_mean: Option<f64>,
    /// E-puck: the detector's hit rate per ErrP on the held-out recording.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub online_hit_rate: Option<f64>,
    /// E-puck: its false alarms per minute of error-free time there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub online_false_alarms_per_min: Option<f64>,
    /// True if the targeting came from the cache (not written to disk).
    #[serde(skip)]
    pub cached: bool,
}

/// The contents of `sweep.json`: enough to rerun the sweep exactly.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Format of the sweep directory.
    pub format: u32,
    /// Version of errp that wrote it.
    pub errp_version: String,
    /// What was swept.
    pub spec: SweepSpec,
    /// The slice this directory holds (none: the whole sweep).
    pub shard: Option<Shard>,
    /// Every calibrated decoder, in level order (empty until calibrated).
    pub decoders: Vec<DecoderInfo>,
}

/// Version of the sweep directory layout.
pub const FORMAT: u32 = 1;

impl Manifest {
    /// A manifest with no decoders yet.
    pub fn new(spec: &SweepSpec, shard: Shard) -> Self {
        Self {
            format: FORMAT,
            errp_version: env!("CARGO_PKG_VERSION").to_string(),
            spec: spec.clone(),
            shard: (!shard.is_all()).then_some(shard),
            decoders: Vec::new(),
        }
    }

    /// Reads `dir/sweep.json`.
    pub fn read(dir: &Path) -> Result<Self> {
        let path = dir.join(MANIFEST);
        let text = std::fs::read_to_string(&path).map_err(|source| SimError::Input {
            path: path.clone(),
            source,
        })?;
        serde_json::from_str(&text).map_err(|e| {
            SimError::Sweep(format!(
                "{}: not a sweep manifest ({e}); was it written by `errp sweep`?",
                path.display()
            ))
        })
    }

    /// Writes `dir/sweep.json` atomically.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self).expect("a manifest serialises") + "\n";
        write_atomic(&dir.join(MANIFEST), text.as_bytes())
    }
}

/// The manifest's file name.
pub const MANIFEST: &str = "sweep.json";
/// The episodes' file name.
pub const EPISODES: &str = "episodes.csv";

/// What a sweep reports as it goes. Every method defaults to nothing;
/// `()` watches nothing.
pub trait SweepObserver: Sync {
    /// A decoder is calibrated (`done` of `total`).
    fn decoder_ready(&self, _info: &DecoderInfo, _done: usize, _total: usize) {}
    /// `done` of this run's `total` episodes are on disk.
    fn episodes_done(&self, _done: usize, _total: usize) {}
}

impl SweepObserver for () {}

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

/// One level, ready to run episodes.
enum Runner {
    Grid {
        scenario: Box<GridScenario>,
        decoder: Arc<AssessmentDecoder>,
        table: Arc<QTable>,
    },
    Epuck {
        scenario: Box<EpuckScenario>,
        decoder: Arc<ContinuousDecoder>,
    },
}

/// The decoder a level needs, before calibration; equal keys share one.
fn decoder_key(level: &Level) -> String {
    match &level.scenario {
        AnyScenario::Grid(s) => format!(
            "{:?}",
            (
                s.accuracy,
                s.seed,
                s.decoder,
                s.p_error,
                s.eeg,
                s.bank_per_class,
                s.params.interval_min_secs,
                s.params.interval_max_secs
            )
        ),
        AnyScenario::Epuck(s) => format!("{:?}", (s.accuracy, s.seed)),
    }
}

enum Prepared {
    Grid(Arc<AssessmentDecoder>),
    Epuck(Arc<ContinuousDecoder>),
}

/// What grid levels share, simulated once before their decoders are
/// prepared: the calibration session (every level uses the same one, at its
/// own ratio) and the epoch banks (likewise). Each is streamed as its noise
/// and ERP parts, the two in parallel.
#[derive(Default)]
struct Shared {
    sessions: HashMap<u64, Arc<SessionParts>>,
    banks: HashMap<String, Arc<EpochBankParts>>,
}

/// The key of a grid level's epoch bank: what its epochs depend on.
fn bank_key(s: &GridScenario) -> String {
    format!(
        "{:?}",
        (
            s.seed,
            s.bank_per_class,
            s.params.interval_min_secs,
            s.params.interval_max_secs
        )
    )
}

impl Shared {
    fn build(levels: &[Level]) -> Result<Self> {
        let mut shared = Shared::default();
        for level in levels {
            let AnyScenario::Grid(s) = &level.scenario else {
                continue;
            };
            if s.decoder != DecoderChoice::Eeg {
                continue;
            }
            if let std::collections::hash_map::Entry::Vacant(slot) = shared.sessions.entry(s.seed) {
                let setup = CalibrationRequest::new(s.accuracy, s.seed).setup;
                let (noise, erp) = rayon::join(
                    || SessionParts::simulate_part(&setup, s.seed, false),
                    || SessionParts::simulate_part(&setup, s.seed, true),
                );
                slot.insert(Arc::new(SessionParts::from_parts(noise?, erp?)?));
            }
            let key = bank_key(s);
            if s.eeg == EegMode::Bank && !shared.banks.contains_key(&key) {
                let setup = CalibrationRequest::new(s.accuracy, s.seed).setup;
                let source = EegSource {
                    generator: &setup.generator,
                    montage: &setup.montage,
                    preprocessor: shared.sessions[&s.seed].preprocessor(),
                };
                let bank = EpochBankParts::build(source, &s.params, s.bank_per_class, s.seed)?;
                shared.banks.insert(key, Arc::new(bank));
            }
        }
        Ok(shared)
    }
}

/// Calibrates the decoder `level` needs, using the cache for the targeting.
fn prepare(level: &Level, cache: &TargetCache, shared: &Shared) -> Result<(Prepared, DecoderInfo)> {
    match &level.scenario {
        AnyScenario::Grid(s) => {
            let mut info = DecoderInfo {
                accuracy: s.accuracy,
                kind: "oracle".into(),
                calibration_seed: s.seed,
                errp_to_noise: None,
                cv_correct: None,
                cv_error: None,
                cv_mean: None,
                online_hit_rate: None,
                online_false_alarms_per_min: None,
                cached: false,
            };
            if s.decoder == DecoderChoice::Oracle {
                let decoder = decoder_from_calibration(s, None)?;
                return Ok((Prepared::Grid(Arc::new(decoder)), info));
            }
            // The level's calibration: the shared session at the ratio
            // targeted for its accuracy.
            let request = CalibrationRequest::new(s.accuracy, s.seed);
            let parts = &shared.sessions[&s.seed];
            let key = format!(
                "{:?} {:?} accuracy={:?} seed={}",
                request.setup, request.search, request.accuracy, request.seed
            );
            let lda = LdaDecoder::default();
            let (targeting, hit) = cache.get_or_search("grid-lda", &key, || {
                Ok(target_accuracy_on(
                    parts,
                    request.accuracy,
                    &lda,
                    &request.setup,
                    &request.search,
                    request.seed,
                    |_| {},
                )?)
            })?;
            let calibrated = calibrate_session(
                &lda,
                parts.session_at(targeting.ratio),
                request.setup.calibration.folds,
                request.seed,
            )?;
            let report = CalibrationReport {
                generator: GeneratorParams {
                    errp_to_noise: targeting.ratio,
                    ..request.setup.generator.clone()
                },
                targeting,
                calibrated,
            };
            let a = report.calibrated.accuracy;
            info.kind = "lda".into();
            info.errp_to_noise = Some(report.targeting.ratio);
            info.cv_correct = Some(a.correct);
            info.cv_error = Some(a.error);
            info.cv_mean = Some(a.mean());
            info.cached = hit;
            let eeg = EegDecoder::from_report(&report, s.p_error);
            let decoder = match s.eeg {
                EegMode::Stream => AssessmentDecoder::Eeg(Box::new(eeg)),
                EegMode::Bank => {
                    AssessmentDecoder::EegBank(Box::new(shared.banks[&bank_key(s)].bank(eeg)))
                }
            };
            Ok((Prepared::Grid(Arc::new(decoder)), info))
        }
        AnyScenario::Epuck(s) => {
            let request = ContinuousRequest::new(s.accuracy, s.seed);
            let key = format!(
                "{:?} {:?} accuracy={:?} seed={}",
                request.setup, request.search, request.accuracy, request.seed
            );
            let (targeting, hit) = cache.get_or_search("epuck-svm", &key, || {
                Ok(target_continuous_accuracy(
                    request.accuracy,
                    &SvmDecoder::default(),
                    &request.setup,
                    &request.search,
                    request.seed,
                    |_| {},
                )?)
            })?;
            let report = calibrate_continuous_at(&request, targeting)?;
            let a = report.calibrated.accuracy;
            let decoder = finish_continuous_decoder(s, &report)?;
            let point = decoder.online.as_ref().map(|o| o.point);
            let info = DecoderInfo {
                accuracy: s.accuracy,
                kind: "svm".into(),
                calibration_seed: s.seed,
                errp_to_noise: Some(report.targeting.ratio),
                cv_correct: Some(a.correct),
                cv_error: Some(a.error),
                cv_mean: Some(a.mean()),
                online_hit_rate: point.map(|p| p.hit_rate),
                online_false_alarms_per_min: point.map(|p| p.false_alarms_per_min),
                cached: hit,
            };
            Ok((Prepared::Epuck(Arc::new(decoder)), info))
        }
    }
}

/// Prepares the decoders of `first_level` (level indices) on every thread of
/// the current pool, the likely slowest first: targeting far from 75 % takes
/// the most search steps. Results are in `first_level` order, whatever the
/// thread count.
fn prepare_all(
    levels: &[Level],
    first_level: &[usize],
    cache: &TargetCache,
    shared: &Shared,
    observer: &dyn SweepObserver,
) -> Result<Vec<(Prepared, DecoderInfo)>> {
    let n = first_level.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| {
        let cost = |i: usize| (levels[first_level[i]].accuracy - 0.75).abs();
        cost(b).total_cmp(&cost(a)).then(a.cmp(&b))
    });
    let next = AtomicUsize::new(0);
    let ready = AtomicUsize::new(0);
    type Slot = Mutex<Option<Result<(Prepared, DecoderInfo)>>>;
    let slots: Vec<Slot> = (0..n).map(|_| Mutex::new(None)).collect();
    rayon::scope(|scope| {
        for _ in 0..rayon::current_num_threads().min(n) {
            scope.spawn(|_| {
                loop {
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(&k) = order.get(i) else { break };
                    let result = prepare(&levels[first_level[k]], cache, shared);
                    if let Ok((_, info)) = &result {
                        let done = ready.fetch_add(1, Ordering::SeqCst) + 1;
                        observer.decoder_ready(info, done, n);
                    }
                    *slots[k].lock().expect("no panic while holding the slot") = Some(result);
                }
            });
        }
    });
    slots
        .into_iter()
        .map(|slot| {
            slot.into_inner()
                .expect("no panic while holding the slot")
                .expect("every decoder was prepared")
        })
        .collect()
}

/// The episodes of a slice, run on every thread of the current pool and
/// written to `episodes.csv` in sweep order as they complete: a worker takes
/// the next episode as soon as it is free (no barrier between chunks), and
/// rows that finish early wait in memory until the rows before them are
/// written, at most `window` of them.
struct EpisodeJob<'a> {
    spec: &'a SweepSpec,
    levels: &'a [Level],
    runners: &'a [Runner],
    items: &'a [usize],
    cancel: &'a AtomicBool,
    observer: &'a dyn SweepObserver,
    sync_every: usize,
    window: usize,
}

/// What the workers share.
struct Writer {
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

impl EpisodeJob<'_> {
    /// Runs the episodes after the first `done` and returns how many rows of
    /// the slice are on disk (all of them unless cancelled).
    fn run(&self, file: File, done: usize, path: &Path) -> Result<usize> {
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
                        let row = run_row(self.spec, &self.levels[l], &self.runners[l], k);
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

/// The header of `episodes.csv` for `spec`.
pub fn episodes_header(spec: &SweepSpec) -> String {
    let mut cols = vec!["level".to_string(), "accuracy".into()];
    cols.extend(spec.axes.iter().map(|a| a.name.clone()));
    cols.extend(["episode", "seed", "success"].map(String::from));
    let task_cols: &[&str] = match spec.task {
        SweepTask::Grid => &[
            "start_x",
            "start_y",
            "goal_x",
            "goal_y",
            "committed_x",
            "committed_y",
            "actions",
            "net_secs",
            "total_secs",
            "errors",
            "detected",
            "false_alarms",
            "missed",
        ],
        SweepTask::Epuck => &[
            "goal",
            "committed",
            "time_secs",
            "path_m",
            "errps",
            "detected",
            "false_alarms",
            "missed",
            "detected_turning",
            "detected_driving",
            "detected_on_goal",
            "hit_rate",
            "false_alarms_per_min",
        ],
    };
    cols.extend(task_cols.iter().map(|s| s.to_string()));
    cols.extend(["acc_correct", "acc_error", "online_accuracy"].map(String::from));
    cols.join(",")
}

/// The name of the cost column (what the sweep minimises) of `task`.
pub fn cost_column(task: SweepTask) -> &'static str {
    match task {
        SweepTask::Grid => "actions",
        SweepTask::Epuck => "time_secs",
    }
}

/// A rate as a CSV field: empty when undefined.
fn rate(x: f64) -> String {
    if x.is_finite() {
        format_number(x)
    } else {
        String::new()
    }
}

/// Correct decisions over all decisions of an accuracy's two classes.
fn overall(a: &errp_bci::Accuracy) -> (usize, usize, f64) {
    let hits_error = (a.error * a.n_error as f64).round() as usize;
    let hits_correct = (a.correct * a.n_correct as f64).round() as usize;
    let n = a.n_error + a.n_correct;
    let acc = if n == 0 {
        f64::NAN
    } else {
        (hits_error + hits_correct) as f64 / n as f64
    };
    (hits_error, hits_correct, acc)
}

/// Runs episode `k` of `level` and formats its CSV row.
fn run_row(spec: &SweepSpec, level: &Level, runner: &Runner, k: usize) -> Result<String> {
    let seed = spec.episode_seed(level.accuracy, k);
    let mut f = vec![level.index.to_string(), format_number(level.accuracy)];
    f.extend(level.values.iter().map(value_text));
    f.extend([k.to_string(), seed.to_string()]);
    let cell = |c: Option<Cell>| match c {
        Some(c) => [c.x.to_string(), c.y.to_string()],
        None => [String::new(), String::new()],
    };
    let online = match runner {
        Runner::Grid {
            scenario,
            decoder,
            table,
        } => {
            let (start, goal) = scenario.episodes[k % scenario.episodes.len()];
            let r = run_grid_episode(start, goal, table, &scenario.params, decoder, seed, false)?;
            let (detected, hits_correct, _) = overall(&r.online);
            f.push(u8::from(r.reached()).to_string());
            f.extend(cell(Some(start)));
            f.extend(cell(Some(goal)));
            f.extend(cell(r.committed));
            f.extend([
                r.actions.to_string(),
                format_number(r.net_secs),
                format_number(r.total_secs),
                r.online.n_error.to_string(),
                detected.to_string(),
                (r.online.n_correct - hits_correct).to_string(),
                (r.online.n_error - detected).to_string(),
            ]);
            r.online
        }
        Runner::Epuck { scenario, decoder } => {
            let r = run_epuck_episode(
                &scenario.params,
                &scenario.arena,
                &scenario.layout,
                scenario.episode,
                decoder,
                seed,
                &mut (),
            )?;
            let names = scenario.layout.names();
            f.push(u8::from(r.reached()).to_string());
            f.push(names[r.goal].to_string());
            f.push(r.committed.map_or(String::new(), |c| names[c].to_string()));
            f.extend([
                format_number(r.time_secs),
                format_number(r.path_m),
                r.errps.to_string(),
                r.detected_errors.to_string(),
                r.false_detections.to_string(),
                r.missed_errors.to_string(),
                r.detected_by_phase[0].to_string(),
                r.detected_by_phase[1].to_string(),
                r.detected_by_phase[2].to_string(),
                rate(r.hit_rate()),
                rate(r.false_alarms_per_min()),
            ]);
            r.online
        }
    };
    let (_, _, acc) = overall(&online);
    f.extend([rate(online.correct), rate(online.error), rate(acc)]);
    Ok(f.join(","))
}

/// The (level, episode) of sweep episode `g`.
fn split(spec: &SweepSpec, g: usize) -> (usize, usize) {
    (g / spec.episodes, g % spec.episodes)
}

/// Checks the rows already in `path` against the slice and drops a last
/// line cut short by a crash. Returns how many complete rows it holds.
fn resume_rows(path: &Path, header: &str, spec: &SweepSpec, items: &[usize]) -> Result<usize> {
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
        std::fs::create_dir_all(out).map_err(|source| SimError::Output {
            path: out.clone(),
            source,
        })?;
        fresh.write(out)?;
    }

    // Decoders: one per distinct calibration, in parallel.
    let mut keys: Vec<String> = Vec::new();
    let mut first_level: Vec<usize> = Vec::new();
    let mut key_of = Vec::with_capacity(levels.len());
    let mut index: HashMap<String, usize> = HashMap::new();
    for level in &levels {
        let key = decoder_key(level);
        let i = *index.entry(key.clone()).or_insert_with(|| {
            keys.push(key);
            first_level.push(level.index);
            keys.len() - 1
        });
        key_of.push(i);
    }
    let shared = Shared::build(&levels)?;
    let prepared = prepare_all(&levels, &first_level, &opts.cache, &shared, observer)?;
    let manifest = Manifest {
        decoders: prepared.iter().map(|(_, i)| i.clone()).collect(),
        ..fresh
    };
    manifest.write(out)?;

    let mut tables: HashMap<String, Arc<QTable>> = HashMap::new();
    let runners: Vec<Runner> = levels
        .iter()
        .zip(&key_of)
        .map(|(level, &d)| {
            Ok(match (&level.scenario, &prepared[d].0) {
                (AnyScenario::Grid(s), Prepared::Grid(decoder)) => {
                    let q = &s.params.control.q;
                    let table = match tables.get(&format!("{q:?}")) {
                        Some(t) => t.clone(),
                        None => {
                            let t = Arc::new(QTable::compute(Grid::paper(), q)?);
                            tables.insert(format!("{q:?}"), t.clone());
                            t
                        }
                    };
                    Runner::Grid {
                        scenario: s.clone(),
                        decoder: decoder.clone(),
                        table,
                    }
                }
                (AnyScenario::Epuck(s), Prepared::Epuck(decoder)) => Runner::Epuck {
                    scenario: s.clone(),
                    decoder: decoder.clone(),
                },
                _ => unreachable!("a level's decoder is of its task"),
            })
        })
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
        match spec.task {
            SweepTask::Grid => 256,
            SweepTask::Epuck => 16,
        }
    };
    let job = EpisodeJob {
        spec,
        levels: &levels,
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
