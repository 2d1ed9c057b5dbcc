//! Grid episodes per second on one core, with the EEG decoder in the loop
//! and with the oracle. Run with `cargo bench -p errp_sim`.

use std::sync::LazyLock;

use divan::{Bencher, black_box};
use errp_bci::{CalibrationParams, CalibrationSetup, Valid, export_session};
use errp_robot::{Grid, GridControlParams, QTable};
use errp_sim::grid::{
    AssessmentDecoder, CORNER_PAIRS, EpochBank, GridTaskParams, eeg_decoder, prepare_decoder,
    run_grid_episode,
};

fn main() {
    divan::main();
}

static EEG: LazyLock<AssessmentDecoder> = LazyLock::new(|| eeg_decoder(0.7438, 1).unwrap());

/// Episodes of the corner pairs at goal reward 2 (long runs; the workload
/// the guide's speed table measures).
fn episodes(bencher: Bencher, decoder: &AssessmentDecoder) {
    let mut params = GridTaskParams::default();
    params.control = params.control.with(|c| c.goal_reward = 2.0).unwrap();
    let table = QTable::compute(Grid::paper(), &params.control.part(GridControlParams::q)).unwrap();
    let mut k = 0u64;
    bencher.bench_local(|| {
        let (start, goal) = CORNER_PAIRS[(k % 5) as usize];
        k += 1;
        black_box(run_grid_episode(start, goal, &table, &params, decoder, k, false).unwrap())
    });
}

/// One grid episode (fixed goals, 74.38 %) with the EEG decoder: every
/// inter-action interval synthesised, filtered and the epoch decoded.
#[divan::bench(sample_count = 30, sample_size = 1)]
fn episode_eeg(bencher: Bencher) {
    episodes(bencher, &EEG);
}

static BANK: LazyLock<AssessmentDecoder> = LazyLock::new(|| {
    let AssessmentDecoder::Eeg(d) = &*EEG else {
        unreachable!()
    };
    let bank = EpochBank::build((**d).clone(), &GridTaskParams::default(), 1000, 1).unwrap();
    AssessmentDecoder::EegBank(Box::new(bank))
});

/// One grid episode with the EEG decoder reading epochs drawn from a bank
/// of 1000 per class streamed in advance.
#[divan::bench]
fn episode_eeg_bank(bencher: Bencher) {
    episodes(bencher, &BANK);
}

/// The decoder calibrated on own EEG (the first half of an exported
/// 400-action session at about 78 %), its held-out epochs drawn.
static RECORDED: LazyLock<AssessmentDecoder> = LazyLock::new(|| {
    let dir = std::env::temp_dir().join(format!("errp-bench-recorded-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let setup = Valid::new(CalibrationSetup {
        calibration: CalibrationParams {
            n_actions: 400,
            ..CalibrationParams::default()
        },
        ..CalibrationSetup::with_ratio(0.94).unwrap()
    })
    .unwrap();
    let file = std::io::BufWriter::new(std::fs::File::create(dir.join("s.edf")).unwrap());
    export_session(&setup, 1, file).unwrap();
    let text = "task = \"grid\"\n[free_goals]\ncount = 1\n[eeg]\nrecording = \"s.edf\"\n";
    std::fs::write(dir.join("s.toml"), text).unwrap();
    let scenario = errp_sim::ScenarioInput::load_as_written(errp_sim::ScenarioSource::File(
        dir.join("s.toml"),
    ))
    .ok()
    .and_then(errp_sim::AnyScenario::into_grid)
    .unwrap();
    let decoder = prepare_decoder(&scenario, |_| {}).unwrap().0;
    std::fs::remove_dir_all(&dir).unwrap();
    decoder
});

/// One grid episode with the decoder calibrated on own EEG, reading
/// its held-out epochs (`[eeg] recording = ...`).
#[divan::bench]
fn episode_recorded(bencher: Bencher) {
    episodes(bencher, &RECORDED);
}

/// One grid episode with the oracle decoder (no EEG).
#[divan::bench]
fn episode_oracle(bencher: Bencher) {
    episodes(bencher, &AssessmentDecoder::Oracle { accuracy: 0.7438 });
}
