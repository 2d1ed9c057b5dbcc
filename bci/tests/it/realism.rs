//! Each effect of `Realism` does what it says, and no more: with the effect
//! off the samples are the ideal user's, and an effect on one part of the
//! signal leaves the others' draws alone.

use errp_bci::{
    Assessment, AssessmentKind, CalibrationParams, CalibrationSetup, Components, EegBlock,
    EegGenerator, FilterChain, GeneratorParams, LdaDecoder, Montage, Realism, SessionOptions,
    Valid, calibrate,
};

const FS: usize = 256;

fn params(realism: Realism) -> Valid<GeneratorParams> {
    Valid::new(GeneratorParams {
        realism,
        ..GeneratorParams::default()
    })
    .unwrap()
}

fn generator(realism: Realism, seed: u64, components: Components) -> EegGenerator {
    EegGenerator::new(&params(realism), &Montage::standard(), seed)
        .unwrap()
        .with_components(components)
}

const BACKGROUND: Components = Components {
    background: true,
    artifacts: false,
    erp: false,
};
const ARTIFACTS: Components = Components {
    background: false,
    artifacts: true,
    erp: false,
};
const ERP: Components = Components {
    background: false,
    artifacts: false,
    erp: true,
};

/// Every effect on at once, at sizes large enough to see.
fn everything() -> Realism {
    Realism {
        background_drift: 0.2,
        alpha_drift: 0.3,
        drift_secs: 20.0,
        electrode_drift_uv: 50.0,
        errp_amplitude_per_hour: -0.3,
        errp_latency_ms_per_hour: 20.0,
        expectancy: 0.8,
        erp_latency_shift_ms: 15.0,
        erp_gain: 0.8,
        clock_offset_secs: 600.0,
        lapse_rate: 0.1,
        lapse_per_hour: 0.1,
        misjudge_rate: 0.1,
        emg_rate_hz: 0.3,
        emg_uv: 20.0,
        pop_rate_hz: 0.2,
        pop_uv: 100.0,
        bad_channel: "Cz".into(),
        bad_channel_uv: 15.0,
        action_blink_probability: 0.5,
        ..Realism::default()
    }
}

fn schedule_alternating(g: &mut EegGenerator, n: usize, period: f64) {
    for k in 0..n {
        let kind = if k % 3 == 0 {
            AssessmentKind::Error
        } else {
            AssessmentKind::Correct
        };
        g.schedule(Assessment {
            onset_secs: 0.5 + period * k as f64,
            kind,
        });
    }
}

/// The paper's notch and [1, 10] Hz band-pass, causal, as online.
fn band_pass(x: &[f64]) -> Vec<f64> {
    let mut y = x.to_vec();
    FilterChain::paper(50.0, 1.0, 10.0, 256.0).process(&mut y);
    y
}

fn sd(x: &[f64]) -> f64 {
    let m = x.iter().sum::<f64>() / x.len() as f64;
    (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / x.len() as f64).sqrt()
}

fn channel<'a>(b: &'a EegBlock, m: &Montage, name: &str) -> &'a [f64] {
    b.channel(m.index(name).unwrap())
}

#[test]
fn with_every_effect_on_blocks_still_carry_all_state_and_parts_add_up() {
    let all = Components::default();
    let mut a = generator(everything(), 3, all);
    let mut b = generator(everything(), 3, all);
    schedule_alternating(&mut a, 12, 0.8);
    schedule_alternating(&mut b, 12, 0.8);
    let whole = a.generate(10 * FS);
    let mut parts = b.generate(FS - 7);
    while parts.n_samples < 10 * FS {
        let n = (10 * FS - parts.n_samples).min(97);
        parts.append(&b.generate(n));
    }
    assert_eq!(whole, parts, "block boundaries change nothing");

    let mut sum = vec![0.0; whole.data.len()];
    for c in [BACKGROUND, ARTIFACTS, ERP] {
        let mut g = generator(everything(), 3, c);
        schedule_alternating(&mut g, 12, 0.8);
        for (s, v) in sum.iter_mut().zip(g.generate(10 * FS).data) {
            *s += v;
        }
    }
    for (s, w) in sum.iter().zip(&whole.data) {
        assert!((s - w).abs() < 1e-9, "parts add up: {s} vs {w}");
    }
}

