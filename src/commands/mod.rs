//! One module per subcommand.

pub(crate) mod calibrate;
pub(crate) mod fit;
pub(crate) mod run;
pub(crate) mod sweep;
pub(crate) mod table1;
