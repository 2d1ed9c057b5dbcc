//! Whole sweeps, as `errp sweep` runs them, on 1 and 2 threads: the grid's
//! 11 levels x 200 episodes with the EEG decoder (epoch bank), cold (the
//! accuracy targeting searched) and warm (targeting from the cache), and
//! e-puck episodes per second. Run with `cargo bench -p errp_sim --bench sweep`.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use divan::Bencher;
use errp_sweep::{
    Shard, SweepOptions, SweepOutcome, SweepSpec, SweepTask, TargetCache, parse_accuracies,
    run_sweep,
};

fn main() {
    divan::main();
}

fn grid_spec(episodes: usize) -> SweepSpec {
    SweepSpec {
        task: SweepTask::Grid,
        scenario_path: "scenarios/grid_fixed_goals.toml".into(),
        scenario_toml: include_str!("../../scenarios/grid_fixed_goals.toml").into(),
        accuracies: parse_accuracies("0.55:0.95:0.04").unwrap(),
        axes: vec![],
        fixed: vec![("eeg".into(), toml::Value::String("bank".into()))],
        episodes,
        seed: 1,
    }
}

fn epuck_spec(episodes: usize) -> SweepSpec {
    SweepSpec {
        task: SweepTask::Epuck,
        scenario_path: "scenarios/mexico_to_pisa.toml".into(),
        scenario_toml: include_str!("../../scenarios/mexico_to_pisa.toml").into(),
        accuracies: parse_accuracies("0.75").unwrap(),
        axes: vec![],
        fixed: vec![],
        episodes,
        seed: 1,
    }
}

fn scratch(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("errp-bench-{name}-{}", std::process::id()))
}

/// Runs `spec` into a fresh directory on `threads` threads.
fn sweep(spec: &SweepSpec, threads: usize, cache: &TargetCache, name: &str) {
    let out = scratch(name);
    let _ = std::fs::remove_dir_all(&out);
    let opts = SweepOptions {
        out: out.clone(),
        cache: cache.clone(),
        shard: Shard::ALL,
        chunk: 0,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let outcome = pool
        .install(|| run_sweep(spec, &opts, &AtomicBool::new(false), &()))
        .unwrap();
    assert!(matches!(outcome, SweepOutcome::Complete { .. }));
    let _ = std::fs::remove_dir_all(&out);
}

/// 11 levels x 200 grid episodes, EEG decoder on an epoch bank, targeting
/// searched from scratch: the "under 60 s" figure.
#[divan::bench(args = [1, 2], sample_count = 1, sample_size = 1)]
fn grid_11x200_cold(bencher: Bencher, threads: usize) {
    let spec = grid_spec(200);
    bencher.bench_local(|| sweep(&spec, threads, &TargetCache::disabled(), "grid-cold"));
}

/// The same with the targeting cached (a rerun, a resume or another shard).
#[divan::bench(args = [1, 2], sample_count = 2, sample_size = 1)]
fn grid_11x200_cached(bencher: Bencher, threads: usize) {
    let spec = grid_spec(200);
    let cache = TargetCache::new(scratch("grid-cache"));
    sweep(&grid_spec(1), 2, &cache, "grid-warm-up");
    bencher.bench_local(|| sweep(&spec, threads, &cache, "grid-cached"));
}

/// 40 e-puck episodes (Mexico to Pisa at 75 %), calibration cached: divide
/// by 40 for the time per episode.
#[divan::bench(args = [1, 2], sample_count = 2, sample_size = 1)]
fn epuck_40_episodes(bencher: Bencher, threads: usize) {
    let spec = epuck_spec(40);
    let cache = TargetCache::new(scratch("epuck-cache"));
    sweep(&epuck_spec(1), 2, &cache, "epuck-warm-up");
    bencher.bench_local(|| sweep(&spec, threads, &cache, "epuck"));
}
