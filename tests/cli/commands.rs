//! The commands as a user runs them: results, files and refusals.

use std::path::{Path, PathBuf};

use crate::{errp, files_in, refused, stderr, temp_dir};

#[cfg(feature = "rerun")]
#[test]
fn calibrate_records_and_exports_at_the_requested_accuracy() {
    let dir = temp_dir("ok");
    let rrd = dir.join("calib.rrd");
    let edf = dir.join("calib.edf");
    let o = errp(&[
        "calibrate",
        "--accuracy",
        "0.7438",
        "--seed",
        "1",
        "--save",
        rrd.to_str().unwrap(),
        "--export",
        edf.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    let mean: f64 = out
        .lines()
        .find(|l| l.trim_start().starts_with("mean"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse().ok())
        .expect("a mean line");
    assert!((mean - 74.38).abs() <= 1.5, "{out}");
    assert!(
        out.contains("correct class") && out.contains("error class"),
        "{out}"
    );
    assert!(stderr(&o).contains("ErrP-to-noise"), "progress is shown");
    assert_eq!(
        files_in(&dir),
        ["calib.edf", "calib.rrd"],
        "no temporary files left"
    );
    let bytes = std::fs::read(&edf).unwrap();
    assert_eq!(&bytes[192..197], b"EDF+C");
    assert!(std::fs::metadata(&rrd).unwrap().len() > 10_000);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Built without Rerun (`--no-default-features`), `--save` is refused before
/// any work, with how to rebuild, and nothing is written.
#[cfg(not(feature = "rerun"))]
#[test]
fn save_without_rerun_is_exit_2_saying_how_to_rebuild() {
    let dir = temp_dir("no-rerun");
    let rrd = dir.join("x.rrd");
    for args in [
        vec!["calibrate", "--save", rrd.to_str().unwrap()],
        vec![
            "run",
            "scenarios/mexico_to_pisa.toml",
            "--save",
            rrd.to_str().unwrap(),
        ],
    ] {
        let e = refused(&args);
        assert!(
            e.contains("--save") && e.contains("without Rerun") && e.contains("cargo build"),
            "{e}"
        );
        assert!(files_in(&dir).is_empty(), "{:?}", files_in(&dir));
    }
}

#[test]
fn accuracy_out_of_range_is_exit_2_naming_the_flag() {
    for bad in ["1.7", "0.5", "-3", "NaN", "abc"] {
        let o = errp(&["calibrate", "--accuracy", bad]);
        assert_eq!(o.status.code(), Some(2), "{bad}");
        let e = stderr(&o);
        assert!(e.contains("--accuracy") && e.contains("0.5"), "{bad}: {e}");
    }
}

#[test]
fn unknown_subject_is_exit_2_listing_the_known_ones() {
    let e = refused(&["calibrate", "--subject", "S9"]);
    assert!(e.contains("S9") && e.contains("S1, S2, S3, S4"), "{e}");
}

#[test]
fn unwritable_output_fails_before_work_and_leaves_nothing() {
    let dir = temp_dir("bad");
    let missing = dir.join("no-such-dir").join("x.rrd");
    let edf = dir.join("x.edf");
    let o = errp(&[
        "calibrate",
        "--export",
        edf.to_str().unwrap(),
        "--save",
        missing.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(e.contains("no-such-dir"), "{e}");
    assert!(!e.contains("ErrP-to-noise"), "no work was done: {e}");
    assert!(files_in(&dir).is_empty(), "{:?}", files_in(&dir));

    let o = errp(&["calibrate", "--save", dir.join("x.txt").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains(".rrd"), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn subjects_lists_table1() {
    let o = errp(&["subjects"]);
    assert!(o.status.success());
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("S2") && out.contains("69.49") && out.contains("88.18"),
        "{out}"
    );
}

/// `--seed N` is the file saying `seed = N`: the grid's free goals, drawn
/// from the seed when the scenario is read, are drawn again (they were not:
/// `--seed` was set after the goals were drawn from the file's seed).
#[test]
fn a_seed_override_draws_the_free_goals_again() {
    let free = "scenarios/grid_free_goals.toml";
    let pairs = |scenario: &str, seed: Option<&str>| {
        let mut args = vec!["run", scenario, "--decoder", "oracle", "--quiet"];
        if let Some(seed) = seed {
            args.extend(["--seed", seed]);
        }
        let o = errp(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let out = String::from_utf8_lossy(&o.stdout).into_owned();
        // "  1  (0, 1) (3, 3) ...": the start and the goal of each episode.
        let rows: Vec<String> = out
            .lines()
            .filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit()))
            .map(|l| {
                l.split_whitespace()
                    .skip(1)
                    .take(4)
                    .collect::<Vec<_>>()
                    .join(" ")
            })
            .collect();
        assert_eq!(rows.len(), 5, "{out}");
        rows
    };
    let by_flag = pairs(free, Some("1"));
    assert_ne!(by_flag, pairs(free, Some("3")), "another seed, other goals");
    assert_eq!(
        pairs(free, Some("2")),
        pairs(free, None),
        "the file's seed is 2"
    );
    let dir = temp_dir("seed-override");
    let copy = dir.join("free.toml");
    let text = std::fs::read_to_string(free).unwrap();
    std::fs::write(&copy, text.replace("seed = 2", "seed = 1")).unwrap();
    assert_eq!(by_flag, pairs(copy.to_str().unwrap(), None));
    let e = refused(&["run", free, "--seed", "9223372036854775808"]);
    assert!(
        e.contains("--seed") && e.contains("9223372036854775807"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_shipped_grid_scenario_loads_and_runs_with_the_oracle() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml")
            || std::fs::read_to_string(&path)
                .unwrap()
                .contains("task = \"epuck\"")
        {
            continue;
        }
        n += 1;
        let o = errp(&[
            "run",
            path.to_str().unwrap(),
            "--decoder",
            "oracle",
            "--quiet",
        ]);
        assert!(o.status.success(), "{}: {}", path.display(), stderr(&o));
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(out.contains("goals reached"), "{out}");
    }
    assert!(n >= 2, "scenarios found: {n}");
}

#[test]
fn a_broken_scenario_is_exit_2_naming_file_field_and_fix() {
    let dir = temp_dir("scenario");
    let path = dir.join("bad.toml");
    std::fs::write(
        &path,
        "task = \"grid\"\n[user]\naccuracy = 0.8\n[[episode]]\nstart = [0, 0]\ngoal = [7, 1]\n",
    )
    .unwrap();
    let rrd = dir.join("run.rrd");
    let e = refused(&[
        "run",
        path.to_str().unwrap(),
        "--save",
        rrd.to_str().unwrap(),
    ]);
    assert!(
        e.contains("bad.toml") && e.contains("episode[0].goal") && e.contains("[7, 1]"),
        "{e}"
    );
    assert!(e.contains("0 <= x, y <= 4"), "{e}");
    assert!(!rrd.exists());
    assert_eq!(files_in(&dir), ["bad.toml"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_epuck_run_prints_the_outcome_and_the_papers_figures() {
    let o = errp(&[
        "run",
        "scenarios/mexico_to_pisa.toml",
        "--accuracy",
        "0.95",
        "--runs",
        "2",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    for want in [
        "SVM decoder calibrated on 70 error + 70 correct",
        "converged on",
        "reached Pisa",
        "[paper: 60]",
        "[paper: 11]",
        "window accuracy",
    ] {
        assert!(out.contains(want), "{want}: {out}");
    }
}

#[test]
fn a_broken_epuck_scenario_is_exit_2_naming_file_field_and_fix() {
    let dir = temp_dir("epuck");
    let rrd = dir.join("run.rrd");
    for (text, field, fix) in [
        (
            "task = \"epuck\"\nstart = \"Mexico\"\ngoal = \"Atlantis\"\n[user]\naccuracy = 0.8\n",
            "goal",
            "Pisa",
        ),
        (
            "task = \"epuck\"\nstart = \"Mexico\"\ngoal = \"Pisa\"\n[user]\naccuracy = 1.7\n",
            "user.accuracy",
            "between 0.5",
        ),
        (
            "task = \"epuck\"\nstart = [20.0, 250.0]\ngoal = \"Pisa\"\n[user]\naccuracy = 0.8\n",
            "start",
            "inside the 200 cm arena",
        ),
    ] {
        let path = dir.join("bad.toml");
        std::fs::write(&path, text).unwrap();
        let o = errp(&[
            "run",
            path.to_str().unwrap(),
            "--save",
            rrd.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{text}");
        let e = stderr(&o);
        assert!(
            e.contains("bad.toml") && e.contains(field) && e.contains(fix),
            "{e}"
        );
        assert!(!rrd.exists());
        assert_eq!(files_in(&dir), ["bad.toml"]);
    }
    // Grid-only flags are refused for an e-puck scenario.
    let o = errp(&[
        "run",
        "scenarios/mexico_to_pisa.toml",
        "--decoder",
        "oracle",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--decoder"), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A small oracle grid scenario for sweeps.
const SWEEP_SCENARIO: &str =
    "task = \"grid\"\ndecoder = \"oracle\"\n[user]\naccuracy = 0.8\n[free_goals]\ncount = 10\n";

#[test]
fn a_sweep_writes_its_files_and_shards_merge_to_the_same_bytes() {
    let dir = temp_dir("sweep");
    let scenario = dir.join("s.toml");
    std::fs::write(&scenario, SWEEP_SCENARIO).unwrap();
    let sweep = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "sweep",
            "--scenario",
            scenario.to_str().unwrap(),
            "--accuracy",
            "0.6:0.9:0.15",
            "--param",
            "strategy=greedy,info_gain",
            "--episodes",
            "30",
            "--seed",
            "3",
            "--no-cache",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        errp(&args)
    };
    let whole = dir.join("whole");
    let o = sweep(&whole, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(
        table.contains("strategy=info_gain") && table.contains("success"),
        "{table}"
    );
    assert_eq!(
        files_in(&whole),
        [
            "episodes.csv",
            "summary.csv",
            "sweep.json",
            "sweep.png",
            "sweep.svg"
        ]
    );
    let summary = std::fs::read_to_string(whole.join("summary.csv")).unwrap();
    assert_eq!(summary.lines().count(), 1 + 6, "{summary}");
    assert!(
        summary.starts_with("level,accuracy,strategy,episodes,success_rate"),
        "{summary}"
    );

    let shards: Vec<PathBuf> = (1..=2).map(|k| dir.join(format!("shard{k}"))).collect();
    for (k, d) in shards.iter().enumerate() {
        let o = sweep(d, &["--shard", &format!("{}/2", k + 1), "--threads", "1"]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert_eq!(files_in(d), ["episodes.csv", "sweep.json"]);
    }
    let merged = dir.join("merged");
    let o = errp(&[
        "merge",
        shards[1].to_str().unwrap(),
        shards[0].to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for f in ["episodes.csv", "summary.csv", "sweep.json"] {
        assert!(
            std::fs::read(whole.join(f)).unwrap() == std::fs::read(merged.join(f)).unwrap(),
            "{f} differs"
        );
    }

    // Rerunning a finished sweep resumes with nothing left to do.
    let o = sweep(&whole, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("0 episodes in"), "{}", stderr(&o));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_sweep_input_is_exit_2_with_the_fix_and_no_output() {
    let dir = temp_dir("sweep-bad");
    let scenario = dir.join("s.toml");
    std::fs::write(&scenario, SWEEP_SCENARIO).unwrap();
    let out = dir.join("out");
    let s = scenario.to_str().unwrap();
    let o_ = out.to_str().unwrap();
    for (args, needles) in [
        (
            vec!["--accuracy", "0.6,1.7"],
            vec!["--accuracy", "1.7", "(0.5, 1)"],
        ),
        (vec!["--accuracy", "0.9:0.6:0.1"], vec!["stop >= start"]),
        (
            vec!["--param", "tau=-1,0.3"],
            vec!["tau=-1", "control.tau", "s.toml"],
        ),
        (
            vec!["--param", "t_e=0.8"],
            vec!["not a grid scenario parameter"],
        ),
        (
            vec!["--param", "strategy=clever"],
            vec!["strategy", "greedy", "info_gain"],
        ),
        (vec!["--shard", "3/2"], vec!["--shard", "K/N"]),
        (
            vec!["--task", "epuck"],
            vec!["does not match", "grid scenario"],
        ),
        (vec!["--episodes", "0"], vec!["--episodes"]),
    ] {
        let mut all = vec!["sweep", "--scenario", s, "--out", o_, "--no-cache"];
        all.extend(args.iter());
        let o = errp(&all);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        for n in needles {
            assert!(e.contains(n), "{args:?}: `{n}` not in {e}");
        }
        assert!(!out.exists(), "{args:?} left {}", out.display());
    }
    // Merging a directory that is not a sweep names it.
    let o = errp(&["merge", dir.to_str().unwrap(), "--out", o_]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("sweep.json"), "{}", stderr(&o));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--prepare-only` fills the targeting cache and runs nothing; a shard
/// started after it finds every targeting there.
#[test]
fn prepare_only_fills_the_cache_so_that_shards_search_nothing() {
    let dir = temp_dir("prepare-only");
    let cache = dir.join("cache");
    let c = cache.to_str().unwrap();
    let args = [
        "--task",
        "epuck",
        "--accuracy",
        "0.8,0.9",
        "--episodes",
        "2",
    ];
    let mut prepare = vec!["sweep", "--prepare-only", "--cache", c];
    prepare.extend(args);
    let o = errp(&prepare);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("Prepared 2 decoder(s) (2 searched now, 0 already cached)"),
        "{out}"
    );
    assert_eq!(files_in(&dir), ["cache"], "no sweep directory");
    let shard_dir = dir.join("shard-1");
    let mut shard = vec![
        "sweep",
        "--cache",
        c,
        "--shard",
        "1/2",
        "--out",
        shard_dir.to_str().unwrap(),
    ];
    shard.extend(args);
    let o = errp(&shard);
    assert!(o.status.success(), "{}", stderr(&o));
    let progress = stderr(&o);
    assert_eq!(
        progress.matches("(targeting cached)").count(),
        2,
        "{progress}"
    );
    // Nothing to keep, or an output it would not write: refused.
    for extra in [
        vec!["--no-cache"],
        vec!["--out", "x"],
        vec!["--shard", "1/2"],
    ] {
        let mut bad = vec!["sweep", "--prepare-only"];
        bad.extend(args);
        bad.extend(extra.iter());
        let e = refused(&bad);
        assert!(e.contains("--prepare-only"), "{extra:?}: {e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_small_fit_prints_its_estimate_and_writes_its_files() {
    let dir = temp_dir("fit");
    let out = dir.join("fit");
    let cache = dir.join("cache");
    let (o, c) = (out.to_str().unwrap(), cache.to_str().unwrap());
    let args = [
        "fit",
        "epuck",
        "--accuracy",
        "0.8,0.95",
        "--calibrations",
        "1",
        "--runs",
        "5",
        "--bootstrap",
        "10",
        "--out",
        o,
        "--cache",
        c,
        "--quiet",
    ];
    let run = errp(&args);
    assert!(run.status.success(), "{}", stderr(&run));
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(text.contains("Estimate: accuracy"), "{text}");
    assert!(text.contains("Held out Mexico to Pisa"), "{text}");
    assert_eq!(
        files_in(&out),
        [
            "fit.json",
            "fit.png",
            "fit.svg",
            "lisbon_to_tokyo",
            "mexico_to_pisa",
            "surface.csv"
        ]
    );
    let json = std::fs::read_to_string(out.join("fit.json")).unwrap();
    assert!(
        json.contains("\"commit\"") && json.contains("fit epuck"),
        "{json}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_fit_input_is_exit_2_naming_the_flag() {
    let dir = temp_dir("fit-bad");
    let o = dir.join("out");
    let o = o.to_str().unwrap();
    let e = refused(&["fit", "epuck", "--runs", "2", "--out", o, "--no-cache"]);
    assert!(e.contains("--runs 2") && e.contains("5 to 100000"), "{e}");
    let e = refused(&[
        "fit",
        "epuck",
        "--accuracy",
        "0.8",
        "--out",
        o,
        "--no-cache",
    ]);
    assert!(e.contains("--accuracy") && e.contains("2 to"), "{e}");
    let e = refused(&[
        "fit",
        "epuck",
        "--accuracy",
        "0.8,1.5",
        "--out",
        o,
        "--no-cache",
    ]);
    assert!(e.contains("1.5"), "{e}");
    let e = refused(&[
        "fit",
        "epuck",
        "--calibrations",
        "0",
        "--out",
        o,
        "--no-cache",
    ]);
    assert!(e.contains("--calibrations 0"), "{e}");
    for (args, want) in [
        (&["--epsilon", "1.5"][..], "--epsilon 1.5"),
        (&["--goal-reward", "abc"][..], "--goal-reward \"abc\""),
        (&["--goal-reward", "0:1:0.5"][..], "(0, 100]"),
        (&["--repeats", "1"][..], "2 to 1000"),
        (
            &["--pair-length", "4:8:1"][..],
            "--pair-length 4 is invalid",
        ),
        (&["--pair-length", "8.5"][..], "--pair-length \"8.5\""),
        (&["--pair-length", "40"][..], "5 to 36"),
        (
            &["--trial-latency-sd", "16.7,abc"][..],
            "--trial-latency-sd \"16.7,abc\"",
        ),
        (&["--trial-latency-sd", "-5"][..], "[0, 100] ms"),
        (
            &["--trial-latency-sd", "25,19"][..],
            "--trial-latency-sd must list increasing",
        ),
    ] {
        let mut full = vec!["fit", "grid"];
        full.extend_from_slice(args);
        full.extend_from_slice(&["--out", o, "--no-cache"]);
        let e = refused(&full);
        assert!(e.contains(want), "{args:?}: {e}");
    }
    assert!(!Path::new(o).exists(), "a refused fit leaves nothing");
    let _ = std::fs::remove_dir_all(&dir);
}
