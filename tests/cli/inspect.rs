//! `errp inspect`: the runs recomputed from a recording are what `errp run`
//! printed, the tables and figures are written, and damaged or foreign
//! files are refused with nothing written.

use std::path::Path;

use crate::{errp, files_in, refused, stderr, temp_dir};

/// The lines of `text` from the one starting with `from` up to (not
/// including) the first empty line or line starting with `until`.
fn block(text: &str, from: &str, until: &str) -> String {
    let mut out = Vec::new();
    let mut on = false;
    for line in text.lines() {
        if line.starts_with(from) {
            on = true;
        }
        if on {
            if line.is_empty() || (!out.is_empty() && line.starts_with(until)) {
                break;
            }
            out.push(line);
        }
    }
    assert!(!out.is_empty(), "no `{from}` in:\n{text}");
    out.join("\n")
}

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
#[ignore = "slow (records 30 e-puck runs, 26 s): `cargo test --workspace -- --ignored` and CI run it"]
fn epuck_runs_recomputed_from_the_recording_are_what_run_printed() {
    let dir = temp_dir("inspect-epuck");
    let rrd = dir.join("m.rrd");
    let rrd_s = rrd.to_str().unwrap();
    let run = errp(&[
        "run",
        "scenarios/mexico_to_pisa.toml",
        "--runs",
        "30",
        "--seed",
        "5",
        "--quiet",
        "--save",
        rrd_s,
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let printed = stdout(&run);
    let o = errp(&["inspect", rrd_s]);
    assert!(o.status.success(), "{}", stderr(&o));
    let inspected = stdout(&o);
    // The per-run table and the summary, byte for byte; and the
    // calibration as printed.
    assert_eq!(
        block(&printed, " run  converged", "Summary"),
        block(&inspected, " run  converged", "Summary")
    );
    assert_eq!(
        block(&printed, "Summary over", "Wrote"),
        block(&inspected, "Summary over", "Wrote")
    );
    assert_eq!(
        block(&printed, "SVM decoder", " run"),
        block(&inspected, "SVM decoder", " run")
    );
    assert!(inspected.contains("30 run(s), seed 5"), "{inspected}");
    assert!(inspected.contains("--seed 5 --runs 30"), "{inspected}");

    // The scenario as run is the file's text, comments and all, with the
    // overrides set: the seed and the runs changed, and the file's `[user]
    // seed` gone with `--seed` (a new simulated user).
    let s = errp(&["inspect", rrd_s, "--scenario"]);
    assert!(s.status.success());
    let text = std::fs::read_to_string("scenarios/mexico_to_pisa.toml").unwrap();
    let as_run = stdout(&s);
    let changed: Vec<&str> = as_run
        .lines()
        .filter(|l| !text.lines().any(|f| f == *l))
        .collect();
    assert_eq!(changed, ["seed = 5", "runs = 30"], "{as_run}");
    assert!(
        as_run.starts_with("# The paper's first e-puck run"),
        "{as_run}"
    );
    assert!(!as_run.contains("shared with lisbon_to_tokyo"), "{as_run}");

    // Tables and the figure.
    let csv = dir.join("tables");
    let fig = dir.join("fig5.png");
    let o = errp(&[
        "inspect",
        rrd_s,
        "--csv",
        csv.to_str().unwrap(),
        "--figure",
        fig.to_str().unwrap(),
        "--run",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        files_in(&csv),
        [
            "belief.csv",
            "detections.csv",
            "errps.csv",
            "events.csv",
            "runs.csv",
            "trajectory.csv"
        ]
    );
    let runs = std::fs::read_to_string(csv.join("runs.csv")).unwrap();
    assert_eq!(runs.lines().count(), 31);
    // Detections in the tables are the printed counts.
    let detected: usize = runs
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(5).unwrap().parse::<usize>().unwrap())
        .sum();
    let det_rows = std::fs::read_to_string(csv.join("detections.csv"))
        .unwrap()
        .lines()
        .count()
        - 1;
    assert_eq!(detected, det_rows);
    // One trajectory row per physics step (64 Hz) of every run.
    let time: f64 = runs
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(4).unwrap().parse::<f64>().unwrap())
        .sum();
    let frames = std::fs::read_to_string(csv.join("trajectory.csv"))
        .unwrap()
        .lines()
        .count()
        - 1;
    assert!(
        (frames as f64 - 64.0 * time).abs() < 30.0 * 1.5,
        "{frames} {time}"
    );
    assert_png_drawn(&fig);

    // A second run over the same tables replaces them (they are ours); a
    // foreign file in their place is refused, and nothing is written.
    let again = errp(&["inspect", rrd_s, "--csv", csv.to_str().unwrap()]);
    assert!(again.status.success(), "{}", stderr(&again));
    std::fs::write(csv.join("events.csv"), "my notes\n").unwrap();
    let before = std::fs::read(csv.join("runs.csv")).unwrap();
    let e = refused(&["inspect", rrd_s, "--csv", csv.to_str().unwrap()]);
    assert!(
        e.contains("events.csv exists and is not a table errp wrote"),
        "{e}"
    );
    assert_eq!(std::fs::read(csv.join("runs.csv")).unwrap(), before);

    // The same tables as Parquet, with the CSV tables in one call: all are
    // written, or none (a foreign Parquet file stops both).
    let pq = dir.join("parquet");
    let csv2 = dir.join("tables2");
    let o = errp(&[
        "inspect",
        rrd_s,
        "--parquet",
        pq.to_str().unwrap(),
        "--csv",
        csv2.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(files_in(&pq).len(), 6);
    for f in files_in(&pq) {
        assert!(f.ends_with(".parquet"), "{f}");
        let bytes = std::fs::read(pq.join(&f)).unwrap();
        assert!(
            bytes.starts_with(b"PAR1") && bytes.ends_with(b"PAR1"),
            "{f}"
        );
    }
    // Snappy makes the trajectory smaller than its CSV text.
    let size = |p: std::path::PathBuf| std::fs::metadata(p).unwrap().len();
    assert!(size(pq.join("trajectory.parquet")) < size(csv2.join("trajectory.csv")) / 2);
    let again = errp(&["inspect", rrd_s, "--parquet", pq.to_str().unwrap()]);
    assert!(again.status.success(), "{}", stderr(&again));
    std::fs::write(pq.join("errps.parquet"), "PAR1 not really PAR1").unwrap();
    let csv3 = dir.join("tables3");
    let e = refused(&[
        "inspect",
        rrd_s,
        "--csv",
        csv3.to_str().unwrap(),
        "--parquet",
        pq.to_str().unwrap(),
    ]);
    assert!(
        e.contains("--parquet") && e.contains("errps.parquet exists and is not a table errp wrote"),
        "{e}"
    );
    assert!(!csv3.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn grid_episodes_recomputed_from_the_recording_are_what_run_printed() {
    let dir = temp_dir("inspect-grid");
    let rrd = dir.join("g.rrd");
    let rrd_s = rrd.to_str().unwrap();
    let run = errp(&[
        "run",
        "scenarios/grid_fixed_goals.toml",
        "--accuracy",
        "0.8",
        "--quiet",
        "--save",
        rrd_s,
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let o = errp(&["inspect", rrd_s]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (printed, inspected) = (stdout(&run), stdout(&o));
    assert_eq!(
        block(&printed, "  #   start", "Wrote"),
        block(&inspected, "  #   start", "Wrote")
    );
    // The override is part of the scenario as run.
    let s = stdout(&errp(&["inspect", rrd_s, "--scenario"]));
    assert!(s.contains("accuracy = 0.8"), "{s}");
    let fig = dir.join("fig4.svg");
    let o = errp(&["inspect", rrd_s, "--figure", fig.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let svg = std::fs::read_to_string(&fig).unwrap();
    assert!(
        svg.contains("<svg") && svg.matches("<rect").count() >= 50,
        "{svg}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A PNG that is not blank: several thousand bytes, and its pixels are not
/// all one colour (a blank deflates to almost nothing).
fn assert_png_drawn(path: &Path) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    assert!(bytes.len() > 20_000, "{} bytes", bytes.len());
}

#[test]
fn damaged_or_foreign_recordings_are_refused_and_nothing_is_written() {
    let dir = temp_dir("inspect-bad");
    let good = dir.join("good.rrd");
    let run = errp(&[
        "run",
        "scenarios/mexico_to_pisa.toml",
        "--runs",
        "2",
        "--quiet",
        "--save",
        good.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let bytes = std::fs::read(&good).unwrap();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("empty.rrd", Vec::new(), "the file is empty"),
        (
            "truncated.rrd",
            bytes[..bytes.len() / 2].to_vec(),
            "truncated",
        ),
        (
            "text.rrd",
            b"hello, this is not a recording\n".to_vec(),
            "not a Rerun recording",
        ),
        (
            "newer.rrd",
            [&bytes[..4], &[0u8, 41, 0, 0][..], &bytes[8..]].concat(),
            "Rerun 0.41.0, newer",
        ),
        (
            "corrupt.rrd",
            [&bytes[..8], &vec![0xA5u8; 4096][..]].concat(),
            "corrupt",
        ),
    ];
    for (name, content, why) in cases {
        let f = dir.join(name);
        std::fs::write(&f, content).unwrap();
        let out = dir.join(format!("out-{name}"));
        let fig = dir.join(format!("{name}.png"));
        let e = refused(&[
            "inspect",
            f.to_str().unwrap(),
            "--csv",
            out.to_str().unwrap(),
            "--figure",
            fig.to_str().unwrap(),
        ]);
        assert!(e.contains(name) && e.contains(why), "{name}: {e}");
        assert!(!out.exists() && !fig.exists(), "{name} left output");
    }
    // A calibration recording has no runs.
    let cal = dir.join("cal.rrd");
    let c = errp(&[
        "calibrate",
        "--accuracy",
        "0.8",
        "--save",
        cal.to_str().unwrap(),
    ]);
    assert!(c.status.success(), "{}", stderr(&c));
    let e = refused(&["inspect", cal.to_str().unwrap()]);
    assert!(e.contains("calibration recording"), "{e}");
    // A figure in place of a file errp did not write is refused and kept.
    let mine = dir.join("mine.png");
    std::fs::write(&mine, "my drawing").unwrap();
    let e = refused(&[
        "inspect",
        good.to_str().unwrap(),
        "--figure",
        mine.to_str().unwrap(),
    ]);
    assert!(
        e.contains("--figure") && e.contains("not a PNG image"),
        "{e}"
    );
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "my drawing");
    // A run number the file does not hold.
    let e = refused(&["inspect", good.to_str().unwrap(), "--run", "3"]);
    assert!(e.contains("runs 1 to 2"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
