//! `--save FILE.rrd`: Rerun recordings, when `errp` is built with them (the
//! default `rerun` feature; `--no-default-features` leaves the Rerun SDK
//! out).

use std::path::Path;

use anyhow::{Result, bail};

use crate::cli::check_extension;
use crate::out::outln;

/// Checks `--save` before any work: the file name, and that this build can
/// record at all.
pub(crate) fn check_save(save: Option<&Path>) -> Result<()> {
    let Some(path) = save else {
        return Ok(());
    };
    check_extension(path, "rrd", "--save")?;
    check_ours(path, b"RRF2", "a Rerun recording", "--save")?;
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
pub(crate) fn wrote(path: &Path) -> Result<()> {
    outln!(
        "Wrote {} (open with: rerun {})",
        path.display(),
        path.display()
    )?;
    Ok(())
}

/// Refuses to replace an existing `path` that this program did not write:
/// one that is not empty and does not begin with `magic` (the format's
/// signature). A special file is left to the writer, which refuses it.
pub(crate) fn check_ours(path: &Path, magic: &[u8], what: &str, flag: &str) -> Result<()> {
    if errp_sim::is_foreign(path, magic) {
        bail!(
            "{flag} {}: the file exists and is not {what}; errp replaces only files it wrote: \
             move it away or give another name",
            path.display()
        );
    }
    Ok(())
}
