//! How sweeps keep their files whole: every corrupted row is found on resume
//! and on merge (and `repair` runs it again), a directory in use or holding
//! other files is refused untouched, and a refused start or merge leaves no
//! directory it created.

use std::path::{Path, PathBuf};

use errp_bci::stop::WindDown;
use errp_sweep::{DirLock, Shard, SweepOutcome, SweepSpec, merge_sweeps, run_sweep};

use crate::{GRID_ORACLE, complete, options, read, spec, temp_dir};

/// A complete small sweep (oracle, 3 levels x 12 episodes) and its 2 shards.
fn sweep_and_shards(name: &str) -> (SweepSpec, PathBuf, [PathBuf; 2]) {
    let spec = spec(GRID_ORACLE, "0.6,0.75,0.9", &[], 12);
    let whole = temp_dir(&format!("{name}-whole"));
    complete(&spec, &whole, Shard::ALL, 2);
    let shards = [1, 2].map(|k| {
        let d = temp_dir(&format!("{name}-shard{k}"));
        complete(&spec, &d, Shard { index: k, count: 2 }, 2);
        d
    });
    (spec, whole, shards)
}

/// A change to a row: what it is, the change, what the error must name.
type Corruption = (&'static str, Box<dyn Fn(&str) -> String>, &'static str);

/// The ways a row (line 5 of `episodes.csv`, a whole row in the middle) can
/// be wrong, and the field each error must name.
fn corruptions() -> Vec<Corruption> {
    let field = |i: usize, to: &'static str| {
        move |row: &str| {
            let mut f: Vec<String> = row.split(',').map(String::from).collect();
            f[i] = to.to_string();
            f.join(",")
        }
    };
    // Columns: level,accuracy,episode,seed,success,start_x,start_y,goal_x,
    // goal_y,committed_x,committed_y,actions,net_secs,total_secs,errors,
    // detected,false_alarms,missed,acc_correct,acc_error,online_accuracy,crc32
    vec![
        ("success = 7", Box::new(field(4, "7")), "`success`"),
        (
            "actions not a number",
            Box::new(field(11, "abc")),
            "`actions`",
        ),
        ("a negative time", Box::new(field(13, "-3")), "`total_secs`"),
        (
            "a rate above 1",
            Box::new(field(20, "1.5")),
            "`online_accuracy`",
        ),
        ("the wrong seed", Box::new(field(3, "12345")), "`seed`"),
        ("the wrong level", Box::new(field(0, "2")), "`level`"),
        ("the wrong episode", Box::new(field(2, "0")), "`episode`"),
        ("a start off the grid", Box::new(field(5, "7")), "`start_x`"),
        (
            "another start",
            Box::new(|row: &str| {
                let mut f: Vec<String> = row.split(',').map(String::from).collect();
                let x: u8 = f[5].parse().unwrap();
                f[5] = ((x + 1) % 5).to_string();
                f.join(",")
            }),
            "`start_x`",
        ),
        (
            "a missing column",
            Box::new(|row: &str| {
                let mut f: Vec<&str> = row.split(',').collect();
                f.remove(12);
                f.join(",")
            }),
            "fields",
        ),
        (
            "a row cut short in the middle of the file",
            Box::new(|row: &str| row[..row.len() / 2].to_string()),
            "fields",
        ),
        (
            // A digit changed: still a valid number, caught by the checksum.
            "bit rot in a number",
            Box::new(|row: &str| {
                let mut f: Vec<String> = row.split(',').map(String::from).collect();
                let t = &mut f[13];
                let last = t.pop().unwrap();
                t.push(if last == '1' { '2' } else { '1' });
                f.join(",")
            }),
            "`crc32`",
        ),
        (
            "not text",
            Box::new(|row: &str| format!("{row}\u{FFFD}")),
            "",
        ),
    ]
}

/// `text` with line `line` (1-based) replaced by `f` of it.
fn with_line(text: &str, line: usize, f: &dyn Fn(&str) -> String) -> String {
    text.lines()
        .enumerate()
        .map(|(i, l)| if i + 1 == line { f(l) } else { l.to_string() })
        .map(|l| l + "\n")
        .collect()
}

