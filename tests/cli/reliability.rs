//! What the program leaves behind when it is stopped by a signal, run twice
//! on one directory, or given input it must refuse.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use crate::{errp, files_in, refused, stderr, temp_dir};

/// `errp args` started in the background (output discarded but stderr).
fn spawn(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_errp"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("errp starts")
}

fn signal(child: &Child, name: &str) {
    let ok = Command::new("kill")
        .args([&format!("-{name}"), &child.id().to_string()])
        .status()
        .expect("kill runs")
        .success();
    assert!(ok, "kill -{name}");
}

/// Waits (up to two minutes) until `ready` holds.
#[track_caller]
fn wait_until(what: &str, ready: impl Fn() -> bool) {
    for _ in 0..1200 {
        if ready() {
            return;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    panic!("timed out waiting for {what}");
}

/// True if `dir` holds a file being written (`.NAME.partial-...`).
#[cfg(feature = "rerun")]
fn has_partial(dir: &Path) -> bool {
    files_in(dir).iter().any(|f| f.contains(".partial-"))
}

/// An oracle grid scenario: fast episodes, many of them.
const ORACLE: &str =
    "task = \"grid\"\ndecoder = \"oracle\"\n[user]\naccuracy = 0.7\n[free_goals]\ncount = 50\n";

fn sweep_args<'a>(scenario: &'a str, out: &'a str, episodes: &'a str) -> Vec<&'a str> {
    vec![
        "sweep",
        "--scenario",
        scenario,
        "--accuracy",
        "0.6",
        "--episodes",
        episodes,
        "--threads",
        "1",
        "--no-cache",
        "--quiet",
        "--out",
        out,
    ]
}

/// A fresh directory `name` holding the oracle scenario as `s.toml`.
fn oracle_dir(name: &str) -> (PathBuf, PathBuf) {
    let dir = temp_dir(name);
    let scenario = dir.join("s.toml");
    std::fs::write(&scenario, ORACLE).unwrap();
    (dir, scenario)
}

/// Rows of `out/episodes.csv` (header included; 0 if there is none).
fn lines_on_disk(out: &Path) -> usize {
    std::fs::read_to_string(out.join("episodes.csv")).map_or(0, |t| t.lines().count())
}

/// `out` holds the same `episodes.csv` and `summary.csv` as the sweep of
/// `scenario` run alone and uninterrupted (into `dir/alone`).
fn assert_same_as_alone(scenario: &str, dir: &Path, out: &Path, episodes: &str) {
    let alone = dir.join("alone");
    let o = errp(&sweep_args(scenario, alone.to_str().unwrap(), episodes));
    assert!(o.status.success(), "{}", stderr(&o));
    for f in ["episodes.csv", "summary.csv"] {
        assert!(
            std::fs::read(out.join(f)).unwrap() == std::fs::read(alone.join(f)).unwrap(),
            "{f} differs"
        );
    }
}

