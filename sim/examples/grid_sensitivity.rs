//! Sensitivity of the grid task to what the paper leaves open.
//!
//! Runs 100 episodes (the five fixed start/goal pairs of
//! `scenarios/grid_fixed_goals.toml`, 20 times each) for each variant, at the
//! paper's mean accuracy (74.38 %) and at 90 %, and prints a markdown table:
//! goals reached and actions (mean +- sd). The first row of each block uses
//! only what the paper states (tau = 0.3, p_c = 0.9, p = 1 / (1 + e^-y)) plus
//! our defaults for what it does not (epsilon, discount, and the goal reward
//! fitted by `errp fit grid`).
//!
//! `cargo run --release -p errp_sim --example grid_sensitivity` (about a
//! minute).

use errp_robot::{Grid, GridControlParams, QTable};
use errp_sim::grid::{
    AssessmentDecoder, EegDecoder, FIXED_PAIRS, GridTaskParams, PErrorChoice, prepare_decoder,
    run_grid_episode,
};
use errp_sim::mean_sd;

struct Variant {
    label: &'static str,
    platt: Option<bool>,
    epsilon: f64,
    discount: f64,
    /// None: the shipped (fitted) goal reward.
    reward: Option<f64>,
}

fn main() {
    let variants = [
        Variant {
            label: "paper: p = sigmoid(y)",
            platt: Some(false),
            epsilon: 0.1,
            discount: 0.9,
            reward: None,
        },
        Variant {
            label: "p = sigmoid(y), discount 0.5",
            platt: Some(false),
            epsilon: 0.1,
            discount: 0.5,
            reward: None,
        },
        Variant {
            label: "**default: Platt-scaled p**",
            platt: Some(true),
            epsilon: 0.1,
            discount: 0.9,
            reward: None,
        },
        Variant {
            label: "Platt, epsilon 0",
            platt: Some(true),
            epsilon: 0.0,
            discount: 0.9,
            reward: None,
        },
        Variant {
            label: "Platt, epsilon 0.3",
            platt: Some(true),
            epsilon: 0.3,
            discount: 0.9,
            reward: None,
        },
        Variant {
            label: "Platt, discount 0.5",
            platt: Some(true),
            epsilon: 0.1,
            discount: 0.5,
            reward: None,
        },
        Variant {
            label: "Platt, goal reward 2 (fitted to the corner pairs)",
            platt: Some(true),
            epsilon: 0.1,
            discount: 0.9,
            reward: Some(2.0),
        },
        Variant {
            label: "Platt, goal reward 6 (the fit's unconstrained estimate)",
            platt: Some(true),
            epsilon: 0.1,
            discount: 0.9,
            reward: Some(6.0),
        },
        Variant {
            label: "oracle decoder, p = accuracy",
            platt: None,
            epsilon: 0.1,
            discount: 0.9,
            reward: None,
        },
    ];
    println!("| accuracy | variant | goals reached | actions |");
    println!("|---|---|---|---|");
    for accuracy in [0.7438, 0.90] {
        // The grid's decoder, targeted as every grid scenario's is (online,
        // on held-out epochs), from calibration seed 3.
        let mut scenario =
            errp_sim::ScenarioInput::load_as_written(errp_sim::ScenarioSource::File(
                std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join("../scenarios/grid_fixed_goals.toml"),
            ))
            .ok()
            .and_then(errp_sim::AnyScenario::into_grid)
            .expect("the shipped grid scenario");
        scenario.accuracy = errp_sim::grid::GridAccuracy::Requested(
            errp_bci::RequestedAccuracy::new(accuracy).expect("a targeted accuracy"),
        );
        scenario.seed = 3;
        let (_, report) = prepare_decoder(&scenario, |_| {}).expect("calibration");
        let report = report.expect("an EEG decoder");
        let eeg =
            |choice| AssessmentDecoder::Eeg(Box::new(EegDecoder::from_report(&report, choice)));
        for v in &variants {
            let decoder = match v.platt {
                Some(true) => eeg(PErrorChoice::Platt),
                Some(false) => eeg(PErrorChoice::Sigmoid),
                None => AssessmentDecoder::Oracle { accuracy },
            };
            let mut params = GridTaskParams::default();
            params.control = params
                .control
                .with(|c| {
                    c.epsilon = v.epsilon;
                    c.discount = v.discount;
                    if let Some(reward) = v.reward {
                        c.goal_reward = reward;
                    }
                })
                .expect("the variants are valid");
            let table = QTable::compute(Grid::paper(), &params.control.part(GridControlParams::q))
                .expect("Q-values");
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
