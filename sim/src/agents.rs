//! Recordings of the episodes an agent of the user's own drives through an
//! environment (the Python package's Gymnasium environments): the grid's
//! written one episode at a time when each ends, the e-puck's streamed as
//! it runs, each with its provenance naming the agent. Without the `rerun`
//! feature nothing records: asking to is an error, and a recording that
//! was not asked for does nothing.

use std::path::{Path, PathBuf};

use crate::epuck::{EpuckAction, EpuckEnvironment, EpuckFeedback, EpuckScenario};
use crate::error::Result;
use crate::grid::{GridEnvironment, GridScenario};
use crate::runner::{MAX_RECORDED_EPISODES, MAX_RECORDED_RUNS};

/// Who drove the episodes a recording holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AgentInfo {
    /// The call that made it, as its words.
    pub command: Vec<String>,
    /// The agent, in words.
    pub agent: String,
}

/// The grid episodes an agent steps, each written when it ends (at most
/// [`MAX_RECORDED_EPISODES`]).
pub struct GridAgentRecording {
    inner: Option<imp::Grid>,
}

impl GridAgentRecording {
    /// A recording into `save` (none without it) of `scenario`, whose text
    /// as run is `text`.
    pub fn create(
        save: Option<&Path>,
        scenario: &GridScenario,
        text: String,
        info: AgentInfo,
    ) -> Result<Self> {
        Ok(Self {
            inner: save
                .map(|p| imp::Grid::create(p, scenario, text, info))
                .transpose()?,
        })
    }

    /// True when no more episodes will be recorded.
    pub fn full(&self) -> bool {
        self.inner
            .as_ref()
            .is_some_and(|g| g.episodes() >= MAX_RECORDED_EPISODES)
    }

    /// A new episode in `env`: recorded (its steps kept) unless full.
    pub fn start(&mut self, env: &mut GridEnvironment) {
        let full = self.full();
        if let Some(g) = self.inner.as_mut() {
            g.start(env, !full);
        }
    }

    /// Writes the episode of `env` (from `seed`), if it is recorded, took
    /// an action and is not written yet.
    pub fn write(&mut self, seed: u64, epoch_secs: f64, env: &GridEnvironment) -> Result<()> {
        match self.inner.as_mut() {
            Some(g) => g.write(seed, epoch_secs, env),
            None => Ok(()),
        }
    }

    /// Moves the recording into place: its path, or none when there is no
    /// recording or no episode in it. It records no more.
    pub fn finish(&mut self) -> Result<Option<PathBuf>> {
        match self.inner.take() {
            Some(g) => g.finish(),
            None => Ok(None),
        }
    }
}

/// The e-puck episodes an agent drives, each streamed as it runs (at most
/// [`MAX_RECORDED_RUNS`]).
pub struct EpuckAgentRecording {
    inner: Option<imp::Epuck>,
}

impl EpuckAgentRecording {
    /// A recording into `save` (none without it) of `scenario` with the
    /// detector's threshold `t_e`, whose text as run is `text`.
    pub fn create(
        save: Option<&Path>,
        scenario: &EpuckScenario,
        t_e: f64,
        text: String,
        info: AgentInfo,
    ) -> Result<Self> {
        Ok(Self {
            inner: save
                .map(|p| imp::Epuck::create(p, scenario, t_e, text, info))
                .transpose()?,
        })
    }

    /// True when no more episodes will be recorded.
    pub fn full(&self) -> bool {
        self.inner
            .as_ref()
            .is_some_and(|e| e.runs() as u64 >= MAX_RECORDED_RUNS)
    }

    /// A new episode of `env` from `seed`, the user's goal named by
    /// `goal_name`: recorded unless full.
    pub fn start(&mut self, env: &EpuckEnvironment, goal_name: &str, seed: u64) {
        let full = self.full();
        if let Some(e) = self.inner.as_mut() {
            e.start(env, goal_name, seed, !full);
        }
    }

