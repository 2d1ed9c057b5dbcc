//! The grid live, on a link with a virtual clock and a decoder that answers
//! from the markers alone: what is published, which decisions apply, the
//! replay of the decisions applied, and the session recorded and replayed
//! from its file.

use std::path::{Path, PathBuf};

use errp_bci::EegBlock;
use errp_sim::grid::GridScenario;
use errp_sim::live::grid::replay_grid;
use errp_sim::live::{EpuckLiveRun, GridLiveRun};
use errp_sim::live::{
    Fate, LiveLink, LiveObserver, LiveOptions, LiveOutcome, LiveRequest, LiveSession, Received,
};
use errp_sim::pace::Speed;
use errp_sim::{
    Names, Result, RunObserver, RunProvenance, ScenarioInput, ScenarioSource, SimError,
};
use serde_json::Value;

/// A link on a virtual clock: waiting moves the clock; the decoder answers
/// every action marker `latency` later with a p(error) from the action's
/// id, except every `late_every`-th action, whose answer comes 0.2 s late
/// (three actions later at speed 50).
struct VirtualLink {
    clock: f64,
    connected: bool,
    markers: Vec<(f64, Value)>,
    states: usize,
    samples: u64,
    last_stamp: Option<f64>,
    spacing: Option<f64>,
    queue: Vec<Received>,
    late_every: u64,
    latency: f64,
    answers: bool,
}

impl VirtualLink {
    fn new(late_every: u64) -> Self {
        Self {
            clock: 1000.0,
            connected: false,
            markers: Vec::new(),
            states: 0,
            samples: 0,
            last_stamp: None,
            spacing: None,
            queue: Vec::new(),
            late_every,
            latency: 0.011,
            answers: true,
        }
    }
}

impl LiveLink for VirtualLink {
    fn clock(&self) -> f64 {
        self.clock
    }

    fn eeg(&mut self, block: &EegBlock, first: f64, period: f64) -> Result<()> {
        assert_eq!(block.n_channels, 40);
        if let Some(last) = self.last_stamp {
            assert!(
                (first - last - period).abs() < 1e-9,
                "samples are evenly spaced"
            );
        }
        self.spacing = Some(period);
        self.last_stamp = Some(first + (block.n_samples - 1) as f64 * period);
        self.samples += block.n_samples as u64;
        Ok(())
    }

    fn marker(&mut self, text: &str, stamp: f64) -> Result<()> {
        let v: Value = serde_json::from_str(text).unwrap();
        if v["event"] == "action" && self.connected && self.answers {
            let id = v["action"].as_u64().unwrap();
            let late = self.late_every > 0 && id % self.late_every == self.late_every - 1;
            self.queue.push(Received {
                id: id as f64,
                p_error: if id.is_multiple_of(3) { 0.8 } else { 0.25 },
                arrived: stamp + if late { 0.2 } else { self.latency },
            });
        }
        self.markers.push((stamp, v));
        Ok(())
    }

    fn state(&mut self, text: &str, _stamp: f64) -> Result<()> {
        let v: Value = serde_json::from_str(text).unwrap();
        assert_eq!(v["belief"].as_array().unwrap().len(), 25);
        self.states += 1;
        Ok(())
    }

    fn wait_for_readers(&mut self, _timeout_secs: f64) -> Result<()> {
        Ok(())
    }

    fn connect(&mut self, _timeout_secs: f64) -> Result<bool> {
        self.connected = true;
        Ok(true)
    }

    fn disconnect(&mut self) {
        self.connected = false;
    }

    fn wait(&mut self, until: f64) -> Result<Vec<Received>> {
        self.clock = self.clock.max(until);
        let now = self.clock;
        let (due, later): (Vec<_>, Vec<_>) = self.queue.drain(..).partition(|r| r.arrived <= now);
        self.queue = later;
        Ok(due)
    }
}

/// Keeps every run of a session, as the front end sees them.
#[derive(Debug, Default)]
struct Runs {
    grid: Vec<GridLiveRun>,
    epuck: Vec<EpuckLiveRun>,
}

impl RunObserver for Runs {}

impl LiveObserver for Runs {
    fn grid_run(&mut self, _k: usize, run: &GridLiveRun) {
        self.grid.push(run.clone());
    }

    fn epuck_run(&mut self, _k: usize, run: &EpuckLiveRun) {
        self.epuck.push(run.clone());
    }
}

fn grid_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/grid_fixed_goals.toml")
}

fn scenario() -> GridScenario {
    let path = grid_path();
    GridScenario::parse(&std::fs::read_to_string(&path).unwrap(), &path).unwrap()
}

