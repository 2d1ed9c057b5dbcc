//! Speed of the continuous task on one core: 60 simulated seconds of a full
//! e-puck run (rapier2d physics at 64 Hz, IR ray casts, tracker, synthetic
//! user, 40-channel EEG at 256 Hz, preprocessing, the sliding-window SVM
//! every 62.5 ms and the belief update), with no recording. Simulated
//! seconds per CPU second = 60 / the median. Run with
//! `cargo bench -p errp_sim --bench epuck`.

use std::sync::LazyLock;

use divan::{Bencher, black_box};
use errp_sim::epuck::{
    ContinuousDecoder, EpuckScenario, prepare_continuous_decoder, run_epuck_episode,
};

fn main() {
    divan::main();
}

static SETUP: LazyLock<(EpuckScenario, ContinuousDecoder)> = LazyLock::new(|| {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenarios/mexico_to_pisa.toml"
    );
    let mut s =
        errp_sim::ScenarioInput::load_as_written(errp_sim::ScenarioSource::File(path.into()))
            .unwrap()
            .into_epuck()
            .unwrap();
    // Exactly 60 s every time: no convergence, no early end.
    s.params.control = s.params.control.with(|c| c.p_c = 0.999_999).unwrap();
    s.params.max_secs = 60.0;
    let (d, _) = prepare_continuous_decoder(&s, |_| {}).unwrap();
    (s, d)
});

/// 60 s of the Mexico-to-Pisa run at the paper's accuracy.
#[divan::bench(sample_count = 10, sample_size = 1)]
fn sixty_simulated_seconds(bencher: Bencher) {
    let (s, d) = &*SETUP;
    let mut seed = 0u64;
    bencher.bench_local(|| {
        seed += 1;
        black_box(run_epuck_episode(s, d, seed, &mut ()).unwrap())
    });
}
