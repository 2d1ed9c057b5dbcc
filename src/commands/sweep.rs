//! `errp sweep` and `errp merge`: argument handling, progress and printing
//! around `errp_sim`'s sweeps.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use errp_sim::Names;
use errp_sim::TaskKind;
use errp_sweep::{
    CheckedSweep, DecoderInfo, MAX_EPISODES, Shard, SweepObserver, SweepOptions, SweepOutcome,
    SweepReport, SweepSpec, TargetCache, aliases, merge_sweeps, parse_axis, prepare_sweep,
    run_sweep, sweep_scenario,
};

use crate::cli::{EegArg, parse_seed};
use crate::interrupt;
use crate::out::{errln, out, outln};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// `--task`: `grid` or `epuck`, parsed as [`TaskKind`] is.
fn task_parser() -> impl clap::builder::TypedValueParser<Value = TaskKind> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
    PossibleValuesParser::new(TaskKind::ALL.map(|t| {
        PossibleValue::new(t.as_str()).help(match t {
            TaskKind::Grid => "The 5x5 grid",
            TaskKind::Epuck => "The e-puck",
        })
    }))
    .map(|s| s.parse::<TaskKind>().expect("one of TaskKind::ALL"))
}

/// `errp sweep`.
#[derive(clap::Args)]
pub struct SweepArgs {
    /// The task. Without --scenario, its built-in scenario is swept
    /// (grid: the five fixed goals; e-puck: Mexico to Pisa); with it, it must
    /// match the scenario's `task`.
    #[arg(long, value_parser = task_parser())]
    task: Option<TaskKind>,
    /// The scenario to sweep.
    #[arg(long, value_name = "FILE.toml")]
    scenario: Option<PathBuf>,
    /// Decoder accuracy levels: start:stop:step (stop included), a list
    /// a,b,c, or one value; each in (0.5, 1) [default: 0.55:0.95:0.05; none
    /// on recordings, whose decoders have the accuracy they give].
    #[arg(long, allow_negative_numbers = true)]
    accuracy: Option<String>,
    /// Also sweep a scenario parameter, NAME=start:stop:step or NAME=a,b,c
    /// (repeatable; every combination runs). Grid: tau, epsilon, p_c,
    /// strategy, max_actions, ...; e-puck: t_e, p_c, k_n, sigma_deg,
    /// strategy, fov_deg, ...; or any dotted path into the scenario file.
    #[arg(long = "param", value_name = "NAME=VALUES", long_help = param_help())]
    params: Vec<String>,
    /// Episodes per level (1 to 1000000).
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u64).range(1..=MAX_EPISODES as u64))]
    episodes: u64,
    /// Sweep seed: every calibration and episode seed derives from it.
    #[arg(long, default_value_t = 1, value_parser = parse_seed, allow_negative_numbers = true)]
    seed: u64,
    /// Output directory (rerunning into it resumes).
    #[arg(long, value_name = "DIR", required_unless_present = "prepare_only")]
    out: Option<PathBuf>,
    /// Grid only: how EEG reaches the decoder [default: bank; per_action is
    /// about 200 times slower].
    #[arg(long, value_enum)]
    eeg: Option<EegArg>,
    /// Run only slice K of N (1 <= K <= N); merge the N directories with
    /// `errp merge`.
    #[arg(long, value_name = "K/N")]
    shard: Option<String>,
    #[command(flatten)]
    workers: Workers,
    /// On resume, drop an invalid row of DIR/episodes.csv (and the rows
    /// after it) and run them again, instead of stopping at it.
    #[arg(long)]
    repair: bool,
    /// Only prepare every level's decoder, keeping their accuracy targeting
    /// in the cache, and run no episode: the first job of a cluster sweep,
    /// so that its shards do not search the targeting again.
    #[arg(long, conflicts_with_all = ["shard", "repair", "no_cache", "out"])]
    prepare_only: bool,
    /// No progress output.
    #[arg(long)]
    quiet: bool,
}

