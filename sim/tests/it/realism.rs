//! The `[realism]` table of a scenario: checked by name, carried to the
//! calibration and, with the task's shift, to the closed loop.

use std::path::Path;

use errp_sim::epuck::EpuckScenario;
use errp_sim::grid::{GridScenario, prepare_decoder};

fn scenario_text(name: &str) -> String {
    std::fs::read_to_string(format!(
        "{}/../scenarios/{name}",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

#[test]
fn a_bad_realism_field_is_named_with_its_value_and_range() {
    let text = format!(
        "{}\n[realism]\nlapse_rate = 1.5\n",
        scenario_text("variants/grid_fixed_goals_ideal.toml")
    );
    let err = GridScenario::parse(&text, Path::new("bad.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("bad.toml") && err.contains("realism.lapse_rate") && err.contains("1.5"),
        "{err}"
    );
    assert!(err.contains("[0, 1]"), "{err}");
    // A day past the range, however far, is refused with the range (not
    // with the limit of the integer type that holds it).
    for day in ["5000", "99999999999"] {
        let text = format!(
            "{}\n[realism]\nday = {day}\n",
            scenario_text("variants/grid_fixed_goals_ideal.toml")
        );
        let err = GridScenario::parse(&text, Path::new("bad.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("realism.day") && err.contains(day) && err.contains("[0, 3650]"),
            "{err}"
        );
    }
    let text = format!(
        "{}\n[realism]\nbad_channel = \"Q9\"\n",
        scenario_text("variants/mexico_to_pisa_ideal.toml")
    );
    let err = EpuckScenario::parse(&text, Path::new("bad.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("realism.bad_channel") && err.contains("FCz"),
        "{err}"
    );
    let text = format!(
        "{}\n[realism]\nlapse = 0.1\n",
        scenario_text("variants/mexico_to_pisa_ideal.toml")
    );
    let err = EpuckScenario::parse(&text, Path::new("bad.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("lapse"), "an unknown key is named: {err}");
}

#[test]
fn an_ideal_realism_table_is_the_ideal_user() {
    let plain = GridScenario::parse(
        &scenario_text("variants/grid_fixed_goals_ideal.toml"),
        Path::new("a"),
    )
    .unwrap();
    let text = format!(
        "{}\n[realism]\nlapse_rate = 0.0\n",
        scenario_text("variants/grid_fixed_goals_ideal.toml")
    );
    let explicit = GridScenario::parse(&text, Path::new("a")).unwrap();
    assert_eq!(plain, explicit);
    assert!(plain.realism.is_ideal());
}

/// The calibration session's cross-validated accuracy and the held-out
/// online accuracy of `scenario`'s decoder, checking that the targeting hit
/// Table 1's 74.38 % online.
fn calibration_and_online(scenario: &GridScenario) -> (f64, f64) {
    let (_, report) = prepare_decoder(scenario, |_| {}).unwrap();
    let report = report.unwrap();
    let online = report.targeting.accuracy.mean();
    assert!((online - 0.7438).abs() <= 0.005, "online {online}");
    (report.calibrated.accuracy.mean(), online)
}

#[test]
fn a_task_shift_puts_online_accuracy_below_calibration() {
    // The grid's decoder is targeted online, on epochs streamed as the
    // closed loop streams them: with the ErrP 40 % smaller in the closed
    // loop than in calibration, the targeting must find a larger ratio, at
    // which the calibration session's cross-validated accuracy is well
    // above the online accuracy (for the ideal user it is below it).
    let text = format!(
        "{}\n[realism]\ntask_gain = 0.6\n",
        scenario_text("variants/grid_fixed_goals_ideal.toml")
    );
    let shifted = GridScenario::parse(&text, Path::new("shifted.toml")).unwrap();
    let (cv, online) = calibration_and_online(&shifted);
    assert!(cv > online + 0.05, "calibration {cv} vs online {online}");
}

/// The shipped scenarios and their variants.
fn shipped() -> Vec<std::path::PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios");
    let mut files = Vec::new();
    for dir in [root.clone(), root.join("variants")] {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

fn load(path: std::path::PathBuf) -> errp_sim::AnyScenario {
    errp_sim::ScenarioInput::load_as_written(errp_sim::ScenarioSource::File(path)).unwrap()
}

#[test]
fn the_shipped_user_is_the_published_one_and_the_ideal_grid_variants_differ_only_by_it() {
    let files = shipped();
    assert!(files.len() >= 16, "{files:?}");
    for path in &files {
        let scenario = load(path.clone());
        let name = path.file_name().unwrap().to_string_lossy();
        if let Some(base) = name.strip_suffix("_ideal.toml") {
            assert!(scenario.realism().is_ideal(), "{name}");
            if matches!(scenario, errp_sim::AnyScenario::Epuck(_)) {
                // The e-puck's keep the idealised user's own fit (90 %)
                // and runs seed; the grid's differ only by the user.
                continue;
            }
            // The same scenario as the shipped one but for the user.
            let shipped = load(path.parent().unwrap().join(format!("../{base}.toml")));
            let strip = |s: &errp_sim::AnyScenario| {
                format!("{s:?}")
                    .replace(&format!("{:?}", s.realism()), "")
                    .replace(&format!("{base}_ideal"), base)
            };
            let (a, b) = (strip(&scenario), strip(&shipped));
            // The file's path is the one difference left.
            let path_free = |s: String| match s.find("path: \"") {
                Some(i) => {
                    let rest = &s[i + 7..];
                    let end = rest.find('"').unwrap();
                    format!("{}{}", &s[..i], &rest[end + 1..])
                }
                None => s,
            };
            assert_eq!(path_free(a), path_free(b), "{name}");
        } else {
            let published = match scenario {
                errp_sim::AnyScenario::Grid(_) => errp_bci::Realism::published(),
                errp_sim::AnyScenario::Epuck(_) => errp_bci::Realism::published_continuous(),
            };
            assert_eq!(
                *scenario.realism(),
                published,
                "{name}: the shipped user is Realism::published() (grid) or \
                 published_continuous() (e-puck)"
            );
        }
    }
}

#[test]
fn at_the_continuous_task_shift_calibration_is_above_online_accuracy() {
    // The grid with the e-puck's shipped user: the ErrP 33.3 ms later in
    // the closed loop and a background that drifts. The decoder is targeted
    // at Table 1's accuracy online, so the calibration session's
    // cross-validated accuracy comes out well above it (the idealised
    // user's, at this seed, is 1.65 points below: a shift of 0 fails).
    let text = format!(
        "{}\n[realism]\nbackground_drift = 0.13\nalpha_drift = 0.18\ndrift_secs = 1800\n\
         task_latency_ms = 33.3\n",
        scenario_text("variants/grid_fixed_goals_ideal.toml")
    );
    let shifted = GridScenario::parse(&text, Path::new("shifted.toml")).unwrap();
    assert_eq!(shifted.realism, errp_bci::Realism::published_continuous());
    let (cv, online) = calibration_and_online(&shifted);
    assert!(cv > online + 0.03, "calibration {cv} vs online {online}");
}
