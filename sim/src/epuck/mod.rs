//! The continuous e-puck task (sec. 5 of the paper): scenario files, the
//! rapier2d world, the camera tracker, the synthetic user, the continuous
//! decoder, one episode, batches of runs and the recording.

pub(crate) mod decoder;
pub(crate) mod environment;
pub(crate) mod episode;
pub(crate) mod hybrid;
pub(crate) mod hybrid_report;
pub(crate) mod observer;
pub(crate) mod params;
pub(crate) mod plant;
pub(crate) mod report;
pub(crate) mod run;
pub(crate) mod scenario;
pub(crate) mod schema;
pub(crate) mod task;
pub(crate) mod tracker;
pub(crate) mod user;
#[cfg(feature = "rerun")]
pub(crate) mod view;
pub(crate) mod world;

pub use crate::own_eeg::{FITTED_FALSE_ALARMS_PER_MIN, MAX_FALSE_ALARMS_PER_MIN};
pub use decoder::{
    ContinuousDecoder, ContinuousReport, ContinuousRequest, OnlineReport, calibrate_continuous_at,
    run_continuous_calibration, run_online_calibration, target_continuous,
};
pub use environment::{EpuckAction, EpuckEnvironment, EpuckFeedback, MAX_WINDOWS_PER_ACTION};
pub use episode::{
    EpuckEpisodeResult, run_epuck_episode, run_epuck_episode_live, run_epuck_episode_with,
    shared_control,
};
pub use errp_robot::AvoidanceParams;
pub use hybrid::{calibrate_on_own_eeg, epuck_decoder_summary, prepare_hybrid};
pub use hybrid_report::{HYBRID_LABEL, HybridReport};
pub use observer::{
    EpisodeStart, EpuckObserver, PHASE_NAMES, PhysicsFrame, STEP_NAMES, WindowFrame,
};
pub use params::{EpuckEpisode, EpuckTaskParams};
pub use plant::{
    EpuckDriver, EpuckPlant, LiveWindow, LiveWindowDecoder, PHYSICS_DT_SECS, PlantWindow,
    STEPS_PER_WINDOW, WINDOW_STEP_SECS, WindowDecoder, WindowDecoding,
};
pub use report::{EpuckRunHeader, EpuckRunRow, EpuckRunsTable, EpuckSummaryReport};
pub use run::{
    EpuckRunsObserver, EpuckSummary, PreparedEpuck, epuck_run_seed, finish_continuous_decoder,
    prepare_continuous_decoder, prepare_continuous_decoder_with, prepare_epuck_decoder,
    run_epuck_batch, run_epuck_batch_counted, run_epuck_once, run_epuck_runs, summarise,
};
pub use scenario::{
    EpuckScenario, MAX_OBSTACLES, MAX_REACTION_LATENCY_MS, MAX_REELICIT_SECS, MAX_RUN_SECS,
    MAX_RUNS, MAX_TRACKER_HZ,
};
pub use task::{EpuckRunner, EpuckTask, epuck_row};
pub use tracker::{CameraTracker, TrackerParams};
pub use user::{Elicited, Judgement, SeenMotion, SyntheticUser, UserParams};
#[cfg(feature = "rerun")]
pub use view::{
    EpuckRecorder, RUN_GAP_SECS, epuck_agent_recording, epuck_recording, record_epuck_runs,
    record_epuck_runs_with,
};
pub use world::{ArenaSpec, Obstacle, ProximitySensors, World};
