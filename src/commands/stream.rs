//! `errp stream`: a scenario on the wall clock over Lab Streaming Layer,
//! with the lab's own decoder in the loop. The session, its link and its
//! recording are `errp_sim::live`'s; this file parses the flags, opens
//! liblsl and prints each run.

use std::path::PathBuf;

use anyhow::{Result, bail};
use errp_bci::{Montage, OnlineStep, RequestedAccuracy, TargetingStep};
use errp_lsl::Lsl;
use errp_robot::GoalLayout;
use errp_sim::epuck::{EpuckRunHeader, EpuckRunRow};
use errp_sim::grid::{GridEpisodeHeader, GridEpisodeRow};
use errp_sim::live::contract::{EEG_STREAM, MARKER_STREAM, STATE_STREAM, SessionId};
use errp_sim::live::{
    EpuckLiveRun, GridLiveRun, LiveObserver, LiveOptions, LiveRequest, LiveRunStats, LiveSession,
    LslLink,
};
use errp_sim::pace::Speed;
use errp_sim::{
    AnyScenario, Names, RunObserver, RunProvenance, ScenarioInput, ScenarioSeed, ScenarioSource,
    SimError, TaskKind,
};

use crate::cli::{parse_run_accuracy, parse_scenario_seed};
use crate::commands::run::{print_online_step, print_targeting};
use crate::out::{errln, outln};