#[test]
fn an_effect_leaves_the_parts_it_does_not_touch_bit_for_bit() {
    let m = Montage::standard();
    let ideal = {
        let mut g = generator(Realism::default(), 5, Components::default());
        schedule_alternating(&mut g, 8, 1.0);
        g.generate(8 * FS)
    };
    // EMG falls on temporal and frontal sites only: Oz and Pz are untouched.
    let emg = {
        let mut g = generator(
            Realism {
                emg_rate_hz: 1.0,
                emg_uv: 30.0,
                ..Realism::default()
            },
            5,
            Components::default(),
        );
        schedule_alternating(&mut g, 8, 1.0);
        g.generate(8 * FS)
    };
    assert_eq!(channel(&ideal, &m, "Oz"), channel(&emg, &m, "Oz"));
    assert_eq!(channel(&ideal, &m, "Pz"), channel(&emg, &m, "Pz"));
    assert_ne!(channel(&ideal, &m, "T7"), channel(&emg, &m, "T7"));
    // A bad channel changes that channel only.
    let bad = {
        let mut g = generator(
            Realism {
                bad_channel: "C2".into(),
                bad_channel_uv: 10.0,
                ..Realism::default()
            },
            5,
            Components::default(),
        );
        schedule_alternating(&mut g, 8, 1.0);
        g.generate(8 * FS)
    };
    for (ch, c) in m.channels().iter().enumerate() {
        if c.name == "C2" {
            assert_ne!(ideal.channel(ch), bad.channel(ch));
        } else {
            assert_eq!(ideal.channel(ch), bad.channel(ch), "{}", c.name);
        }
    }
}

/// The SD across 10 s blocks of each block's SD, relative to their mean.
fn block_sd_spread(x: &[f64]) -> f64 {
    let sds: Vec<f64> = x.chunks_exact(10 * FS).map(sd).collect();
    let mean = sds.iter().sum::<f64>() / sds.len() as f64;
    sd(&sds) / mean
}

#[test]
fn drift_raises_the_variance_of_10_s_blocks() {
    let m = Montage::standard();
    let spread = |realism: Realism| {
        let b = generator(realism, 7, BACKGROUND).generate(1200 * FS);
        block_sd_spread(channel(&b, &m, "FCz"))
    };
    let ideal = spread(Realism::default());
    let drifting = spread(Realism {
        background_drift: 0.2,
        drift_secs: 60.0,
        ..Realism::default()
    });
    assert!(ideal < 0.08, "stationary background: {ideal}");
    // A log-amplitude of SD 0.2 with a 60 s time constant: blocks of 10 s
    // differ by about 0.2 x sqrt(1 - 10 / 60 ...) ~ 0.15 beyond sampling.
    assert!(
        drifting > 0.12 && drifting > 2.0 * ideal,
        "drift {drifting} vs ideal {ideal}"
    );
    // The mean square stays as stated (the gain is normalised).
    let b = generator(
        Realism {
            background_drift: 0.2,
            drift_secs: 60.0,
            ..Realism::default()
        },
        8,
        BACKGROUND,
    )
    .generate(1200 * FS);
    let fcz = sd(channel(&b, &m, "FCz"));
    assert!((fcz - 10.0).abs() < 2.0, "FCz sd {fcz}");
}

