//! `errp stream`: a scenario on the wall clock over Lab Streaming Layer,
//! with the lab's own decoder in the loop. The loop is `errp_sim::live`;
//! the link (liblsl behind `LiveLink`) is in `link`; this file parses the
//! flags, prints each run and records the session (`--save`).

use std::path::PathBuf;

use anyhow::{Result, bail};
use errp_bci::{Montage, RequestedAccuracy};
use errp_lsl::Lsl;
use errp_robot::GoalLayout;
use errp_sim::epuck::{EpuckObserver, EpuckRunHeader, EpuckRunRow};
use errp_sim::grid::{GridEpisodeHeader, GridEpisodeRow};
use errp_sim::live::epuck::{EpuckLiveRun, run_epuck_live};
use errp_sim::live::grid::{GridLiveRun, run_grid_live};
use errp_sim::live::{LiveObserver, LiveOptions, LiveRunStats};
use errp_sim::{AnyScenario, ScenarioInput, ScenarioSeed, ScenarioSource};

use crate::cli::{parse_run_accuracy, parse_scenario_seed};
use crate::commands::run::FLAGS;
use crate::out::{errln, outln};
use link::{EegStream, LslLink};

mod link;
#[cfg(feature = "rerun")]
mod save;
#[cfg(not(feature = "rerun"))]
#[path = "no_save.rs"]
mod save;

/// The EEG stream's name.
pub(crate) const EEG_STREAM: &str = "errp-eeg";
/// The markers' stream.
pub(crate) const MARKER_STREAM: &str = "errp-markers";
/// The device's state.
pub(crate) const STATE_STREAM: &str = "errp-state";
/// The version of the contract the streams follow (in the EEG stream's
/// description): markers, state and decisions as the guide describes them.
pub(crate) const CONTRACT: u32 = 1;

/// Arguments of `errp stream`.
#[derive(clap::Args)]
pub(crate) struct StreamArgs {
    /// The scenario (a grid or an e-puck scenario file).
    pub(crate) scenario: PathBuf,
    /// Simulated seconds per wall second: the clock and the EEG stream's
    /// nominal rate run this many times faster (1: real time; at most 100).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub(crate) speed: f64,
    /// Seconds to wait for the decoder (to open the EEG stream, to publish
    /// its decisions after the calibration) and the longest silence
    /// allowed from it during the control (at most 3600).
    #[arg(
        long,
        default_value_t = 30.0,
        value_name = "SECS",
        allow_negative_numbers = true
    )]
    pub(crate) timeout: f64,
    /// Actions in the calibration session (40 to 4000; default the paper's
    /// 400).
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub(crate) calibration_actions: Option<usize>,
    /// Runs to stream: the grid scenario's first N, or N runs of the
    /// e-puck's (default: the scenario's).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub(crate) runs: Option<u64>,
    /// The decoder's stream, by an LSL property: name=NAME, type=TYPE or
    /// source_id=ID.
    #[arg(long, default_value = "name=errp-decoder", value_name = "PROP=VALUE")]
    pub(crate) decisions: String,
    /// liblsl to load (default: ERRP_LIBLSL, PYLSL_LIB, the system's, then
    /// the copy in pylsl's wheel).
    #[arg(long, value_name = "FILE")]
    pub(crate) liblsl: Option<PathBuf>,
    /// Override the scenario's seed.
    #[arg(long, value_parser = parse_scenario_seed, allow_negative_numbers = true)]
    pub(crate) seed: Option<ScenarioSeed>,
    /// Override the simulated user's accuracy, in (0.5, 1).
    #[arg(long, value_parser = parse_run_accuracy, allow_negative_numbers = true)]
    pub(crate) accuracy: Option<RequestedAccuracy>,
    /// Record the session into FILE.rrd: each run as `errp run --save`
    /// records it, and every decision as received, with its latency
    /// (`errp inspect FILE.rrd --replay` runs the runs again with them).
    #[arg(long, value_name = "FILE.rrd")]
    pub(crate) save: Option<PathBuf>,
    /// Print only the results.
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

/// The `--decisions` property and value.
fn decisions_query(text: &str) -> Result<(&str, &str)> {
    match text.split_once('=') {
        Some((p @ ("name" | "type" | "source_id"), v)) if !v.is_empty() => Ok((p, v)),
        _ => bail!(
            "--decisions {text:?}: expected name=NAME, type=TYPE or source_id=ID (default \
             name=errp-decoder)"
        ),
    }
}

