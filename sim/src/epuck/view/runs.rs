//! An e-puck scenario's runs recorded one after another, as `errp run
//! --save` records them.

use crate::epuck::decoder::ContinuousDecoder;
use crate::epuck::episode::EpuckEpisodeResult;
use crate::epuck::plant::WindowDecoder;
use crate::epuck::run::run_epuck_runs;
use crate::epuck::scenario::EpuckScenario;
use crate::epuck::view::recorder::EpuckRecorder;
use crate::error::Result;
use crate::record::RrdFile;
use crate::record::data::Provenance;

/// The runs of `scenario` one after another, each recorded into `file` as
/// `errp run --save` records them, with `provenance` (its `runs` set here).
pub fn record_epuck_runs(
    file: &RrdFile,
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
    provenance: &Provenance,
) -> Result<Vec<EpuckEpisodeResult>> {
    record_epuck_runs_with(
        file,
        scenario,
        decoder,
        provenance,
        scenario.runs,
        None,
        &|_| {},
    )
}

/// [`record_epuck_runs`] of `runs` runs, with `window_decoder` (a decoder
/// of the caller's own, as in [`crate::epuck::run_epuck_episode_with`]) in
/// place of the calibrated SVM when given; `on_run(k)` is called after run
/// `k` (from 0) is recorded.
pub fn record_epuck_runs_with(
    file: &RrdFile,
    scenario: &EpuckScenario,
    decoder: &ContinuousDecoder,
    provenance: &Provenance,
    runs: usize,
    window_decoder: Option<WindowDecoder<'_>>,
    on_run: &(dyn Fn(usize) + Sync),
) -> Result<Vec<EpuckEpisodeResult>> {
    provenance.write(file, runs)?;
    let t_e = decoder.detector_t_e(&scenario.params, window_decoder.is_some());
    let mut recorder = EpuckRecorder::new(file, &scenario.arena, &scenario.layout, t_e)?;
    recorder.set_run_title(format!(
        "the user wants {} ({})",
        scenario.layout.goals()[scenario.episode.goal].name,
        scenario.decoder_text()
    ));
    let out = run_epuck_runs(
        scenario,
        decoder,
        runs,
        window_decoder,
        &mut recorder,
        on_run,
    )?;
    recorder.finish()?;
    Ok(out)
}