/// A session of the scenario at `path`, `runs` of its runs at `options`,
/// recorded at `save` if given, run on `link`: its outcome and its runs.
fn session(
    path: &Path,
    options: LiveOptions,
    runs: u64,
    save: Option<&Path>,
    link: &mut dyn LiveLink,
) -> Result<(LiveOutcome, Runs)> {
    let loaded = ScenarioInput::new(ScenarioSource::File(path.to_path_buf())).load(&Names::CLI)?;
    let request = LiveRequest {
        options,
        runs: Some(runs),
        decoder: "name=virtual",
        save,
        provenance: &RunProvenance::default(),
        names: &Names::CLI,
    };
    let mut seen = Runs::default();
    let outcome = LiveSession::new(loaded, request)?.run(link, &mut seen)?;
    Ok((outcome, seen))
}

fn speed(k: f64) -> Speed {
    Speed::new(k).unwrap()
}

#[test]
fn the_decisions_applied_replay_to_the_same_runs() {
    let s = scenario();
    let mut link = VirtualLink::new(7);
    let options = LiveOptions {
        speed: speed(50.0),
        ..LiveOptions::default()
    };
    // Recorded as `errp stream --save` records, when the crate records.
    let save = cfg!(feature = "rerun").then(|| scratch("grid").join("live.rrd"));
    let (outcome, seen) = session(&grid_path(), options, 2, save.as_deref(), &mut link).unwrap();
    let runs = seen.grid;
    assert_eq!(runs.len(), 2);
    assert_eq!(
        outcome.reached,
        runs.iter().map(|r| r.result.reached()).collect::<Vec<_>>()
    );
    // The calibration: 400 labelled actions, then the control's actions
    // with no label; the EEG at 256 Hz x 50.
    let labelled = link
        .markers
        .iter()
        .filter(|(_, m)| m["event"] == "calibration_action")
        .count();
    assert_eq!(labelled, 400);
    assert!(
        link.markers
            .iter()
            .filter(|(_, m)| m["event"] == "action")
            .all(|(_, m)| m.get("label").is_none() && m.get("error").is_none()),
        "the control's markers never tell the user's verdict"
    );
    assert_eq!(link.spacing, Some(1.0 / (256.0 * 50.0)));
    let actions: usize = runs.iter().map(|r| r.result.actions).sum();
    assert_eq!(link.states, actions, "one state per action");
    // Every 7th action's decision came late: missed, counted, not applied.
    for r in &runs {
        let missed = r.decisions.iter().filter(|d| d.is_none()).count();
        assert_eq!(r.stats.missed, missed);
        assert_eq!(r.stats.latencies_secs().len(), r.result.actions - missed);
        for l in r.stats.latencies_secs() {
            assert!((l - 0.011).abs() < 1e-9, "latency {l}");
        }
        // Each late decision came 0.2 s after its own action's onset.
        for d in r.stats.decisions.iter().filter(|d| d.fate == Fate::Late) {
            assert!((d.latency_secs - 0.2).abs() < 1e-9, "{d:?}");
        }
    }
    let missed: usize = runs.iter().map(|r| r.stats.missed).sum();
    assert_eq!(missed, actions / 7, "{actions} actions");
    // The late ones are counted when they come (the last few may not have).
    let late: usize = runs.iter().map(|r| r.stats.late()).sum();
    assert!(
        late + 3 >= missed && late <= missed,
        "{late} late of {missed}"
    );
    // The same decisions, offline: the same runs.
    let decisions: Vec<_> = runs.iter().map(|r| r.decisions.clone()).collect();
    let again = replay_grid(&s, &decisions).unwrap();
    // (Compared as printed: a missed action's p(error) is NaN.)
    for (live, offline) in runs.iter().zip(&again) {
        assert_eq!(format!("{:?}", live.result), format!("{offline:?}"));
    }
    // A replay with fewer decisions than a run needs says so.
    let short = vec![decisions[0][..1].to_vec()];
    let e = replay_grid(&s, &short).unwrap_err().to_string();
    assert!(e.contains("more decisions than the 1 recorded"), "{e}");
    #[cfg(feature = "rerun")]
    saved::check_grid(&outcome, &runs);
}

#[test]
fn a_decoder_that_never_answers_stops_the_loop() {
    let mut link = VirtualLink::new(0);
    link.answers = false;
    let options = LiveOptions {
        speed: speed(50.0),
        timeout_secs: 2.0,
        ..LiveOptions::default()
    };
    let e = session(&grid_path(), options, 1, None, &mut link).unwrap_err();
    assert!(matches!(e, SimError::Live(_)), "{e}");
    assert!(
        e.to_string().contains("\"virtual\" sent nothing for"),
        "{e}"
    );
}

