//! `errp stream --save` in a build without Rerun: `check_save` has refused
//! the flag, so no recording ever exists.

use std::path::Path;

use anyhow::{Result, bail};
use errp_sim::AnyScenario;
use errp_sim::epuck::EpuckObserver;
use errp_sim::live::epuck::EpuckLiveRun;
use errp_sim::live::grid::GridLiveRun;

/// No recording.
pub(super) enum Recorder {}

/// How a live session ran (unused without Rerun).
pub(super) struct LiveProvenance {
    pub(super) speed: f64,
    pub(super) decoder: String,
}

pub(super) fn open(
    path: &Path,
    _scenario: &AnyScenario,
    _text: &str,
    live: LiveProvenance,
) -> Result<Recorder> {
    bail!(
        "--save {}: this errp was built without Rerun, so it cannot record the session \
         (decisions from {} at speed {})",
        path.display(),
        live.decoder,
        live.speed
    )
}

pub(super) fn finish(recorder: Recorder) -> Result<()> {
    match recorder {}
}

impl Recorder {
    pub(super) fn grid_run(&mut self, _k: usize, _run: &GridLiveRun) -> errp_sim::Result<()> {
        match *self {}
    }

    pub(super) fn epuck_watch(&mut self, _k: usize, _seed: u64) -> Option<&mut dyn EpuckObserver> {
        match *self {}
    }

    pub(super) fn epuck_run(&mut self, _k: usize, _run: &EpuckLiveRun) -> errp_sim::Result<()> {
        match *self {}
    }
}
