//! The continuous e-puck task (sec. 5 of the paper): scenario files, the
//! rapier2d world, the camera tracker, the synthetic user, the continuous
//! decoder, one episode, batches of runs and the recording.

pub(crate) mod decoder;
pub(crate) mod episode;
pub(crate) mod run;
pub(crate) mod scenario;
pub(crate) mod tracker;
pub(crate) mod user;
pub(crate) mod view;
pub(crate) mod world;