#[test]
fn electrode_offsets_wander_by_their_sd_and_the_band_pass_removes_them() {
    let m = Montage::standard();
    let b = generator(
        Realism {
            electrode_drift_uv: 40.0,
            electrode_drift_secs: 30.0,
            ..Realism::default()
        },
        2,
        ARTIFACTS,
    )
    .generate(600 * FS);
    // Means of 1 s blocks of every EEG channel: SD about 40 uV.
    let mut means = Vec::new();
    for ch in 0..m.n_eeg() {
        for block in b.channel(ch).chunks_exact(FS) {
            means.push(block.iter().sum::<f64>() / FS as f64);
        }
    }
    let s = sd(&means);
    assert!((s - 40.0).abs() < 8.0, "offset sd {s}");
    // Through the paper's 1 Hz high-pass, little is left.
    let ideal = generator(Realism::default(), 2, ARTIFACTS).generate(600 * FS);
    let filtered = band_pass(channel(&b, &m, "FCz"));
    let filtered_ideal = band_pass(channel(&ideal, &m, "FCz"));
    let extra: Vec<f64> = filtered
        .iter()
        .zip(&filtered_ideal)
        .map(|(a, c)| a - c)
        .skip(10 * FS)
        .collect();
    let left = sd(&extra);
    // An OU process of SD s and time constant tau has s^2 / (2 pi^2 tau)
    // x 0.9 / Hz of power in 1-10 Hz: 1.6 uV here.
    assert!(left < 0.1 * 40.0, "after the band-pass {left} uV");
}

/// The ERP alone at FCz after one assessment of `kind` at 0.5 s, with no
/// single-trial variability: the response, and the time of its largest
/// positive peak (ms after the onset).
fn erp_response(realism: Realism, kind: AssessmentKind, earlier: &[AssessmentKind]) -> (f64, f64) {
    let m = Montage::standard();
    let p = Valid::new(GeneratorParams {
        latency_jitter_ms: 0.0,
        amplitude_variability: 0.0,
        realism,
        ..GeneratorParams::default()
    })
    .unwrap();
    let mut g = EegGenerator::new(&p, &m, 1).unwrap().with_components(ERP);
    // Earlier actions, 2 s apart, whose ERPs are over by the last one.
    for (k, &e) in earlier.iter().enumerate() {
        g.schedule(Assessment {
            onset_secs: 0.5 + 2.0 * k as f64,
            kind: e,
        });
    }
    let onset = 0.5 + 2.0 * earlier.len() as f64;
    g.schedule(Assessment {
        onset_secs: onset,
        kind,
    });
    let b = g.generate(((onset + 1.2) * FS as f64) as usize + 1);
    let fcz = channel(&b, &m, "FCz");
    let from = (onset * FS as f64).round() as usize;
    let (i, peak) = fcz[from..]
        .iter()
        .enumerate()
        .fold((0, f64::MIN), |a, (i, &v)| if v > a.1 { (i, v) } else { a });
    (peak, i as f64 * 1000.0 / FS as f64)
}

#[test]
fn a_task_shift_moves_the_peak_by_the_shift_and_scales_it_by_the_gain() {
    let (p0, t0) = erp_response(Realism::default(), AssessmentKind::Error, &[]);
    let shifted = Realism {
        erp_latency_shift_ms: 40.0,
        erp_gain: 0.7,
        ..Realism::default()
    };
    let (p1, t1) = erp_response(shifted, AssessmentKind::Error, &[]);
    assert!((t1 - t0 - 40.0).abs() <= 4.0, "peak {t0} -> {t1} ms");
    assert!((p1 / p0 - 0.7).abs() < 0.01, "amplitude {p0} -> {p1}");
}

/// The SD (ms) of the positive peak's time over `n` error ERPs, 2 s
/// apart, with no amplitude variability: the single-trial latency spread.
fn peak_time_sd(realism: Realism, n: usize) -> f64 {
    let m = Montage::standard();
    let p = Valid::new(GeneratorParams {
        amplitude_variability: 0.0,
        realism,
        ..GeneratorParams::default()
    })
    .unwrap();
    let mut g = EegGenerator::new(&p, &m, 3).unwrap().with_components(ERP);
    for k in 0..n {
        g.schedule(Assessment {
            onset_secs: 0.5 + 2.0 * k as f64,
            kind: AssessmentKind::Error,
        });
    }
    let b = g.generate(((0.5 + 2.0 * n as f64) * FS as f64) as usize);
    let fcz = channel(&b, &m, "FCz");
    let times: Vec<f64> = (0..n)
        .map(|k| {
            let from = ((0.5 + 2.0 * k as f64) * FS as f64).round() as usize;
            let window = &fcz[from..from + (1.2 * FS as f64) as usize];
            let (i, _) = window
                .iter()
                .enumerate()
                .fold((0, f64::MIN), |a, (i, &v)| if v > a.1 { (i, v) } else { a });
            i as f64 * 1000.0 / FS as f64
        })
        .collect();
    sd(&times)
}

