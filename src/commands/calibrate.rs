//! `errp calibrate` and `errp subjects`.

use anyhow::{Context, Result, bail};
use errp_bci::{EdfWriter, GoalSet, MeanAccuracy, SFREQ_HZ, SessionOptions, subject, subjects};
use errp_sim::PendingFile;
use errp_sim::calibration::{CalibrationReport, CalibrationRequest, run_calibration};

use crate::cli::{CalibrateArgs, Goals, check_extension};
use crate::out::{errln, outln};
use crate::save::check_save;

/// The accuracy to target, and whose it is (for the report).
fn requested(args: &CalibrateArgs) -> Result<(MeanAccuracy, String)> {
    // (clap lets `requires` pass when the required flag conflicts with one
    // given, as --subject does with --accuracy.)
    if let (Some(_), None) = (args.goals, &args.subject) {
        bail!(
            "--goals chooses which of a --subject's accuracies to target; without --subject \
             it does nothing: give --subject S1..S4, or leave --goals out"
        );
    }
    let (accuracy, who) = match &args.subject {
        Some(name) => {
            let s = subject(name).context("--subject")?;
            let goals = match args.goals.unwrap_or(Goals::Fixed) {
                Goals::Fixed => GoalSet::Fixed,
                Goals::Free => GoalSet::Free,
            };
            let a = MeanAccuracy::new(s.accuracy(goals))?;
            (
                a,
                format!("subject {} ({:?} goals)", s.name, goals).to_lowercase(),
            )
        }
        None => (
            args.accuracy.unwrap_or(MeanAccuracy::new(0.7438)?),
            "requested".to_string(),
        ),
    };
    Ok((accuracy, who))
}

pub(crate) fn calibrate(args: &CalibrateArgs) -> Result<()> {
    let (accuracy, who) = requested(args)?;
    check_save(args.save.as_deref())?;
    if let Some(p) = &args.export {
        check_extension(p, "edf", "--export")?;
        // An EDF file's header begins with its version, "0" and 7 spaces.
        crate::save::check_ours(p, b"0       ", "an EDF file", "--export")?;
    }
    // Reserve the outputs first: an unwritable path fails before the work.
    let mut edf = match &args.export {
        Some(p) => {
            let (pending, file) = PendingFile::create(p).context("--export")?;
            let montage = errp_bci::Montage::standard();
            let writer = EdfWriter::new(std::io::BufWriter::new(file), &montage, SFREQ_HZ)?;
            Some((pending, writer))
        }
        None => None,
    };
    #[cfg(feature = "rerun")]
    let rrd = match &args.save {
        Some(p) => Some(errp_sim::calibration::calibration_recording(p).context("--save")?),
        None => None,
    };

    let request = CalibrationRequest::new(accuracy, args.seed);
    if !args.quiet {
        errln!(
            "Targeting a mean accuracy of {:.2} % ({who}), seed {}:",
            100.0 * accuracy.get(),
            args.seed
        );
    }
    let quiet = args.quiet;
    let progress = |s: &errp_bci::TargetingStep| {
        if !quiet {
            errln!(
                "  ErrP-to-noise {:.4}: correct {:.2} %, error {:.2} %, mean {:.2} %",
                s.ratio,
                100.0 * s.accuracy.correct,
                100.0 * s.accuracy.error,
                100.0 * s.accuracy.mean()
            );
        }
    };
    // A failure to write the export stops the session, and is the
    // export's (naming --export), not the calibration's.
    let mut export_failed = None;
    let mut sink = |block: &errp_bci::EegBlock, events: &[errp_bci::Assessment]| match edf.as_mut()
    {
        Some((_, w)) => w
            .write(block, events)
            .inspect_err(|e| export_failed = Some(e.to_string())),
        None => Ok(()),
    };
    // Grand averages for the recording, the raw session for the export.
    let options = SessionOptions {
        grand_average: args.save.is_some(),
        raw_sink: if args.export.is_some() {
            Some(&mut sink)
        } else {
            None
        },
        ..SessionOptions::default()
    };
    let report = run_calibration(&request, progress, options);
    if let (Some(e), Some(p)) = (export_failed, &args.export) {
        bail!("--export: cannot write {}: {e}", p.display());
    }
    let report = report.context("calibration failed")?;
    print_report(&report, &request, &who)?;

    if let (Some((pending, writer)), Some(p)) = (edf, &args.export) {
        writer
            .finish()
            .with_context(|| format!("--export: cannot write {}", p.display()))?;
        let path = pending.commit().context("--export")?;
        outln!(
            "Wrote {} (EDF+, raw EEG + EOG, 256 Hz, annotated)",
            path.display()
        )?;
    }
    #[cfg(feature = "rerun")]
    if let Some(file) = rrd {
        let montage = errp_bci::Montage::standard();
        crate::save::wrote(
            &errp_sim::calibration::record_calibration(file, &report, &montage)
                .context("--save")?,
        )?;
    }
    Ok(())
}

/// The calibration's scores, against what was asked (`who`'s accuracy).
fn print_report(report: &CalibrationReport, request: &CalibrationRequest, who: &str) -> Result<()> {
    let accuracy = request.accuracy;
    let a = &report.calibrated.accuracy;
    let m = &report.calibrated.model;
    outln!(
        "Calibration session: {} actions ({} error, {} correct), {}-fold cross-validation",
        a.n_correct + a.n_error,
        a.n_error,
        a.n_correct,
        request.setup.calibration.folds
    )?;
    outln!("  correct class  {:6.2} %", 100.0 * a.correct)?;
    outln!("  error class    {:6.2} %", 100.0 * a.error)?;
    outln!(
        "  mean           {:6.2} %   ({who} {:.2} %, off by {:+.2} points)",
        100.0 * a.mean(),
        100.0 * accuracy.get(),
        100.0 * (a.mean() - accuracy.get())
    )?;
    outln!(
        "  ErrP-to-noise ratio {:.4}; decoder: {} PCA components, Ledoit-Wolf shrinkage {:.3}",
        report.generator.errp_to_noise,
        m.n_components(),
        m.shrinkage()
    )?;
    Ok(())
}

pub(crate) fn print_subjects() -> Result<()> {
    outln!("subject  fixed goals  free goals   (mean accuracy, Table 1)")?;
    for s in subjects() {
        outln!(
            "{:<8} {:>9.2} %  {:>8.2} %",
            s.name,
            s.fixed_goals_pct,
            s.free_goals_pct
        )?;
    }
    Ok(())
}
