//! `errp run`: a grid or an e-puck scenario, printed per episode and summarised.

use std::sync::Mutex;

use anyhow::Result;
use errp_bci::{OnlineStep, TargetingStep};
use errp_sim::epuck::{EpuckRunsTable, EpuckSummaryReport, summarise};
use errp_sim::grid::{DecoderChoice, GridEpisodeHeader, GridEpisodeResult, GridEpisodeRow};
use errp_sim::{
    AnyScenario, Names, RunHeadline, RunObserver, RunOptions, RunOutcome, RunProvenance,
    ScenarioInput, ScenarioSource, TaskKind, run_scenario,
};

use crate::cli::{DecoderArg, RunArgs};
use crate::out::{errln, out, outln};
use crate::save::check_save;

pub(crate) fn run(args: &RunArgs) -> Result<()> {
    // The flags are keys of the scenario file, set before it is parsed, so
    // they are checked and carried through exactly as the file's own.
    let input = ScenarioInput {
        accuracy: args.accuracy,
        seed: args.seed,
        runs: args.runs,
        decoder: args.decoder.map(|d| match d {
            DecoderArg::Eeg => DecoderChoice::Eeg,
            DecoderArg::Oracle => DecoderChoice::Oracle,
        }),
        eeg: args.eeg.map(|e| e.mode()),
        ..ScenarioInput::new(ScenarioSource::File(args.scenario.clone()))
    };
    let loaded = input.load(&Names::CLI)?;
    check_save(args.save.as_deref())?;
    let provenance = RunProvenance {
        command: crate::commands::command_line(),
        commit: Some(crate::commands::fit::COMMIT.to_string()),
    };
    let options = RunOptions {
        save: args.save.as_deref(),
        provenance: &provenance,
        names: &Names::CLI,
    };
    let printer = Printer {
        quiet: args.quiet,
        task: loaded.scenario.kind(),
        printed: Mutex::new(Ok(())),
    };
    let run = run_scenario(loaded, options, &printer).map_err(|e| match e.context {
        Some(c) => anyhow::Error::new(e.error).context(c),
        None => e.error.into(),
    });
    // A standard output that fails stops the run before its next stage
    // (grid episodes run on); its first failure is the command's.
    printer
        .printed
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner)?;
    let run = run?;
    match &run.outcome {
        RunOutcome::Grid(report) => out!("{report}")?,
        RunOutcome::Epuck(r) => {
            let s = &r.scenario;
            out!(
                "{}",
                EpuckRunsTable {
                    results: &r.results,
                    layout: &s.layout
                }
            )?;
            out!(
                "{}",
                EpuckSummaryReport {
                    summary: &summarise(&r.results),
                    scenario: &s.name,
                    goal: &s.layout.goals()[s.episode.goal].name,
                    t_e: r.decoder.detector_t_e(&s.params, false),
                }
            )?;
        }
    }
    #[cfg(feature = "rerun")]
    if let Some(path) = &run.recording {
        crate::save::wrote(path)?;
    }
    Ok(())
}

/// Prints the run as it goes: the calibration (unless quiet), the
/// decoder's summary, and each grid episode's row.
struct Printer {
    quiet: bool,
    /// The task: a grid run's table of episodes follows the decoder's
    /// summary.
    task: TaskKind,
    /// The first failure to print.
    printed: Mutex<Result<()>>,
}

impl Printer {
    fn print(&self, f: impl FnOnce() -> Result<()>) {
        let mut printed = self
            .printed
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if printed.is_ok() {
            *printed = f();
        }
    }
}

impl RunObserver for Printer {
    fn start(&self, scenario: &AnyScenario) {
        if !self.quiet {
            errln!("{}", RunHeadline(scenario));
        }
    }

    fn stopped(&self) -> bool {
        self.printed
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .is_err()
    }

    fn targeting(&self, s: &TargetingStep) {
        if !self.quiet {
            print_targeting(s);
        }
    }

    fn online_step(&self, s: &OnlineStep) {
        if !self.quiet {
            print_online_step(s);
        }
    }

    fn decoder_ready(&self, summary: &str) {
        self.print(|| out!("{summary}"));
        if self.task == TaskKind::Grid {
            self.print(|| outln!("{GridEpisodeHeader}"));
        }
    }

    fn grid_episode(&self, k: usize, r: &GridEpisodeResult) {
        self.print(|| outln!("{}", GridEpisodeRow(k, r)));
    }

    fn epuck_runs_start(&self, runs: u64, parallel: bool) {
        if parallel && !self.quiet && runs > 1 {
            errln!("  running {runs} runs in parallel");
        }
    }
}

/// A step of the search for the ErrP-to-noise ratio, on standard error.
pub(crate) fn print_targeting(s: &TargetingStep) {
    errln!(
        "  calibrating: ErrP-to-noise {:.4} -> mean {:.2} %",
        s.ratio,
        100.0 * s.accuracy.mean()
    );
}

/// A step of the e-puck detector's calibration, on standard error.
pub(crate) fn print_online_step(s: &OnlineStep) {
    errln!(
        "  calibrating: ErrP-to-noise {:.4}, T_e {:.3} -> {:.1} % hits, {:.2} false alarms/min",
        s.ratio,
        s.t_e,
        100.0 * s.point.hit_rate,
        s.point.false_alarms_per_min
    );
}