#[test]
fn a_decoder_always_late_decides_nothing() {
    let mut link = VirtualLink::new(1);
    let options = LiveOptions {
        speed: speed(50.0),
        ..LiveOptions::default()
    };
    let (_, seen) = session(&grid_path(), options, 1, None, &mut link).unwrap();
    let r = &seen.grid[0];
    // Never applied: the belief never moves and the run fails.
    assert!(r.decisions.iter().all(Option::is_none));
    assert_eq!(r.result.committed, None);
    assert_eq!(r.stats.missed, r.result.actions);
    assert!(r.stats.late() + 3 >= r.stats.missed, "{:?}", r.stats);
}

/// The e-puck on a virtual link: the decoder answers each block of EEG
/// (the window ending at its last sample) 20 ms later, with a p(error) that
/// is high for 6 blocks in every 60.
struct WindowLink {
    clock: f64,
    connected: bool,
    queue: Vec<Received>,
    blocks: u64,
    phases: usize,
}

impl LiveLink for WindowLink {
    fn clock(&self) -> f64 {
        self.clock
    }

    fn eeg(&mut self, block: &EegBlock, first: f64, period: f64) -> Result<()> {
        let last = first + (block.n_samples - 1) as f64 * period;
        if self.connected {
            self.blocks += 1;
            self.queue.push(Received {
                id: last,
                p_error: if self.blocks % 60 < 6 { 0.97 } else { 0.1 },
                arrived: last + 0.02,
            });
        }
        Ok(())
    }

    fn marker(&mut self, text: &str, _stamp: f64) -> Result<()> {
        let v: Value = serde_json::from_str(text).unwrap();
        if v["event"] == "phase" {
            self.phases += 1;
        }
        Ok(())
    }

    fn state(&mut self, _text: &str, _stamp: f64) -> Result<()> {
        Ok(())
    }

    fn wait_for_readers(&mut self, _timeout_secs: f64) -> Result<()> {
        Ok(())
    }

    fn connect(&mut self, _timeout_secs: f64) -> Result<bool> {
        self.connected = true;
        Ok(true)
    }

    fn disconnect(&mut self) {
        self.connected = false;
    }

    fn wait(&mut self, until: f64) -> Result<Vec<Received>> {
        self.clock = self.clock.max(until);
        let now = self.clock;
        let (due, later): (Vec<_>, Vec<_>) = self.queue.drain(..).partition(|r| r.arrived <= now);
        self.queue = later;
        Ok(due)
    }
}

#[test]
fn the_epuck_windows_applied_replay_to_the_same_runs() {
    use errp_sim::epuck::EpuckScenario;
    use errp_sim::live::epuck::{prepare_live_epuck, replay_epuck};

    let scenario_path = path_of_scenario();
    let s = EpuckScenario::parse(
        &std::fs::read_to_string(&scenario_path).unwrap(),
        &scenario_path,
    )
    .unwrap();
    let mut link = WindowLink {
        clock: 50.0,
        connected: false,
        queue: Vec::new(),
        blocks: 0,
        phases: 0,
    };
    let options = LiveOptions {
        speed: speed(10.0),
        calibration_actions: Some(40),
        ..LiveOptions::default()
    };
    let save = cfg!(feature = "rerun").then(|| scratch("epuck").join("live.rrd"));
    let (outcome, seen) = session(&scenario_path, options, 1, save.as_deref(), &mut link).unwrap();
    let r = &seen.epuck[0];
    assert!(link.phases >= 2, "{} phase markers", link.phases);
    // Each decision came 20 ms after its window: applied at the next
    // window, 0.2 s of simulated time later at speed 10.
    assert!(!r.stats.latencies_secs().is_empty());
    for l in r.stats.latencies_secs() {
        assert!((l - 0.02).abs() < 1e-9, "latency {l}");
    }
    let applied: usize = r.decisions.iter().map(Vec::len).sum();
    assert_eq!(applied, r.stats.latencies_secs().len());
    assert!(r.result.detected_errors > 0, "{:?}", r.result);
    let decoder = prepare_live_epuck(&s, &()).unwrap();
    let again = replay_epuck(&s, &decoder, std::slice::from_ref(&r.decisions)).unwrap();
    assert_eq!(again[0], r.result);
    #[cfg(feature = "rerun")]
    saved::check_epuck(&outcome, r, &s);
    #[cfg(not(feature = "rerun"))]
    let _ = outcome;
}

fn path_of_scenario() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/mexico_to_pisa.toml")
}

/// An empty directory of this test process.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("errp-live-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The sessions recorded as `errp stream --save` records them, read back
/// and replayed.
#[cfg(feature = "rerun")]
mod saved {
    use errp_sim::epuck::EpuckScenario;
    use errp_sim::inspect::Recording;
    use errp_sim::live::{EpuckLiveRun, GridLiveRun};
    use errp_sim::live::{LiveOutcome, LiveRunStats};

    /// The session's recording, read back (and its directory removed).
    fn read(outcome: &LiveOutcome) -> Recording {
        let path = outcome.recording.as_ref().expect("a recording");
        let rec = Recording::open(path).unwrap();
        std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
        rec
    }

