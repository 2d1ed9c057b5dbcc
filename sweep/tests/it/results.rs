//! What sweeps compute: sharded + merged equals unsharded, 1 thread equals
//! 2, a resumed sweep equals an uninterrupted one, and the numbers move the
//! right way.

use std::path::{Path, PathBuf};

use errp_bci::stop::WindDown;
use errp_sweep::{
    Manifest, Shard, SweepObserver, SweepOutcome, SweepSpec, merge_sweeps, run_sweep,
};

use crate::{GRID_EEG, GRID_ORACLE, assert_same_files, complete, options, read, spec, temp_dir};

#[test]
fn sharded_and_merged_equals_unsharded_and_threads_do_not_matter() {
    let spec = spec(GRID_EEG, "0.7,0.9", &["tau=0.3,0.6"], 12);
    let whole = temp_dir("whole");
    complete(&spec, &whole, Shard::ALL, 2);
    let episodes = String::from_utf8(read(&whole, "episodes.csv")).unwrap();
    assert_eq!(episodes.lines().count(), 1 + 4 * 12);
    for f in ["summary.csv", "sweep.svg", "sweep.png", "sweep.json"] {
        assert!(whole.join(f).is_file(), "{f}");
    }

    let one = temp_dir("one-thread");
    complete(&spec, &one, Shard::ALL, 1);
    assert_same_files(&whole, &one);

    let shards: Vec<PathBuf> = (1..=3)
        .map(|k| {
            let d = temp_dir(&format!("shard{k}"));
            complete(&spec, &d, Shard { index: k, count: 3 }, 2);
            d
        })
        .collect();
    let merged = temp_dir("merged");
    // Any order of the shard directories.
    let order = vec![shards[2].clone(), shards[0].clone(), shards[1].clone()];
    merge_sweeps(&order, &merged).unwrap();
    assert_same_files(&whole, &merged);
    assert!(read(&whole, "sweep.svg") == read(&merged, "sweep.svg"));

    // A missing shard or a shard given twice is refused, naming it.
    let e = merge_sweeps(&shards[..2], &temp_dir("merged-missing"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing shard(s) 3/3"), "{e}");
    let twice = vec![shards[0].clone(), shards[0].clone(), shards[1].clone()];
    let e = merge_sweeps(&twice, &temp_dir("merged-twice"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("given twice"), "{e}");
    for d in [whole, one, merged].iter().chain(&shards) {
        let _ = std::fs::remove_dir_all(d);
    }
}

/// Requests the wind-down once `after` episodes are on disk.
struct CancelAfter<'a> {
    after: usize,
    wind_down: &'a WindDown,
}

impl SweepObserver for CancelAfter<'_> {
    fn episodes_done(&self, done: usize, _total: usize) {
        if done >= self.after {
            self.wind_down.request();
        }
    }
}

#[test]
fn an_interrupted_or_crashed_sweep_resumes_to_the_same_files() {
    let spec = spec(GRID_ORACLE, "0.6:0.9:0.1", &[], 40);
    let whole = temp_dir("uninterrupted");
    complete(&spec, &whole, Shard::ALL, 2);

    // Ctrl-C after the first chunks: the rows so far stay on disk.
    let resumed = temp_dir("resumed");
    let wind_down = WindDown::new();
    let stop = CancelAfter {
        after: 30,
        wind_down: &wind_down,
    };
    let sweep = spec.clone().checked(&errp_sim::Names::CLI).unwrap();
    let outcome = run_sweep(&sweep, &options(&resumed, Shard::ALL, 7), &wind_down, &stop).unwrap();
    let SweepOutcome::Interrupted { done, total } = outcome else {
        panic!("{outcome:?}")
    };
    // Workers run ahead of the oldest unfinished row by a bounded window, so
    // more than 30 rows may be on disk when the flag is seen.
    assert!((30..160).contains(&done) && total == 160, "{done} {total}");
    let partial = String::from_utf8(read(&resumed, "episodes.csv")).unwrap();
    assert_eq!(partial.lines().count(), 1 + done);
    assert!(!resumed.join("summary.csv").exists());

    // A crash in the middle of a row: the cut row is dropped and rerun.
    let cut = partial.len() - 9;
    std::fs::write(resumed.join("episodes.csv"), &partial.as_bytes()[..cut]).unwrap();

    // Resume with another chunk size and thread count.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let outcome = pool
        .install(|| {
            run_sweep(
                &sweep,
                &options(&resumed, Shard::ALL, 50),
                &WindDown::new(),
                &(),
            )
        })
        .unwrap();
    let SweepOutcome::Complete { ran, total, report } = outcome else {
        panic!("{outcome:?}")
    };
    assert_eq!((ran, total), (160 - done + 1, 160));
    assert!(report.is_some());
    assert_same_files(&whole, &resumed);

    // The same directory with other parameters is refused, untouched.
    let other = spec_with_seed(&spec, 6);
    let e = run_sweep(
        &other.checked(&errp_sim::Names::CLI).unwrap(),
        &options(&resumed, Shard::ALL, 7),
        &WindDown::new(),
        &(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("holds a different sweep"), "{e}");
    assert_same_files(&whole, &resumed);
    let _ = std::fs::remove_dir_all(&whole);
    let _ = std::fs::remove_dir_all(&resumed);
}

fn spec_with_seed(spec: &SweepSpec, seed: u64) -> SweepSpec {
    SweepSpec {
        seed,
        ..spec.clone()
    }
}

/// The summary rows of a finished sweep: (accuracy, success rate, mean cost).
fn summary_rows(dir: &Path) -> Vec<(f64, f64, f64)> {
    let text = String::from_utf8(read(dir, "summary.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let (a, s, m) = (col("accuracy"), col("success_rate"), col("actions_mean"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (
                f[a].parse().unwrap(),
                f[s].parse().unwrap(),
                f[m].parse().unwrap(),
            )
        })
        .collect()
}

#[test]
fn inference_degrades_as_the_decoder_gets_worse() {
    // 300 oracle episodes per level. A sweep that mixed up levels or seeds,
    // or summarised the wrong column, would break the ordering or the bounds.
    // At goal reward 2, where the bounds were measured (the shipped 5 makes
    // the belief commit sooner: more wrong goals, fewer actions).
    let scenario = format!("{GRID_ORACLE}[control]\ngoal_reward = 2.0\n");
    let spec = spec(&scenario, "0.6,0.75,0.9", &[], 300);
    let out = temp_dir("degrades");
    complete(&spec, &out, Shard::ALL, 2);
    let rows = summary_rows(&out);
    assert_eq!(rows.len(), 3);
    let (lo, mid, hi) = (rows[0], rows[1], rows[2]);
    assert!(hi.1 > 0.95, "success at 0.9: {}", hi.1);
    assert!(lo.1 < mid.1 && mid.1 < hi.1 + 0.02, "{rows:?}");
    assert!(
        lo.2 > 1.5 * mid.2 && mid.2 > 1.3 * hi.2,
        "mean actions {rows:?}"
    );
    // Measured (seed 5): 0.6 -> 48 % in 213 actions, 0.75 -> 100 % in 65,
    // 0.9 -> 100 % in 21.
    assert!(lo.1 > 0.3 && lo.1 < 0.65, "success at 0.6: {}", lo.1);
    assert!(hi.2 > 14.0 && hi.2 < 30.0, "mean actions at 0.9: {}", hi.2);
    let _ = std::fs::remove_dir_all(&out);
}

/// A sweep calibrates each level's decoder exactly as `errp run` calibrates
/// the same scenario: the same ratio and the same cross-validated accuracy,
/// to the bit, whether the targeting came from the cache or not.
#[test]
fn a_sweep_calibrates_like_errp_run() {
    let spec = spec(GRID_EEG, "0.65,0.8", &[], 1);
    let out = temp_dir("same-calibration");
    complete(&spec, &out, Shard::ALL, 2);
    let manifest = Manifest::read(&out).unwrap();
    let sweep = spec.checked(&errp_sim::Names::CLI).unwrap();
    for (level, info) in sweep.levels().iter().zip(&manifest.decoders) {
        let errp_sim::AnyScenario::Grid(scenario) = &level.scenario else {
            panic!("a grid level");
        };
        let (_, report) = errp_sim::grid::prepare_decoder(scenario, |_| {}).unwrap();
        let report = report.expect("an EEG decoder is calibrated");
        let a = report.calibrated.accuracy;
        assert_eq!(
            info.errp_to_noise.map(f64::to_bits),
            Some(report.targeting.ratio.to_bits())
        );
        assert_eq!(info.cv_mean.map(f64::to_bits), Some(a.mean().to_bits()));
        assert_eq!(info.cv_error.map(f64::to_bits), Some(a.error.to_bits()));
    }
    let _ = std::fs::remove_dir_all(&out);
}
