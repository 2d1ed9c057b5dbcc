//! `errp`: the command-line program of errp-testbed.
//!
//! Thin glue: parse arguments, call the libraries, print, write files.

mod sweep_cmd;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand, ValueEnum};
use errp_bci::{EdfWriter, GoalSet, OnlineStep, TargetingStep, subject, subjects};
use errp_sim::calibration::{
    CalibrationRequest, calibration_recording, record_calibration, run_calibration,
};
use errp_sim::epuck::{
    EpuckRecorder, EpuckScenario, epuck_recording, prepare_continuous_decoder_with,
    run_epuck_batch, run_epuck_once, summarise,
};
use errp_sim::grid::{
    DecoderChoice, EegMode, GridRunReport, GridScenario, Table1Options, accuracy_time_correlation,
    grid_recording, prepare_decoder, record_grid_run, run_grid_scenario, run_table1,
};
use errp_sim::{AnyScenario, PAPER_EPUCK, load_scenario, load_scenario_with};
use errp_sim::{PAPER, PAPER_POOLED, PendingFile, mean_sd};

/// Simulated shared control of a robot from EEG error potentials.
#[derive(Parser)]
#[command(name = "errp", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Calibrate the ErrP decoder of a synthetic user at a requested accuracy.
    ///
    /// Searches the ErrP-to-noise ratio of the synthetic EEG so that the
    /// paper's decoder (z-score, PCA 95 %, shrinkage LDA), cross-validated on a
    /// 400-action calibration session with 20 % errors, reaches the requested
    /// mean accuracy; then runs that session and reports per-class rates.
    Calibrate(CalibrateArgs),
    /// Run a scenario: the e-puck in its arena steered by the sliding-window
    /// ErrP decoder (sec. 5), or episodes of the grid task (sec. 4), printed
    /// per run and summarised next to the paper.
    Run(RunArgs),
    /// Re-run Table 1: subjects S1-S4 at their accuracies on the fixed and
    /// free goals, side by side with the paper, with the accuracy-time
    /// correlation.
    Table1(Table1Args),
    /// List the subjects of Table 1 of the paper and their accuracies.
    Subjects,
    /// Monte Carlo sweep over decoder accuracy (and any scenario parameter):
    /// episodes in parallel, streamed to DIR/episodes.csv (a rerun resumes),
    /// then DIR/summary.csv, a printed table, DIR/sweep.svg and .png, and
    /// DIR/sweep.json to rerun it exactly.
    Sweep(sweep_cmd::SweepArgs),
    /// Merge the directories of a sharded sweep (`errp sweep --shard K/N`)
    /// into the files one unsharded run writes.
    Merge(sweep_cmd::MergeArgs),
}

#[derive(Clone, Copy, ValueEnum)]
enum Goals {
    /// The five goals shared by all subjects.
    Fixed,
    /// The goals each subject chose.
    Free,
}

#[derive(clap::Args)]
struct CalibrateArgs {
    /// Requested mean accuracy (mean of the correct- and error-class rates),
    /// strictly between 0.5 and 1. Default: 0.7438, the paper's mean over
    /// subjects with the fixed goals.
    #[arg(long, value_parser = parse_accuracy, conflicts_with = "subject", allow_negative_numbers = true)]
    accuracy: Option<f64>,
    /// Take the accuracy of a subject of Table 1 (S1..S4) instead.
    #[arg(long)]
    subject: Option<String>,
    /// Which of the subject's accuracies: fixed or free goals.
    #[arg(long, value_enum, default_value = "fixed", requires = "subject")]
    goals: Goals,
    /// Seed of the synthetic user and session.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Record grand averages, a topography and the summary to this `.rrd`.
    #[arg(long, value_name = "FILE.rrd")]
    save: Option<PathBuf>,
    /// Write the raw synthetic EEG + EOG of the session, with `error` /
    /// `correct` annotations, to this EDF+ file.
    #[arg(long, value_name = "FILE.edf")]
    export: Option<PathBuf>,
    /// Print only the results, not the search.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum DecoderArg {
    /// Synthetic EEG through the real preprocessing and decoder.
    Eeg,
    /// Assessments flipped with probability 1 - accuracy, no EEG.
    Oracle,
}