pub(crate) fn stream(args: &StreamArgs) -> Result<()> {
    let options = LiveOptions {
        speed: args.speed,
        timeout_secs: args.timeout,
        calibration_actions: args.calibration_actions,
        ..LiveOptions::default()
    };
    options.check(["--speed", "--timeout", "--calibration-actions"])?;
    let query = decisions_query(&args.decisions)?;
    let input = ScenarioInput {
        accuracy: args.accuracy,
        seed: args.seed,
        ..ScenarioInput::new(ScenarioSource::File(args.scenario.clone()))
    };
    let loaded = input.load(&FLAGS)?;
    crate::save::check_save(args.save.as_deref())?;
    let (all_runs, seed) = match &loaded.scenario {
        AnyScenario::Grid(s) => (s.episodes.len(), s.seed),
        AnyScenario::Epuck(s) => (s.runs, s.seed),
    };
    // The grid streams its first runs; the e-puck any number, each seeded
    // as `errp run` seeds it.
    let runs = match (&loaded.scenario, args.runs) {
        (_, None) => all_runs,
        (AnyScenario::Grid(_), Some(n)) => (n as usize).min(all_runs),
        (AnyScenario::Epuck(_), Some(n)) => n as usize,
    };
    // Made before any work, so that an unwritable path fails first.
    let recording = args
        .save
        .as_deref()
        .map(|path| {
            let live = save::LiveProvenance {
                speed: options.speed,
                decoder: args.decisions.clone(),
            };
            save::open(path, &loaded.scenario, &loaded.text, live)
        })
        .transpose()?;
    let lsl = Lsl::find(args.liblsl.as_deref()).map_err(|e| match &args.liblsl {
        Some(_) => anyhow::anyhow!("--liblsl: {e}"),
        None => e.into(),
    })?;
    let montage = Montage::standard();
    let fs = 256.0;
    let task = match &loaded.scenario {
        AnyScenario::Grid(_) => "grid",
        AnyScenario::Epuck(_) => "epuck",
    };
    let stream = EegStream {
        fs,
        speed: options.speed,
        seed,
        task,
    };
    let mut link = LslLink::open(&lsl, &montage, &stream, query)?;
    if !args.quiet {
        errln!(
            "liblsl {}.{} from {}; publishing {EEG_STREAM} (EEG, {} channels at {fs} Hz x \
             speed {} = {} Hz nominal), {MARKER_STREAM}, {STATE_STREAM}; decisions from {}",
            lsl.version() / 100,
            lsl.version() % 100,
            lsl.path().display(),
            montage.len(),
            options.speed,
            fs * options.speed,
            args.decisions
        );
    }
    let mut observer = Printer {
        quiet: args.quiet,
        header: false,
        layout: None,
        failed: None,
        recording,
    };
    let name = query.1.to_string();
    let started = (lsl.clock(), process_cpu_secs());
    let (reached, stats): (Vec<bool>, Vec<LiveRunStats>) = match &loaded.scenario {
        AnyScenario::Grid(s) => run_grid_live(s, &mut link, options, runs, &name, &mut observer)?
            .into_iter()
            .map(|r| (r.result.reached(), r.stats))
            .unzip(),
        AnyScenario::Epuck(s) => {
            observer.layout = Some(s.layout.clone());
            run_epuck_live(s, &mut link, options, runs, &name, &mut observer)?
                .into_iter()
                .map(|r| (r.result.reached(), r.stats))
                .unzip()
        }
    };
    if let Some(e) = observer.failed.take() {
        return Err(e);
    }
    let cost = Cost {
        wall_secs: lsl.clock() - started.0,
        cpu_secs: started.1.zip(process_cpu_secs()).map(|(a, b)| b - a),
        publishing_secs: link.busy,
    };
    summary(&reached, &stats, options.speed, task == "epuck", &cost)?;
    match observer.recording.take() {
        Some(recording) => save::finish(recording),
        None => Ok(()),
    }
}

/// What a session cost: wall time, the process's CPU time and the time
/// spent publishing the samples (s).
struct Cost {
    wall_secs: f64,
    cpu_secs: Option<f64>,
    publishing_secs: f64,
}

