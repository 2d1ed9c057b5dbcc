//! What `errp calibrate --save` records: grand averages like Fig. 1 of the
//! paper, a topography at the peak, and the targeting summary.

use std::path::{Path, PathBuf};

use errp_bci::{GrandAverage, Montage};
use rerun::blueprint::{
    Blueprint, Horizontal, Spatial2DView, TextDocumentView, TimeSeriesView, Vertical,
};
use rerun::{Color, Image, LineStrips2D, Points2D, Scalars, SeriesLines, TextDocument};

use crate::calibration::CalibrationReport;
use crate::error::{Result, SimError};
use crate::record::{LATENCY_TIMELINE, RrdFile, paths, record_error};

/// Side of the topography image (pixels).
const MAP_PX: usize = 200;

const ERROR_RGB: [u8; 3] = [220, 50, 47];
const CORRECT_RGB: [u8; 3] = [38, 139, 210];
const DIFF_RGB: [u8; 3] = [40, 40, 40];

/// Channels whose grand averages are recorded.
const GA_CHANNELS: [&str; 3] = ["FCz", "Cz", "Fz"];

fn blueprint() -> Blueprint {
    let mut series: Vec<rerun::blueprint::ContainerLike> = Vec::new();
    for ch in GA_CHANNELS {
        series.push(
            TimeSeriesView::new(format!("Grand average at {ch} (uV)"))
                .with_origin(paths::grand_average(ch))
                .into(),
        );
    }
    crate::record::opening_view(
        Blueprint::new(Horizontal::new([
            Vertical::new(series).into(),
            Vertical::new([
                Spatial2DView::new("Error - correct at the peak")
                    .with_origin(paths::TOPOGRAPHY)
                    .into(),
                TextDocumentView::new("Calibration")
                    .with_origin(paths::SUMMARY)
                    .into(),
            ])
            .into(),
        ])),
        crate::record::LATENCY_TIMELINE,
    )
}

/// Opens the `.rrd` of a calibration run, with its layout. Open it before
/// the run, so that an unwritable path fails before any work.
pub fn calibration_recording(path: &Path) -> Result<RrdFile> {
    RrdFile::create("errp_calibrate", path, blueprint())
}

/// Writes `report` (which must carry grand averages) to `file` and moves the
/// file into place.
pub fn record_calibration(
    file: RrdFile,
    report: &CalibrationReport,
    montage: &Montage,
) -> Result<PathBuf> {
    let path = file.path().to_path_buf();
    log_calibration(file.stream(), report, montage, &path)?;
    file.finish()
}

fn log_calibration(
    rec: &rerun::RecordingStream,
    report: &CalibrationReport,
    montage: &Montage,
    path: &Path,
) -> Result<()> {
    let ga = report
        .calibrated
        .session
        .grand_average
        .as_ref()
        .ok_or_else(|| SimError::Record {
            path: path.to_path_buf(),
            message: "the calibration was run without grand averages".into(),
        })?;
    let diff = ga.difference();
    log_grand_averages(rec, ga, &diff, path)?;
    rec.reset_time();
    let (peak_ms, limit) = log_topography(rec, ga, &diff, montage, path)?;
    log_summary(rec, report, peak_ms, limit, path)
}

/// The grand averages of Fig. 1 on the latency timeline: error, correct and
/// their difference at each channel of [`GA_CHANNELS`].
fn log_grand_averages(
    rec: &rerun::RecordingStream,
    ga: &GrandAverage,
    diff: &impl std::ops::Index<(usize, usize), Output = f64>,
    path: &Path,
) -> Result<()> {
    let err = record_error(path);
    for name in GA_CHANNELS {
        let row = channel_row(ga, name, path)?;
        let base = paths::grand_average(name);
        for (label, rgb) in [
            ("error", ERROR_RGB),
            ("correct", CORRECT_RGB),
            ("difference", DIFF_RGB),
        ] {
            rec.log_static(
                format!("{base}/{label}"),
                &SeriesLines::new()
                    .with_colors([Color::from_rgb(rgb[0], rgb[1], rgb[2])])
                    .with_names([label]),
            )
            .map_err(&err)?;
        }
        for (t, &ms) in ga.times_ms.iter().enumerate() {
            rec.set_duration_secs(LATENCY_TIMELINE, ms / 1000.0);
            rec.log(
                format!("{base}/error"),
                &Scalars::single(ga.error[(row, t)]),
            )
            .map_err(&err)?;
            rec.log(
                format!("{base}/correct"),
                &Scalars::single(ga.correct[(row, t)]),
            )
            .map_err(&err)?;
            rec.log(
                format!("{base}/difference"),
                &Scalars::single(diff[(row, t)]),
            )
            .map_err(&err)?;
        }
    }
    Ok(())
}