#[derive(Clone, Copy, ValueEnum)]
enum EegArg {
    /// Synthesise each action's EEG when it happens.
    Stream,
    /// Draw preprocessed epochs from a bank streamed in advance.
    Bank,
}

impl EegArg {
    fn mode(self) -> EegMode {
        match self {
            EegArg::Stream => EegMode::Stream,
            EegArg::Bank => EegMode::Bank,
        }
    }
}

#[derive(clap::Args)]
struct RunArgs {
    /// The scenario file (TOML), e.g. scenarios/mexico_to_pisa.toml or
    /// scenarios/grid_fixed_goals.toml.
    scenario: PathBuf,
    /// Override the scenario's seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Override the scenario's decoder (grid scenarios).
    #[arg(long, value_enum)]
    decoder: Option<DecoderArg>,
    /// Override the decoder's accuracy (mean of the per-class rates, in
    /// (0.5, 1)).
    #[arg(long, value_parser = parse_accuracy, allow_negative_numbers = true)]
    accuracy: Option<f64>,
    /// Override the number of runs (e-puck scenarios); each run has its own
    /// seed derived from the scenario's.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    runs: Option<u64>,
    /// Override how the EEG reaches the decoder: streamed or from a bank
    /// (grid scenarios).
    #[arg(long, value_enum)]
    eeg: Option<EegArg>,
    /// Record every episode to this `.rrd`. Grid: cursor, goal, posterior,
    /// visited states, p(error), EEG at FCz, event log. E-puck: arena,
    /// cities coloured by belief, robot, trajectory, detected errors, belief
    /// bars and series, p(error) and T_e, EEG at FCz and Cz, event log.
    #[arg(long, value_name = "FILE.rrd")]
    save: Option<PathBuf>,
    /// Print only the results.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(clap::Args)]
struct Table1Args {
    /// Runs per start/goal pair (5 pairs per subject and goal set).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=1000))]
    episodes: u64,
    /// Base seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// EEG decoder (default) or oracle.
    #[arg(long, value_enum, default_value = "eeg")]
    decoder: DecoderArg,
    /// Stream each action's EEG (default) or draw epochs from a bank of
    /// 1000 per class streamed in advance (much faster).
    #[arg(long, value_enum, default_value = "stream")]
    eeg: EegArg,
    /// Print only the results.
    #[arg(long, short)]
    quiet: bool,
}

fn parse_accuracy(s: &str) -> Result<f64, String> {
    let v: f64 = s.trim().parse().map_err(|_| {
        format!(
            "{s:?} is not a number: give a mean accuracy strictly between 0.5 and 1 as a \
                 fraction, e.g. 0.7438"
        )
    })?;
    errp_bci::check_requested_accuracy(v).map_err(|_| {
        format!(
            "{s} is out of range: give a mean accuracy strictly between 0.5 (chance) and 1 \
             as a fraction, e.g. 0.7438 for 74.38 %"
        )
    })?;
    Ok(v)
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Calibrate(args) => calibrate(&args),
        Command::Run(args) => run(&args),
        Command::Table1(args) => table1(&args),
        Command::Subjects => {
            print_subjects();
            Ok(())
        }
        Command::Merge(args) => sweep_cmd::merge(&args),
        Command::Sweep(args) => match sweep_cmd::sweep(&args) {
            Ok(true) => Ok(()),
            Ok(false) => return ExitCode::from(130),
            Err(e) => Err(e),
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn print_subjects() {
    println!("subject  fixed goals  free goals   (mean accuracy, Table 1)");
    for s in subjects() {
        println!(
            "{:<8} {:>9.2} %  {:>8.2} %",
            s.name, s.fixed_goals_pct, s.free_goals_pct
        );
    }
}

fn check_extension(path: &Path, ext: &str, flag: &str) -> Result<()> {
    if path.extension().and_then(|e| e.to_str()) != Some(ext) {
        bail!(
            "{flag} {}: the file name must end in .{ext}",
            path.display()
        );
    }
    Ok(())
}

fn calibrate(args: &CalibrateArgs) -> Result<()> {
    let (accuracy, who) = match &args.subject {
        Some(name) => {
            let s = subject(name).context("--subject")?;
            let goals = match args.goals {
                Goals::Fixed => GoalSet::Fixed,
                Goals::Free => GoalSet::Free,
            };
            let a = s.accuracy(goals);
            (
                a,
                format!("subject {} ({:?} goals)", s.name, goals).to_lowercase(),
            )
        }
        None => (args.accuracy.unwrap_or(0.7438), "requested".to_string()),
    };
    if let Some(p) = &args.save {
        check_extension(p, "rrd", "--save")?;
    }
    if let Some(p) = &args.export {
        check_extension(p, "edf", "--export")?;
    }
    // Reserve the outputs first: an unwritable path fails before the work.
    let mut edf = match &args.export {
        Some(p) => {
            let (pending, file) = PendingFile::create(p)?;
            let montage = errp_bci::Montage::standard();
            let writer = EdfWriter::new(std::io::BufWriter::new(file), &montage, 256.0)?;
            Some((pending, writer))
        }
        None => None,
    };
    let rrd = match &args.save {
        Some(p) => Some(calibration_recording(p)?),
        None => None,
    };

    let mut request = CalibrationRequest::new(accuracy, args.seed);
    request.grand_average = args.save.is_some();
    if !args.quiet {
        eprintln!(
            "Targeting a mean accuracy of {:.2} % ({who}), seed {}:",
            100.0 * accuracy,
            args.seed
        );
    }
    let quiet = args.quiet;
    let progress = |s: &errp_bci::TargetingStep| {
        if !quiet {
            eprintln!(
                "  ErrP-to-noise {:.4}: correct {:.2} %, error {:.2} %, mean {:.2} %",
                s.ratio,
                100.0 * s.accuracy.correct,
                100.0 * s.accuracy.error,
                100.0 * s.accuracy.mean()
            );
        }
    };
    let mut sink = |block: &errp_bci::EegBlock, events: &[errp_bci::Assessment]| match edf.as_mut()
    {
        Some((_, w)) => w.write(block, events),
        None => Ok(()),
    };
    let report = run_calibration(
        &request,
        progress,
        if args.export.is_some() {
            Some(&mut sink)
        } else {
            None
        },
    )
    .context("calibration failed")?;

    let a = &report.calibrated.accuracy;
    let m = &report.calibrated.model;
    println!(
        "Calibration session: {} actions ({} error, {} correct), {}-fold cross-validation",
        a.n_correct + a.n_error,
        a.n_error,
        a.n_correct,
        request.setup.calibration.folds
    );
    println!("  correct class  {:6.2} %", 100.0 * a.correct);
    println!("  error class    {:6.2} %", 100.0 * a.error);
    println!(
        "  mean           {:6.2} %   ({who} {:.2} %, off by {:+.2} points)",
        100.0 * a.mean(),
        100.0 * accuracy,
        100.0 * (a.mean() - accuracy)
    );
    println!(
        "  ErrP-to-noise ratio {:.4}; decoder: {} PCA components, Ledoit-Wolf shrinkage {:.3}",
        report.generator.errp_to_noise,
        m.n_components(),
        m.shrinkage()
    );

    if let Some((pending, writer)) = edf {
        writer.finish()?;
        let path = pending.commit()?;
        println!(
            "Wrote {} (EDF+, raw EEG + EOG, 256 Hz, annotated)",
            path.display()
        );
    }
    if let Some(file) = rrd {
        let montage = errp_bci::Montage::standard();
        let path = record_calibration(file, &report, &montage)?;
        println!(
            "Wrote {} (open with: rerun {})",
            path.display(),
            path.display()
        );
    }
    Ok(())
}

fn run(args: &RunArgs) -> Result<()> {
    // Overrides are keys of the scenario file, set before it is parsed, so
    // they are checked and carried through exactly as the file's own.
    let mut overrides: Vec<(&str, toml::Value)> = Vec::new();
    if let Some(a) = args.accuracy {
        overrides.push(("user.accuracy", toml::Value::Float(a)));
    }
    // The file as written is checked first, so that its own errors quote
    // its own lines; the overrides are then set in a copy of its TOML.
    let epuck = matches!(load_scenario(&args.scenario)?, AnyScenario::Epuck(_));
    if !epuck {
        if let Some(d) = args.decoder {
            let name = match d {
                DecoderArg::Eeg => "eeg",
                DecoderArg::Oracle => "oracle",
            };
            overrides.push(("decoder", toml::Value::String(name.into())));
        }
        if let Some(e) = args.eeg {
            let name = match e.mode() {
                EegMode::Stream => "stream",
                EegMode::Bank => "bank",
            };
            overrides.push(("eeg", toml::Value::String(name.into())));
        }
    }
    match load_scenario_with(&args.scenario, &overrides)? {
        AnyScenario::Grid(s) => {
            if args.runs.is_some() {
                bail!(
                    "--runs applies to e-puck scenarios; a grid scenario lists its episodes \
                     (set `repeats` in {})",
                    args.scenario.display()
                );
            }
            run_grid(args, *s)
        }
        AnyScenario::Epuck(s) => {
            if args.decoder.is_some() || args.eeg.is_some() {
                bail!(
                    "--decoder and --eeg apply to grid scenarios; the e-puck task always runs \
                     the streamed EEG through the sliding-window SVM"
                );
            }
            run_epuck(args, *s)
        }
    }
}

/// Prints each accuracy-targeting step to stderr, unless `quiet`.
fn calibration_progress(quiet: bool) -> impl FnMut(&TargetingStep) {
    move |s| {
        if !quiet {
            eprintln!(
                "  calibrating: ErrP-to-noise {:.4} -> mean {:.2} %",
                s.ratio,
                100.0 * s.accuracy.mean()
            );
        }
    }
}

fn run_grid(args: &RunArgs, mut scenario: GridScenario) -> Result<()> {
    if let Some(seed) = args.seed {
        scenario.seed = seed;
    }
    if args.accuracy.is_some() {
        scenario.user.push_str(" (--accuracy)");
    }
    if let Some(p) = &args.save {
        check_extension(p, "rrd", "--save")?;
    }
    let rrd = match &args.save {
        Some(p) => Some(grid_recording(p)?),
        None => None,
    };
    let quiet = args.quiet;
    if !quiet {
        eprintln!(
            "{}: {} episodes, {} decoder at {:.2} % ({}), seed {}",
            scenario.name,
            scenario.episodes.len(),
            match scenario.decoder {
                DecoderChoice::Eeg => "EEG",
                DecoderChoice::Oracle => "oracle",
            },
            100.0 * scenario.accuracy,
            scenario.user,
            scenario.seed
        );
    }
    let (decoder, calibration) = prepare_decoder(&scenario, calibration_progress(quiet))
        .context("calibrating the decoder")?;
    if let Some(c) = &calibration {
        println!(
            "Decoder calibrated on 400 actions: correct {:.2} %, error {:.2} %, mean {:.2} % (cross-validated)",
            100.0 * c.calibrated.accuracy.correct,
            100.0 * c.calibrated.accuracy.error,
            100.0 * c.calibrated.accuracy.mean()
        );
    }
    println!(
        "{:>3}  {:>6} {:>6}  {:>13}  {:>7}  {:>8}  {:>9}  {:>8} {:>8} {:>8}",
        "#",
        "start",
        "goal",
        "committed",
        "actions",
        "net (s)",
        "total (s)",
        "acc corr",
        "acc err",
        "acc mean"
    );
    let episodes = run_grid_scenario(&scenario, &decoder, args.save.is_some(), |k, r| {
        let committed = match r.committed {
            Some(c) if c == r.goal => format!("{c} ok"),
            Some(c) => format!("{c} WRONG"),
            None => "none".to_string(),
        };
        let pct = |v: f64| {
            if v.is_nan() {
                "-".to_string()
            } else {
                format!("{:.1}", 100.0 * v)
            }
        };
        println!(
            "{:>3}  {:>6} {:>6}  {:>13}  {:>7}  {:>8.2}  {:>9.2}  {:>8} {:>8} {:>8}",
            k + 1,
            r.start.to_string(),
            r.goal.to_string(),
            committed,
            r.actions,
            r.net_secs,
            r.total_secs,
            pct(r.online.correct),
            pct(r.online.error),
            pct(r.online.mean())
        );
    })?;
    let report = GridRunReport {
        scenario,
        calibration,
        episodes,
    };
    let n = report.episodes.len();
    let reached = report.episodes.iter().filter(|r| r.reached()).count();
    let col = |f: fn(&errp_sim::grid::GridEpisodeResult) -> f64| {
        mean_sd(&report.episodes.iter().map(f).collect::<Vec<_>>())
    };
    let (am, asd) = col(|r| r.actions as f64);
    let (nm, nsd) = col(|r| r.net_secs);
    let (tm, tsd) = col(|r| r.total_secs);
    let online = report.online_accuracy();
    println!("Summary over {n} episodes:");
    println!("  goals reached    {reached} / {n}");
    println!("  actions          {am:.1} +- {asd:.1}");
    println!("  net time (s)     {nm:.2} +- {nsd:.2}");
    println!("  total time (s)   {tm:.2} +- {tsd:.2}");
    println!(
        "  online accuracy  correct {:.2} %, error {:.2} %, mean {:.2} % over {} actions",
        100.0 * online.correct,
        100.0 * online.error,
        100.0 * online.mean(),
        online.n_correct + online.n_error
    );
    if let Some(file) = rrd {
        let path = record_grid_run(file, &report)?;
        println!(
            "Wrote {} (open with: rerun {})",
            path.display(),
            path.display()
        );
    }
    Ok(())
}

fn table1(args: &Table1Args) -> Result<()> {
    let options = Table1Options {
        repeats: args.episodes as usize,
        seed: args.seed,
        decoder: match args.decoder {
            DecoderArg::Eeg => DecoderChoice::Eeg,
            DecoderArg::Oracle => DecoderChoice::Oracle,
        },
        eeg: args.eeg.mode(),
        params: errp_sim::grid::GridTaskParams::default(),
    };
    let quiet = args.quiet;
    if !quiet {
        eprintln!(
            "Table 1: 4 subjects x 2 goal sets x {} runs, seed {} (calibrating 8 decoders in parallel)",
            5 * options.repeats,
            options.seed
        );
    }
    let cells = run_table1(&options, |label, s| {
        if !quiet {
            eprintln!(
                "  {label}: ErrP-to-noise {:.4} -> {:.2} %",
                s.ratio,
                100.0 * s.accuracy.mean()
            );
        }
    })?;
    println!(
        "{:<10} {:>8}  {:>18}  {:>22}  {:>24}  {:>22}",
        "", "reached", "actions", "net time (s)", "total time (s)", "mean accuracy (%)"
    );
    println!(
        "{:<10} {:>8}  {:>18}  {:>22}  {:>24}  {:>22}",
        "", "", "ours [paper]", "ours [paper]", "ours [paper]", "ours [paper]"
    );
    let fmt = |(m, sd): (f64, f64), (pm, psd): (f64, f64), d: usize| {
        format!("{m:.d$}+-{sd:.d$} [{pm:.d$}+-{psd:.d$}]")
    };
    for set in [GoalSet::Fixed, GoalSet::Free] {
        let set_name = if set == GoalSet::Fixed {
            "fixed"
        } else {
            "free"
        };
        let mut all: Vec<&errp_sim::grid::GridEpisodeResult> = Vec::new();
        for c in cells.iter().filter(|c| c.goals == set) {
            let paper = PAPER
                .iter()
                .find(|p| p.0 == c.subject && p.1 == set)
                .map(|p| p.2)
                .unwrap_or([f64::NAN; 8]);
            let reached = c.runs.iter().filter(|r| r.reached()).count();
            println!(
                "{:<10} {:>8}  {:>18}  {:>22}  {:>24}  {:>22}",
                format!("{} {set_name}", c.subject),
                format!("{reached}/{}", c.runs.len()),
                fmt(c.stat(|r| r.actions as f64), (paper[0], paper[1]), 0),
                fmt(c.stat(|r| r.net_secs), (paper[2], paper[3]), 2),
                fmt(c.stat(|r| r.total_secs), (paper[4], paper[5]), 2),
                fmt(c.stat(|r| 100.0 * r.online.mean()), (paper[6], paper[7]), 2),
            );
            all.extend(c.runs.iter());
        }
        let stat = |f: &dyn Fn(&errp_sim::grid::GridEpisodeResult) -> f64| {
            mean_sd(&all.iter().map(|r| f(r)).collect::<Vec<_>>())
        };
        let (paper_mean, paper_r, paper_p) = PAPER_POOLED
            .iter()
            .find(|p| p.0 == set)
            .map(|p| (p.1, p.2, p.3))
            .expect("both goal sets are in the paper's table");
        let reached = all.iter().filter(|r| r.reached()).count();
        println!(
            "{:<10} {:>8}  {:>18}  {:>22}  {:>24}  {:>22}",
            format!("mean {set_name}"),
            format!("{reached}/{}", all.len()),
            fmt(
                stat(&|r| r.actions as f64),
                (paper_mean[0], paper_mean[1]),
                0
            ),
            fmt(stat(&|r| r.net_secs), (paper_mean[2], paper_mean[3]), 2),
            fmt(stat(&|r| r.total_secs), (paper_mean[4], paper_mean[5]), 2),
            fmt(
                stat(&|r| 100.0 * r.online.mean()),
                (paper_mean[6], paper_mean[7]),
                2
            ),
        );
        let (r, p) = accuracy_time_correlation(&cells, set);
        println!(
            "           accuracy vs total time ({set_name} goals): r = {r:.2}, p = {p:.2e}   [paper: r = {paper_r}, p = {paper_p:.2e}]"
        );
    }
    Ok(())
}

fn run_epuck(args: &RunArgs, mut scenario: EpuckScenario) -> Result<()> {
    if let Some(seed) = args.seed {
        scenario.seed = seed;
    }
    if let Some(runs) = args.runs {
        scenario.runs = runs as usize;
    }
    if let Some(p) = &args.save {
        check_extension(p, "rrd", "--save")?;
    }
    let rrd = match &args.save {
        Some(p) => Some(epuck_recording(p)?),
        None => None,
    };
    let quiet = args.quiet;
    let decoder_text = match scenario.online_target {
        None => format!("decoder accuracy {:.2} %", 100.0 * scenario.accuracy),
        Some(t) => format!(
            "decoder calibrated online for {:.1} % hits{}",
            100.0 * t.hit_rate,
            t.false_alarms_per_min
                .map(|f| format!(" at {f} false alarms per minute"))
                .unwrap_or_default()
        ),
    };
    let layout = &scenario.layout;
    let start = &scenario.episode.start;
    let goal = &layout.goals()[scenario.episode.goal].name;
    if !quiet {
        eprintln!(
            "{}: e-puck from ({:.0}, {:.0}) cm to {goal}, {} run(s), {decoder_text}, seed {}",
            scenario.name,
            100.0 * start.x_m,
            100.0 * start.y_m,
            scenario.runs,
            scenario.seed
        );
    }
    let (decoder, report) = prepare_continuous_decoder_with(
        &scenario,
        calibration_progress(quiet),
        |s: &OnlineStep| {
            if !quiet {
                eprintln!(
                    "  calibrating: ErrP-to-noise {:.4}, T_e {:.3} -> {:.1} % hits, {:.2} false alarms/min",
                    s.ratio,
                    s.t_e,
                    100.0 * s.point.hit_rate,
                    s.point.false_alarms_per_min
                );
            }
        },
    )
    .context("calibrating the continuous decoder")?;
    let acc = report.calibrated.accuracy;
    println!(
        "SVM decoder calibrated on {} error + {} correct button-locked examples: correct {:.2} %, \
         error {:.2} %, mean {:.2} % (cross-validated); {} support vectors",
        acc.n_error,
        acc.n_correct,
        100.0 * acc.correct,
        100.0 * acc.error,
        100.0 * acc.mean(),
        decoder.model.n_support()
    );
    if let Some(online) = &decoder.online {
        print!("{online}");
    }
    let results = match &rrd {
        Some(file) => {
            let mut recorder = EpuckRecorder::new(
                file,
                &scenario.arena,
                layout,
                decoder.t_e(scenario.params.control.t_e),
            )?;
            let mut out = Vec::with_capacity(scenario.runs);
            for k in 0..scenario.runs {
                recorder.next_run(&format!(
                    "run {}: the user wants {goal} ({decoder_text})",
                    k + 1
                ));
                out.push(run_epuck_once(&scenario, &decoder, k, &mut recorder)?);
            }
            recorder.finish()?;
            out
        }
        None => {
            if !quiet && scenario.runs > 1 {
                eprintln!("  running {} runs in parallel", scenario.runs);
            }
            run_epuck_batch(&scenario, &decoder, scenario.runs)?
        }
    };
    println!(
        "{:>4}  {:<16} {:>8}  {:>8} {:>6} {:>6} {:>6}  {:>8} {:>8}  {:>5} {:>6}",
        "run",
        "converged on",
        "time (s)",
        "detected",
        "false",
        "missed",
        "ErrPs",
        "acc corr",
        "acc err",
        "hit %",
        "FA/min"
    );
    for (k, r) in results.iter().enumerate() {
        let on = match r.committed {
            Some(c) if c == r.goal => layout.goals()[c].name.clone(),
            Some(c) => format!("{} WRONG", layout.goals()[c].name),
            None => "time-out".into(),
        };
        println!(
            "{:>4}  {:<16} {:>8.1}  {:>8} {:>6} {:>6} {:>6}  {:>8.1} {:>8.1}  {:>5.0} {:>6.2}",
            k + 1,
            on,
            r.time_secs,
            r.detected_errors,
            r.false_detections,
            r.missed_errors,
            r.errps,
            100.0 * r.online.correct,
            100.0 * r.online.error,
            100.0 * r.hit_rate(),
            r.false_alarms_per_min()
        );
    }
    let s = summarise(&results);
    println!("Summary over {} run(s):", s.runs);
    println!(
        "  reached {goal}      {} / {} ({} converged on a wrong city)",
        s.reached, s.runs, s.wrong
    );
    let paper = PAPER_EPUCK.iter().find(|p| p.0 == scenario.name);
    let paper_note = |v: Option<String>| v.map(|v| format!("   [paper: {v}]")).unwrap_or_default();
    println!(
        "  median time (s)      {:.1}{}",
        s.median_secs,
        paper_note(paper.map(|p| format!("{:.0}", p.1)))
    );
    println!(
        "  median detected      {:.1}{}",
        s.median_detected,
        paper_note(paper.map(|p| p.2.to_string()))
    );
    println!("  median false         {:.1}", s.median_false);
    println!(
        "  detections           {:.3} per second of run; {:.0} % turning, {:.0} % driving, \
         {:.0} % on a goal   [paper: 0.18 and 0.21, mostly during turns]",
        s.detections_per_sec,
        100.0 * s.phase_shares[0],
        100.0 * s.phase_shares[1],
        100.0 * s.phase_shares[2]
    );
    println!(
        "  true detections      of ErrPs judging a turn {:.0} %, a drive {:.0} %, a stop {:.0} %",
        100.0 * s.judged_shares[0],
        100.0 * s.judged_shares[1],
        100.0 * s.judged_shares[2]
    );
    println!(
        "  online detector      hit rate {:.1} % per ErrP, {:.2} false alarms per error-free minute",
        100.0 * s.hit_rate,
        s.false_alarms_per_min
    );
    println!(
        "  window accuracy      correct {:.2} %, error {:.2} % at T_e = {} ({} clean / {} ErrP windows)",
        100.0 * s.online.correct,
        100.0 * s.online.error,
        decoder.t_e(scenario.params.control.t_e),
        s.online.n_correct,
        s.online.n_error
    );
    if let Some(file) = rrd {
        let path = file.finish()?;
        println!(
            "Wrote {} (open with: rerun {})",
            path.display(),
            path.display()
        );
    }
    Ok(())
}