#[test]
#[ignore = "slow (16 s): `cargo test --workspace -- --ignored` and CI run it"]
fn a_second_sweep_on_one_directory_is_refused_and_the_first_finishes_intact() {
    let (dir, scenario) = oracle_dir("two-sweeps");
    let s = scenario.to_str().unwrap();
    let out = dir.join("out");
    let o = out.to_str().unwrap();
    let mut first = spawn(&sweep_args(s, o, "40000"));
    wait_until("the first sweep's rows", || lines_on_disk(&out) > 1);
    // The same command again, as a resubmitted cluster job would run it.
    let e = refused(&sweep_args(s, o, "40000"));
    assert!(
        e.contains("is in use")
            && e.contains(&format!("pid {}", first.id()))
            && e.contains("sweep.lock"),
        "{e}"
    );
    let status = first.wait().unwrap();
    assert!(status.success(), "the first sweep: {status:?}");
    assert!(!out.join("sweep.lock").exists());
    // Intact: the same bytes as the sweep run alone.
    assert_same_as_alone(s, &dir, &out, "40000");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
#[ignore = "slow (12 s): `cargo test --workspace -- --ignored` and CI run it"]
fn sigterm_stops_a_sweep_between_episodes_and_the_same_command_resumes() {
    let (dir, scenario) = oracle_dir("sweep-sigterm");
    let s = scenario.to_str().unwrap();
    let out = dir.join("out");
    let o = out.to_str().unwrap();
    let mut child = spawn(&sweep_args(s, o, "40000"));
    wait_until("rows on disk", || lines_on_disk(&out) > 100);
    signal(&child, "TERM");
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    let rows = std::fs::read_to_string(out.join("episodes.csv")).unwrap();
    assert!(rows.ends_with('\n') && rows.lines().count() < 40_001);
    assert_eq!(
        files_in(&out),
        ["episodes.csv", "sweep.json"],
        "no lock, no partial"
    );
    let resumed = errp(&sweep_args(s, o, "40000"));
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    assert_same_as_alone(s, &dir, &out, "40000");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_signal_while_decoders_are_prepared_stops_at_once_and_leaves_nothing() {
    let dir = temp_dir("sweep-prepare-signal");
    // Two directories to make: both go (a hostile user's reproduction 14).
    let out = dir.join("newdir").join("sub");
    // The grid's EEG decoders: several seconds of calibration per level.
    let mut child = spawn(&[
        "sweep",
        "--task",
        "grid",
        "--accuracy",
        "0.6,0.7,0.8,0.9",
        "--episodes",
        "10",
        "--no-cache",
        "--out",
        out.to_str().unwrap(),
    ]);
    wait_until("the sweep to start", || out.join("sweep.lock").exists());
    std::thread::sleep(Duration::from_millis(500));
    signal(&child, "INT");
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    // Stopped before any episode: the directories it made, its lock and its
    // temporaries are gone.
    assert!(!dir.join("newdir").exists(), "{:?}", files_in(&dir));
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(feature = "rerun")]
#[test]
fn a_signal_removes_the_files_being_written_and_a_kill_is_cleaned_up_next_time() {
    let dir = temp_dir("signals");
    let rrd = dir.join("calib.rrd");
    let edf = dir.join("calib.edf");
    for sig in ["TERM", "INT", "HUP"] {
        let mut child = spawn(&[
            "calibrate",
            "--quiet",
            "--save",
            rrd.to_str().unwrap(),
            "--export",
            edf.to_str().unwrap(),
        ]);
        wait_until("the temporaries", || {
            files_in(&dir)
                .iter()
                .filter(|f| f.contains(".partial-"))
                .count()
                == 2
        });
        signal(&child, sig);
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(130), "{sig}");
        assert!(files_in(&dir).is_empty(), "{sig}: {:?}", files_in(&dir));
    }
    // SIGKILL cannot be caught: its temporary stays until the next command
    // that writes into the directory (on this host) removes it.
    let mut child = spawn(&["calibrate", "--quiet", "--save", rrd.to_str().unwrap()]);
    wait_until("the temporary", || has_partial(&dir));
    signal(&child, "KILL");
    let _ = child.wait();
    assert!(has_partial(&dir));
    let grid = errp(&[
        "run",
        "scenarios/grid_fixed_goals.toml",
        "--decoder",
        "oracle",
        "--quiet",
        "--save",
        dir.join("grid.rrd").to_str().unwrap(),
    ]);
    assert!(grid.status.success(), "{}", stderr(&grid));
    assert_eq!(files_in(&dir), ["grid.rrd"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Bad input: exit 2, a message naming the flag or the file and field, the
/// value and what is accepted, and no file left behind.
#[test]
fn bad_input_is_refused_naming_flag_field_value_and_range_leaving_nothing() {
    let dir = temp_dir("refusals");
    let write = |name: &str, text: &str| -> PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let grid = |extra: &str| {
        format!(
            "task = \"grid\"\n{extra}\n[user]\naccuracy = 0.8\n[[episode]]\nstart = [0, 0]\n\
             goal = [4, 4]\n"
        )
    };
    let epuck = |user: &str, extra: &str| {
        format!(
            "task = \"epuck\"\nstart = \"Mexico\"\ngoal = \"Pisa\"\n{extra}\n[user]\n\
             accuracy = 0.9\n{user}\n"
        )
    };
    let out = dir.join("out");
    let rrd = dir.join("x.rrd");
    let (o, r) = (out.to_str().unwrap(), rrd.to_str().unwrap());
    let cases: Vec<(String, Vec<String>, Vec<&str>)> = vec![
        (grid("bank_per_class = 1e9"), vec![], vec!["`bank_per_class` = 1000000000", "1 to 20000"]),
        (grid("bank_per_class = -1"), vec![], vec!["`bank_per_class` = -1", "1 to 20000"]),
        (grid("repeats = 1e9"), vec![], vec!["`repeats`", "1 to 10000"]),
        (grid("seed = -1"), vec![], vec!["`seed` = -1", "whole number"]),
        (
            grid("[free_goals]\ncount = 1e9"),
            vec![],
            vec!["`free_goals.count` = 1000000000", "1 to 10000"],
        ),
        (
            grid("[timing]\ninterval_max_secs = 1e12"),
            vec![],
            vec!["`timing.interval_max_secs`", "60 s"],
        ),
        (
            grid("[timing]\nepoch_secs = 5"),
            vec![],
            vec!["`timing.epoch_secs` = 5", "interval_min_secs"],
        ),
        (
            "task = \"grid\"\n[user]\naccuracy = 0.8\n[[episode]]\nstart = [0, 0, 7]\ngoal = [4, 4]\n"
                .into(),
            vec![],
            vec!["`episode.start` = an array of 3", "two values"],
        ),
        (
            grid("[control]\ntau = \"x\""),
            vec![],
            vec!["line", "`control.tau` = \"x\"", "a number"],
        ),
        (epuck("", "runs = 1e9"), vec![], vec!["`runs`", "1 to 100000"]),
        (
            epuck("reaction_latency_ms = 1e9", ""),
            vec![],
            vec!["`user.reaction_latency_ms`", "0 to 2000 ms"],
        ),
        (
            epuck("", "max_secs = 1e12"),
            vec![],
            vec!["`max_secs`", "3600"],
        ),
        (
            epuck("", "[tracker]\nrate_hz = 1e9"),
            vec![],
            vec!["`tracker.rate_hz`", "1 to 1000 Hz"],
        ),
        (
            epuck("", "[control]\nstop_secs = 1e9"),
            vec![],
            vec!["`control.stop_secs`", "(0, 10]"],
        ),
        (
            epuck(
                "",
                "[[arena.obstacle]]\nshape = \"box\"\ncenter_cm = [195, 60]\nsize_cm = [20, 5]",
            ),
            vec![],
            vec!["`arena.obstacle[0].center_cm`", "inside the walls"],
        ),
        (
            epuck("", "[[arena.obstacle]]\nshape = \"box\"\ncenter_cm = [60, 40, 99]\nsize_cm = [5, 5]"),
            vec![],
            vec!["center_cm` = an array of 3", "two values"],
        ),
        (
            "task = \"epuck\"\nstart = [20, 20, 7]\ngoal = \"Pisa\"\n[user]\naccuracy = 0.9\n".into(),
            vec![],
            vec!["`start` = an array of 3", "[x_cm, y_cm]"],
        ),
        (
            epuck("", "").replace("accuracy = 0.9", "accuracy = 1.7"),
            vec![],
            vec!["`user.accuracy` = 1.7", "strictly between 0.5 (chance) and 1"],
        ),
        (grid(""), vec!["--seed".into(), "-1".into()], vec!["--seed", "-1", "0 to"]),
        // A negative number is a value of its flag, not an unknown argument.
        (epuck("", ""), vec!["--runs".into(), "-1".into()], vec!["'--runs <", "'-1'"]),
        (
            grid(""),
            vec!["--accuracy".into(), "1".into()],
            vec!["--accuracy 1", "--decoder oracle"],
        ),
    ];
    // (A build without Rerun refuses every --save first.)
    let cases = cases.into_iter().chain(cfg!(feature = "rerun").then(|| {
        (
            epuck("", ""),
            vec!["--runs".into(), "500".into(), "--save".into(), r.into()],
            vec!["--save", "at most 100 runs"],
        )
    }));
    for (text, extra, needles) in cases {
        let scenario = write("bad.toml", &text);
        let mut args = vec!["run".to_string(), scenario.to_str().unwrap().to_string()];
        args.extend(extra.iter().cloned());
        if !extra.iter().any(|a| a == "--save") {
            args.extend(["--save".to_string(), r.to_string()]);
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let e = refused(&args);
        for n in &needles {
            assert!(e.contains(n), "{text}\n{extra:?}: `{n}` not in {e}");
        }
        assert!(
            e.contains("bad.toml") || extra.iter().any(|a| a.starts_with("--")),
            "{e}"
        );
        assert!(
            !e.contains("usize") && !e.contains("f64"),
            "a Rust type: {e}"
        );
        assert_eq!(files_in(&dir), ["bad.toml"], "{text}");
    }

    let scenario = write("s.toml", ORACLE);
    let s = scenario.to_str().unwrap();
    let deep = format!("{}=1", vec!["a"; 3000].join("."));
    for (args, needles) in [
        (
            vec!["--accuracy", "0.7,0.7"],
            vec!["--accuracy", "0.7 is given twice"],
        ),
        (
            vec!["--param", "tau=0.3,0.3"],
            vec!["--param tau", "0.3 is given twice"],
        ),
        (
            vec!["--param", "tau=0.3", "--param", "tau=0.5"],
            vec!["both set control.tau"],
        ),
        (
            vec!["--param", "tau=0.3", "--param", "control.tau=0.5"],
            vec!["both set control.tau"],
        ),
        (
            vec!["--param", deep.as_str()],
            vec!["--param", "1 to 4 parts"],
        ),
        (
            vec!["--param", "tau=0.1:0.9:0.01", "--param", "epsilon=0:1:0.05"],
            vec!["levels", "at most 1000"],
        ),
        (
            vec!["--episodes", "2000000"],
            vec!["--episodes", "1..=1000000"],
        ),
        (vec!["--seed", "-1"], vec!["--seed", "0 to"]),
        (
            vec!["--param", "tau=abc"],
            vec!["`control.tau` = \"abc\"", "a number"],
        ),
    ] {
        let mut all = vec!["sweep", "--scenario", s, "--no-cache", "--out", o];
        all.extend(args.iter());
        let e = refused(&all);
        for n in needles {
            assert!(e.contains(n), "{args:?}: `{n}` not in {e}");
        }
        assert!(!e.contains("line "), "a generated TOML's line: {e}");
        assert_eq!(files_in(&dir), ["bad.toml", "s.toml"], "{args:?}");
    }
    // An --out that holds other files; one that cannot be made.
    let mut sweep = sweep_args(s, dir.to_str().unwrap(), "5");
    let e = refused(&sweep);
    assert!(e.contains("not a sweep's (bad.toml, s.toml)"), "{e}");
    sweep.pop();
    sweep.push("/proc/errp-cannot-be-made");
    let e = refused(&sweep);
    assert!(e.contains("--out /proc/errp-cannot-be-made"), "{e}");
    assert_eq!(
        e.matches("No such file or directory").count(),
        1,
        "the OS error once: {e}"
    );
    assert_eq!(files_in(&dir), ["bad.toml", "s.toml"]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A targeting cache that cannot be used is not an error, but the user is
/// told, once, why every run searches again.
#[test]
fn an_unusable_cache_is_a_warning_not_a_silent_fallback() {
    let (dir, scenario) = oracle_dir("cache-warning");
    let s = scenario.to_str().unwrap();
    let mut args = sweep_args(s, "", "3");
    args.retain(|a| *a != "--no-cache");
    let run = |out: &str, cache: Option<&str>, home: bool| {
        let mut all: Vec<&str> = args
            .iter()
            .map(|a| if a.is_empty() { out } else { a })
            .collect();
        if let Some(c) = cache {
            all.extend(["--cache", c]);
        }
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_errp"));
        cmd.args(&all);
        cmd.env_remove("ERRP_CACHE_DIR")
            .env_remove("XDG_CACHE_HOME");
        if !home {
            cmd.env_remove("HOME");
        }
        cmd.output().unwrap()
    };
    let o = run(
        dir.join("a").to_str().unwrap(),
        Some("/proc/errp-cache"),
        true,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert_eq!(
        e.matches("warning: the targeting cache cannot be written")
            .count(),
        1,
        "{e}"
    );
    assert!(
        e.contains("/proc/errp-cache") && e.contains("--no-cache"),
        "{e}"
    );
    let o = run(dir.join("b").to_str().unwrap(), None, false);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("warning: no targeting cache"),
        "{}",
        stderr(&o)
    );
    let _ = std::fs::remove_dir_all(&dir);
}
