//! The determinism contracts of `errp_sim`: the same scenario and seed give
//! the same episode, whatever the thread count, and the golden digests below
//! pin the results themselves (every field, through their exact `Debug`
//! form), so that a change that alters them shows here first. Update a
//! digest only for a change meant to alter the numbers, and say so in the
//! commit.

use errp_bci::rng::fnv1a;
use errp_robot::Cell;
use errp_sim::epuck::{prepare_continuous_decoder, run_epuck_batch, run_epuck_once};
use errp_sim::grid::{AssessmentDecoder, GridEpisodeResult, GridTaskParams, run_grid_episode};

use crate::{epuck, grid};

/// The digest of `value`'s exact `Debug` text (floats print their shortest
/// round-trip form).
fn digest(value: &impl std::fmt::Debug) -> u64 {
    fnv1a(format!("{value:?}"))
}

/// The episode from (0, 0) to (3, 4) with `decoder` and `seed`, every
/// action recorded, at goal reward 2 (the golden digest's Q scale).
fn episode(decoder: &AssessmentDecoder, seed: u64) -> GridEpisodeResult {
    let params = grid::long_runs();
    let t = grid::table(&params);
    let (start, goal) = (Cell::new(0, 0), Cell::new(3, 4));
    run_grid_episode(start, goal, &t, &params, decoder, seed, true).unwrap()
}

#[test]
fn same_seed_same_episode() {
    let oracle = AssessmentDecoder::Oracle { accuracy: 0.75 };
    assert_eq!(episode(&oracle, 5), episode(&oracle, 5));
    assert_ne!(episode(&oracle, 5), episode(&oracle, 6));
    // With the EEG decoder calibrated at 80 % (seed 3): the golden episode.
    let got = digest(&episode(&grid::eeg_decoder(0.8, 3), 3));
    assert_eq!(
        got, 0x7dc6_e57f_8e29_66bc,
        "grid episode, EEG at 80 %: digest {got:#x}"
    );
}

#[test]
fn table1_gives_the_same_results_on_one_and_two_threads() {
    let options = errp_sim::grid::Table1Options {
        repeats: 1,
        seed: 4,
        decoder: errp_sim::grid::DecoderChoice::Oracle,
        eeg: errp_sim::grid::EegMode::PerAction,
        params: GridTaskParams::default(),
        realism: errp_bci::Realism::published(),
    };
    let on = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| errp_sim::grid::run_table1(&options, |_, _| {}).unwrap())
    };
    let (one, two) = (on(1), on(2));
    assert_eq!(one.len(), 8);
    for (a, b) in one.iter().zip(&two) {
        assert_eq!((&a.subject, a.goals), (&b.subject, b.goals));
        assert_eq!(a.runs, b.runs, "{} {:?}", a.subject, a.goals);
    }
}

#[test]
fn the_same_seed_gives_the_same_run() {
    // The idealised user, whose pinned digest predates the realistic one.
    let mut s = epuck::scenario("variants/lisbon_to_tokyo_ideal.toml");
    s.params.max_secs = 40.0;
    let (decoder, _) = prepare_continuous_decoder(&s, |_| {}).unwrap();
    let a = run_epuck_once(&s, &decoder, 3, &mut ()).unwrap();
    let b = run_epuck_once(&s, &decoder, 3, &mut ()).unwrap();
    assert_eq!(a, b);
    let c = run_epuck_once(&s, &decoder, 4, &mut ()).unwrap();
    assert_ne!(a, c, "another run index, another run");
    // The batch (parallel) gives the runs in order, identical to one by one.
    let batch = run_epuck_batch(&s, &decoder, 5).unwrap();
    assert_eq!(batch[3], a);
    let got = digest(&a);
    assert_eq!(
        got, 0x784c_430b_3738_cda2,
        "Lisbon to Tokyo, run 3: digest {got:#x}"
    );
}

#[test]
fn the_city_scenarios_share_one_user_and_draw_their_own_runs() {
    // One simulated user (calibration seed) for both of the paper's runs,
    // each scenario's runs from its own seed.
    let m = epuck::scenario("mexico_to_pisa.toml");
    let l = epuck::scenario("lisbon_to_tokyo.toml");
    assert_eq!(m.user_seed, l.user_seed);
    assert_ne!(m.seed, l.seed);
    // `errp run --seed` gives a new user and new runs.
    let mut r = l.clone();
    r.reseed(9);
    assert_eq!((r.seed, r.user_seed), (9, 9));
    // Without `[user] seed`, the user is the scenario's seed.
    let h = epuck::scenario("obstacles_havana_to_seoul.toml");
    assert_eq!(h.user_seed, h.seed);
}
