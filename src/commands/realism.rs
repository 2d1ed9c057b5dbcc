//! `errp realism`: the simulated user's statistics beside published
//! recordings of people.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use errp_sim::realism::measure_realism;
use errp_sim::{AnyScenario, TaskKind};

use crate::out::{errln, out};

#[derive(clap::Args)]
pub(crate) struct RealismArgs {
    /// The grid scenario whose user (its `[realism]` table) and decoder are
    /// measured: the background, the ErrP, the discrete decoder's
    /// per-class rates, calibration against the closed loop.
    #[arg(
        long,
        value_name = "FILE.toml",
        default_value = "scenarios/grid_fixed_goals.toml"
    )]
    pub(crate) grid: PathBuf,
    /// The e-puck scenario whose detector is measured (per-trial TPR and TNR).
    #[arg(
        long,
        value_name = "FILE.toml",
        default_value = "scenarios/mexico_to_pisa.toml"
    )]
    pub(crate) epuck: PathBuf,
    /// Print only the table.
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

pub(crate) fn realism(args: &RealismArgs) -> Result<()> {
    let grid = match crate::commands::load(&args.grid)? {
        AnyScenario::Grid(s) => s,
        AnyScenario::Epuck(_) => wrong_task(&args.grid, "--grid", TaskKind::Grid)?,
    };
    let epuck = match crate::commands::load(&args.epuck)? {
        AnyScenario::Epuck(s) => s,
        AnyScenario::Grid(_) => wrong_task(&args.epuck, "--epuck", TaskKind::Epuck)?,
    };
    let quiet = args.quiet;
    let report = measure_realism(&grid, &epuck, &mut |stage: &str| {
        if !quiet {
            errln!("  measuring {stage} ...");
        }
    })?;
    out!("{report}")?;
    Ok(())
}

fn wrong_task<T>(path: &Path, flag: &str, task: TaskKind) -> Result<T> {
    bail!(
        "{flag} {}: field `task` is not \"{task}\": give a {task} scenario, e.g. {}",
        path.display(),
        task.built_in_path()
    )
}
