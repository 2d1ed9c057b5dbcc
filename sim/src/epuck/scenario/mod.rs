//! Scenario files of the continuous e-puck task.
//!
//! Lengths are in centimetres and angles in degrees in the file, as a user
//! measures them on the arena; they are converted to SI once, here.

use std::path::{Path, PathBuf};

use errp_bci::{MeanAccuracy, OnlineTarget, Realism};
use errp_robot::{EpuckControlParams, GoalLayout, Valid};

use crate::epuck::hybrid_report::HYBRID_LABEL;
use crate::epuck::params::{EpuckEpisode, EpuckTaskParams};
use crate::epuck::schema::EpuckFile;
use crate::epuck::world::ArenaSpec;
use crate::error::Result;
use crate::own_eeg::OwnEegSpec;
use crate::scenario_file::{
    checked_realism, field_error, parse_toml, robot_error, scenario_name, table_into, whole,
};
use crate::task_kind::TaskKind;

mod arena;
mod decoder;
mod tracker;
mod user;

pub use arena::MAX_OBSTACLES;
use arena::{arena, start_pose};
use decoder::{OWN_EEG_PLACEHOLDER_ACCURACY, decoder_target, detector_params, refuse_with_own_eeg};
pub use tracker::MAX_TRACKER_HZ;
use tracker::tracker_params;
use user::user_params;
pub use user::{MAX_REACTION_LATENCY_MS, MAX_REELICIT_SECS};

/// Most runs of one e-puck scenario.
pub const MAX_RUNS: u64 = 100_000;
/// The longest time-out of a run, s.
pub const MAX_RUN_SECS: f64 = 3600.0;
/// A validated e-puck scenario, loaded through
/// [`crate::ScenarioInput`]; it cannot be written as a struct
/// literal outside this crate.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct EpuckScenario {
    /// The file it came from.
    pub path: PathBuf,
    /// Display name.
    pub name: String,
    /// What it reproduces, in words.
    pub description: String,
    /// Base seed of the runs (and of the calibration, unless `user_seed`
    /// says otherwise).
    pub seed: u64,
    /// Seed of the simulated user's calibration: the decoder and its
    /// operating point measured on held-out EEG (`[user] seed`; by default
    /// `seed`). The two city scenarios share one, so that their runs are one
    /// simulated user's, as the paper's two runs were one subject's, while
    /// their runs draw from seeds of their own.
    pub user_seed: u64,
    /// The continuous decoder's cross-validated mean accuracy (with an
    /// online target: its hit rate, as the device assumes it).
    pub accuracy: MeanAccuracy,
    /// Calibrate for this online operating point instead of the accuracy.
    pub online_target: Option<Valid<OnlineTarget>>,
    /// Runs of the episode, each from its own derived seed.
    pub runs: usize,
    /// Start pose and goal.
    pub episode: EpuckEpisode,
    /// Walls and obstacles.
    pub arena: ArenaSpec,
    /// The 25 city goals.
    pub layout: GoalLayout,
    /// Robot, control, user, tracker, avoidance, time-out.
    pub params: EpuckTaskParams,
    /// How far the simulated user is from the ideal one (`[realism]`; the
    /// ideal one with own EEG).
    pub realism: Realism,
    /// A person's own EEG in place of the synthetic user's EEG (`[eeg]`):
    /// the decoder is calibrated and run on a hybrid of it.
    pub own_eeg: Option<Box<OwnEegSpec>>,
}

impl EpuckScenario {
    /// Gives the scenario a new base seed for everything: a new simulated
    /// user (`user_seed`) and new runs (`errp run --seed`).
    pub fn reseed(&mut self, seed: u64) {
        self.seed = seed;
        self.user_seed = seed;
    }

