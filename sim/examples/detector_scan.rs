//! Scans the asynchronous detector's settings on a held-out session: for
//! T_e in 0.5..0.9 and 1..8 smoothed windows, the hit rate per ErrP, the
//! false alarms per minute and the median latency, for a decoder calibrated
//! at a given cross-validated accuracy.
//!
//! `cargo run -p errp_sim --example detector_scan -- [ACCURACY] [SEED]`
//! (defaults 0.95 and 1; 30 minutes of held-out EEG).

use errp_bci::{
    Detector, DetectorMode, DetectorParams, HeldOutParams, Valid, detector_span, operating_point,
    simulate_held_out,
};
use errp_sim::epuck::{ContinuousDecoder, ContinuousRequest, run_continuous_calibration};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let accuracy: f64 = args.next().map_or(Ok(0.95), |a| a.parse())?;
    let seed: u64 = args.next().map_or(Ok(1), |a| a.parse())?;
    let report = run_continuous_calibration(
        &ContinuousRequest::new(errp_bci::MeanAccuracy::new(accuracy)?, seed),
        |_| {},
    )?;
    let d = ContinuousDecoder::from_report(&report);
    let params = Valid::new(HeldOutParams {
        duration_secs: 1800.0,
        ..HeldOutParams::default()
    })?;
    let rec = simulate_held_out(
        &d.generator,
        &d.montage,
        &d.preprocessor,
        &d.model,
        &params,
        seed,
    )?;
    println!("t_e  windows  span (s)    hit rate  false alarms/min  median latency (s)");
    for t_e in [0.5, 0.6, 0.7, 0.8, 0.9] {
        for n in [1usize, 2, 3, 4, 6, 8] {
            let p = Valid::new(DetectorParams {
                mode: DetectorMode::Smoothed,
                smooth_windows: n,
                ..DetectorParams::default()
            })?;
            let span = detector_span(&rec, p, t_e)?;
            let op = operating_point(&rec, Detector::new(p, t_e)?, span);
            println!(
                "{t_e:.1}  {n:>7}  {:.2}-{:.2}  {:>7.1} %  {:>16.2}  {:>18.2}",
                op.span.from_secs,
                op.span.to_secs,
                100.0 * op.hit_rate,
                op.false_alarms_per_min,
                op.median_latency_secs
            );
        }
    }
    Ok(())
}
