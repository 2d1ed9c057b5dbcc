//! The arguments of `errp calibrate`, `errp run` and `errp table1`, and what
//! the commands share: checks of file names and accuracies, progress lines.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use clap::ValueEnum;
use errp_bci::{MeanAccuracy, RequestedAccuracy};
use errp_sim::ScenarioSeed;
use errp_sim::grid::EegMode;

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum Goals {
    /// The five goals shared by all subjects.
    Fixed,
    /// The goals each subject chose.
    Free,
}

#[derive(clap::Args)]
pub(crate) struct CalibrateArgs {
    /// Requested mean accuracy (mean of the correct- and error-class rates),
    /// strictly between 0.5 and 1. Default: 0.7438, the paper's mean over
    /// subjects with the fixed goals.
    #[arg(long, value_parser = parse_accuracy, conflicts_with = "subject", allow_negative_numbers = true)]
    pub(crate) accuracy: Option<MeanAccuracy>,
    /// Take the accuracy of a subject of Table 1 (S1..S4) instead.
    #[arg(long)]
    pub(crate) subject: Option<String>,
    /// Which of the subject's accuracies: fixed or free goals (with
    /// --subject only). [default: fixed]
    #[arg(long, value_enum, requires = "subject")]
    pub(crate) goals: Option<Goals>,
    /// Seed of the synthetic user and session.
    #[arg(long, default_value_t = 1, value_parser = parse_seed, allow_negative_numbers = true)]
    pub(crate) seed: u64,
    /// Record grand averages, a topography and the summary to this `.rrd`.
    #[arg(long, value_name = "FILE.rrd")]
    pub(crate) save: Option<PathBuf>,
    /// Write the raw synthetic EEG + EOG of the session, with `error` /
    /// `correct` annotations, to this EDF+ file.
    #[arg(long, value_name = "FILE.edf")]
    pub(crate) export: Option<PathBuf>,
    /// Print only the results, not the search.
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum DecoderArg {
    /// Synthetic EEG through the real preprocessing and decoder.
    Eeg,
    /// Assessments flipped with probability 1 - accuracy, no EEG.
    Oracle,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum EegArg {
    /// Synthesise each action's EEG when it happens.
    #[value(name = "per_action")]
    PerAction,
    /// Draw preprocessed epochs from a bank synthesised in advance.
    Bank,
    /// The former name of per_action, still read.
    #[value(hide = true)]
    Stream,
}

impl EegArg {
    pub(crate) fn mode(self) -> EegMode {
        match self {
            EegArg::PerAction | EegArg::Stream => EegMode::PerAction,
            EegArg::Bank => EegMode::Bank,
        }
    }

    /// As it was given (`stream` for its former name), for what is set in
    /// a scenario and named in errors.
    pub(crate) fn word(self) -> &'static str {
        match self {
            EegArg::Stream => "stream",
            e => e.mode().key(),
        }
    }
}

#[derive(clap::Args)]
pub(crate) struct RunArgs {
    /// The scenario file (TOML), e.g. scenarios/mexico_to_pisa.toml or
    /// scenarios/grid_fixed_goals.toml.
    pub(crate) scenario: PathBuf,
    /// Override the scenario's seed (a new simulated user, new runs, new
    /// free goals).
    #[arg(long, value_parser = parse_scenario_seed, allow_negative_numbers = true)]
    pub(crate) seed: Option<ScenarioSeed>,
    /// Override the scenario's decoder (grid scenarios).
    #[arg(long, value_enum)]
    pub(crate) decoder: Option<DecoderArg>,
    /// Override the decoder's accuracy (mean of the per-class rates, in
    /// (0.5, 1); 1 for the grid's oracle decoder).
    #[arg(long, value_parser = parse_run_accuracy, allow_negative_numbers = true)]
    pub(crate) accuracy: Option<RequestedAccuracy>,
    /// Override the number of runs (e-puck scenarios); each run has its own
    /// seed derived from the scenario's.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub(crate) runs: Option<u64>,
    /// Override how the EEG reaches the decoder: synthesised per action or
    /// drawn from a bank (grid scenarios).
    #[arg(long, value_enum)]
    pub(crate) eeg: Option<EegArg>,
    /// Record every episode to this `.rrd`. Grid: cursor, goal, posterior,
    /// visited states, p(error), EEG at FCz, event log. E-puck: arena,
    /// cities coloured by belief, robot, trajectory, detected errors, belief
    /// bars and series, p(error) and T_e, EEG at FCz and Cz, event log.
    #[arg(long, value_name = "FILE.rrd")]
    pub(crate) save: Option<PathBuf>,
    /// Print only the results.
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

#[derive(clap::Args)]
pub(crate) struct Table1Args {
    /// Runs per start/goal pair (5 pairs per subject and goal set).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub(crate) episodes: u64,
    /// Base seed.
    #[arg(long, default_value_t = 1, value_parser = parse_seed, allow_negative_numbers = true)]
    pub(crate) seed: u64,
    /// EEG decoder (default) or oracle.
    #[arg(long, value_enum, default_value = "eeg")]
    pub(crate) decoder: DecoderArg,
    /// Synthesise each action's EEG (default) or draw epochs from a bank of
    /// 1000 per class synthesised in advance (much faster).
    #[arg(long, value_enum, default_value = "per_action")]
    pub(crate) eeg: EegArg,
    /// The simulated users: the `[realism]` table of this scenario file
    /// (e.g. scenarios/variants/grid_fixed_goals_ideal.toml for the
    /// idealised user). Default: the shipped scenarios' user.
    #[arg(long, value_name = "SCENARIO")]
    pub(crate) realism: Option<PathBuf>,
    /// Print only the results.
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

pub(crate) fn parse_accuracy(s: &str) -> Result<MeanAccuracy, String> {
    let v: f64 = s.trim().parse().map_err(|_| {
        format!(
            "{s:?} is not a number: give a mean accuracy strictly between 0.5 and 1 as a \
                 fraction, e.g. 0.7438"
        )
    })?;
    MeanAccuracy::new(v).map_err(|_| {
        format!(
            "{s} is out of range: give a mean accuracy strictly between 0.5 (chance) and 1 \
             as a fraction, e.g. 0.7438 for 74.38 %"
        )
    })
}

/// `--accuracy` of `errp run`: a mean accuracy in (0.5, 1), or 1 (for the
/// grid's oracle; `errp run` checks the decoder).
pub(crate) fn parse_run_accuracy(s: &str) -> Result<RequestedAccuracy, String> {
    match s.trim().parse::<f64>().map(RequestedAccuracy::new) {
        Ok(Ok(a)) => Ok(a),
        _ => parse_accuracy(s)
            .map(RequestedAccuracy::Targeted)
            .map_err(|e| format!("{e} (or 1 with --decoder oracle)")),
    }
}

/// A seed: a whole number from 0 to 2^64 - 1.
pub(crate) fn parse_seed(s: &str) -> Result<u64, String> {
    s.trim().parse::<u64>().map_err(|_| {
        format!(
            "{s:?} is not a seed: give a whole number from 0 to {}",
            u64::MAX
        )
    })
}

/// A scenario's seed: a whole number from 0 to 2^63 - 1 (a TOML integer,
/// as the file holds it).
pub(crate) fn parse_scenario_seed(s: &str) -> Result<ScenarioSeed, String> {
    s.trim()
        .parse::<u64>()
        .ok()
        .and_then(ScenarioSeed::new)
        .ok_or_else(|| {
            format!(
                "{s:?} is not a scenario's seed: give a whole number from 0 to {}",
                ScenarioSeed::MAX
            )
        })
}

pub(crate) fn check_extension(path: &Path, ext: &str, flag: &str) -> Result<()> {
    if path.extension().and_then(|e| e.to_str()) != Some(ext) {
        bail!(
            "{flag} {}: the file name must end in .{ext}",
            path.display()
        );
    }
    Ok(())
}

/// Arguments of `errp inspect`.
#[derive(clap::Args)]
pub(crate) struct InspectArgs {
    /// Recordings made by `errp run --save` or the Python package's
    /// `save=`. With two or more, a summary side by side.
    #[arg(required = true, num_args = 1..=16)]
    pub(crate) files: Vec<PathBuf>,
    /// Write the tidy tables (runs, trajectory, detections, belief, errps,
    /// events; for the grid runs, actions, belief, visits) as CSV files
    /// into this directory (one subdirectory per file when several).
    #[arg(long, value_name = "DIR")]
    pub(crate) csv: Option<PathBuf>,
    /// Write the same tables as Parquet files (typed columns, Snappy) into
    /// this directory, for pandas, Polars or DuckDB.
    #[arg(long, value_name = "DIR")]
    pub(crate) parquet: Option<PathBuf>,
    /// Draw the paper's Fig. 5 (e-puck: the arena, every run's path faint,
    /// one in blue with red marks at its detections) or Fig. 4 (grid: visit
    /// frequencies and paths) into FILE.png or FILE.svg (one recording).
    #[arg(long, value_name = "FILE")]
    pub(crate) figure: Option<PathBuf>,
    /// The run drawn in full in the figure, from 1.
    #[arg(long, value_name = "K", default_value_t = 1)]
    pub(crate) run: usize,
    /// Print the scenario as it was run (TOML) and nothing else, e.g. to
    /// run it again: `errp inspect F.rrd --scenario > s.toml`.
    #[arg(long, conflicts_with_all = ["provenance", "csv", "parquet", "figure"])]
    pub(crate) scenario: bool,
    /// Print the provenance document (JSON) and nothing else.
    #[arg(long, conflicts_with_all = ["csv", "parquet", "figure"])]
    pub(crate) provenance: bool,
    /// A live session's recording (`errp stream --save`): run its runs
    /// again offline, each decided by the decisions it applied, and check
    /// that the per-run table is the one recorded (an error if not).
    #[arg(long, conflicts_with_all = ["scenario", "provenance"])]
    pub(crate) replay: bool,
}