    /// The decisions a recording read back holds: those received, each with
    /// its fate and latency, and the same count missed.
    fn assert_recorded(recorded: &[LiveRunStats], live: &[&LiveRunStats]) {
        assert_eq!(recorded.len(), live.len());
        for (r, l) in recorded.iter().zip(live) {
            assert_eq!(r.missed, l.missed);
            assert_eq!(r.decisions.len(), l.decisions.len());
            for (a, b) in r.decisions.iter().zip(&l.decisions) {
                assert_eq!(a.fate, b.fate);
                assert_eq!(a.received.p_error, b.received.p_error);
                assert_eq!(a.received.id, b.received.id);
                assert!(
                    a.latency_secs == b.latency_secs
                        || (a.latency_secs.is_nan() && b.latency_secs.is_nan())
                );
            }
        }
    }

    /// The grid session's recording holds the decisions as received; its
    /// runs replayed from it give the table the session printed.
    pub(super) fn check_grid(outcome: &LiveOutcome, runs: &[GridLiveRun]) {
        let rec = read(outcome);
        let live = rec.live.as_ref().expect("a live recording");
        assert_eq!(live.speed.get(), 50.0);
        assert_eq!(live.decoder, "name=virtual");
        assert_recorded(
            &live.runs,
            &runs.iter().map(|r| &r.stats).collect::<Vec<_>>(),
        );
        let replay = rec.replay_live().unwrap();
        let printed: Vec<String> = runs
            .iter()
            .enumerate()
            .map(|(k, r)| errp_sim::grid::GridEpisodeRow(k, &r.result).to_string())
            .collect();
        assert_eq!(replay.recorded, printed);
        assert_eq!(replay.replayed, printed);
        assert_eq!(replay.first_difference(), None);
        check_decisions_table(&rec, runs);
    }

    /// The decisions table (`errp inspect --csv`, `read_recording`): runs
    /// and the actions decisions were applied to both from 1, and a late
    /// decision applied to none (an empty field, a Parquet null).
    fn check_decisions_table(rec: &Recording, runs: &[GridLiveRun]) {
        use errp_sim::record::data::Column;
        let tables = errp_sim::inspect::csv_tables(rec);
        let table = tables.iter().find(|t| t.name == "decisions").unwrap();
        let column = |name: &str| &table.columns.iter().find(|(c, _)| *c == name).unwrap().1;
        let (Column::I64(run), Column::Str(fate), Column::OptI64(applied_to)) =
            (column("run"), column("fate"), column("applied_to"))
        else {
            panic!("run, fate or applied_to of another kind: {table:?}")
        };
        for (k, r) in runs.iter().enumerate() {
            // Each run's applied decisions name its actions that had one,
            // in order, from 1; the missed actions (every 7th) have none.
            let want: Vec<i64> = (1..)
                .zip(&r.decisions)
                .filter_map(|(action, d)| d.map(|_| action))
                .collect();
            let rows: Vec<usize> = (0..run.len()).filter(|&i| run[i] == k as i64 + 1).collect();
            let got: Vec<i64> = rows.iter().filter_map(|&i| applied_to[i]).collect();
            assert_eq!(got, want, "run {}", k + 1);
            for &i in &rows {
                assert_eq!(fate[i] == "applied", applied_to[i].is_some(), "row {i}");
            }
        }
        assert!(fate.iter().any(|f| f == "late"), "{fate:?}");
        // As CSV: a late decision's applied_to is an empty last field.
        let csv = table.to_csv();
        assert!(
            csv.starts_with("run,t_s,id,p_error,latency_ms,fate,applied_to\n"),
            "{csv}"
        );
        for line in csv.lines().skip(1) {
            assert_eq!(line.ends_with(",late,"), line.contains(",late,"), "{line}");
            assert!(!line.ends_with(",0") && !line.ends_with(",-1"), "{line}");
        }
    }

    /// The e-puck session's recording: the decisions as received, each
    /// window's as applied, and the run replayed from the file as the
    /// session printed it.
    pub(super) fn check_epuck(outcome: &LiveOutcome, r: &EpuckLiveRun, s: &EpuckScenario) {
        let rec = read(outcome);
        let live = rec.live.as_ref().expect("a live recording");
        assert_recorded(&live.runs, &[&r.stats]);
        assert_eq!(live.applied[0], r.decisions);
        let replay = rec.replay_live().unwrap();
        let printed = errp_sim::epuck::EpuckRunRow {
            index: 0,
            result: &r.result,
            layout: &s.layout,
        }
        .to_string();
        assert_eq!(replay.recorded, std::slice::from_ref(&printed));
        assert_eq!(replay.replayed, [printed]);
    }
}