/// The session's last lines: the runs reached, the decisions' timing over
/// all runs, and the cost.
fn summary(
    reached: &[bool],
    stats: &[LiveRunStats],
    speed: f64,
    windows: bool,
    cost: &Cost,
) -> Result<()> {
    let all = LiveRunStats::merged(stats);
    outln!(
        "{} of {} runs reached their goal; decisions: {}",
        reached.iter().filter(|&&r| r).count(),
        reached.len(),
        all.timing(windows, Some(speed))
    )?;
    if let Some(cpu) = cost.cpu_secs {
        let wall = cost.wall_secs;
        outln!(
            "cost at speed {speed}: {:.1} % of one core over {wall:.0} s (the simulation and \
             LSL, all threads), of which publishing the samples {:.1} %",
            100.0 * cpu / wall,
            100.0 * cost.publishing_secs / wall
        )?;
    }
    Ok(())
}

/// CPU seconds of this process so far, all threads (Linux's
/// `/proc/self/stat`, at its 100 ticks a second); none elsewhere.
fn process_cpu_secs() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The fields after the command's name (in parentheses): utime and
    // stime are the 12th and 13th.
    let rest = &stat[stat.rfind(')')? + 2..];
    let fields: Vec<&str> = rest.split(' ').collect();
    let ticks = fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// Prints the notes (unless quiet) and each run as it ends: the task's row
/// and the decisions' timing.
struct Printer {
    quiet: bool,
    header: bool,
    layout: Option<GoalLayout>,
    /// The first failure to write standard output (a full disk) or the
    /// recording, the command's error once the session ends.
    failed: Option<anyhow::Error>,
    /// The session's recording (`--save`).
    recording: Option<save::Recorder>,
}

impl Printer {
    fn note(&mut self, text: &str) {
        if !self.quiet {
            errln!("{text}");
        }
    }

    fn print(&mut self, line: std::fmt::Arguments<'_>) {
        if let Err(e) = outln!("{line}") {
            self.failed.get_or_insert(e);
        }
    }

    fn recorded(&mut self, result: errp_sim::Result<()>) {
        if let Err(e) = result {
            self.failed
                .get_or_insert(anyhow::Error::new(e).context("--save"));
        }
    }

    fn timing(&mut self, stats: &LiveRunStats, windows: bool) {
        let text = stats.timing(windows, None);
        self.print(format_args!("      decisions: {text}"));
    }
}

impl LiveObserver<GridLiveRun> for Printer {
    fn note(&mut self, text: &str) {
        Printer::note(self, text);
    }

    fn run(&mut self, k: usize, run: &GridLiveRun) {
        if !std::mem::replace(&mut self.header, true) {
            self.print(format_args!("{GridEpisodeHeader}"));
        }
        self.print(format_args!("{}", GridEpisodeRow(k, &run.result)));
        self.timing(&run.stats, false);
        if let Some(r) = &mut self.recording {
            let result = r.grid_run(k, run);
            self.recorded(result);
        }
    }
}

impl LiveObserver<EpuckLiveRun> for Printer {
    fn note(&mut self, text: &str) {
        Printer::note(self, text);
    }

    fn run(&mut self, k: usize, run: &EpuckLiveRun) {
        if !std::mem::replace(&mut self.header, true) {
            self.print(format_args!("{EpuckRunHeader}"));
        }
        if let Some(layout) = self.layout.take() {
            let row = EpuckRunRow {
                index: k,
                result: &run.result,
                layout: &layout,
            };
            self.print(format_args!("{row}"));
            self.layout = Some(layout);
        }
        self.timing(&run.stats, true);
        if let Some(r) = &mut self.recording {
            let result = r.epuck_run(k, run);
            self.recorded(result);
        }
    }

    fn watch(&mut self, k: usize, seed: u64) -> Option<&mut dyn EpuckObserver> {
        self.recording.as_mut()?.epuck_watch(k, seed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_decisions_flag_names_a_property() {
        assert_eq!(decisions_query("name=x").unwrap(), ("name", "x"));
        assert_eq!(
            decisions_query("type=Decisions").unwrap(),
            ("type", "Decisions")
        );
        let e = decisions_query("x").unwrap_err().to_string();
        assert!(
            e.starts_with("--decisions \"x\": expected name=NAME"),
            "{e}"
        );
        assert!(decisions_query("name=").is_err());
        assert!(decisions_query("host=a").is_err());
    }
}