    /// Steps `env` ([`EpuckEnvironment::step`]), watched when the episode
    /// is recorded.
    pub fn step(
        &mut self,
        env: &mut EpuckEnvironment,
        action: EpuckAction,
        windows: usize,
        keep_window: bool,
    ) -> Result<EpuckFeedback> {
        match self.inner.as_mut() {
            Some(e) => e.step(env, action, windows, keep_window),
            None => env.step(action, windows, keep_window),
        }
    }

    /// Ends the recorded episode of `env` in progress, if it took a step.
    pub fn end(&mut self, env: &mut EpuckEnvironment) {
        if let Some(e) = self.inner.as_mut() {
            e.end(env);
        }
    }

    /// Moves the recording into place: its path, or none when there is no
    /// recording or no episode in it. It records no more.
    pub fn finish(&mut self) -> Result<Option<PathBuf>> {
        match self.inner.take() {
            Some(e) => e.finish(),
            None => Ok(None),
        }
    }
}

#[cfg(feature = "rerun")]
mod imp {
    use std::path::{Path, PathBuf};

    use super::AgentInfo;
    use crate::epuck::{
        EpuckAction, EpuckEnvironment, EpuckFeedback, EpuckObserver, EpuckRecorder, EpuckScenario,
    };
    use crate::error::Result;
    use crate::grid::{GridEnvironment, GridRecorder, GridScenario};
    use crate::record::RrdFile;
    use crate::record::data::Provenance;
    use crate::task_kind::TaskKind;

    fn provenance(
        task: TaskKind,
        name: &str,
        text: String,
        seed: u64,
        info: AgentInfo,
    ) -> Provenance {
        let mut p = Provenance::new(task, name, text, seed);
        p.command = info.command;
        p.agent = Some(info.agent);
        p
    }

    pub(super) struct Grid {
        recorder: GridRecorder,
        provenance: Provenance,
        /// The episode being stepped is recorded and not yet written.
        open: bool,
    }

    impl Grid {
        pub(super) fn create(
            path: &Path,
            s: &GridScenario,
            text: String,
            info: AgentInfo,
        ) -> Result<Self> {
            let file = crate::grid::grid_recording(path)?;
            Ok(Self {
                recorder: GridRecorder::new(file)?,
                provenance: provenance(TaskKind::Grid, &s.name, text, s.seed, info),
                open: false,
            })
        }

        pub(super) fn episodes(&self) -> usize {
            self.recorder.episodes()
        }

        pub(super) fn start(&mut self, env: &mut GridEnvironment, record: bool) {
            self.open = record;
            if record {
                env.keep_steps();
            }
        }

        pub(super) fn write(
            &mut self,
            seed: u64,
            epoch_secs: f64,
            env: &GridEnvironment,
        ) -> Result<()> {
            if self.open && env.actions() > 0 {
                self.open = false;
                self.recorder.episode(seed, epoch_secs, &env.result())?;
            }
            Ok(())
        }

        pub(super) fn finish(self) -> Result<Option<PathBuf>> {
            if self.recorder.episodes() == 0 {
                return Ok(None);
            }
            self.recorder.finish(&self.provenance).map(Some)
        }
    }

    pub(super) struct Epuck {
        file: RrdFile,
        recorder: EpuckRecorder,
        provenance: Provenance,
        /// Episodes recorded to their end.
        runs: usize,
        /// The episode being stepped is recorded and has not ended.
        open: bool,
    }

    impl Epuck {
        pub(super) fn create(
            path: &Path,
            s: &EpuckScenario,
            t_e: f64,
            text: String,
            info: AgentInfo,
        ) -> Result<Self> {
            let file = crate::epuck::epuck_agent_recording(path)?;
            let recorder = EpuckRecorder::new(&file, &s.arena, &s.layout, t_e)?;
            Ok(Self {
                file,
                recorder,
                provenance: provenance(TaskKind::Epuck, &s.name, text, s.seed, info),
                runs: 0,
                open: false,
            })
        }

