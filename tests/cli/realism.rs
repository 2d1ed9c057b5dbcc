//! `errp realism` as a user runs it: the table of the simulated user
//! beside published figures, and its refusals.

use crate::{errp, refused, stderr};

#[test]
fn realism_sets_the_shipped_user_beside_published_figures() {
    let o = errp(&["realism", "--quiet"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    let value = |what: &str| -> f64 {
        out.lines()
            .find(|l| l.starts_with(what))
            .and_then(|l| l[58..].split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("a row {what:?} in\n{out}"))
    };
    // The generator's alpha is a 10 Hz resonator 2 Hz wide.
    let alpha = value("background: alpha peak at Oz");
    assert!((alpha - 10.0).abs() <= 1.0, "{alpha}");
    // Its background is 1/f.
    let exponent = value("background: 1/f exponent");
    assert!((0.8..=1.6).contains(&exponent), "{exponent}");
    // The ErrP template's peaks, at 250 and 350 ms, give the grand average's.
    let negative = value("ErrP at FCz: negative peak latency");
    let positive = value("ErrP at FCz: positive peak latency");
    assert!((negative - 250.0).abs() <= 25.0, "{negative}");
    assert!((positive - 350.0).abs() <= 25.0, "{positive}");
    // The discrete decoder's cross-validated rates on the calibration: the
    // targeting hits Table 1's 74.38 % online, on the closed-loop user whose
    // ErrP is later, so the calibration's mean is at or above it; the error
    // class is the weaker one.
    let error = value("discrete decoder: error class");
    let correct = value("discrete decoder: correct class");
    let mean = (error + correct) / 2.0;
    assert!(
        error < correct && mean > 74.4 - 3.0 && mean < 74.4 + 10.0,
        "{mean}"
    );
    // What the class rates alone carry, as a binary channel (1 - H(a) at
    // equal rates), and what the graded p(error) carries: more.
    let binary = value("discrete decoder: information in its class rates");
    let expected = errp_bci::binary_channel_bits(error / 100.0, correct / 100.0);
    assert!(
        (binary - expected).abs() <= 0.006,
        "{binary} against {expected}"
    );
    let bits = value("discrete decoder: information in p(error)");
    assert!(
        bits > binary + 0.02 && bits < 1.0,
        "{bits} against {binary}"
    );
    assert!(out.contains("Chavarriaga & Millan 2010"), "{out}");
    assert!(out.contains("Lopes-Dias et al. 2019"), "{out}");
}

#[test]
fn realism_refuses_a_scenario_of_the_other_task() {
    let err = refused(&["realism", "--grid", "scenarios/mexico_to_pisa.toml"]);
    assert!(
        err.contains("--grid") && err.contains("mexico_to_pisa.toml"),
        "{err}"
    );
    assert!(err.contains("grid_fixed_goals.toml"), "{err}");
    let err = refused(&["realism", "--epuck", "scenarios/no_such_file.toml"]);
    assert!(err.contains("no_such_file.toml"), "{err}");
}
