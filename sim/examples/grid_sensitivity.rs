//! Sensitivity of the grid task to what the paper leaves open.
//!
//! Runs 100 episodes (the five fixed start/goal pairs of
//! `scenarios/grid_fixed_goals.toml`, 20 times each) for each variant, at the
//! paper's mean accuracy (74.38 %) and at 90 %, and prints a markdown table:
//! goals reached and actions (mean +- sd). The first row of each block uses
//! only what the paper states (tau = 0.3, p_c = 0.9, p = 1 / (1 + e^-y)) plus
//! our defaults for what it does not (epsilon, reward model).
//!
//! `cargo run -p errp_sim --example grid_sensitivity` (a few minutes).

use errp_bci::SessionOptions;
use errp_robot::{Grid, QTable};
use errp_sim::calibration::{CalibrationRequest, run_calibration};
use errp_sim::grid::{
    AssessmentDecoder, EegDecoder, FIXED_PAIRS, GridTaskParams, PErrorChoice, run_grid_episode,
};
use errp_sim::mean_sd;

struct Variant {
    label: &'static str,
    platt: Option<bool>,
    epsilon: f64,
    discount: f64,
    reward: f64,
}

fn main() {
    let variants = [
        Variant {
            label: "paper: p = sigmoid(y)",
            platt: Some(false),
            epsilon: 0.1,
            discount: 0.9,
            reward: 1.0,
        },
        Variant {
            label: "p = sigmoid(y), discount 0.5",
            platt: Some(false),
            epsilon: 0.1,
            discount: 0.5,
            reward: 1.0,
        },
        Variant {
            label: "**default: Platt-scaled p**",
            platt: Some(true),
            epsilon: 0.1,
            discount: 0.9,
            reward: 1.0,
        },
        Variant {
            label: "Platt, epsilon 0",
            platt: Some(true),
            epsilon: 0.0,
            discount: 0.9,
            reward: 1.0,
        },
        Variant {
            label: "Platt, epsilon 0.3",
            platt: Some(true),
            epsilon: 0.3,
            discount: 0.9,
            reward: 1.0,
        },
        Variant {
            label: "Platt, discount 0.5",
            platt: Some(true),
            epsilon: 0.1,
            discount: 0.5,
            reward: 1.0,
        },
        Variant {
            label: "Platt, goal reward 3 (Q scale x3)",
            platt: Some(true),
            epsilon: 0.1,
            discount: 0.9,
            reward: 3.0,
        },
        Variant {
            label: "oracle decoder, p = accuracy",
            platt: None,
            epsilon: 0.1,
            discount: 0.9,
            reward: 1.0,
        },
    ];
    println!("| accuracy | variant | goals reached | actions |");
    println!("|---|---|---|---|");
    for accuracy in [0.7438, 0.90] {
        let report = run_calibration(
            &CalibrationRequest::new(
                errp_bci::MeanAccuracy::new(accuracy).expect("an accuracy in (0.5, 1)"),
                3,
            ),
            |_| {},
            SessionOptions::default(),
        )
        .expect("calibration");
        let eeg =
            |choice| AssessmentDecoder::Eeg(Box::new(EegDecoder::from_report(&report, choice)));
        for v in &variants {
            let decoder = match v.platt {
                Some(true) => eeg(PErrorChoice::Platt),
                Some(false) => eeg(PErrorChoice::Sigmoid),
                None => AssessmentDecoder::Oracle { accuracy },
            };
            let mut params = GridTaskParams::default();
            params.control.epsilon = v.epsilon;
            params.control.discount = v.discount;
            params.control.goal_reward = v.reward;
            let table = QTable::compute(Grid::paper(), &params.control.q()).expect("Q-values");
            let mut reached = 0;
            let mut actions = Vec::new();
            for k in 0..100 {
                let (s, g) = FIXED_PAIRS[k % FIXED_PAIRS.len()];
                let r = run_grid_episode(s, g, &table, &params, &decoder, 9000 + k as u64, false)
                    .expect("episode");
                reached += usize::from(r.reached());
                actions.push(r.actions as f64);
            }
            let (m, sd) = mean_sd(&actions);
            println!(
                "| {:.2} % | {} | {reached} / 100 | {m:.1} +- {sd:.1} |",
                100.0 * accuracy,
                v.label
            );
        }
    }
}
