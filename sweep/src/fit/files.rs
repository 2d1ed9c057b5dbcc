//! What every fit writes, and the directory it writes into.

use std::path::{Path, PathBuf};

use errp_sim::{Result, SimError, write_atomic};
use serde::Serialize;

use super::surface::Surface;
use crate::plot::{Curve, CurvePoint, FitPlot, fit_png, fit_svg};

/// The files a fit writes in its directory.
pub const FIT_FILES: [&str; 4] = ["fit.json", "surface.csv", "fit.svg", "fit.png"];

/// Writes [`FIT_FILES`] into `out`, each atomically: `fit` as JSON, the
/// surface's CSV and the figure as SVG and PNG.
pub(crate) fn write_fit_files(
    out: &Path,
    fit: &impl Serialize,
    csv: String,
    plot: &FitPlot,
) -> Result<Vec<PathBuf>> {
    let json = serde_json::to_string_pretty(fit)
        .map_err(|e| SimError::Sweep(format!("cannot encode the fit: {e}")))?;
    let svg = fit_svg(plot).map_err(|e| SimError::Sweep(e.to_string()))?;
    let png = fit_png(plot).map_err(|e| SimError::Sweep(e.to_string()))?;
    let files = [
        (FIT_FILES[0], format!("{json}\n").into_bytes()),
        (FIT_FILES[1], csv.into_bytes()),
        (FIT_FILES[2], svg.into_bytes()),
        (FIT_FILES[3], png),
    ];
    let mut written = Vec::new();
    for (name, bytes) in files {
        let path = out.join(name);
        write_atomic(&path, &bytes)?;
        written.push(path);
    }
    Ok(written)
}

/// Refuses an `out` that holds anything but [`FIT_FILES`], partial files
/// and the entries `ours` accepts (a fit's sweeps); `what` names the fit in
/// the message ("a fit's", "a grid fit's").
pub(crate) fn check_out(out: &Path, ours: impl Fn(&Path) -> bool, what: &str) -> Result<()> {
    // A fit inside another fit's directory would make that one's rerun
    // refuse its own directory.
    if let Some(outer) = std::path::absolute(out).ok().and_then(|abs| {
        abs.ancestors()
            .skip(1)
            .find(|a| is_fit_json(&a.join(FIT_FILES[0])))
            .map(Path::to_path_buf)
    }) {
        return Err(SimError::Sweep(format!(
            "--out {} is inside the directory of another fit, {} (its {}); give a directory \
             outside it",
            out.display(),
            outer.display(),
            FIT_FILES[0]
        )));
    }
    if !out.exists() {
        return check_writable(out);
    }
    if !out.is_dir() {
        return Err(SimError::Sweep(format!(
            "--out {} exists and is not a directory",
            out.display()
        )));
    }
    let entries = std::fs::read_dir(out).map_err(|source| SimError::Input {
        path: out.to_path_buf(),
        source,
    })?;
    // The fit's file names are a fit's only beside a fit.json that a fit
    // wrote: a user's own fit.json (or figures) of these names stay.
    let a_fit = is_fit_json(&out.join(FIT_FILES[0]));
    let mut foreign: Vec<String> = entries
        .flatten()
        .filter(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            !((a_fit && FIT_FILES.contains(&name.as_str()))
                || ours(&e.path())
                || (name.starts_with('.') && name.contains(".partial-")))
        })
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .take(6)
        .collect();
    if foreign.is_empty() {
        return check_writable(out);
    }
    foreign.sort();
    Err(SimError::Sweep(format!(
        "--out {} holds files that are not {what} ({}); give a new or empty directory",
        out.display(),
        foreign.join(", ")
    )))
}

/// Checks, before the work, that the fit's files can be written into
/// `out`: a temporary is created (and removed) in `out`, or in its nearest
/// existing parent if `out` is still to be made.
fn check_writable(out: &Path) -> Result<()> {
    let mut at = out;
    while !at.exists() {
        match at.parent() {
            Some(p) if !p.as_os_str().is_empty() => at = p,
            _ => {
                at = Path::new(".");
                break;
            }
        }
    }
    errp_sim::PendingFile::create(at.join("write-probe"))
        .map(drop)
        .map_err(|e| SimError::Sweep(format!("--out {}: {e}", out.display())))
}

/// True if `path` is a `fit.json` that `errp fit` wrote: a regular file
/// of at most 64 MiB holding a JSON object with the fit's `format`,
/// `parameter` and `provenance` (with `errp_version`).
fn is_fit_json(path: &Path) -> bool {
    use std::io::Read;
    const MAX_FIT_JSON: u64 = 64 << 20;
    let mut text = String::new();
    let read =
        errp_sim::open_regular(path).and_then(|f| f.take(MAX_FIT_JSON).read_to_string(&mut text));
    if read.is_err() {
        return false;
    }
    let Ok(v) = serde_json::from_str::<serde_json::Value>(&text) else {
        return false;
    };
    v["format"].is_u64()
        && v["parameter"].is_string()
        && v["provenance"]["errp_version"].is_string()
}

/// The log-likelihood panel of a fit's figure: each observation's curve
/// (labelled by `labels`) relative to its own maximum, and their sum
/// (`total_label`) relative to the estimate's, each with +- its Monte Carlo
/// sd (none where that is not finite).
pub(crate) fn log_lik_curves(s: &Surface, labels: &[String], total_label: &str) -> Vec<Curve> {
    let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
    let mut curves: Vec<Curve> = labels
        .iter()
        .enumerate()
        .map(|(i, label)| {
            let top = s.log_lik[i]
                .iter()
                .copied()
                .fold(f64::NEG_INFINITY, f64::max);
            Curve {
                label: label.clone(),
                points: (0..s.grid.len())
                    .map(|j| {
                        let sd = finite(s.mc_sd[i][j]);
                        let v = s.log_lik[i][j] - top;
                        CurvePoint {
                            x: s.grid[j],
                            y: v,
                            lo: v - sd,
                            hi: v + sd,
                        }
                    })
                    .collect(),
            }
        })
        .collect();
    let best = s.total[s.estimate];
    curves.push(Curve {
        label: total_label.into(),
        points: (0..s.grid.len())
            .map(|j| {
                let sd = finite(s.total_sd[j]);
                CurvePoint {
                    x: s.grid[j],
                    y: s.total[j] - best,
                    lo: (s.total[j] - sd) - best,
                    hi: (s.total[j] + sd) - best,
                }
            })
            .collect(),
    });
    curves
}