/// The scalp map of the difference at its largest |value| at FCz within
/// 150-600 ms; returns that time (ms) and the colour range (uV).
fn log_topography(
    rec: &rerun::RecordingStream,
    ga: &GrandAverage,
    diff: &impl std::ops::Index<(usize, usize), Output = f64>,
    montage: &Montage,
    path: &Path,
) -> Result<(f64, f64)> {
    let err = record_error(path);
    let fcz = channel_row(ga, "FCz", path)?;
    let peak = (0..ga.times_ms.len())
        .filter(|&t| (150.0..=600.0).contains(&ga.times_ms[t]))
        .max_by(|&a, &b| diff[(fcz, a)].abs().total_cmp(&diff[(fcz, b)].abs()))
        .unwrap_or(0);
    let values: Vec<f64> = (0..ga.channels.len()).map(|r| diff[(r, peak)]).collect();
    let positions: Vec<[f64; 2]> = ga
        .channels
        .iter()
        .map(|n| {
            let i = montage
                .index(n)
                .expect("grand-average channels are in the montage");
            project(montage.channels()[i].position)
        })
        .collect();
    let limit = values.iter().fold(1e-9f64, |a, v| a.max(v.abs()));
    let image = topography_image(&positions, &values, limit);
    rec.log_static(
        paths::TOPOGRAPHY_MAP,
        &Image::from_rgb24(image, [MAP_PX as u32, MAP_PX as u32]),
    )
    .map_err(&err)?;
    let to_px = |p: [f64; 2]| {
        let c = MAP_PX as f64 / 2.0;
        [
            (c + p[0] * 0.45 * MAP_PX as f64) as f32,
            (c - p[1] * 0.45 * MAP_PX as f64) as f32,
        ]
    };
    rec.log_static(
        paths::TOPOGRAPHY_ELECTRODES,
        &Points2D::new(positions.iter().map(|&p| to_px(p)))
            .with_radii([2.5])
            .with_colors(values.iter().map(|&v| color(v / limit)))
            .with_labels(
                ga.channels
                    .iter()
                    .zip(&values)
                    .map(|(n, v)| format!("{n} {v:+.1}")),
            ),
    )
    .map_err(&err)?;
    let head: Vec<[f32; 2]> = (0..=64)
        .map(|k| {
            let a = k as f64 / 64.0 * std::f64::consts::TAU;
            to_px([a.cos(), a.sin()])
        })
        .collect();
    let nose = vec![
        to_px([-0.12, 0.99]),
        to_px([0.0, 1.12]),
        to_px([0.12, 0.99]),
    ];
    rec.log_static(
        paths::TOPOGRAPHY_HEAD,
        &LineStrips2D::new([head, nose]).with_colors([Color::from_rgb(80, 80, 80)]),
    )
    .map_err(&err)?;

    Ok((ga.times_ms[peak], limit))
}

