//! Speed of the EEG side: synthesis, preprocessing, features, decoding.
//!
//! Run with `cargo bench -p errp_bci`. Figures are per call on one core.

use std::sync::LazyLock;

use divan::{Bencher, black_box};
use errp_bci::{
    Assessment, AssessmentKind, CalibrationParams, CalibrationSetup, ContinuousFeatures,
    ContinuousSetup, EegGenerator, EpochWindow, ErrorModel, GeneratorParams, LdaDecoder, LdaModel,
    Montage, Preprocessor, Realism, SessionOptions, SvmDecoder, SvmModel, Valid, calibrate,
    calibrate_continuous,
};

fn main() {
    divan::main();
}

const FS: usize = 256;

struct Trained {
    setup: Valid<CalibrationSetup>,
    pre: Preprocessor,
    model: LdaModel,
}

static TRAINED: LazyLock<Trained> = LazyLock::new(|| {
    let setup = Valid::new(CalibrationSetup {
        calibration: CalibrationParams {
            n_actions: 120,
            ..CalibrationParams::default()
        },
        ..CalibrationSetup::with_ratio(0.8).unwrap()
    })
    .unwrap();
    let c = calibrate(&LdaDecoder::default(), &setup, 1, SessionOptions::default()).unwrap();
    Trained {
        pre: c.session.preprocessor.clone(),
        model: c.model,
        setup,
    }
});

/// One second of all 40 channels (34 EEG + 6 EOG) at 256 Hz.
#[divan::bench]
fn generate_one_second(bencher: Bencher) {
    let mut g = EegGenerator::new(
        &Valid::<GeneratorParams>::default(),
        &Montage::standard(),
        1,
    )
    .unwrap();
    bencher.bench_local(|| black_box(g.generate(FS)));
}

/// One second of all 40 channels of the ideal user judging one action a
/// second: the reference for `generate_one_second_realistic`, which has the
/// same schedule.
#[divan::bench]
fn generate_one_second_with_actions(bencher: Bencher) {
    one_action_a_second(bencher, &Valid::default());
}

/// Benches one second of the user of `params` judging one action in it, as
/// the e-puck's user judges.
fn one_action_a_second(bencher: Bencher, params: &Valid<GeneratorParams>) {
    let mut g = EegGenerator::new(params, &Montage::standard(), 1).unwrap();
    let mut onset = 0.5;
    bencher.bench_local(|| {
        g.schedule(Assessment {
            onset_secs: onset,
            kind: AssessmentKind::Error,
        });
        onset += 1.0;
        black_box(g.generate(FS))
    });
}

/// One second of all 40 channels with every effect of `Realism` on (drifts,
/// electrode offsets, EMG bursts, pops, a bad channel, action blinks, and
/// an ErrP that changes): the cost of the realistic user against
/// `generate_one_second`.
#[divan::bench]
fn generate_one_second_realistic(bencher: Bencher) {
    let params = Valid::new(GeneratorParams {
        realism: Realism {
            background_drift: 0.15,
            alpha_drift: 0.3,
            electrode_drift_uv: 20.0,
            errp_amplitude_per_hour: -0.2,
            expectancy: 0.5,
            lapse_rate: 0.05,
            misjudge_rate: 0.05,
            emg_rate_hz: 0.1,
            emg_uv: 20.0,
            pop_rate_hz: 0.05,
            pop_uv: 100.0,
            bad_channel: "C2".into(),
            bad_channel_uv: 10.0,
            action_blink_probability: 0.3,
            ..Realism::default()
        },
        ..GeneratorParams::default()
    })
    .unwrap();
    one_action_a_second(bencher, &params);
}

/// Preprocess (CAR + EOG regression + notch + band-pass, 8 output channels),
/// extract the 312 features and classify one epoch, from raw samples.
#[divan::bench]
fn decode_epoch(bencher: Bencher) {
    let t = &*TRAINED;
    let window = EpochWindow::paper(FS as f64);
    let mut g = EegGenerator::new(&t.setup.generator, &t.setup.montage, 2).unwrap();
    let raw = g.generate(window.span());
    let mut pre = t.pre.clone();
    bencher.bench_local(|| {
        let clean = pre.process(black_box(&raw));
        let x = window.extract(&clean, 0);
        black_box(t.model.p_error(&x))
    });
}

/// One action of the discrete task with the EEG decoder, net time only: the
/// 0.8 s epoch after the action synthesised (with its ErrP) and decoded.
#[divan::bench]
fn synthesize_and_decode_epoch(bencher: Bencher) {
    action(bencher, 0.8);
}

/// One action including the 3.25 s mean inter-action interval: all EEG
/// between actions is synthesised and filtered, as in a continuous session.
#[divan::bench]
fn synthesize_and_decode_action_with_interval(bencher: Bencher) {
    action(bencher, 3.25);
}

fn action(bencher: Bencher, secs: f64) {
    let t = &*TRAINED;
    let window = EpochWindow::paper(FS as f64);
    let n = ((secs * FS as f64) as usize).max(window.span());
    let mut g = EegGenerator::new(&t.setup.generator, &t.setup.montage, 3).unwrap();
    let mut pre = t.pre.clone();
    let mut k = 0u64;
    bencher.bench_local(|| {
        let onset = g.now_secs();
        g.schedule(Assessment {
            onset_secs: onset,
            kind: if k.is_multiple_of(5) {
                AssessmentKind::Error
            } else {
                AssessmentKind::Correct
            },
        });
        k += 1;
        let raw = g.generate(n);
        let clean = pre.process(&raw);
        black_box(t.model.p_error(&window.extract(&clean, 0)))
    });
}

struct TrainedContinuous {
    window: errp_bci::EegBlock,
    model: SvmModel,
}

static TRAINED_CONTINUOUS: LazyLock<TrainedContinuous> = LazyLock::new(|| {
    let setup = Valid::new(ContinuousSetup::with_ratio(1.0).unwrap()).unwrap();
    let c = calibrate_continuous(&SvmDecoder::default(), &setup, 1).unwrap();
    let mut g = EegGenerator::new(&setup.generator, &setup.montage, 4).unwrap();
    let mut pre = c.session.preprocessor.clone();
    let window = pre.process(&g.generate(ContinuousFeatures::paper(FS as f64).span()));
    TrainedContinuous {
        window,
        model: c.model,
    }
});

/// One step of the continuous decoder's sliding window: the 512 features
/// (temporal + theta PSD) of one preprocessed 800 ms window of the 8 decoding
/// channels, and the SVM's p(error) (~130 support vectors, the paper's
/// calibration of 70 examples per class).
#[divan::bench(name = "continuous window: features + SVM p_error")]
fn continuous_window(bencher: Bencher) {
    let t = &*TRAINED_CONTINUOUS;
    let features = ContinuousFeatures::paper(FS as f64);
    bencher.bench_local(|| {
        let x = features.extract(black_box(&t.window), 0);
        black_box(t.model.p_error(&x))
    });
}
