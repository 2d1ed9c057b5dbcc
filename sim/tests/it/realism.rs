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
        scenario_text("grid_fixed_goals.toml")
    );
    let err = GridScenario::parse(&text, Path::new("bad.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("bad.toml") && err.contains("realism.lapse_rate") && err.contains("1.5"),
        "{err}"
    );
    assert!(err.contains("[0, 1]"), "{err}");
    let text = format!(
        "{}\n[realism]\nbad_channel = \"Q9\"\n",
        scenario_text("mexico_to_pisa.toml")
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
        scenario_text("mexico_to_pisa.toml")
    );
    let err = EpuckScenario::parse(&text, Path::new("bad.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("lapse"), "an unknown key is named: {err}");
}

#[test]
fn an_ideal_realism_table_is_the_ideal_user() {
    let plain =
        GridScenario::parse(&scenario_text("grid_fixed_goals.toml"), Path::new("a")).unwrap();
    let text = format!(
        "{}\n[realism]\nlapse_rate = 0.0\n",
        scenario_text("grid_fixed_goals.toml")
    );
    let explicit = GridScenario::parse(&text, Path::new("a")).unwrap();
    assert_eq!(plain, explicit);
    assert!(plain.realism.is_ideal());
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
        scenario_text("grid_fixed_goals.toml")
    );
    let shifted = GridScenario::parse(&text, Path::new("shifted.toml")).unwrap();
    let (_, report) = prepare_decoder(&shifted, |_| {}).unwrap();
    let report = report.unwrap();
    let online = report.targeting.accuracy.mean();
    let cv = report.calibrated.accuracy.mean();
    assert!((online - 0.7438).abs() <= 0.005, "online {online}");
    assert!(cv > online + 0.05, "calibration {cv} vs online {online}");
}
