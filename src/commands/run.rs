//! `errp run`: a grid or an e-puck scenario, printed per episode and summarised.

#[cfg(feature = "rerun")]
use std::path::Path;

use anyhow::{Context, Result, bail};
use errp_bci::{OnlineStep, RequestedAccuracy};
#[cfg(feature = "rerun")]
use errp_sim::epuck::record_epuck_runs;
use errp_sim::epuck::{
    EpuckRunHeader, EpuckRunRow, EpuckScenario, EpuckSummaryReport,
    prepare_continuous_decoder_with, run_epuck_batch, summarise,
};
use errp_sim::grid::{
    DecoderChoice, EegMode, GridEpisodeHeader, GridEpisodeRow, GridRunReport, GridScenario,
    prepare_decoder, run_grid_scenario,
};
use errp_sim::{AnyScenario, load_scenario, load_scenario_with};

use crate::cli::{DecoderArg, RunArgs, calibration_progress};
use crate::out::{errln, out, outln};
use crate::save::check_save;

/// The most e-puck runs one recording holds.
const MAX_RECORDED_RUNS: usize = 100;

/// The most grid episodes one recording holds (each adds about 20 kB to
/// the file and 150 kB of memory while it is written: measured on 1000
/// episodes of `grid_fixed_goals.toml`).
const MAX_RECORDED_EPISODES: usize = 5_000;

pub(crate) fn run(args: &RunArgs) -> Result<()> {
    // Overrides are keys of the scenario file, set before it is parsed, so
    // they are checked and carried through exactly as the file's own.
    let mut overrides: Vec<(&str, toml::Value)> = Vec::new();
    if let Some(a) = args.accuracy {
        overrides.push(("user.accuracy", toml::Value::Float(a)));
    }
    // A seed of the file's range (parse_scenario_seed), so a recording's
    // scenario says it.
    if let Some(seed) = args.seed {
        overrides.push(("seed", toml::Value::Integer(seed as i64)));
    }
    // The file as written is checked first, so that its own errors quote
    // its own lines; the overrides are then set in a copy of its TOML.
    let as_written = load_scenario(&args.scenario)?;
    let epuck = matches!(as_written, AnyScenario::Epuck(_));
    let perfect = args.accuracy.map(RequestedAccuracy::new);
    if let Some(Ok(RequestedAccuracy::Perfect)) = perfect {
        let oracle = match (&as_written, args.decoder) {
            (AnyScenario::Grid(_), Some(d)) => matches!(d, DecoderArg::Oracle),
            (AnyScenario::Grid(s), None) => s.decoder == DecoderChoice::Oracle,
            (AnyScenario::Epuck(_), _) => false,
        };
        if !oracle {
            bail!(
                "--accuracy 1: only the grid's oracle decoder may be perfect (with --decoder \
                 oracle); the EEG decoders take a mean accuracy strictly between 0.5 and 1, \
                 e.g. 0.95"
            );
        }
    }
    if epuck && let Some(runs) = args.runs {
        overrides.push(("runs", toml::Value::Integer(runs as i64)));
    }
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
    let scenario = load_scenario_with(&args.scenario, &overrides)?;
    check_save(args.save.as_deref())?;
    // What a recording says it ran: the file with the overrides set.
    let text = match &args.save {
        Some(_) => errp_sim::scenario_text_with(
            &errp_sim::read_scenario(&args.scenario)?,
            &args.scenario,
            &overrides,
        )?,
        None => String::new(),
    };
    if let (AnyScenario::Epuck(s), Some(_)) = (&scenario, &args.save) {
        let runs = s.runs;
        if runs > MAX_RECORDED_RUNS {
            bail!(
                "--save with {runs} runs: a recording holds at most {MAX_RECORDED_RUNS} runs \
                 (each adds about 2.5 MB to the file and 9 MB of memory while it is written); \
                 record fewer (--runs {MAX_RECORDED_RUNS}), or run them all without --save"
            );
        }
    }
    if let (AnyScenario::Grid(s), Some(_)) = (&scenario, &args.save)
        && s.episodes.len() > MAX_RECORDED_EPISODES
    {
        bail!(
            "--save with {} episodes: a recording holds at most {MAX_RECORDED_EPISODES} grid \
             episodes (each adds about 20 kB to the file and 150 kB of memory while it is \
             written, so {:.1} GB here); record fewer (lower `repeats` in {}), or run them \
             all without --save",
            s.episodes.len(),
            s.episodes.len() as f64 * 150e3 / 1e9,
            args.scenario.display()
        );
    }
    match scenario {
        AnyScenario::Grid(s) => {
            if args.runs.is_some() {
                bail!(
                    "--runs applies to e-puck scenarios; a grid scenario lists its episodes \
                     (set `repeats` in {})",
                    args.scenario.display()
                );
            }
            run_grid(args, *s, text)
        }
        AnyScenario::Epuck(s) => {
            if args.decoder.is_some() || args.eeg.is_some() {
                bail!(
                    "--decoder and --eeg apply to grid scenarios; the e-puck task always runs \
                     the streamed EEG through the sliding-window SVM"
                );
            }
            run_epuck(args, *s, text)
        }
    }
}

/// The provenance of a recording of `task` by this command.
#[cfg(feature = "rerun")]
fn provenance(
    task: &str,
    name: &str,
    text: String,
    seed: u64,
    decoder_summary: String,
) -> errp_sim::record::data::Provenance {
    let mut p = errp_sim::record::data::Provenance::new(task, name, text, seed);
    p.commit = crate::commands::fit::COMMIT.to_string();
    p.command = crate::commands::command_line();
    p.decoder_summary = decoder_summary;
    p
}

