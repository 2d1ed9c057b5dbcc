//! The determinism contracts of `errp_sim`: the same scenario and seed give
//! the same episode, whatever the thread count, and the golden digests below
//! pin the results themselves (every field, through their exact `Debug`
//! form), so that a change that alters them shows here first. Update a
//! digest only for a change meant to alter the numbers, and say so in the
//! commit.

use errp_robot::Cell;
use errp_sim::epuck::{prepare_continuous_decoder, run_epuck_batch, run_epuck_once};
use errp_sim::grid::{AssessmentDecoder, GridTaskParams, run_grid_episode};

use crate::{epuck, grid};

/// FNV-1a over the `Debug` text of `value` (exact: floats print their
/// shortest round-trip form).
fn digest(value: &impl std::fmt::Debug) -> u64 {
    format!("{value:?}")
        .bytes()
        .fold(0xcbf2_9ce4_8422_2325, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
        })
}

#[track_caller]
fn assert_digest(what: &str, got: u64, golden: u64) {
    assert_eq!(
        got, golden,
        "{what}: digest {got:#018x}, golden {golden:#018x}"
    );
}

/// A grid episode with the EEG decoder calibrated at 80 % (seed 3), every
/// action recorded.
#[test]
fn a_grid_episode_is_the_golden_one() {
    let params = GridTaskParams::default();
    let t = grid::table(&params);
    let decoder = grid::eeg_decoder(0.8, 3);
    let r = run_grid_episode(
        Cell::new(0, 0),
        Cell::new(3, 4),
        &t,
        &params,
        &decoder,
        3,
        true,
    )
    .unwrap();
    assert_digest(
        "grid episode, EEG at 80 %, seed 3",
        digest(&r),
        0xa224_67d1_8840_7c5d,
    );
}

#[test]
fn same_seed_same_episode() {
    let params = GridTaskParams::default();
    let t = grid::table(&params);
    let decoder = AssessmentDecoder::Oracle { accuracy: 0.75 };
    let run = |seed| {
        run_grid_episode(
            Cell::new(0, 0),
            Cell::new(3, 4),
            &t,
            &params,
            &decoder,
            seed,
            true,
        )
        .unwrap()
    };
    assert_eq!(run(5), run(5));
    assert_ne!(run(5), run(6));
}

#[test]
fn table1_gives_the_same_results_on_one_and_two_threads() {
    let options = errp_sim::grid::Table1Options {
        repeats: 1,
        seed: 4,
        decoder: errp_sim::grid::DecoderChoice::Oracle,
        eeg: errp_sim::grid::EegMode::Stream,
        params: GridTaskParams::default(),
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
    let mut s = epuck::scenario("lisbon_to_tokyo.toml");
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
    assert_digest("Lisbon to Tokyo, run 3", digest(&a), 0xd84c_c185_866c_8066);
}