    /// The decoder in words, as `errp run` prints it and its recording
    /// shows it: "decoder accuracy 75.00 %", or the online target.
    pub fn decoder_text(&self) -> String {
        if let Some(r) = &self.own_eeg {
            return format!("{HYBRID_LABEL} (recording {})", r.written);
        }
        match self.online_target {
            None => format!("decoder accuracy {:.2} %", 100.0 * self.accuracy.get()),
            Some(t) => format!(
                "decoder calibrated online for {:.1} % hits{}",
                100.0 * t.hit_rate,
                t.false_alarms_per_min
                    .map(|f| format!(" at {f} false alarms per minute"))
                    .unwrap_or_default()
            ),
        }
    }

    /// This scenario on a person's own EEG `eeg` (given in memory, from
    /// Python): its runs on a hybrid of it, its decoder calibrated on the
    /// EEG's first part with no accuracy targeted and T_e set for a
    /// false-alarm rate (a simulated user's `[realism]` and decoder target
    /// are not used).
    pub fn on_own_eeg(mut self, eeg: OwnEegSpec) -> Self {
        self.realism = Realism::default();
        self.online_target = None;
        self.own_eeg = Some(Box::new(eeg));
        self
    }

    /// Validates scenario text; `path` names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let file: EpuckFile = parse_toml(text, path)?;
        let raw: toml::Table = parse_toml(text, path)?;
        Self::from_file(file, &raw, path)
    }

    /// Validates a scenario given as a TOML table (a file's with values set
    /// from the command line or a sweep); errors name fields, not lines.
    pub fn from_table(table: &toml::Table, path: &Path) -> Result<Self> {
        Self::from_file(table_into(table, path)?, table, path)
    }

    /// `raw` is the same scenario as a plain table: whether a key was
    /// written (the typed tables hold defaults).
    fn from_file(file: EpuckFile, raw: &toml::Table, path: &Path) -> Result<Self> {
        let given = |table: &str, key: &str| raw.get(table).and_then(|t| t.get(key)).is_some();
        let bad =
            |field: &str, value: String, expected: &str| field_error(path, field, value, expected);
        if file.task != TaskKind::Epuck.as_str() {
            let expected = format!("{:?}", TaskKind::Epuck.as_str());
            return Err(bad("task", format!("{:?}", file.task), &expected));
        }
        let layout = GoalLayout::cities();
        let cities = || layout.names().join(", ");
        let goal = layout.index_of(&file.goal).ok_or_else(|| {
            bad(
                "goal",
                format!("{:?}", file.goal),
                &format!("one of the 25 cities: {}", cities()),
            )
        })?;

        let mut params = EpuckTaskParams::default();
        let radius_m = params.control.epuck.body_diameter_m / 2.0;
        let start = start_pose(&file, &layout, radius_m, path)?;
        if start.distance_to(layout.goals()[goal].x_m, layout.goals()[goal].y_m) < 0.05 {
            return Err(bad(
                "goal",
                format!("{:?}", file.goal),
                "a goal away from the start",
            ));
        }
        let recording = match file.eeg.clone() {
            Some(r) => Some(Box::new(r.0.check(path, TaskKind::Epuck)?)),
            None => None,
        };
        let (online_target, accuracy) = match &recording {
            Some(r) => {
                refuse_with_own_eeg(&file.user, given("control", "t_e"), r, path)?;
                // Not targeted: the accuracy the control assumes is the
                // recording's, set once it is calibrated.
                (None, MeanAccuracy::new(OWN_EEG_PLACEHOLDER_ACCURACY)?)
            }
            None => decoder_target(&file.user, given("control", "t_e"), path)?,
        };
        params.user = user_params(&file.user, path)?;
        if let Some(d) = &file.detector {
            params.detector = detector_params(d, path)?;
        }
        // The device knows its decoder's accuracy from the calibration.
        let control = EpuckControlParams {
            assumed_accuracy: accuracy.get(),
            ..file.control.clone()
        };
        params.control = Valid::new(control).map_err(|e| robot_error(path, "control", e))?;
        params.tracker = tracker_params(file.tracker.as_ref(), path)?;
        if let Some(v) = file.avoidance.as_ref().and_then(|a| a.enabled) {
            params.avoidance.enabled = v;
        }
        // At least one second: the decoder's window is 1 s long, and a run
        // is simulated in whole 0.1 s steps, so a shorter time-out would be
        // reported as a run longer than itself.
        if !(file.max_secs.is_finite() && (1.0..=MAX_RUN_SECS).contains(&file.max_secs)) {
            return Err(bad(
                "max_secs",
                file.max_secs.to_string(),
                &format!("a time-out of 1 to {MAX_RUN_SECS} s (default 600)"),
            ));
        }
        params.max_secs = file.max_secs;
        let runs = match file.runs {
            Some(n) => whole(path, "runs", n, 1, MAX_RUNS, " (default 1)")?,
            None => 1,
        };
        let arena = arena(&file, &layout, start, radius_m, path)?;
        let mut realism = checked_realism(file.realism.clone(), path)?;
        if recording.is_some() {
            // The recording is the person; [realism] describes a simulated one.
            realism = Realism::default();
        }

        Ok(Self {
            path: path.to_path_buf(),
            name: scenario_name(file.name, path),
            description: file.description.unwrap_or_default(),
            seed: file.seed,
            user_seed: file.user.seed.unwrap_or(file.seed),
            accuracy,
            online_target,
            runs,
            episode: EpuckEpisode { start, goal },
            arena,
            layout,
            params,
            realism,
            own_eeg: recording,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const OK: &str = r#"
task = "epuck"
start = "Mexico"
goal = "Pisa"
[user]
accuracy = 0.7438
"#;

    fn err(text: &str) -> String {
        EpuckScenario::parse(text, Path::new("scenarios/x.toml"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn control_is_the_robots_own_type_and_refuses_what_a_file_may_not_set() {
        let s = EpuckScenario::parse(
            &format!("{OK}[control]\nt_e = 0.7\ngoal_hold_secs = 2.5\nstrategy = \"info_gain\"\n"),
            Path::new("x.toml"),
        )
        .unwrap();
        assert_eq!(s.params.control.t_e, 0.7);
        assert_eq!(s.params.control.goal_hold_secs, Some(2.5));
        // Omitted: left to the episode, which derives it from the detector.
        assert_eq!(s.params.control.veto_window_secs, None);
        assert_eq!(s.params.control.strategy, errp_robot::Strategy::InfoGain);
        // The device's assumed accuracy comes from the calibration, and the
        // controller's own tuning is not a scenario field.
        for key in ["assumed_accuracy = 0.9", "heading_gain = 1", "tua = 0.3"] {
            let e = err(&format!("{OK}[control]\n{key}\n"));
            assert!(e.contains("unknown field") && e.contains("line 8"), "{e}");
        }
    }

    #[test]
    fn a_minimal_scenario_gets_the_papers_defaults() {
        let s = EpuckScenario::parse(OK, Path::new("x.toml")).unwrap();
        assert_eq!(s.params.control.t_e, 0.8);
        assert_eq!(s.params.control.p_c, 0.4);
        assert_eq!(s.layout.goals()[s.episode.goal].name, "Pisa");
        assert!((s.episode.start.x_m - 0.2).abs() < 1e-12);
        assert!(s.arena.obstacles.is_empty());
    }

    #[test]
    fn the_decoder_is_an_accuracy_or_an_online_operating_point() {
        let online = OK.replace(
            "accuracy = 0.7438",
            "hit_rate = 0.9\nfalse_alarms_per_min = 0.5",
        );
        let s = EpuckScenario::parse(&online, Path::new("x.toml")).unwrap();
        let t = s.online_target.unwrap();
        assert_eq!((t.hit_rate, t.false_alarms_per_min), (0.9, Some(0.5)));
        assert_eq!(s.params.control.assumed_accuracy, 0.9);
        for (text, field, range) in [
            (
                OK.replace("accuracy = 0.7438", "accuracy = 0.8\nhit_rate = 0.9"),
                "user.accuracy",
                "not both",
            ),
            (
                OK.replace("accuracy = 0.7438", "false_alarms_per_min = 0.5"),
                "user.false_alarms_per_min",
                "user.hit_rate",
            ),
            (
                OK.replace("accuracy = 0.7438", "hit_rate = 1.5"),
                "user.hit_rate",
                "(0, 1)",
            ),
            (
                OK.replace(
                    "accuracy = 0.7438",
                    "hit_rate = 0.9\nfalse_alarms_per_min = 0",
                ),
                "user.false_alarms_per_min",
                "(0, 60]",
            ),
            (
                format!("{online}[control]\nt_e = 0.8\n"),
                "control.t_e",
                "calibrated",
            ),
            (
                OK.replace("accuracy = 0.7438", ""),
                "user.accuracy",
                "hit_rate",
            ),
            (
                format!("{OK}[detector]\nsmooth_windows = 40\n"),
                "detector.smooth_windows",
                "1 to 16",
            ),
            (
                format!("{OK}[detector]\nmode = \"literal\"\nsmooth_windows = 3\n"),
                "detector.mode",
                "smoothed",
            ),
            (
                format!("{OK}[control]\ngoal_hold_secs = -1\n"),
                "control.goal_hold_secs",
                "[0, 10]",
            ),
        ] {
            let e = err(&text);
            assert!(e.contains("scenarios/x.toml"), "{e}");
            assert!(e.contains(field), "{field}: {e}");
            assert!(e.contains(range), "{range}: {e}");
        }
    }

    #[test]
    fn every_bad_value_names_file_field_value_and_range() {
        for (text, field, value) in [
            (OK.replace("0.7438", "1.7"), "user.accuracy", "1.7"),
            (OK.replace("0.7438", "nan"), "user.accuracy", "NaN"),
            (OK.replace("\"Pisa\"", "\"Atlantis\""), "goal", "Atlantis"),
            (OK.replace("\"Pisa\"", "\"Mexico\""), "goal", "Mexico"),
            (
                OK.replace("\"Mexico\"", "[250.0, 10.0]"),
                "start",
                "[250, 10]",
            ),
            (
                format!(
                    "{OK}[[arena.obstacle]]\nshape = \"circle\"\ncenter_cm = [100.0, 100.0]\nradius_cm = 10.0\n"
                ),
                "arena.obstacle[0].center_cm",
                "Athens",
            ),
            (
                format!(
                    "{OK}[[arena.obstacle]]\nshape = \"circle\"\ncenter_cm = [300.0, 100.0]\nradius_cm = 5.0\n"
                ),
                "arena.obstacle[0].center_cm",
                "[300, 100]",
            ),
            (
                format!("{OK}[[arena.obstacle]]\nshape = \"star\"\ncenter_cm = [80.0, 80.0]\n"),
                "arena.obstacle[0].shape",
                "star",
            ),
            (
                OK.replace("[user]", "max_secs = -1.0\n[user]"),
                "max_secs",
                "-1",
            ),
            (OK.replace("\"epuck\"", "\"epuk\""), "task", "epuk"),
        ] {
            let e = err(&text);
            assert!(e.contains("scenarios/x.toml"), "{e}");
            assert!(e.contains(field), "{field}: {e}");
            assert!(e.contains(value), "{value}: {e}");
            assert!(e.contains("expected"), "{e}");
        }
        // Ranges are the robot's own (EpuckControlParams::validate),
        // reported under the file's name for the field.
        let e = err(&format!("{OK}[control]\nt_e = 1.5\n"));
        assert!(
            e.contains("scenarios/x.toml")
                && e.contains("`control.t_e` = 1.5")
                && e.contains("(0, 1]"),
            "{e}"
        );
        let e = err(&OK.replace("accuracy = 0.7438", "accuracy = 0.7438\nfov_deg = 0.0"));
        assert!(e.contains("fov_deg"), "{e}");
    }
}