fn run(spec: &SweepSpec, out: &Path, shard: Shard, repair: bool) -> errp_sim::Result<SweepOutcome> {
    let mut opts = options(out, shard, 7);
    opts.repair = repair;
    run_sweep(
        &spec.clone().checked(&errp_sim::Names::CLI)?,
        &opts,
        &WindDown::new(),
        &(),
    )
}

#[test]
fn every_corrupted_row_is_found_on_resume_and_repair_runs_it_again() {
    let (spec, whole, shards) = sweep_and_shards("resume");
    let good = String::from_utf8(read(&whole, "episodes.csv")).unwrap();
    let dir = temp_dir("resume-corrupt");
    for (what, corrupt, column) in corruptions() {
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        for f in ["sweep.json", "episodes.csv"] {
            std::fs::copy(whole.join(f), dir.join(f)).unwrap();
        }
        let bad = with_line(&good, 5, corrupt.as_ref());
        // "not text": a byte that is not UTF-8.
        let bytes = if what == "not text" {
            let mut b = good.as_bytes().to_vec();
            let at = good.match_indices('\n').nth(3).unwrap().0 + 3;
            b[at] = 0xff;
            b
        } else {
            bad.into_bytes()
        };
        std::fs::write(dir.join("episodes.csv"), &bytes).unwrap();
        let e = run(&spec, &dir, Shard::ALL, false).unwrap_err().to_string();
        assert!(
            e.contains("episodes.csv line 5") && e.contains(column) && e.contains("--repair"),
            "{what}: {e}"
        );
        // Refused: the file is as it was.
        assert!(read(&dir, "episodes.csv") == bytes, "{what}");
        // With repair, the bad row and those after it run again, to the
        // same bytes as the sweep that was never damaged.
        let outcome = run(&spec, &dir, Shard::ALL, true).unwrap();
        assert!(
            matches!(outcome, SweepOutcome::Complete { ran, .. } if ran == 36 - 3),
            "{what}: {outcome:?}"
        );
        assert!(read(&dir, "episodes.csv") == good.as_bytes(), "{what}");
        assert!(
            read(&dir, "summary.csv") == read(&whole, "summary.csv"),
            "{what}"
        );
    }
    for d in [whole, dir].iter().chain(&shards) {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn every_corrupted_or_incomplete_shard_is_refused_by_merge() {
    let (_, whole, shards) = sweep_and_shards("merge");
    let good = String::from_utf8(read(&shards[1], "episodes.csv")).unwrap();
    let copy = temp_dir("merge-corrupt-shard");
    let out = temp_dir("merge-corrupt-out");
    let reset = || {
        let _ = std::fs::remove_dir_all(&copy);
        std::fs::create_dir_all(&copy).unwrap();
        std::fs::copy(shards[1].join("sweep.json"), copy.join("sweep.json")).unwrap();
    };
    let merged = |text: &[u8]| {
        std::fs::write(copy.join("episodes.csv"), text).unwrap();
        let e = merge_sweeps(&[shards[0].clone(), copy.clone()], &out)
            .unwrap_err()
            .to_string();
        assert!(!out.exists(), "a refused merge leaves no --out: {e}");
        e
    };
    for (what, corrupt, column) in corruptions() {
        if what == "not text" {
            continue;
        }
        reset();
        let e = merged(with_line(&good, 5, corrupt.as_ref()).as_bytes());
        assert!(
            e.contains(&format!("{} line 5", copy.join("episodes.csv").display()))
                && e.contains(column),
            "{what}: {e}"
        );
    }
    // The last row cut mid-row (a shard killed while writing it), or
    // missing altogether.
    reset();
    let e = merged(&good.as_bytes()[..good.len() - 30]);
    assert!(e.contains("incomplete") && e.contains("cut short"), "{e}");
    reset();
    let e = merged(&good.as_bytes()[..good.len() - good.lines().last().unwrap().len() - 1]);
    assert!(
        e.contains("incomplete") && e.contains("ends before line"),
        "{e}"
    );
    // A shard that is still being written.
    reset();
    std::fs::write(copy.join("episodes.csv"), &good).unwrap();
    let lock = DirLock::acquire(&copy, "--out").unwrap();
    let e = merge_sweeps(&[shards[0].clone(), copy.clone()], &out)
        .unwrap_err()
        .to_string();
    assert!(e.contains("still being written"), "{e}");
    drop(lock);
    // Whole again: the merge equals the unsharded sweep.
    merge_sweeps(&[shards[0].clone(), copy.clone()], &out).unwrap();
    assert!(read(&out, "episodes.csv") == read(&whole, "episodes.csv"));
    for d in [whole, copy, out].iter().chain(&shards) {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn a_directory_in_use_or_holding_other_files_is_refused_untouched() {
    let spec = spec(GRID_ORACLE, "0.7", &[], 5);
    // In use by another writer (here: a lock this test holds).
    let busy = temp_dir("in-use");
    std::fs::create_dir_all(&busy).unwrap();
    let lock = DirLock::acquire(&busy, "--out").unwrap();
    let e = run(&spec, &busy, Shard::ALL, false)
        .unwrap_err()
        .to_string();
    assert!(e.contains("is in use") && e.contains("pid"), "{e}");
    assert!(!busy.join("sweep.json").exists());
    drop(lock);
    complete(&spec, &busy, Shard::ALL, 1);
    assert!(
        !busy.join("sweep.lock").exists(),
        "the lock goes with the sweep"
    );

    // Not empty, and not a sweep.
    let other = temp_dir("other-files");
    std::fs::create_dir_all(&other).unwrap();
    std::fs::write(other.join("notes.txt"), "mine").unwrap();
    let e = run(&spec, &other, Shard::ALL, false)
        .unwrap_err()
        .to_string();
    assert!(e.contains("not a sweep's (notes.txt)"), "{e}");
    let mut names: Vec<_> = std::fs::read_dir(&other)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert_eq!(names, ["notes.txt"]);

    // A start refused after the directory was made leaves none: here the
    // task does not match the scenario.
    let fresh = temp_dir("refused-fresh");
    let wrong = SweepSpec {
        task: errp_sim::TaskKind::Epuck,
        ..spec.clone()
    };
    assert!(run(&wrong, &fresh, Shard::ALL, false).is_err());
    assert!(!fresh.exists());
    for d in [busy, other] {
        let _ = std::fs::remove_dir_all(d);
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig {
        cases: 500,
        ..proptest::prelude::ProptestConfig::default()
    })]

    /// Any one byte of `episodes.csv` changed (but its very last newline,
    /// whose loss is a crash's cut row, rerun by design) makes the resume
    /// refuse, naming the line; the file is left as it was.
    #[test]
    fn any_changed_byte_is_found_on_resume(
        at in proptest::prelude::any::<proptest::sample::Index>(),
        to in proptest::prelude::any::<u8>(),
    ) {
        use std::sync::OnceLock;
        static SWEEP: OnceLock<(SweepSpec, PathBuf)> = OnceLock::new();
        let (spec, whole) = SWEEP.get_or_init(|| {
            let spec = spec(GRID_ORACLE, "0.6,0.9", &[], 20);
            let whole = temp_dir("byte-whole");
            complete(&spec, &whole, Shard::ALL, 2);
            (spec, whole)
        });
        let mut bytes = read(whole, "episodes.csv");
        let i = at.index(bytes.len() - 1);
        proptest::prop_assume!(bytes[i] != to);
        bytes[i] = to;
        let dir = temp_dir(&format!("byte-{i}-{to}"));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::copy(whole.join("sweep.json"), dir.join("sweep.json")).unwrap();
        std::fs::write(dir.join("episodes.csv"), &bytes).unwrap();
        let result = run(spec, &dir, Shard::ALL, false);
        let after = read(&dir, "episodes.csv");
        let _ = std::fs::remove_dir_all(&dir);
        let e = result.expect_err("a changed byte must be found").to_string();
        proptest::prop_assert!(e.contains("episodes.csv"), "{}", e);
        proptest::prop_assert!(after == bytes);
    }
}
