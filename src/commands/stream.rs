//! `errp stream`: a scenario on the wall clock over Lab Streaming Layer,
//! with the lab's own decoder in the loop. The loop is `errp_sim::live`;
//! this file is the link: liblsl's outlets and inlet (`errp_lsl`) behind
//! `LiveLink`, and the printing.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{Result, bail};
use errp_bci::{ChannelKind, EegBlock, Montage, RequestedAccuracy};
use errp_lsl::{Element, Format, Inlet, Lsl, LslError, Outlet, StreamSpec};
use errp_robot::GoalLayout;
use errp_sim::epuck::{EpuckRunHeader, EpuckRunRow};
use errp_sim::grid::{GridEpisodeHeader, GridEpisodeRow};
use errp_sim::live::epuck::{EpuckLiveRun, run_epuck_live};
use errp_sim::live::grid::{GridLiveRun, run_grid_live};
use errp_sim::live::{LiveLink, LiveObserver, LiveOptions, LiveRunStats, Received};
use errp_sim::{AnyScenario, ScenarioInput, ScenarioSeed, ScenarioSource, SimError};

use crate::cli::{parse_run_accuracy, parse_scenario_seed};
use crate::commands::run::FLAGS;
use crate::out::{errln, outln};

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
    summary(&reached, &stats, options.speed, task == "epuck", &cost)
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
    let all = LiveRunStats {
        latencies_secs: stats
            .iter()
            .flat_map(|r| r.latencies_secs.iter().copied())
            .collect(),
        missed: stats.iter().map(|r| r.missed).sum(),
        late: stats.iter().map(|r| r.late).sum(),
        stray: stats.iter().map(|r| r.stray).sum(),
    };
    outln!(
        "{} of {} runs reached their goal; decisions: {}",
        reached.iter().filter(|&&r| r).count(),
        reached.len(),
        timing_text(&all, speed, windows)
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

/// Latencies (median and 95th percentile, wall ms, and in simulated ms),
/// missed, late and stray decisions; `windows` for the e-puck's (a latency
/// from the window's last sample; a device window without a decision).
fn timing_text(s: &LiveRunStats, speed: f64, windows: bool) -> String {
    let ms = |q: f64| {
        s.latency_quantile(q)
            .map_or("-".into(), |v| format!("{:.0}", v * 1000.0))
    };
    let sim = |q: f64| {
        s.latency_quantile(q)
            .map_or("-".into(), |v| format!("{:.0}", v * 1000.0 * speed))
    };
    let (from, missed) = if windows {
        ("the window's end", "device windows without one")
    } else {
        ("the action's onset", "missed")
    };
    format!(
        "{} applied, latency from {from} median {} ms, 95th percentile {} ms (simulated: {} / \
         {} ms); {} {missed}, {} late, {} stray",
        s.latencies_secs.len(),
        ms(0.5),
        ms(0.95),
        sim(0.5),
        sim(0.95),
        s.missed,
        s.late,
        s.stray
    )
}

/// Prints the notes (unless quiet) and each run as it ends: the task's row
/// and the decisions' timing.
struct Printer {
    quiet: bool,
    header: bool,
    layout: Option<GoalLayout>,
    /// The first failure to write standard output (a full disk), the
    /// command's error once the session ends.
    failed: Option<anyhow::Error>,
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

    fn timing(&mut self, stats: &LiveRunStats, windows: bool) {
        let text = timing_text(stats, 1.0, windows);
        let wall = text.split(" (simulated").next().unwrap_or_default();
        self.print(format_args!("      decisions: {wall}"));
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
    }
}

/// The streams of `errp stream` and the decoder's inlet.
struct LslLink {
    lsl: Lsl,
    eeg: Outlet,
    markers: Outlet,
    state: Outlet,
    query: (String, String),
    decisions: Option<Inlet>,
    sample: Vec<f32>,
    /// Seconds spent publishing the EEG (LSL's clock).
    busy: f64,
}

/// What the EEG stream says of itself beyond its channels.
struct EegStream {
    /// The true sampling rate (Hz).
    fs: f64,
    speed: f64,
    seed: u64,
    /// `grid` or `epuck`.
    task: &'static str,
}

impl LslLink {
    fn open(lsl: &Lsl, montage: &Montage, stream: &EegStream, query: (&str, &str)) -> Result<Self> {
        let seed = stream.seed;
        let eeg = lsl.outlet(&eeg_spec(montage, stream))?;
        let text = |name: &str, kind: &str| StreamSpec {
            name: name.into(),
            kind: kind.into(),
            channels: 1,
            rate_hz: 0.0,
            format: Format::String,
            source_id: format!("{name}-{seed}"),
            desc: vec![Element::leaf("contract", CONTRACT)],
        };
        Ok(Self {
            lsl: lsl.clone(),
            eeg,
            markers: lsl.outlet(&text(MARKER_STREAM, "Markers"))?,
            state: lsl.outlet(&text(STATE_STREAM, "State"))?,
            query: (query.0.into(), query.1.into()),
            decisions: None,
            sample: vec![0.0; montage.len()],
            busy: 0.0,
        })
    }
}

/// The EEG stream's description, after LSL's meta-data conventions for EEG
/// (channels with label, type and unit; the cap; the acquisition), and
/// what the testbed adds: the contract, the speed and the true rate.
fn eeg_spec(montage: &Montage, stream: &EegStream) -> StreamSpec {
    let EegStream {
        fs,
        speed,
        seed,
        task,
    } = *stream;
    let channels = montage
        .channels()
        .iter()
        .map(|c| {
            let [x, y, z] = c.position;
            Element::node(
                "channel",
                vec![
                    Element::leaf("label", &c.name),
                    Element::leaf(
                        "type",
                        match c.kind {
                            ChannelKind::Eeg => "EEG",
                            ChannelKind::Eog => "EOG",
                        },
                    ),
                    Element::leaf("unit", "microvolts"),
                    Element::node(
                        "location",
                        vec![
                            Element::leaf("X", format!("{:.1}", x * 95.0)),
                            Element::leaf("Y", format!("{:.1}", y * 95.0)),
                            Element::leaf("Z", format!("{:.1}", z * 95.0)),
                        ],
                    ),
                ],
            )
        })
        .collect();
    StreamSpec {
        name: EEG_STREAM.into(),
        kind: "EEG".into(),
        channels: montage.len() as u32,
        rate_hz: fs * speed,
        format: Format::Float32,
        source_id: format!("{EEG_STREAM}-{seed}"),
        desc: vec![
            Element::node("channels", channels),
            Element::node(
                "reference",
                vec![
                    Element::leaf("label", "A1"),
                    Element::leaf("subtracted", "yes"),
                ],
            ),
            Element::node(
                "cap",
                vec![
                    Element::leaf("labelscheme", "10-20"),
                    Element::leaf("size", "58"),
                ],
            ),
            Element::node(
                "acquisition",
                vec![
                    Element::leaf("manufacturer", "errp-testbed"),
                    Element::leaf("model", "simulated user"),
                ],
            ),
            Element::node(
                "errp",
                vec![
                    Element::leaf("contract", CONTRACT),
                    Element::leaf("task", task),
                    Element::leaf("speed", speed),
                    Element::leaf("sampling_rate_hz", fs),
                    Element::leaf("seed", seed),
                ],
            ),
        ],
    }
}

fn live_error(e: LslError) -> SimError {
    SimError::Live(e.to_string())
}

impl LiveLink for LslLink {
    fn clock(&self) -> f64 {
        self.lsl.clock()
    }

    fn eeg(&mut self, block: &EegBlock, first: f64, period: f64) -> errp_sim::Result<()> {
        let t = self.lsl.clock();
        for i in 0..block.n_samples {
            for (ch, v) in self.sample.iter_mut().enumerate() {
                *v = block.channel(ch)[i] as f32;
            }
            self.eeg
                .push(&self.sample, first + i as f64 * period)
                .map_err(live_error)?;
        }
        self.busy += self.lsl.clock() - t;
        Ok(())
    }

    fn marker(&mut self, text: &str, stamp: f64) -> errp_sim::Result<()> {
        self.markers.push_text(text, stamp).map_err(live_error)
    }

    fn state(&mut self, text: &str, stamp: f64) -> errp_sim::Result<()> {
        self.state.push_text(text, stamp).map_err(live_error)
    }

    fn wait_for_readers(&mut self, timeout: f64) -> errp_sim::Result<()> {
        if !self.eeg.wait_for_consumers(timeout) {
            return Err(SimError::Live(format!(
                "no program opened the EEG stream {EEG_STREAM} within {timeout} s (--timeout): \
                 start the decoder (it reads the calibration from the stream) before or with \
                 errp stream"
            )));
        }
        Ok(())
    }

    fn connect(&mut self, timeout_secs: f64) -> errp_sim::Result<bool> {
        let (prop, value) = (&self.query.0, &self.query.1);
        let found = self
            .lsl
            .resolve(prop, value, timeout_secs)
            .map_err(live_error)?;
        let Some(stream) = found.first() else {
            return Ok(false);
        };
        let name = stream.name();
        let numeric = !matches!(stream.format(), Some(Format::String) | None);
        if stream.channels() != 2 || stream.rate_hz() != 0.0 || !numeric {
            return Err(SimError::Live(format!(
                "the decoder stream {name:?} ({prop}={value}) has {} channels of {} at {} Hz; \
                 expected 2 numeric channels (action, p(error)) at an irregular rate (0 Hz)",
                stream.channels(),
                stream.format().map_or("an unknown format", Format::name),
                stream.rate_hz()
            )));
        }
        self.decisions = Some(stream.open(5.0).map_err(live_error)?);
        Ok(true)
    }

    fn disconnect(&mut self) {
        self.decisions = None;
    }

    fn wait(&mut self, until: f64) -> errp_sim::Result<Vec<Received>> {
        let mut got = Vec::new();
        let Some(inlet) = &self.decisions else {
            let left = until - self.lsl.clock();
            if left > 0.0 {
                std::thread::sleep(Duration::from_secs_f64(left));
            }
            return Ok(got);
        };
        let mut buf = [0.0; 2];
        loop {
            let left = (until - self.lsl.clock()).max(0.0);
            match inlet.pull(&mut buf, left).map_err(live_error)? {
                Some(_) => got.push(Received {
                    id: buf[0],
                    p_error: buf[1],
                    arrived: self.lsl.clock(),
                }),
                None if left <= 0.0 => break,
                None => {}
            }
            if got.len() > 10_000 {
                return Err(SimError::Live(format!(
                    "the decoder stream {:?} sent over 10 000 decisions within one 62.5 ms hop",
                    inlet.name()
                )));
            }
        }
        Ok(got)
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

    #[test]
    fn the_eeg_description_lists_every_channel() {
        let m = Montage::standard();
        let stream = EegStream {
            fs: 256.0,
            speed: 4.0,
            seed: 1,
            task: "grid",
        };
        let spec = eeg_spec(&m, &stream);
        assert_eq!(spec.rate_hz, 1024.0);
        let channels = &spec.desc[0].children;
        assert_eq!(channels.len(), m.len());
        assert_eq!(
            channels[0].children[0],
            Element::leaf("label", &m.channels()[0].name)
        );
        let eog = channels
            .iter()
            .filter(|c| c.children[1] == Element::leaf("type", "EOG"))
            .count();
        assert_eq!(eog, m.n_eog());
    }
}