        pub(super) fn runs(&self) -> usize {
            self.runs
        }

        pub(super) fn start(
            &mut self,
            env: &EpuckEnvironment,
            goal_name: &str,
            seed: u64,
            record: bool,
        ) {
            self.open = record;
            if record {
                let title = format!(
                    "episode {}: the user wants {goal_name} (an agent drives)",
                    self.runs + 1
                );
                self.recorder.next_run(&title, seed);
                self.recorder.on_start(&env.start());
                self.recorder
                    .on_event(0.0, &format!("the user wants {goal_name}"), false);
            }
        }

        pub(super) fn step(
            &mut self,
            env: &mut EpuckEnvironment,
            action: EpuckAction,
            windows: usize,
            keep_window: bool,
        ) -> Result<EpuckFeedback> {
            if !self.open {
                return env.step(action, windows, keep_window);
            }
            let f = env.step_observed(action, windows, keep_window, &mut self.recorder)?;
            if env.ended() {
                self.open = false;
                self.runs += 1;
            }
            Ok(f)
        }

        pub(super) fn end(&mut self, env: &mut EpuckEnvironment) {
            if self.open {
                self.open = false;
                if env.time_secs() > 0.0 {
                    env.end(&mut self.recorder);
                    self.runs += 1;
                }
            }
        }

        pub(super) fn finish(self) -> Result<Option<PathBuf>> {
            self.recorder.finish()?;
            if self.runs == 0 {
                return Ok(None);
            }
            self.provenance.write(&self.file, self.runs)?;
            self.file.finish().map(Some)
        }
    }
}

#[cfg(not(feature = "rerun"))]
mod imp {
    use std::path::{Path, PathBuf};

    use super::AgentInfo;
    use crate::epuck::{EpuckAction, EpuckEnvironment, EpuckFeedback, EpuckScenario};
    use crate::error::{Result, SimError};
    use crate::grid::{GridEnvironment, GridScenario};

    fn refused(path: &Path) -> SimError {
        SimError::NoRecorder {
            path: path.to_path_buf(),
        }
    }

    /// Never made: there is no recording without Rerun.
    pub(super) enum Grid {}

    impl Grid {
        pub(super) fn create(p: &Path, _: &GridScenario, _: String, _: AgentInfo) -> Result<Self> {
            Err(refused(p))
        }

        pub(super) fn episodes(&self) -> usize {
            match *self {}
        }

        pub(super) fn start(&mut self, _: &mut GridEnvironment, _: bool) {
            match *self {}
        }

        pub(super) fn write(&mut self, _: u64, _: f64, _: &GridEnvironment) -> Result<()> {
            match *self {}
        }

        pub(super) fn finish(self) -> Result<Option<PathBuf>> {
            match self {}
        }
    }

    /// Never made: there is no recording without Rerun.
    pub(super) enum Epuck {}

    impl Epuck {
        pub(super) fn create(
            p: &Path,
            _: &EpuckScenario,
            _: f64,
            _: String,
            _: AgentInfo,
        ) -> Result<Self> {
            Err(refused(p))
        }

        pub(super) fn runs(&self) -> usize {
            match *self {}
        }

        pub(super) fn start(&mut self, _: &EpuckEnvironment, _: &str, _: u64, _: bool) {
            match *self {}
        }

        pub(super) fn step(
            &mut self,
            _: &mut EpuckEnvironment,
            _: EpuckAction,
            _: usize,
            _: bool,
        ) -> Result<EpuckFeedback> {
            match *self {}
        }

        pub(super) fn end(&mut self, _: &mut EpuckEnvironment) {
            match *self {}
        }

        pub(super) fn finish(self) -> Result<Option<PathBuf>> {
            match self {}
        }
    }
}