/// Where the work runs: threads and the targeting cache (`errp sweep`,
/// `errp fit`).
#[derive(clap::Args)]
pub(crate) struct Workers {
    /// Worker threads, 1 to 1024 (default: $SLURM_CPUS_PER_TASK inside a
    /// Slurm job, else one per core). Results do not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1024))]
    threads: Option<u64>,
    /// Where targeting results are cached (default: $ERRP_CACHE_DIR, else
    /// $XDG_CACHE_HOME/errp, else ~/.cache/errp).
    #[arg(long, value_name = "DIR", conflicts_with = "no_cache")]
    cache: Option<PathBuf>,
    /// Do not read or write the targeting cache.
    #[arg(long)]
    no_cache: bool,
}

impl Workers {
    /// The targeting cache asked for.
    pub(crate) fn cache(&self) -> TargetCache {
        match (&self.cache, self.no_cache) {
            (_, true) => TargetCache::disabled(),
            (Some(dir), false) => TargetCache::new(dir),
            (None, false) => TargetCache::default_location(),
        }
    }

    /// The worker threads: `--threads`, else $SLURM_CPUS_PER_TASK, else one
    /// per core.
    pub(crate) fn pool(&self) -> Result<(rayon::ThreadPool, usize)> {
        let threads = match self.threads {
            Some(n) => n as usize,
            None => slurm_cpus().unwrap_or_else(rayon::current_num_threads),
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .context("cannot start the worker threads")?;
        Ok((pool, threads))
    }
}

/// `errp merge`.
#[derive(clap::Args)]
pub struct MergeArgs {
    /// The shard directories (all N of one sweep).
    #[arg(required = true, value_name = "DIR")]
    dirs: Vec<PathBuf>,
    /// Where the merged sweep goes.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

/// Now, for the elapsed times the program prints. Only the command line
/// reads the clock; nothing it computes depends on it.
#[allow(
    clippy::disallowed_methods,
    reason = "the elapsed times printed; nothing computed reads the clock"
)]
pub(crate) fn wall_clock() -> Instant {
    Instant::now()
}

/// Progress on a terminal (a bar), plain lines in logs, or nothing.
pub(crate) struct Progress {
    pub(crate) bar: Option<ProgressBar>,
    plain: bool,
    started: Instant,
    /// Plain progress: the last tenth of the episodes reported (a line per
    /// tenth in logs, where there is no bar).
    tenths: AtomicUsize,
}

impl Progress {
    pub(crate) fn new(quiet: bool) -> Self {
        let ci = std::env::var_os("CI").is_some_and(|v| !v.is_empty() && v != "false");
        let terminal = std::io::stderr().is_terminal();
        if quiet {
            return Self {
                bar: None,
                plain: false,
                started: wall_clock(),
                tenths: AtomicUsize::new(0),
            };
        }
        if !terminal || ci {
            return Self {
                bar: None,
                plain: true,
                started: wall_clock(),
                tenths: AtomicUsize::new(0),
            };
        }
        let bar = ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(
                "{msg:>12} [{bar:40}] {pos}/{len} ({per_sec}, {eta} left)",
            )
            .expect("a valid template")
            .progress_chars("=> "),
        );
        Self {
            bar: Some(bar),
            plain: false,
            started: wall_clock(),
            tenths: AtomicUsize::new(0),
        }
    }

    pub(crate) fn line(&self, text: &str) {
        match &self.bar {
            Some(bar) => bar.println(text),
            None if self.plain => errln!("{text}"),
            None => {}
        }
    }
}

impl SweepObserver for Progress {
    fn decoder_ready(&self, info: &DecoderInfo, done: usize, total: usize) {
        let reached = info.cv_mean.map_or("exact (oracle)".to_string(), |m| {
            format!("{:.2} % cross-validated", 100.0 * m)
        });
        let what = match &info.own_eeg {
            Some(r) => format!("recording {}", r.name),
            None => format!("accuracy {}", info.accuracy),
        };
        self.line(&format!(
            "  decoder {done}/{total}: {what} -> {reached}{} [{:.1} s]",
            if info.cached {
                " (targeting cached)"
            } else {
                ""
            },
            self.started.elapsed().as_secs_f64()
        ));
        if let Some(bar) = &self.bar {
            bar.set_message("calibrating");
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        }
    }

    fn episodes_done(&self, done: usize, total: usize) {
        // Rows are on disk from now on: a signal stops between episodes.
        interrupt::graceful(true);
        if self.plain && total > 0 {
            let tenth = 10 * done / total;
            let before = self.tenths.swap(tenth, Ordering::Relaxed);
            if tenth != before && tenth > 0 {
                errln!(
                    "  episodes {done}/{total} [{:.1} s]",
                    self.started.elapsed().as_secs_f64()
                );
            }
        }
        if let Some(bar) = &self.bar {
            if bar.message() != "episodes" {
                bar.set_message("episodes");
                bar.set_length(total as u64);
                bar.reset_eta();
            }
            bar.set_position(done as u64);
        }
    }

