//! `errp`: the command-line program of errp-testbed.
//!
//! Thin glue: parse arguments, call the libraries, print, write files.

// No function over 100 lines of code (clippy.toml) outside the tests.
#![forbid(unsafe_code)]
#![cfg_attr(not(test), warn(clippy::too_many_lines))]

mod cli;
mod commands;
mod interrupt;
mod out;
mod save;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::cli::{CalibrateArgs, InspectArgs, RunArgs, Table1Args};
use crate::commands::{calibrate, fit, run, sweep, table1};
use crate::out::errln;

/// Simulated shared control of a robot from EEG error potentials.
#[derive(Parser)]
#[command(name = "errp", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Calibrate the ErrP decoder of a synthetic user at a requested accuracy.
    ///
    /// Searches the ErrP-to-noise ratio of the synthetic EEG so that the
    /// paper's decoder (z-score, PCA 95 %, shrinkage LDA), cross-validated on a
    /// 400-action calibration session with 20 % errors, reaches the requested
    /// mean accuracy; then runs that session and reports per-class rates.
    #[command(allow_negative_numbers = true)]
    Calibrate(CalibrateArgs),
    /// Run a scenario: the e-puck in its arena steered by the sliding-window
    /// ErrP decoder (sec. 5), or episodes of the grid task (sec. 4), printed
    /// per run and summarised next to the paper.
    #[command(allow_negative_numbers = true)]
    Run(RunArgs),
    /// Re-run Table 1: subjects S1-S4 at their accuracies on the fixed and
    /// free goals, side by side with the paper, with the accuracy-time
    /// correlation.
    #[command(allow_negative_numbers = true)]
    Table1(Table1Args),
    /// List the subjects of Table 1 of the paper and their accuracies.
    Subjects,
    /// Monte Carlo sweep over decoder accuracy (and any scenario parameter):
    /// episodes in parallel, streamed to DIR/episodes.csv (a rerun resumes),
    /// then DIR/summary.csv, a printed table, DIR/sweep.svg and .png, and
    /// DIR/sweep.json to rerun it exactly.
    #[command(allow_negative_numbers = true)]
    Sweep(sweep::SweepArgs),
    /// Merge the directories of a sharded sweep (`errp sweep --shard K/N`)
    /// into the files one unsharded run writes.
    Merge(sweep::MergeArgs),
    /// Estimate a parameter the paper does not state from the paper's own
    /// numbers, by maximum likelihood over a grid with Monte Carlo
    /// likelihoods.
    #[command(subcommand)]
    Fit(fit::FitCommand),
    /// The simulated user's statistics beside published recordings of
    /// people: the background EEG, the ErrP at FCz, the decoders' per-class
    /// rates, calibration against the closed loop; each row with the
    /// published range, its source and whether the user falls inside it.
    #[command(allow_negative_numbers = true)]
    Realism(commands::realism::RealismArgs),
    /// Read recordings back: what a `.rrd` holds and how to make it again,
    /// each run recomputed from it (the table `errp run` printed), tidy CSV
    /// tables, and the paper's Fig. 5 (e-puck) or Fig. 4 (grid).
    #[command(allow_negative_numbers = true)]
    Inspect(InspectArgs),
    /// Run a grid or e-puck scenario on the wall clock over Lab Streaming
    /// Layer, with your own online decoder in the loop: the simulated
    /// user's EEG (40 channels, 256 Hz, µV), markers and state out, p(error)
    /// per grid action or e-puck window back from your decoder's stream;
    /// the calibration session first.
    #[command(allow_negative_numbers = true)]
    Stream(commands::stream::StreamArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    interrupt::install();
    let result = match cli.command {
        Command::Calibrate(args) => calibrate::calibrate(&args),
        Command::Run(args) => run::run(&args),
        Command::Table1(args) => table1::table1(&args),
        Command::Subjects => calibrate::print_subjects(),
        Command::Stream(args) => commands::stream::stream(&args),
        Command::Realism(args) => commands::realism::realism(&args),
        Command::Merge(args) => sweep::merge(&args),
        #[cfg(feature = "rerun")]
        Command::Inspect(args) => commands::inspect::inspect(&args),
        #[cfg(not(feature = "rerun"))]
        Command::Inspect(_) => Err(anyhow::anyhow!(
            "errp inspect reads recordings with the Rerun crates, which this errp was built \
             without (cargo's --no-default-features); rebuild it with the default features \
             (`cargo build --release`)"
        )),
        Command::Fit(cmd) => match fit::fit(&cmd) {
            Ok(true) => Ok(()),
            Ok(false) => return ExitCode::from(interrupt::EXIT_INTERRUPTED),
            Err(e) => Err(e),
        },
        Command::Sweep(args) => match sweep::sweep(&args) {
            Ok(true) => Ok(()),
            Ok(false) => return ExitCode::from(interrupt::EXIT_INTERRUPTED),
            Err(e) => Err(e),
        },
    };
    // What standard output still buffers must reach it, or the command
    // fails (a full disk), as for every line before.
    match result.and_then(|()| out::flush()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            errln!("error: {}", error_text(&e));
            ExitCode::from(2)
        }
    }
}

/// The error and its causes, each once: a cause whose text its parent
/// already ends with (an I/O error a file error quotes) is not repeated.
fn error_text(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let part = cause.to_string();
        if text.ends_with(&part) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&part);
    }
    text
}
