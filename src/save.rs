//! `--save FILE.rrd`: Rerun recordings, when `errp` is built with them (the
//! default `rerun` feature; `--no-default-features` leaves the Rerun SDK
//! out).

use std::path::Path;

use anyhow::{Result, bail};

use crate::cli::check_extension;

/// Checks `--save` before any work: the file name, and that this build can
/// record at all.
pub(crate) fn check_save(save: Option<&Path>) -> Result<()> {
    let Some(path) = save else {
        return Ok(());
    };
    check_extension(path, "rrd", "--save")?;
    if !cfg!(feature = "rerun") {
        bail!(
            "--save {}: this errp was built without Rerun (cargo's --no-default-features); \
             rebuild it with the default features (`cargo build --release`) to write recordings",
            path.display()
        );
    }
    Ok(())
}

/// Prints where a recording went.
#[cfg(feature = "rerun")]
pub(crate) fn wrote(path: &Path) {
    println!(
        "Wrote {} (open with: rerun {})",
        path.display(),
        path.display()
    );
}