#[test]
fn the_single_trial_latency_sd_sets_the_spread_of_the_peaks() {
    // Unset, the EEG model's own 25 ms; set to it, the same samples.
    let mut a = generator(Realism::default(), 9, ERP);
    let mut b = generator(
        Realism {
            trial_latency_sd_ms: Some(25.0),
            ..Realism::default()
        },
        9,
        ERP,
    );
    schedule_alternating(&mut a, 30, 1.5);
    schedule_alternating(&mut b, 30, 1.5);
    let n = 50 * FS;
    assert_eq!(a.generate(n).data, b.generate(n).data);
    // The peaks spread by the SD set: none at 0, about 20 ms at 20.
    let at = |sd: f64| {
        peak_time_sd(
            Realism {
                trial_latency_sd_ms: Some(sd),
                ..Realism::default()
            },
            300,
        )
    };
    let (none, twenty) = (at(0.0), at(20.0));
    assert!(none < 1.0, "peak times spread by {none} ms with no jitter");
    assert!(
        (twenty - 20.0).abs() < 3.0,
        "peak times spread by {twenty} ms at 20 ms"
    );
}

#[test]
fn the_errp_changes_along_the_session_by_its_slopes() {
    let (p0, t0) = erp_response(Realism::default(), AssessmentKind::Error, &[]);
    let an_hour_in = Realism {
        errp_amplitude_per_hour: -0.25,
        errp_latency_ms_per_hour: 30.0,
        clock_offset_secs: 3600.0,
        ..Realism::default()
    };
    let (p1, t1) = erp_response(an_hour_in, AssessmentKind::Error, &[]);
    assert!((p1 / p0 - 0.75).abs() < 0.01, "amplitude {p0} -> {p1}");
    assert!((t1 - t0 - 30.0).abs() <= 4.0, "latency {t0} -> {t1} ms");
}

#[test]
fn the_errp_shrinks_as_errors_become_expected() {
    let r = Realism {
        expectancy: 1.0,
        expectancy_actions: 5.0,
        ..Realism::default()
    };
    let (alone, _) = erp_response(r.clone(), AssessmentKind::Error, &[]);
    let (ideal, _) = erp_response(Realism::default(), AssessmentKind::Error, &[]);
    assert!(
        (alone - ideal).abs() < 1e-9,
        "at the reference rate, the template"
    );
    let errors = [AssessmentKind::Error; 30];
    let (after_errors, _) = erp_response(r.clone(), AssessmentKind::Error, &errors);
    // q -> 1 after 30 errors weighed over 5: the factor is 1 - (1 - 0.2).
    assert!(
        (after_errors / alone - 0.2).abs() < 0.02,
        "{after_errors} vs {alone}"
    );
    let corrects = [AssessmentKind::Correct; 30];
    let (after_corrects, _) = erp_response(r, AssessmentKind::Error, &corrects);
    assert!(
        (after_corrects / alone - 1.2).abs() < 0.02,
        "a rare error is larger: {after_corrects} vs {alone}"
    );
}

#[test]
fn lapses_and_misjudgements_lower_the_per_class_rates_by_their_rate() {
    // A decoder that reads this user almost perfectly when ideal.
    let setup = |realism: Realism| {
        let mut s = CalibrationSetup::with_ratio(10.0).unwrap();
        s.generator = s.generator.with(|g| g.realism = realism).unwrap();
        s.calibration = CalibrationParams {
            n_actions: 600,
            ..CalibrationParams::default()
        };
        Valid::new(s).unwrap()
    };
    let rates = |realism: Realism| {
        let c = calibrate(
            &LdaDecoder::default(),
            &setup(realism),
            4,
            SessionOptions::default(),
        )
        .unwrap();
        (c.accuracy.error, c.accuracy.correct)
    };
    let (e0, c0) = rates(Realism::default());
    assert!(e0 > 0.9 && c0 > 0.97, "ideal {e0} {c0}");
    let (e1, c1) = rates(Realism {
        misjudge_rate: 0.15,
        ..Realism::default()
    });
    // A misjudged action carries the other class's potential: each class
    // is detected about 15 points less often.
    assert!((e0 - e1 - 0.15).abs() < 0.08, "error class {e0} -> {e1}");
    assert!((c0 - c1 - 0.15).abs() < 0.06, "correct class {c0} -> {c1}");
    let (e2, c2) = rates(Realism {
        lapse_rate: 0.3,
        ..Realism::default()
    });
    // An unattended error has no ErrP, but no correct-action potential
    // either, which a decoder at this ratio partly tells apart from a
    // correct action's: the error class loses up to 30 points.
    assert!(e0 - e2 > 0.1 && e0 - e2 < 0.33, "error class {e0} -> {e2}");
    assert!(c0 - c2 < 0.05, "correct class {c0} -> {c2}");
}

