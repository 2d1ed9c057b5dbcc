//! `errp stream --save`: the session's recording (`errp_sim::live::save`),
//! made as `errp run --save` makes one, its provenance saying how the
//! decisions came.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use errp_sim::AnyScenario;
use errp_sim::live::save::LiveRecording;
pub(super) use errp_sim::record::data::LiveProvenance;
use errp_sim::record::data::Provenance;

/// The session's recording.
pub(super) type Recorder = LiveRecording;

/// Creates the recording of `scenario` (run as `text`) at `path` before
/// the session starts, so that an unwritable path fails first.
pub(super) fn open(
    path: &Path,
    scenario: &AnyScenario,
    text: &str,
    live: LiveProvenance,
) -> Result<Recorder> {
    let (task, name, seed) = match scenario {
        AnyScenario::Grid(s) => ("grid", &s.name, s.seed),
        AnyScenario::Epuck(s) => ("epuck", &s.name, s.seed),
    };
    let mut p = Provenance::new(task, name, text.to_string(), seed);
    p.command = crate::commands::command_line();
    crate::commands::fit::COMMIT.clone_into(&mut p.commit);
    p.decoder_summary = format!(
        "decoder: outside the process, over Lab Streaming Layer ({}), live at speed {}\n",
        live.decoder, live.speed
    );
    match scenario {
        AnyScenario::Grid(s) => LiveRecording::grid(path, s, p, live),
        AnyScenario::Epuck(s) => LiveRecording::epuck(path, s, p, live),
    }
    .context("--save")
}

/// Finishes the recording and says where it went.
pub(super) fn finish(recorder: Recorder) -> Result<()> {
    let path: PathBuf = recorder.finish().context("--save")?;
    crate::save::wrote(&path)
}
