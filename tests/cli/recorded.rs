//! A person's recording in the grid's closed loop, as a lab would use it:
//! a session exported by `errp calibrate --export` and run on, and what a
//! recording that cannot be used is refused for (exit 2, the thing named,
//! nothing written).

use std::path::Path;

use crate::{errp, files_in, refused, stderr, temp_dir};

const SCENARIO: &str = "task = \"grid\"\nname = \"own EEG\"\n[free_goals]\ncount = 20\n[eeg]\n";

/// Writes `dir/name.toml` on the recording `edf` with the `[eeg]` table's
/// other lines `extra`.
fn scenario(dir: &Path, name: &str, edf: &str, extra: &str) -> String {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, format!("{SCENARIO}recording = \"{edf}\"\n{extra}")).unwrap();
    path.to_string_lossy().into_owned()
}

/// The number after `before` in `text`.
fn number_after(text: &str, before: &str) -> f64 {
    let at = text
        .find(before)
        .unwrap_or_else(|| panic!("{before:?} in {text}"));
    text[at + before.len()..]
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

#[test]
#[ignore = "slow (calibrates on an export, 27 s): `cargo test --workspace -- --ignored` and CI run it"]
fn an_exported_session_runs_the_grid_at_the_accuracy_it_was_made_at() {
    let d = temp_dir("recorded-round-trip");
    let edf = d.join("s.edf");
    let o = errp(&[
        "calibrate",
        "--quiet",
        "--accuracy",
        "0.78",
        "--seed",
        "1",
        "--export",
        edf.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = scenario(&d, "s", "s.edf", "");
    let rrd = d.join("s.rrd");
    let o = errp(&["run", &s, "--save", rrd.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    // The decoder's accuracy cross-validated on the recording's first half.
    let cv = number_after(&out, "mean accuracy");
    assert!((cv - 78.0).abs() <= 3.0, "{out}");
    let said = stderr(&o);
    assert!(
        said.contains("EEG decoder on the recording s.edf"),
        "{said}"
    );
    assert!(
        out.contains("recording s.edf") && out.contains("SHA-256"),
        "{out}"
    );
    let reached = number_after(&out, "goals reached");
    assert!(reached >= 18.0, "{out}");
    // The recording names the file, its size and its SHA-256.
    let o = errp(&["inspect", rrd.to_str().unwrap()]);
    let shown = String::from_utf8_lossy(&o.stdout);
    let bytes = std::fs::metadata(&edf).unwrap().len();
    assert!(
        shown.contains(&format!("recording s.edf ({bytes} bytes, SHA-256 ")),
        "{shown}"
    );
    // --accuracy with a recording is refused, and says why.
    let e = refused(&["run", &s, "--accuracy", "0.7"]);
    assert!(
        e.contains("--accuracy")
            && e.contains("recording")
            && e.contains("no accuracy is targeted"),
        "{e}"
    );
    // A sweep over the recording: one level, at the accuracy it gives.
    let out = d.join("sweep");
    let o = errp(&[
        "sweep",
        "--scenario",
        &s,
        "--param",
        "eeg.recording=s.edf",
        "--episodes",
        "4",
        "--out",
        out.to_str().unwrap(),
        "--no-cache",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let level: f64 = summary
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    // (The sweep's seed draws the cross-validation's folds: not the run's.)
    assert!((100.0 * level - cv).abs() < 2.0, "{summary} against {cv}");
    the_epuck_reaches_pisa_on_a_hybrid_of(&d);
    std::fs::remove_dir_all(&d).unwrap();
}

/// The e-puck on a hybrid of `dir/s.edf` (the session exported at 78 %):
/// the shipped example, Mexico to Pisa over 50 runs, reaches Pisa in at
/// least half of them, with the hybrid named in the output and the
/// recording's provenance.
fn the_epuck_reaches_pisa_on_a_hybrid_of(dir: &Path) {
    let example = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/recorded/own_eeg_epuck.toml"),
    )
    .unwrap()
    .replace("\"s01.edf\"", "\"s.edf\"");
    let s = dir.join("epuck.toml");
    std::fs::write(&s, &example).unwrap();
    let s = s.to_str().unwrap();
    let o = errp(&["run", s]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains(
            "EEG: hybrid: recorded background, recorded ErrP template, from recording \
                      s.edf"
        ) && out.contains("SHA-256"),
        "{out}"
    );
    // The paper-fitted user's false alarms a minute, met on the held-out
    // hybrid.
    assert!(
        out.contains(": 5.37 false alarms a minute on the held-out hybrid"),
        "{out}"
    );
    let reached = number_after(&out, "reached Pisa");
    assert!(reached >= 25.0, "{out}");
    // A recording's e-puck takes no accuracy, no T_e and no draw.
    let e = refused(&["run", s, "--accuracy", "0.9"]);
    assert!(
        e.contains("--accuracy") && e.contains("no accuracy is targeted"),
        "{e}"
    );
    for (extra, field) in [
        ("[control]\nt_e = 0.7\n", "control.t_e"),
        ("draw = \"with_replacement\"\n", "eeg.draw"),
    ] {
        let bad = dir.join("bad.toml");
        let text = if extra.starts_with('[') {
            format!("{example}{extra}")
        } else {
            example.replace("[eeg]\n", &format!("[eeg]\n{extra}"))
        };
        std::fs::write(&bad, text).unwrap();
        let e = refused(&["run", bad.to_str().unwrap()]);
        assert!(e.contains(field), "{e}");
    }
}

/// `bytes` with the first EDF channel label `from` renamed `to`.
fn relabelled(bytes: &[u8], from: &str, to: &str) -> Vec<u8> {
    let n: usize = std::str::from_utf8(&bytes[252..256])
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let mut out = bytes.to_vec();
    for i in 0..n {
        let at = 256 + 16 * i;
        if std::str::from_utf8(&bytes[at..at + 16]).unwrap().trim() == from {
            let label = format!("{to:<16}");
            out[at..at + 16].copy_from_slice(label.as_bytes());
            return out;
        }
    }
    panic!("no channel {from}");
}

#[test]
#[ignore = "slow (18 s): `cargo test --workspace -- --ignored` and CI run it"]
fn a_recording_that_cannot_calibrate_is_refused_naming_what_is_missing() {
    let d = temp_dir("recorded-refused");
    let edf = d.join("s.edf");
    let o = errp(&[
        "calibrate",
        "--quiet",
        "--accuracy",
        "0.75",
        "--seed",
        "2",
        "--export",
        edf.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&edf).unwrap();
    std::fs::write(d.join("no_fcz.edf"), relabelled(&bytes, "FCz", "FCx")).unwrap();
    std::fs::write(d.join("cut.edf"), &bytes[..bytes.len() / 2]).unwrap();
    std::fs::write(d.join("text.edf"), "subject 1, session 2\n").unwrap();
    for (name, edf, extra, named) in [
        ("no_fcz", "no_fcz.edf", "", vec!["no_fcz.edf", "FCz"]),
        ("cut", "cut.edf", "", vec!["cut.edf", "truncated"]),
        (
            "text",
            "text.edf",
            "",
            vec!["text.edf", "not an EDF or BDF file"],
        ),
        (
            "no_class",
            "s.edf",
            "error = \"S 96\"\n",
            vec!["s.edf", "S 96"],
        ),
        (
            "short",
            "s.edf",
            "calibration_events = 8\n",
            vec!["s.edf", "calibration part"],
        ),
        ("missing", "none.edf", "", vec!["none.edf"]),
    ] {
        let s = scenario(&d, name, edf, extra);
        let rrd = d.join(format!("{name}.rrd"));
        let e = refused(&["run", &s, "--save", rrd.to_str().unwrap()]);
        for n in named {
            assert!(e.contains(n), "{name}: {n:?} in {e}");
        }
        assert!(
            !rrd.exists(),
            "{name}: a refused run left {}",
            rrd.display()
        );
    }
    // A sweep over recordings targets no accuracy and sets no EEG mode:
    // --accuracy and --eeg are refused, saying why; a swept recording that
    // cannot calibrate is named; nothing is written.
    let s = scenario(&d, "sweep", "s.edf", "");
    let out = d.join("sweep");
    let o_ = out.to_str().unwrap();
    let e = refused(&[
        "sweep",
        "--scenario",
        &s,
        "--accuracy",
        "0.8",
        "--out",
        o_,
        "--no-cache",
    ]);
    assert!(
        e.contains("--accuracy") && e.contains("no accuracy is targeted"),
        "{e}"
    );
    let e = refused(&[
        "sweep",
        "--scenario",
        &s,
        "--eeg",
        "stream",
        "--out",
        o_,
        "--no-cache",
    ]);
    assert!(e.contains("--eeg stream") && e.contains("recording"), "{e}");
    let e = refused(&[
        "sweep",
        "--scenario",
        &s,
        "--param",
        "eeg.recording=s.edf,no_fcz.edf",
        "--episodes",
        "2",
        "--out",
        o_,
        "--no-cache",
    ]);
    assert!(e.contains("no_fcz.edf") && e.contains("FCz"), "{e}");
    assert!(!out.exists());
    let mut left = files_in(&d);
    left.retain(|f| !f.ends_with(".toml") && !f.ends_with(".edf"));
    assert!(left.is_empty(), "{left:?}");
    std::fs::remove_dir_all(&d).unwrap();
}