#[test]
fn attention_declines_along_the_session() {
    let count = |clock: f64| {
        let r = Realism {
            lapse_per_hour: 0.5,
            clock_offset_secs: clock,
            ..Realism::default()
        };
        let m = Montage::standard();
        let p = Valid::new(GeneratorParams {
            latency_jitter_ms: 0.0,
            amplitude_variability: 0.0,
            realism: r,
            ..GeneratorParams::default()
        })
        .unwrap();
        let mut g = EegGenerator::new(&p, &m, 9).unwrap().with_components(ERP);
        let n = 400;
        for k in 0..n {
            g.schedule(Assessment {
                onset_secs: 0.5 + 1.5 * k as f64,
                kind: AssessmentKind::Error,
            });
        }
        let b = g.generate((1.5 * n as f64 * FS as f64) as usize + FS);
        let fcz = channel(&b, &m, "FCz");
        (0..n)
            .filter(|k| {
                let at = ((0.5 + 1.5 * *k as f64 + 0.35) * FS as f64) as usize;
                fcz[at].abs() > 1e-6
            })
            .count() as f64
            / n as f64
    };
    let start = count(0.0);
    let an_hour_in = count(3600.0);
    // Over the 10 minutes of each stream the lapse rate rises from 0 to
    // 0.08 (mean 0.04), and an hour later from 0.5 to 0.58 (mean 0.54).
    assert!((start - 0.96).abs() < 0.04, "attended at the start {start}");
    assert!((an_hour_in - 0.46).abs() < 0.07, "an hour in {an_hour_in}");
}

#[test]
fn emg_bursts_raise_1_to_10_hz_power_on_temporal_sites_most() {
    let m = Montage::standard();
    let b = generator(
        Realism {
            emg_rate_hz: 0.2,
            emg_uv: 30.0,
            ..Realism::default()
        },
        4,
        ARTIFACTS,
    )
    .generate(300 * FS);
    let band = |name: &str| sd(&band_pass(channel(&b, &m, name)));
    let ideal = generator(Realism::default(), 4, ARTIFACTS).generate(300 * FS);
    let ideal_t7 = sd(&band_pass(channel(&ideal, &m, "T7")));
    assert!(
        band("T7") > 1.5 * ideal_t7,
        "T7 {} vs {ideal_t7}",
        band("T7")
    );
    assert!(
        band("T7") > 3.0 * band("Cz"),
        "T7 {} Cz {}",
        band("T7"),
        band("Cz")
    );
}

/// Excess kurtosis.
fn kurtosis(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let v = x.iter().map(|a| (a - m).powi(2)).sum::<f64>() / n;
    x.iter().map(|a| (a - m).powi(4)).sum::<f64>() / n / (v * v) - 3.0
}

