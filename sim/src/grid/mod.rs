//! The discrete grid task (sec. 3-4 of the paper): scenario files, one
//! episode, a scenario's runs, Table 1 and the recording.

pub(crate) mod episode;
pub(crate) mod run;
pub(crate) mod scenario;
pub(crate) mod table1;
pub(crate) mod view;
