//! Finishing a sweep directory: its summary, table, figures and final
//! manifest, each written whole.

use std::path::Path;

use errp_sim::write_atomic;
use errp_sim::{Result, SimError};
use errp_sim::{ScenarioInput, ScenarioSource};

use crate::figure::sweep_plot;
use crate::manifest::{EPISODES, Manifest};
use crate::plot::{self};
use crate::summary::{SweepReport, summarise_dir};
use crate::table::summary_csv;
use errp_sim::Names;

/// Writes `summary.csv`, `sweep.svg`, `sweep.png` and the final `sweep.json`
/// of a complete sweep in `dir`, each atomically.
pub fn finish_dir(dir: &Path, manifest: &Manifest) -> Result<SweepReport> {
    let spec = &manifest.spec;
    let mut report = summarise_dir(dir, spec)?;
    // The scenario as the file gives it with what the sweep sets for every
    // level (the e-puck's paper point is drawn at its accuracy; the grid's
    // EEG mode is the levels'), else the first level's.
    let as_run = ScenarioInput {
        keys: spec.fixed.clone(),
        ..ScenarioInput::new(ScenarioSource::Text {
            text: spec.scenario_toml.clone(),
            name: spec.scenario_path.clone(),
        })
    };
    let scenario = match as_run.load(&Names::FILE) {
        Ok(s) => s.scenario,
        Err(_) => spec
            .levels(&Names::CLI)?
            .into_iter()
            .next()
            .map(|l| l.scenario)
            .ok_or_else(|| SimError::Sweep("a sweep without levels".into()))?,
    };
    let plot = sweep_plot(spec, &report, &scenario);
    let plot_error =
        |e: plot::PlotError| SimError::Sweep(format!("plotting the sweep failed: {e}"));
    let files = [
        ("summary.csv", summary_csv(spec, &report).into_bytes()),
        (
            "sweep.svg",
            plot::svg(&plot).map_err(plot_error)?.into_bytes(),
        ),
        ("sweep.png", plot::png(&plot).map_err(plot_error)?),
    ];
    for (name, bytes) in &files {
        write_atomic(&dir.join(name), bytes)?;
        report.files.push(dir.join(name));
    }
    manifest.write(dir)?;
    report.files.push(dir.join(crate::manifest::MANIFEST));
    report.files.push(dir.join(EPISODES));
    Ok(report)
}