    fn note(&self, text: &str) {
        match &self.bar {
            Some(bar) => bar.println(format!("note: {text}")),
            None => errln!("note: {text}"),
        }
    }

    fn warning(&self, text: &str) {
        // Shown even with --quiet: something was wrong.
        match &self.bar {
            Some(bar) => bar.println(format!("warning: {text}")),
            None => errln!("warning: {text}"),
        }
    }
}

/// The sweep the flags ask for, each flag parsed (named by `NAMES`).
fn sweep_spec(args: &SweepArgs, names: Names) -> Result<SweepSpec> {
    let (task, text, path) = sweep_scenario(args.scenario.as_deref(), args.task, names)?;
    let mut spec = SweepSpec {
        task,
        scenario_path: path,
        scenario_toml: text,
        accuracies: Vec::new(),
        axes: args
            .params
            .iter()
            .map(|p| parse_axis(task, p, &names))
            .collect::<errp_sim::Result<_>>()?,
        fixed: Vec::new(),
        episodes: args.episodes as usize,
        seed: args.seed,
    };
    // On own EEG no accuracy is targeted: no default levels (the sweep's
    // check refuses --accuracy, saying why).
    let accuracy = match &args.accuracy {
        Some(a) => Some(a.as_str()),
        None => (!spec.on_own_eeg()).then_some(DEFAULT_ACCURACIES),
    };
    spec.set_levels(accuracy, args.eeg.map(EegArg::word), &names)?;
    Ok(spec)
}

/// The accuracy levels of `errp sweep` without `--accuracy`.
const DEFAULT_ACCURACIES: &str = "0.55:0.95:0.05";

/// Runs `errp sweep`. Returns false if interrupted (exit code 130).
pub fn sweep(args: &SweepArgs) -> Result<bool> {
    const NAMES: Names = Names::CLI;
    let spec = sweep_spec(args, NAMES)?;
    let shard = match &args.shard {
        Some(s) => Shard::parse(s)?,
        None => Shard::ALL,
    };
    let cache = args.workers.cache();
    // Every level is built and checked before anything is printed or
    // started; the sweep takes them checked.
    let sweep = spec.checked(&NAMES)?;
    let spec = sweep.spec();
    // A cache that cannot be used is not an error, but the user is told.
    if let Some(why) = cache.problem() {
        if args.prepare_only {
            bail!("--prepare-only keeps the targeting in the cache, and {why}");
        }
        errln!("warning: {why}");
    }
    let (pool, threads) = args.workers.pool()?;
    let progress = Progress::new(args.quiet);
    if args.prepare_only {
        return prepare(&sweep, &cache, &pool, &progress).map(|()| true);
    }
    let out = args
        .out
        .clone()
        .expect("clap requires --out without --prepare-only");
    let opts = SweepOptions {
        out,
        cache,
        shard,
        chunk: 0,
        repair: args.repair,
    };
    progress.line(&format!(
        "Sweeping {} ({}): {} levels x {} episodes{}, seed {}, into {} on {threads} thread(s)",
        spec.scenario_path.display(),
        spec.task,
        spec.n_levels(),
        spec.episodes,
        if shard.is_all() {
            String::new()
        } else {
            format!(", shard {shard}")
        },
        spec.seed,
        opts.out.display()
    ));
    let started = wall_clock();
    let outcome = pool.install(|| {
        run_sweep(&sweep, &opts, &interrupt::WIND_DOWN, &progress)
            .map_err(|e| name_flag(e, "--out", &opts.out))
    });
    interrupt::graceful(false);
    let outcome = outcome?;
    if let Some(bar) = &progress.bar {
        bar.finish_and_clear();
    }
    let secs = started.elapsed().as_secs_f64();
    match outcome {
        SweepOutcome::Interrupted { done, total } => {
            errln!(
                "Interrupted: {done} of {total} episodes are in {}. Run the same command again \
                 to resume.",
                opts.out.join("episodes.csv").display()
            );
            Ok(false)
        }
        SweepOutcome::Complete { ran, total, report } => {
            if !args.quiet {
                errln!(
                    "{ran} episodes in {secs:.1} s ({:.0} per second){}",
                    ran as f64 / secs.max(1e-9),
                    if ran < total {
                        format!("; {} were already on disk", total - ran)
                    } else {
                        String::new()
                    }
                );
            }
            if let Some(report) = report {
                print_report(&report)?;
            } else {
                outln!(
                    "Shard {shard} done: {total} episodes in {}. When all {} shards are done: \
                     errp merge DIR... --out MERGED",
                    opts.out.display(),
                    shard.count
                )?;
            }
            Ok(true)
        }
    }
}

