//! Edges a hostile user finds: file names that are not UTF-8, a file-size
//! limit, outputs that collide, a fit inside another fit.

use std::ffi::OsStr;
#[cfg(feature = "rerun")]
use std::os::unix::ffi::OsStrExt;
use std::path::Path;
use std::process::{Command, Output};

use crate::{files_in, stderr, temp_dir};

fn errp_os(dir: &Path, args: &[&OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_errp"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("errp runs")
}

#[cfg(feature = "rerun")]
fn scenario(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios")
        .join(name)
        .display()
        .to_string()
}

/// A file name with a byte that is not UTF-8 is a file name like any
/// other: the command runs and writes it (its provenance keeps the name
/// with U+FFFD), never exit 101.
#[cfg(feature = "rerun")]
#[test]
fn names_that_are_not_utf8_are_written_not_a_panic() {
    let dir = temp_dir("non-utf8");
    let grid = scenario("grid_fixed_goals.toml");
    let name = OsStr::from_bytes(b"\xff.rrd");
    let o = errp_os(
        &dir,
        &[
            "run".as_ref(),
            grid.as_ref(),
            "--decoder".as_ref(),
            "oracle".as_ref(),
            "-q".as_ref(),
            "--save".as_ref(),
            name,
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(dir.join(name).is_file());
    let out = OsStr::from_bytes(b"d\xff");
    let o = errp_os(
        &dir,
        &[
            "sweep".as_ref(),
            "--task".as_ref(),
            "grid".as_ref(),
            "--accuracy".as_ref(),
            "0.8".as_ref(),
            "--param".as_ref(),
            "decoder=oracle".as_ref(),
            "--episodes".as_ref(),
            "2".as_ref(),
            "--quiet".as_ref(),
            "--out".as_ref(),
            out,
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let files = files_in(&dir.join(out));
    assert!(files.contains(&"summary.csv".to_string()), "{files:?}");
    assert!(!files.iter().any(|f| f.contains("lock")), "{files:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Under a file-size limit a recording that passes it is an error (exit
/// 2, EFBIG), and nothing is left: not a death by SIGXFSZ that leaves its
/// temporary.
#[cfg(feature = "rerun")]
#[test]
fn a_file_size_limit_is_an_error_that_leaves_nothing() {
    let dir = temp_dir("ulimit");
    let o = Command::new("sh")
        .current_dir(&dir)
        .arg("-c")
        .arg(format!(
            "ulimit -f 200 && exec '{}' run '{}' --decoder oracle -q --save x.rrd",
            env!("CARGO_BIN_EXE_errp"),
            scenario("grid_fixed_goals.toml")
        ))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("x.rrd"), "{}", stderr(&o));
    assert!(files_in(&dir).is_empty(), "{:?}", files_in(&dir));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--figure` and `--csv` (or `--parquet`) naming the same path are
/// refused before anything is written.
#[cfg(feature = "rerun")]
#[test]
fn a_figure_and_a_table_directory_of_one_path_are_refused_first() {
    let dir = temp_dir("same-out");
    let grid = scenario("grid_fixed_goals.toml");
    let o = errp_os(
        &dir,
        &[
            "run".as_ref(),
            grid.as_ref(),
            "--decoder".as_ref(),
            "oracle".as_ref(),
            "-q".as_ref(),
            "--save".as_ref(),
            "x.rrd".as_ref(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    for flag in ["--csv", "--parquet"] {
        let o = errp_os(
            &dir,
            &[
                "inspect".as_ref(),
                "x.rrd".as_ref(),
                flag.as_ref(),
                "f.png".as_ref(),
                "--figure".as_ref(),
                "./f.png".as_ref(),
            ],
        );
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains(flag), "{}", stderr(&o));
        assert_eq!(files_in(&dir), ["x.rrd"]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A fit's directory inside another fit's is refused (a rerun of the outer
/// one would refuse its own directory), before any work.
#[test]
fn a_fit_inside_another_fit_is_refused() {
    let dir = temp_dir("fit-in-fit");
    std::fs::write(
        dir.join("fit.json"),
        r#"{"format": 1, "parameter": "accuracy", "provenance": {"errp_version": "0.1.0"}}"#,
    )
    .unwrap();
    for kind in ["epuck", "grid"] {
        let o = errp_os(
            &dir,
            &[
                "fit".as_ref(),
                kind.as_ref(),
                "--out".as_ref(),
                "inner".as_ref(),
                "--no-cache".as_ref(),
            ],
        );
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("inner") && e.contains("another fit"), "{e}");
        assert_eq!(files_in(&dir), ["fit.json"]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Messages show numbers as the user wrote them and blame the field that
/// is wrong; a size that would be ignored is refused.
#[test]
fn messages_show_numbers_as_written_and_blame_the_wrong_field() {
    let dir = temp_dir("messages");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let read = |name: &str| std::fs::read_to_string(root.join(name)).unwrap();
    let cases = [
        (
            format!(
                "{}\n[control]\nk_turn = 1e300\n",
                read("mexico_to_pisa.toml")
            ),
            "control.k_turn` = 1e300",
        ),
        (
            read("grid_fixed_goals.toml").replacen(
                "[control]\n",
                "[control]\nwrong_goal_reward = 1e300\n",
                1,
            ),
            "control.wrong_goal_reward` = 1e300",
        ),
        (
            read("obstacles_havana_to_seoul.toml").replacen(
                "shape = \"circle\"",
                "size_cm = [10, 10]\nshape = \"circle\"",
                1,
            ),
            "size_cm` = [10, 10] is invalid: expected no size_cm for a circle",
        ),
    ];
    for (k, (text, want)) in cases.iter().enumerate() {
        let file = dir.join(format!("s{k}.toml"));
        std::fs::write(&file, text).unwrap();
        let e = crate::refused(&["run", file.to_str().unwrap(), "-q", "--runs", "1"]);
        assert!(e.contains(want), "{want}: {e}");
        assert!(e.len() < 400, "{e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// What is undefined is printed as `-`, never as NaN or an invented 0: runs
/// too short for any ErrP window or any goal; a time-out shorter than the
/// decoder's window is refused.
#[test]
fn undefined_figures_are_dashes_not_numbers() {
    let dir = temp_dir("undefined");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/mexico_to_pisa.toml"),
    )
    .unwrap();
    let short = dir.join("short.toml");
    std::fs::write(&short, text.replacen("max_secs = 600", "max_secs = 1", 1)).unwrap();
    let o = crate::errp(&["run", short.to_str().unwrap(), "--runs", "2", "--quiet"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(!out.contains("NaN"), "{out}");
    assert!(out.contains("median time (s)      -"), "{out}");
    assert!(out.contains("- % turning"), "{out}");
    let tiny = dir.join("tiny.toml");
    std::fs::write(&tiny, text.replacen("max_secs = 600", "max_secs = 1e-9", 1)).unwrap();
    let e = crate::refused(&["run", tiny.to_str().unwrap(), "--quiet"]);
    assert!(e.contains("max_secs` = 1e-9") && e.contains("1 to"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A second process recording to the path another is recording to is
/// refused (exit 2, naming the path); the first finishes its file.
#[cfg(feature = "rerun")]
#[test]
fn a_second_process_recording_one_path_is_refused() {
    let dir = temp_dir("two-writers");
    let epuck = scenario("mexico_to_pisa.toml");
    let mut first = Command::new(env!("CARGO_BIN_EXE_errp"))
        .current_dir(&dir)
        .args([
            "run",
            epuck.as_str(),
            "--runs",
            "20",
            "-q",
            "--save",
            "x.rrd",
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("errp runs");
    // Wait (up to a minute) for the first one's temporary.
    let mut waited = 0;
    while !files_in(&dir)
        .iter()
        .any(|f| f.starts_with(".x.rrd.partial-"))
    {
        assert!(waited < 600, "the first run never started its recording");
        std::thread::sleep(std::time::Duration::from_millis(100));
        waited += 1;
    }
    let o = errp_os(
        &dir,
        &[
            "run".as_ref(),
            epuck.as_ref(),
            "--runs".as_ref(),
            "1".as_ref(),
            "-q".as_ref(),
            "--save".as_ref(),
            "x.rrd".as_ref(),
        ],
    );
    let still_running = first.try_wait().unwrap().is_none();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("x.rrd") && stderr(&o).contains("writing the same file"),
        "{}",
        stderr(&o)
    );
    assert!(still_running, "the first run ended before the check");
    assert!(first.wait().unwrap().success());
    assert_eq!(files_in(&dir), ["x.rrd"]);
    let _ = std::fs::remove_dir_all(&dir);
}
