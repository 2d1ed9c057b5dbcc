//! The integration tests of `errp_sweep`, one binary: what sweeps compute
//! (`results`: sharded + merged equals unsharded, 1 thread equals 2, a
//! resumed sweep equals an uninterrupted one, the numbers move the right
//! way), how they keep their files whole (`integrity`: locks, corrupted
//! rows on resume and merge, refused directories), and the fits built on
//! them (`fit`).

mod fit;
mod integrity;
mod own_eeg;
mod results;

use std::path::{Path, PathBuf};

use errp_bci::stop::WindDown;
use errp_sim::Names;
use errp_sim::TaskKind;
use errp_sweep::{
    Shard, SweepOptions, SweepOutcome, SweepSpec, TargetCache, parse_accuracies, parse_axis,
    run_sweep,
};

/// A grid scenario with the EEG decoder on a small epoch bank.
pub(crate) const GRID_EEG: &str = r#"
task = "grid"
decoder = "eeg"
eeg = "bank"
bank_per_class = 150
[user]
accuracy = 0.8
[[episode]]
start = [0, 0]
goal = [4, 4]
[[episode]]
start = [4, 0]
goal = [1, 3]
[[episode]]
start = [2, 2]
goal = [0, 4]
"#;

/// The same with the oracle decoder (no EEG): fast enough for many episodes.
pub(crate) const GRID_ORACLE: &str = r#"
task = "grid"
decoder = "oracle"
[user]
accuracy = 0.8
[free_goals]
count = 50
"#;

pub(crate) fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("errp-sweep-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// A cache shared by the tests of this binary, so each level's targeting is
/// searched once.
pub(crate) fn cache() -> TargetCache {
    TargetCache::new(std::env::temp_dir().join(format!("errp-sweep-cache-{}", std::process::id())))
}

pub(crate) fn spec(text: &str, accuracy: &str, params: &[&str], episodes: usize) -> SweepSpec {
    SweepSpec {
        task: TaskKind::Grid,
        scenario_path: "test.toml".into(),
        scenario_toml: text.into(),
        accuracies: parse_accuracies(accuracy, &Names::CLI).unwrap(),
        axes: params
            .iter()
            .map(|p| parse_axis(TaskKind::Grid, p, &Names::CLI).unwrap())
            .collect(),
        fixed: vec![],
        episodes,
        seed: 5,
    }
}

pub(crate) fn options(out: &Path, shard: Shard, chunk: usize) -> SweepOptions {
    SweepOptions {
        out: out.to_path_buf(),
        cache: cache(),
        shard,
        chunk,
        repair: false,
    }
}

/// Runs a sweep to the end on `threads` threads (which writes its summary).
pub(crate) fn complete(spec: &SweepSpec, out: &Path, shard: Shard, threads: usize) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let outcome = pool
        .install(|| {
            let sweep = spec.clone().checked(&Names::CLI).unwrap();
            run_sweep(&sweep, &options(out, shard, 7), &WindDown::new(), &())
        })
        .unwrap();
    let SweepOutcome::Complete { report, .. } = outcome else {
        panic!("{outcome:?}")
    };
    assert_eq!(report.is_some(), shard.is_all());
}

pub(crate) fn read(dir: &Path, name: &str) -> Vec<u8> {
    std::fs::read(dir.join(name)).unwrap_or_else(|e| panic!("{}: {e}", dir.join(name).display()))
}

pub(crate) fn assert_same_files(a: &Path, b: &Path) {
    for name in ["episodes.csv", "summary.csv", "sweep.json"] {
        assert!(
            read(a, name) == read(b, name),
            "{name} differs between {} and {}",
            a.display(),
            b.display()
        );
    }
}