pub(crate) fn run_grid(args: &RunArgs, mut scenario: GridScenario, text: String) -> Result<()> {
    if args.accuracy.is_some() {
        scenario.user.push_str(" (--accuracy)");
    }
    #[cfg(feature = "rerun")]
    let rrd = open_recording(args, errp_sim::grid::grid_recording)?;
    let quiet = args.quiet;
    if !quiet {
        errln!(
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
    let decoder_summary = match &calibration {
        Some(c) => format!(
            "Decoder calibrated on 400 actions: mean accuracy {:.2} % on held-out epochs (the \
             target; correct {:.2} %, error {:.2} %), {:.2} % cross-validated\n",
            100.0 * c.targeting.accuracy.mean(),
            100.0 * c.targeting.accuracy.correct,
            100.0 * c.targeting.accuracy.error,
            100.0 * c.calibrated.accuracy.mean()
        ),
        None => String::new(),
    };
    out!("{decoder_summary}")?;
    #[cfg(not(feature = "rerun"))]
    let _ = (text, &decoder_summary);
    outln!("{GridEpisodeHeader}")?;
    // A standard output that fails stops nothing here (the episodes run
    // on); the first failure is the command's.
    let mut printed = Ok(());
    let episodes = run_grid_scenario(&scenario, &decoder, args.save.is_some(), |k, r| {
        if printed.is_ok() {
            printed = outln!("{}", GridEpisodeRow(k, r));
        }
    })?;
    printed?;
    let report = GridRunReport {
        scenario,
        calibration,
        episodes,
    };
    out!("{report}")?;
    #[cfg(feature = "rerun")]
    if let Some(file) = rrd {
        let p = provenance(
            "grid",
            &report.scenario.name,
            text,
            report.scenario.seed,
            decoder_summary,
        );
        crate::save::wrote(&errp_sim::grid::record_grid_run(file, &report, &p).context("--save")?)?;
    }
    Ok(())
}

pub(crate) fn run_epuck(args: &RunArgs, scenario: EpuckScenario, text: String) -> Result<()> {
    #[cfg(feature = "rerun")]
    let rrd = open_recording(args, errp_sim::epuck::epuck_recording)?;
    let quiet = args.quiet;
    let decoder_text = scenario.decoder_text();
    let layout = &scenario.layout;
    let start = &scenario.episode.start;
    let goal = &layout.goals()[scenario.episode.goal].name;
    if !quiet {
        errln!(
            "{}: e-puck from ({:.0}, {:.0}) cm to {goal}, {} run(s), {decoder_text}, seed {}{}",
            scenario.name,
            100.0 * start.x_m,
            100.0 * start.y_m,
            scenario.runs,
            scenario.seed,
            if scenario.user_seed == scenario.seed {
                String::new()
            } else {
                format!(" (user seed {})", scenario.user_seed)
            }
        );
    }
    let (decoder, report) = prepare_continuous_decoder_with(
        &scenario,
        calibration_progress(quiet),
        |s: &OnlineStep| {
            if !quiet {
                errln!(
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
    let mut decoder_summary = format!(
        "SVM decoder calibrated on {} error + {} correct button-locked examples: correct {:.2} %, \
         error {:.2} %, mean {:.2} % (cross-validated); {} support vectors\n",
        acc.n_error,
        acc.n_correct,
        100.0 * acc.correct,
        100.0 * acc.error,
        100.0 * acc.mean(),
        decoder.model.n_support()
    );
    if let Some(online) = &decoder.online {
        decoder_summary.push_str(&online.to_string());
    }
    out!("{decoder_summary}")?;
    #[cfg(feature = "rerun")]
    let recorded = match &rrd {
        Some(file) => {
            let p = provenance(
                "epuck",
                &scenario.name,
                text,
                scenario.seed,
                decoder_summary,
            );
            Some(record_epuck_runs(file, &scenario, &decoder, &p)?)
        }
        None => None,
    };
    #[cfg(not(feature = "rerun"))]
    let recorded = {
        let _ = (text, decoder_summary);
        None
    };
    let results = match recorded {
        Some(results) => results,
        None => {
            if !quiet && scenario.runs > 1 {
                errln!("  running {} runs in parallel", scenario.runs);
            }
            run_epuck_batch(&scenario, &decoder, scenario.runs)?
        }
    };
    print_epuck_runs(&results, layout)?;
    let summary = summarise(&results);
    out!(
        "{}",
        EpuckSummaryReport {
            summary: &summary,
            scenario: &scenario.name,
            goal,
            t_e: decoder.detector_t_e(&scenario.params, false),
        }
    )?;
    #[cfg(feature = "rerun")]
    if let Some(file) = rrd {
        crate::save::wrote(&file.finish().context("--save")?)?;
    }
    Ok(())
}

/// The `--save` recording, created before any work, so that an unwritable
/// path fails first.
#[cfg(feature = "rerun")]
fn open_recording<T>(
    args: &RunArgs,
    open: impl FnOnce(&Path) -> errp_sim::Result<T>,
) -> Result<Option<T>> {
    match &args.save {
        Some(path) => Ok(Some(open(path).context("--save")?)),
        None => Ok(None),
    }
}

/// Prints the per-run table of e-puck `results` (`errp run`, and `errp
/// inspect` from a recording).
pub(crate) fn print_epuck_runs(
    results: &[errp_sim::epuck::EpuckEpisodeResult],
    layout: &errp_robot::GoalLayout,
) -> Result<()> {
    outln!("{EpuckRunHeader}")?;
    for (index, result) in results.iter().enumerate() {
        outln!(
            "{}",
            EpuckRunRow {
                index,
                result,
                layout
            }
        )?;
    }
    Ok(())
}
