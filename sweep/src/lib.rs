//! Monte Carlo sweeps: how goal inference degrades with decoder accuracy,
//! and how strategies and parameters change that.
//!
//! A sweep runs `episodes` episodes at every level (an accuracy and one value
//! of every swept parameter). Each episode's seed derives from the sweep seed,
//! its accuracy and its index, so results do not depend on threads, shards or
//! interruptions. Rows stream to `episodes.csv` as they finish; a rerun of the
//! same sweep resumes; `summary.csv`, `sweep.svg`, `sweep.png` and
//! `sweep.json` are written whole at the end.
//!
//! Episodes are run by [`errp_sim`]'s task modules; this crate adds the
//! levels, the ordered and resumable `episodes.csv`, the target cache,
//! sharding and merging, the summaries and the plots.
//!
//! ```
//! use errp_sim::Names;
//! use errp_sweep::parse_accuracies;
//!
//! // A sweep's accuracy levels, as `--accuracy` and `accuracy=` give them.
//! let levels = parse_accuracies("0.6:0.9:0.1", &Names::CLI).unwrap();
//! assert_eq!(levels.len(), 4);
//! assert!(parse_accuracies("0.4", &Names::CLI).is_err());
//! ```

#![forbid(unsafe_code)]
#![warn(clippy::unwrap_used, clippy::print_stdout, clippy::iter_over_hash_type)]
// No function over 100 lines of code (clippy.toml) outside the tests.
#![cfg_attr(not(test), warn(clippy::too_many_lines))]

mod cache;
mod figure;
mod finish;
pub mod fit;
mod lock;
mod manifest;
mod merge;
mod observer;
mod plot;
mod prepare;
mod rows;
mod run;
mod spec;
mod summary;
mod table;
mod writer;

pub use cache::{Reporting, TargetCache};
pub use errp_sim::task::DecoderInfo;
pub use figure::sweep_plot;
pub use finish::finish_dir;
pub use lock::{DirLock, HEARTBEAT, Holder, LOCK, STALE_AFTER};
pub use manifest::{EPISODES, FORMAT, MANIFEST, MAX_MANIFEST_BYTES, Manifest};
pub use merge::merge_sweeps;
pub use observer::SweepObserver;
pub use plot::{
    ArenaPlot, Curve, CurvePoint, FitPanel, FitPlot, GridPlot, LevelPoint, PaperPoint, PlotError,
    RunPath, Series, SweepPlot, arena_png, arena_svg, fit_png, fit_svg, grid_png, grid_svg,
};
pub use rows::{CHECKSUM, episodes_header};
pub use run::{MAX_DECODER_BYTES, SweepOptions, SweepOutcome, prepare_sweep, run_sweep};
pub use spec::{
    Axis, CheckedSweep, Level, MAX_EPISODES, MAX_LEVELS, Shard, SweepSpec, aliases,
    parse_accuracies, parse_axis, parse_values, read_task, sweep_fixed, sweep_scenario, sweepable,
};
pub use summary::{LevelSummary, SweepReport, summarise_dir};
pub use table::summary_csv;