/// Arguments of `errp stream`.
#[derive(clap::Args)]
pub(crate) struct StreamArgs {
    /// The scenario (a grid or an e-puck scenario file).
    pub(crate) scenario: PathBuf,
    /// Simulated seconds per wall second: the clock and the EEG stream's
    /// nominal rate run this many times faster (1: real time; 0.1 to 100).
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
    /// This session's id, at the end of every stream's source id
    /// (`errp-eeg-ID`): the decoder's stream is taken only if its source
    /// id ends with `-ID` too. 1 to 16 letters, digits or _ (default: 8
    /// fresh hexadecimal digits).
    #[arg(long, value_name = "ID", value_parser = parse_session)]
    pub(crate) session: Option<SessionId>,
    /// The decoder's stream, by an LSL property: name=NAME, type=TYPE or
    /// source_id=ID.
    #[arg(long, default_value = "name=errp-decoder", value_name = "PROP=VALUE")]
    pub(crate) decisions: String,
    /// liblsl to load, a file (a name without a directory is one in the
    /// current directory); default: ERRP_LIBLSL, PYLSL_LIB, the system's,
    /// then the copy in pylsl's wheel.
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

/// `--session ID`, checked.
fn parse_session(text: &str) -> std::result::Result<SessionId, String> {
    SessionId::new(text).ok_or_else(|| {
        format!(
            "{:?} is not a session id: expected 1 to {} letters, digits or _",
            errp_bci::shown(text),
            SessionId::MAX_LEN
        )
    })
}

pub(crate) fn stream(args: &StreamArgs) -> Result<()> {
    let names = &Names::CLI;
    let mut options = LiveOptions::new(args.speed, args.timeout, args.calibration_actions, names)?;
    if let Some(id) = args.session {
        options.session = id;
    }
    let query = decisions_query(&args.decisions)?;
    let input = ScenarioInput {
        accuracy: args.accuracy,
        seed: args.seed,
        ..ScenarioInput::new(ScenarioSource::File(args.scenario.clone()))
    };
    let loaded = input.load(names)?;
    crate::save::check_save(args.save.as_deref())?;
    let layout = match &loaded.scenario {
        AnyScenario::Epuck(s) => Some(s.layout.clone()),
        AnyScenario::Grid(_) => None,
    };
    let provenance = RunProvenance {
        command: crate::commands::command_line(),
        commit: Some(crate::commands::fit::COMMIT.to_string()),
    };
    let request = LiveRequest {
        options,
        runs: args.runs,
        decoder: &args.decisions,
        save: args.save.as_deref(),
        provenance: &provenance,
        names,
    };
    // The recording is made here, before any work, so that an unwritable
    // path fails first.
    let session = LiveSession::new(loaded, request).map_err(save_context)?;
    let lsl = Lsl::find(args.liblsl.as_deref()).map_err(|e| match &args.liblsl {
        Some(_) => anyhow::anyhow!("--liblsl: {e}"),
        None => e.into(),
    })?;
    let montage = Montage::standard();
    let header = session.header();
    let mut link = LslLink::open(&lsl, &montage, &header, query)?;
    if !args.quiet {
        errln!(
            "liblsl {}.{} from {}; publishing {EEG_STREAM} (EEG, {} channels at {} Hz x \
             speed {} = {} Hz nominal), {MARKER_STREAM}, {STATE_STREAM} as session {}; \
             decisions from {} (source id ending -{})",
            lsl.version() / 100,
            lsl.version() % 100,
            lsl.path().display(),
            montage.len(),
            header.fs_hz,
            header.speed,
            header.speed.rate(header.fs_hz),
            header.session,
            args.decisions,
            header.session
        );
    }
    let mut printer = Printer {
        quiet: args.quiet,
        header: false,
        layout,
        failed: None,
    };
    let started = (lsl.clock(), process_cpu_secs());
    let outcome = session.run(&mut link, &mut printer);
    if let Some(e) = printer.failed.take() {
        return Err(e);
    }
    let outcome = outcome.map_err(save_context)?;
    let cost = Cost {
        wall_secs: lsl.clock() - started.0,
        cpu_secs: started.1.zip(process_cpu_secs()).map(|(a, b)| b - a),
        publishing_secs: link.busy,
    };
    summary(
        &outcome.reached,
        &outcome.stats,
        options.speed,
        outcome.task,
        &cost,
    )?;
    match &outcome.recording {
        Some(path) => crate::save::wrote(path),
        None => Ok(()),
    }
}

/// An error of the recording, named by the flag that asked for it.
fn save_context(e: SimError) -> anyhow::Error {
    match e {
        SimError::Output { .. } | SimError::Record { .. } | SimError::NoRecorder { .. } => {
            anyhow::Error::new(e).context("--save")
        }
        e => e.into(),
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
    speed: Speed,
    task: TaskKind,
    cost: &Cost,
) -> Result<()> {
    let windows = task == TaskKind::Epuck;
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

/// Prints the notes and the calibration (unless quiet) and each run as
/// it ends: the task's row and the decisions' timing.
struct Printer {
    quiet: bool,
    header: bool,
    /// The e-puck's goals, by which its rows name them.
    layout: Option<GoalLayout>,
    /// The first failure to write standard output (a full disk), the
    /// command's error once the session ends.
    failed: Option<anyhow::Error>,
}

impl Printer {
    fn print(&mut self, line: std::fmt::Arguments<'_>) {
        if let Err(e) = outln!("{line}") {
            self.failed.get_or_insert(e);
        }
    }

    fn timing(&mut self, stats: &LiveRunStats, task: TaskKind) {
        let text = stats.timing(task == TaskKind::Epuck, None);
        self.print(format_args!("      decisions: {text}"));
    }
}

impl RunObserver for Printer {
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
}

impl LiveObserver for Printer {
    fn note(&mut self, text: &str) {
        if !self.quiet {
            errln!("{text}");
        }
    }

    fn grid_run(&mut self, k: usize, run: &GridLiveRun) {
        if !std::mem::replace(&mut self.header, true) {
            self.print(format_args!("{GridEpisodeHeader}"));
        }
        self.print(format_args!("{}", GridEpisodeRow(k, &run.result)));
        self.timing(&run.stats, TaskKind::Grid);
    }

    fn epuck_run(&mut self, k: usize, run: &EpuckLiveRun) {
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
        self.timing(&run.stats, TaskKind::Epuck);
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