/// The calibration in words: the accuracy requested and reached, the
/// decoder, the topography's time and range, the targeting steps.
fn log_summary(
    rec: &rerun::RecordingStream,
    report: &CalibrationReport,
    peak_ms: f64,
    limit: f64,
    path: &Path,
) -> Result<()> {
    let err = record_error(path);
    let t = &report.targeting;
    let a = &report.calibrated.accuracy;
    let mut md = format!(
        "# Calibration\n\n\
         Requested mean accuracy **{:.2} %**; ErrP-to-noise ratio found **{:.4}**.\n\n\
         | | rate |\n|---|---|\n\
         | correct class ({} trials) | {:.2} % |\n| error class ({} trials) | {:.2} % |\n\
         | mean | **{:.2} %** |\n\n\
         Decoder: {} principal components, Ledoit-Wolf shrinkage {:.3}.\n\n\
         Topography: error - correct at {:.0} ms (peak at FCz), colour range +-{:.1} uV.\n\n\
         ## Targeting steps\n\n| ratio | mean accuracy |\n|---|---|\n",
        100.0 * t.requested,
        t.ratio,
        a.n_correct,
        100.0 * a.correct,
        a.n_error,
        100.0 * a.error,
        100.0 * a.mean(),
        report.calibrated.model.n_components(),
        report.calibrated.model.shrinkage(),
        peak_ms,
        limit,
    );
    for s in &t.steps {
        md.push_str(&format!(
            "| {:.4} | {:.2} % |\n",
            s.ratio,
            100.0 * s.accuracy.mean()
        ));
    }
    rec.log_static(
        paths::SUMMARY,
        &TextDocument::new(md).with_media_type(rerun::MediaType::markdown()),
    )
    .map_err(&err)?;
    Ok(())
}

fn channel_row(ga: &GrandAverage, name: &str, path: &Path) -> Result<usize> {
    ga.channels
        .iter()
        .position(|c| c == name)
        .ok_or_else(|| SimError::Record {
            path: path.to_path_buf(),
            message: format!("channel {name} is not in the grand average"),
        })
}

/// Azimuthal equidistant projection of a head-sphere position: the vertex at
/// the centre, the equator (Fpz-T7-Oz ring) on the unit circle, nose up.
fn project(p: [f64; 3]) -> [f64; 2] {
    let polar = p[2].clamp(-1.0, 1.0).acos();
    let r = polar / std::f64::consts::FRAC_PI_2;
    let az = p[0].atan2(p[1]);
    [r * az.sin(), r * az.cos()]
}

/// Diverging blue-white-red colour for `x` in [-1, 1].
fn rgb(x: f64) -> [u8; 3] {
    let x = x.clamp(-1.0, 1.0);
    let (r, g, b) = if x >= 0.0 {
        (1.0, 1.0 - x, 1.0 - x)
    } else {
        (1.0 + x, 1.0 + x, 1.0)
    };
    [(r * 255.0) as u8, (g * 255.0) as u8, (b * 255.0) as u8]
}

fn color(x: f64) -> Color {
    let [r, g, b] = rgb(x);
    Color::from_rgb(r, g, b)
}

/// Inverse-distance-weighted interpolation inside the head circle, RGB.
fn topography_image(positions: &[[f64; 2]], values: &[f64], limit: f64) -> Vec<u8> {
    let mut img = vec![255u8; MAP_PX * MAP_PX * 3];
    let c = MAP_PX as f64 / 2.0;
    let scale = 0.45 * MAP_PX as f64;
    for py in 0..MAP_PX {
        for px in 0..MAP_PX {
            let x = (px as f64 + 0.5 - c) / scale;
            let y = (c - py as f64 - 0.5) / scale;
            if x * x + y * y > 1.0 {
                continue;
            }
            let (mut num, mut den) = (0.0, 0.0);
            for (p, v) in positions.iter().zip(values) {
                let d2 = (p[0] - x).powi(2) + (p[1] - y).powi(2) + 1e-6;
                let w = 1.0 / (d2 * d2);
                num += w * v;
                den += w;
            }
            let i = (py * MAP_PX + px) * 3;
            img[i..i + 3].copy_from_slice(&rgb(num / den / limit));
        }
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_puts_cz_in_the_centre_and_fpz_ring_on_the_circle() {
        let m = Montage::standard();
        let at = |n: &str| project(m.channels()[m.index(n).unwrap()].position);
        let cz = at("Cz");
        assert!(cz[0].abs() < 1e-9 && cz[1].abs() < 1e-9);
        let fp1 = at("Fp1");
        assert!(((fp1[0].powi(2) + fp1[1].powi(2)).sqrt() - 1.0).abs() < 1e-6);
        assert!(fp1[1] > 0.9 && fp1[0] < 0.0, "front-left: {fp1:?}");
    }
}
