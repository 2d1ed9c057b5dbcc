//! `errp run`: a grid or an e-puck scenario, printed per episode and summarised.

use std::path::Path;

use anyhow::{Context, Result, bail};
use errp_bci::OnlineStep;
use errp_sim::epuck::{
    EpuckRecorder, EpuckRunHeader, EpuckRunRow, EpuckScenario, EpuckSummaryReport, epuck_recording,
    prepare_continuous_decoder_with, run_epuck_batch, run_epuck_once, summarise,
};
use errp_sim::grid::{
    DecoderChoice, EegMode, GridEpisodeHeader, GridEpisodeRow, GridRunReport, GridScenario,
    grid_recording, prepare_decoder, record_grid_run, run_grid_scenario,
};
use errp_sim::{AnyScenario, load_scenario, load_scenario_with};

use crate::cli::{DecoderArg, RunArgs, calibration_progress, check_extension};

pub(crate) fn run(args: &RunArgs) -> Result<()> {
    // Overrides are keys of the scenario file, set before it is parsed, so
    // they are checked and carried through exactly as the file's own.
    let mut overrides: Vec<(&str, toml::Value)> = Vec::new();
    if let Some(a) = args.accuracy {
        overrides.push(("user.accuracy", toml::Value::Float(a.get())));
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

pub(crate) fn run_grid(args: &RunArgs, mut scenario: GridScenario) -> Result<()> {
    if let Some(seed) = args.seed {
        scenario.seed = seed;
    }
    if args.accuracy.is_some() {
        scenario.user.push_str(" (--accuracy)");
    }
    let rrd = open_recording(args, grid_recording)?;
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
    println!("{GridEpisodeHeader}");
    let episodes = run_grid_scenario(&scenario, &decoder, args.save.is_some(), |k, r| {
        println!("{}", GridEpisodeRow(k, r));
    })?;
    let report = GridRunReport {
        scenario,
        calibration,
        episodes,
    };
    print!("{report}");
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

pub(crate) fn run_epuck(args: &RunArgs, mut scenario: EpuckScenario) -> Result<()> {
    if let Some(seed) = args.seed {
        scenario.seed = seed;
    }
    if let Some(runs) = args.runs {
        scenario.runs = runs as usize;
    }
    let rrd = open_recording(args, epuck_recording)?;
    let quiet = args.quiet;
    let decoder_text = match scenario.online_target {
        None => format!("decoder accuracy {:.2} %", 100.0 * scenario.accuracy.get()),
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
    println!("{EpuckRunHeader}");
    for (index, result) in results.iter().enumerate() {
        println!(
            "{}",
            EpuckRunRow {
                index,
                result,
                layout
            }
        );
    }
    let summary = summarise(&results);
    print!(
        "{}",
        EpuckSummaryReport {
            summary: &summary,
            scenario: &scenario.name,
            goal,
            t_e: decoder.t_e(scenario.params.control.t_e),
        }
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

/// The `--save` recording, checked and created before any work, so that a
/// bad or unwritable path fails first.
fn open_recording<T>(
    args: &RunArgs,
    open: impl FnOnce(&Path) -> errp_sim::Result<T>,
) -> Result<Option<T>> {
    let Some(path) = &args.save else {
        return Ok(None);
    };
    check_extension(path, "rrd", "--save")?;
    Ok(Some(open(path)?))
}
