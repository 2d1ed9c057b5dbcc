//! Whole sweeps, as `errp sweep` runs them, on 1 and 2 threads: the grid's
//! 11 levels x 200 episodes with the EEG decoder (epoch bank), cold (the
//! accuracy targeting searched) and warm (targeting from the cache), and
//! e-puck episodes per second; and the check of every row when a finished
//! sweep is rerun. Run with `cargo bench -p errp_sweep --bench sweep`.

use std::path::PathBuf;

use errp_bci::stop::WindDown;

use divan::Bencher;
use errp_sim::Names;
use errp_sim::TaskKind;
use errp_sweep::{
    Shard, SweepOptions, SweepOutcome, SweepSpec, TargetCache, parse_accuracies, run_sweep,
};

fn main() {
    divan::main();
}

/// A sweep of the shipped scenario `file` (its text is `toml`).
fn spec(task: TaskKind, file: &str, toml: &str, accuracies: &str, episodes: usize) -> SweepSpec {
    SweepSpec {
        task,
        scenario_path: format!("scenarios/{file}").into(),
        scenario_toml: toml.into(),
        accuracies: parse_accuracies(accuracies, &Names::CLI).unwrap(),
        axes: vec![],
        fixed: vec![],
        episodes,
        seed: 1,
    }
}

fn grid_spec(episodes: usize) -> SweepSpec {
    let toml = include_str!("../../scenarios/grid_fixed_goals.toml");
    SweepSpec {
        fixed: vec![("eeg".into(), toml::Value::String("bank".into()))],
        ..spec(
            TaskKind::Grid,
            "grid_fixed_goals.toml",
            toml,
            "0.55:0.95:0.04",
            episodes,
        )
    }
}

fn epuck_spec(episodes: usize) -> SweepSpec {
    let toml = include_str!("../../scenarios/mexico_to_pisa.toml");
    spec(
        TaskKind::Epuck,
        "mexico_to_pisa.toml",
        toml,
        "0.75",
        episodes,
    )
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
        repair: false,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let outcome = pool
        .install(|| {
            let sweep = spec.clone().checked(&Names::CLI).unwrap();
            run_sweep(&sweep, &opts, &WindDown::new(), &())
        })
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
    cached(bencher, threads, grid_spec, 200, "grid");
}

/// 40 e-puck episodes (Mexico to Pisa at 75 %), calibration cached: divide
/// by 40 for the time per episode.
#[divan::bench(args = [1, 2], sample_count = 2, sample_size = 1)]
fn epuck_40_episodes(bencher: Bencher, threads: usize) {
    cached(bencher, threads, epuck_spec, 40, "epuck");
}

/// Rerunning a finished sweep of 4 levels x 10000 oracle grid episodes:
/// every row of `episodes.csv` read back and checked (fields, seed,
/// checksum), then the summary and plots written again. What a resume or a
/// merge pays per row.
#[divan::bench(sample_count = 3, sample_size = 1)]
fn recheck_40000_rows(bencher: Bencher) {
    let toml = "task = \"grid\"\ndecoder = \"oracle\"\n[user]\naccuracy = 0.8\n\
                [free_goals]\ncount = 50\n";
    let spec = spec(TaskKind::Grid, "oracle.toml", toml, "0.6:0.9:0.1", 10_000);
    let out = scratch("recheck");
    let _ = std::fs::remove_dir_all(&out);
    let opts = SweepOptions {
        out: out.clone(),
        cache: TargetCache::disabled(),
        shard: Shard::ALL,
        chunk: 0,
        repair: false,
    };
    let wind_down = WindDown::new();
    let sweep = spec.checked(&Names::CLI).unwrap();
    run_sweep(&sweep, &opts, &wind_down, &()).unwrap();
    bencher.bench_local(|| {
        let outcome = run_sweep(&sweep, &opts, &wind_down, &()).unwrap();
        assert!(matches!(outcome, SweepOutcome::Complete { ran: 0, .. }));
    });
    let _ = std::fs::remove_dir_all(&out);
}

/// Benches a sweep of `episodes` episodes per level made by `spec`, its
/// targeting cached by a one-episode warm-up.
fn cached(
    bencher: Bencher,
    threads: usize,
    spec: fn(usize) -> SweepSpec,
    episodes: usize,
    name: &str,
) {
    let cache = TargetCache::new(scratch(&format!("{name}-cache")));
    sweep(&spec(1), 2, &cache, &format!("{name}-warm-up"));
    let spec = spec(episodes);
    bencher.bench_local(|| sweep(&spec, threads, &cache, name));
}
