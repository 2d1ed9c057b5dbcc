//! One module per subcommand.

pub(crate) mod calibrate;
pub(crate) mod fit;
#[cfg(feature = "rerun")]
pub(crate) mod inspect;
pub(crate) mod realism;
pub(crate) mod run;
pub(crate) mod sweep;
pub(crate) mod table1;