/// The CPUs Slurm gave this job's task (`$SLURM_CPUS_PER_TASK`), if set.
fn slurm_cpus() -> Option<usize> {
    std::env::var("SLURM_CPUS_PER_TASK")
        .ok()?
        .trim()
        .parse::<usize>()
        .ok()
        .filter(|n| (1..=1024).contains(n))
}

/// `errp sweep --prepare-only`: every level's decoder once, the targeting
/// kept in the cache, a line per decoder printed.
fn prepare(
    sweep: &CheckedSweep,
    cache: &TargetCache,
    pool: &rayon::ThreadPool,
    progress: &Progress,
) -> Result<()> {
    let spec = sweep.spec();
    let dir = cache.dir().expect("checked: a cache").to_path_buf();
    progress.line(&format!(
        "Preparing the decoders of {} ({}): {} levels, seed {}, targeting cached in {} on {} \
         thread(s)",
        spec.scenario_path.display(),
        spec.task,
        spec.n_levels(),
        spec.seed,
        dir.display(),
        pool.current_num_threads()
    ));
    let infos = pool.install(|| prepare_sweep(sweep, cache, progress))?;
    if let Some(bar) = &progress.bar {
        bar.finish_and_clear();
    }
    let searched = infos.iter().filter(|i| !i.cached).count();
    outln!(
        "Prepared {} decoder(s) ({searched} searched now, {} already cached), their targeting \
         kept in {}:",
        infos.len(),
        infos.len() - searched,
        dir.display()
    )?;
    for i in &infos {
        match (i.cv_mean, i.errp_to_noise) {
            (Some(m), Some(r)) => outln!(
                "  accuracy {} -> {:.2} % cross-validated (ErrP-to-noise {r:.4}){}",
                i.accuracy,
                100.0 * m,
                if i.cached { ", cached" } else { "" }
            )?,
            _ => outln!("  accuracy {}: {} (nothing to target)", i.accuracy, i.kind)?,
        }
    }
    outln!(
        "Shards of this sweep run with the same cache now find every targeting there \
         (\"targeting cached\" in their progress)."
    )?;
    Ok(())
}

fn print_report(report: &SweepReport) -> Result<()> {
    out!("{report}")?;
    outln!("Wrote:")?;
    for f in &report.files {
        outln!("  {}", f.display())?;
    }
    Ok(())
}

/// Runs `errp merge`.
pub fn merge(args: &MergeArgs) -> Result<()> {
    let report = merge_sweeps(&args.dirs, Path::new(&args.out))
        .map_err(|e| name_flag(e, "--out", &args.out))?;
    print_report(&report)?;
    Ok(())
}

/// An error about a file under `dir` (an output directory given by `flag`)
/// names the flag; other errors name their own files.
fn name_flag(e: errp_sim::SimError, flag: &str, dir: &Path) -> anyhow::Error {
    use errp_sim::SimError;
    match &e {
        SimError::Output { path, .. } | SimError::Input { path, .. } if path.starts_with(dir) => {
            let text = format!("{flag} {}", dir.display());
            anyhow::Error::new(e).context(text)
        }
        _ => e.into(),
    }
}

/// The long help of `--param`, listing every short name (from the sweep's
/// own table, so the two cannot disagree).
fn param_help() -> String {
    format!(
        "Also sweep a scenario parameter, NAME=start:stop:step or NAME=a,b,c \
         (repeatable; every combination runs). NAME is a dotted path into the scenario \
         file (e.g. control.tau) or a short name.\n\nGrid: {}\n\nE-puck: {}",
        aliases(TaskKind::Grid),
        aliases(TaskKind::Epuck)
    )
}
