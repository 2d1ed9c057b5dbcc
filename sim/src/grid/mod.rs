//! The discrete grid task (sec. 3-4 of the paper): scenario files, one
//! episode, a scenario's runs, Table 1 and the recording.

pub(crate) mod builder;
pub(crate) mod decoder;
pub(crate) mod environment;
pub(crate) mod episode;
pub(crate) mod own_eeg;
pub(crate) mod p_error;
pub(crate) mod pairs;
pub(crate) mod params;
pub(crate) mod plant;
pub(crate) mod report;
pub(crate) mod run;
pub(crate) mod scenario;
pub(crate) mod table1;
pub(crate) mod task;
#[cfg(feature = "rerun")]
pub(crate) mod view;

pub use builder::GridScenarioBuilder;
pub use decoder::{
    AssessmentDecoder, EegDecoder, EegSource, EpochBank, EpochBankParts, EpochBlocks,
    INFORMATION_PER_CLASS,
};
pub use environment::{GridEnvironment, GridFeedback};
pub use episode::{run_grid_episode, run_grid_episode_with};
pub use own_eeg::{CV_REPEATS, OwnEegBank, OwnEegReport};
pub use p_error::{PErrorChoice, PErrorMapping};
pub use pairs::{
    CENTRAL_RUN, PAIRS_PER_SET, PairFamily, keeps_to_the_centre, manhattan, pairs_text,
    total_length,
};
pub use params::GridTaskParams;
pub use plant::{
    EpochDecoder, GridDecoding, GridEpisodeResult, GridStep, LiveAction, LiveDecoder,
    grid_episode_seed,
};
pub use report::{GridEpisodeHeader, GridEpisodeRow, Table1Report};
pub use run::{
    GridRunReport, GridShared, HELD_OUT_PER_CLASS, PreparedGrid, decoder_accuracy, eeg_decoder,
    pooled_accuracy, prepare_decoder, prepare_grid_decoder, run_grid_scenario,
    run_grid_scenario_with, target_online_accuracy,
};
pub use scenario::{
    DecoderChoice, EegMode, GridAccuracy, GridScenario, MAX_ACTIONS, MAX_BANK_PER_CLASS,
    MAX_EPISODES, MAX_INTERVAL_SECS, MAX_PAIRS, free_pairs,
};
pub use table1::{
    CORNER_PAIRS, FIXED_PAIRS, Table1Cell, Table1Options, accuracy_time_correlation, run_table1,
};
pub use task::{GridRunner, GridTask, grid_row};
#[cfg(feature = "rerun")]
pub use view::{GridRecorder, grid_recording, record_grid_run};
