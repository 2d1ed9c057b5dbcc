//! `errp table1`: Table 1 of the paper, re-run.

use anyhow::Result;
use errp_sim::grid::{DecoderChoice, FIXED_PAIRS, Table1Options, Table1Report, run_table1};

use crate::cli::{DecoderArg, Table1Args};
use crate::out::{errln, out};

pub(crate) fn table1(args: &Table1Args) -> Result<()> {
    let options = Table1Options {
        repeats: args.episodes as usize,
        seed: args.seed,
        decoder: match args.decoder {
            DecoderArg::Eeg => DecoderChoice::Eeg,
            DecoderArg::Oracle => DecoderChoice::Oracle,
        },
        eeg: args.eeg.mode(),
        params: errp_sim::grid::GridTaskParams::default(),
        realism: crate::commands::user_realism(args.realism.as_deref())?,
    };
    let quiet = args.quiet;
    if !quiet {
        errln!(
            "Table 1: 4 subjects x 2 goal sets x {} runs, seed {} (calibrating 8 decoders in parallel)",
            5 * options.repeats,
            options.seed
        );
    }
    let cells = run_table1(&options, |label, s| {
        if !quiet {
            errln!(
                "  {label}: ErrP-to-noise {:.4} -> {:.2} % on held-out epochs",
                s.ratio,
                100.0 * s.accuracy.mean()
            );
        }
    })?;
    out!(
        "Fixed pairs (total length {}): {}; goal reward {}, epsilon {}\n{}",
        errp_sim::grid::total_length(&FIXED_PAIRS),
        errp_sim::grid::pairs_text(&FIXED_PAIRS),
        errp_sim::task::format_number(options.params.control.goal_reward),
        errp_sim::task::format_number(options.params.control.epsilon),
        Table1Report(&cells)
    )?;
    Ok(())
}