#[test]
fn pops_and_a_bad_channel_show_where_they_should() {
    let m = Montage::standard();
    let all = Components::default();
    let r = Realism {
        pop_rate_hz: 0.5,
        pop_uv: 150.0,
        bad_channel: "FCz".into(),
        bad_channel_uv: 20.0,
        ..Realism::default()
    };
    let b = generator(r, 6, all).generate(300 * FS);
    let ideal = generator(Realism::default(), 6, all).generate(300 * FS);
    // Pops: heavy tails over the montage.
    let k: f64 = (0..m.n_eeg())
        .map(|ch| kurtosis(b.channel(ch)))
        .sum::<f64>()
        / m.n_eeg() as f64;
    let k0: f64 = (0..m.n_eeg())
        .map(|ch| kurtosis(ideal.channel(ch)))
        .sum::<f64>()
        / m.n_eeg() as f64;
    assert!(k > k0 + 1.0, "kurtosis {k} vs ideal {k0}");
    // The bad channel's variance grows by about its noise's.
    let fcz = m.index("FCz").unwrap();
    let extra: Vec<f64> = b
        .channel(fcz)
        .iter()
        .zip(ideal.channel(fcz))
        .map(|(a, c)| a - c)
        .collect();
    // What differs at FCz is the pops that fell there and the noise.
    let s = sd(&extra);
    assert!(s > 19.0 && s < 40.0, "extra at FCz {s}");
}

#[test]
fn people_blink_after_the_actions_they_judge() {
    let m = Montage::standard();
    let r = Realism {
        action_blink_probability: 0.8,
        action_blink_latency_ms: 400.0,
        ..Realism::default()
    };
    let params = Valid::new(GeneratorParams {
        blink_rate_hz: 0.0,
        realism: r,
        ..GeneratorParams::default()
    })
    .unwrap();
    let mut g = EegGenerator::new(&params, &m, 3)
        .unwrap()
        .with_components(ARTIFACTS);
    let n = 100;
    for k in 0..n {
        g.schedule(Assessment {
            onset_secs: 1.0 + 3.0 * k as f64,
            kind: AssessmentKind::Correct,
        });
    }
    let b = g.generate(3 * n * FS + FS);
    let la = channel(&b, &m, "EOG LA");
    // Action-locked average of the vertical EOG: a blink peaks 400 ms
    // + half a blink (175 ms) after the action.
    let mut avg = vec![0.0; 3 * FS];
    for k in 0..n {
        let at = (1.0 + 3.0 * k as f64) as usize * FS;
        for (a, v) in avg.iter_mut().zip(&la[at..at + 3 * FS]) {
            *a += v / n as f64;
        }
    }
    let (i, peak) = avg
        .iter()
        .enumerate()
        .fold((0, f64::MIN), |a, (i, &v)| if v > a.1 { (i, v) } else { a });
    let ms = i as f64 * 1000.0 / FS as f64;
    assert!((ms - 575.0).abs() < 60.0, "peak at {ms} ms");
    assert!(peak > 0.5 * 150.0 * 0.8, "mean blink {peak} uV");
}

#[test]
fn bad_fields_are_named_with_their_range() {
    let cases: Vec<(Realism, &str)> = vec![
        (
            Realism {
                lapse_rate: 1.5,
                ..Realism::default()
            },
            "realism.lapse_rate",
        ),
        (
            Realism {
                background_drift: f64::NAN,
                ..Realism::default()
            },
            "realism.background_drift",
        ),
        (
            Realism {
                erp_latency_shift_ms: 1000.0,
                ..Realism::default()
            },
            "realism.erp_latency_shift_ms",
        ),
        (
            Realism {
                task_latency_ms: 1000.0,
                ..Realism::default()
            },
            "realism.task_latency_ms",
        ),
        (
            Realism {
                task_latency_ms: f64::INFINITY,
                ..Realism::default()
            },
            "realism.task_latency_ms",
        ),
        (
            Realism {
                task_latency_ms: f64::NAN,
                ..Realism::default()
            },
            "realism.task_latency_ms",
        ),
        (
            Realism {
                bad_channel: "Xx".into(),
                ..Realism::default()
            },
            "realism.bad_channel",
        ),
        (
            Realism {
                drift_secs: 0.0,
                ..Realism::default()
            },
            "realism.drift_secs",
        ),
        (
            Realism {
                trial_latency_sd_ms: Some(-1.0),
                ..Realism::default()
            },
            "realism.trial_latency_sd_ms",
        ),
    ];
    for (r, name) in cases {
        let err = Valid::new(GeneratorParams {
            realism: r,
            ..GeneratorParams::default()
        })
        .unwrap_err()
        .to_string();
        assert!(err.contains(name), "{err}");
    }
}
