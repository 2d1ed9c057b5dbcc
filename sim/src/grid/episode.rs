//! The discrete grid task end to end (sec. 4 of the paper): the synthetic user
//! judges each action, the EEG generator turns the judgement into an epoch,
//! the decoder gives p(error), the controller updates its belief and acts.

use errp_bci::rng::labelled;
use errp_robot::{Cell, Grid, GridController, QTable};

use crate::error::{Result, SimError};
use crate::grid::decoder::AssessmentDecoder;
use crate::grid::own_eeg::own_eeg_control;
use crate::grid::params::GridTaskParams;
use crate::grid::plant::{GridDecoding, GridEpisodeResult, GridPlant};

/// Runs one episode from `start` towards the user's `goal`. Everything random
/// derives from `seed`: the same seed gives the same episode, bit for bit.
pub fn run_grid_episode(
    start: Cell,
    goal: Cell,
    table: &QTable,
    params: &GridTaskParams,
    decoder: &AssessmentDecoder,
    seed: u64,
    record_steps: bool,
) -> Result<GridEpisodeResult> {
    run_grid_episode_with(
        start,
        goal,
        table,
        params,
        GridDecoding::Builtin(decoder),
        seed,
        record_steps,
    )
}

/// [`run_grid_episode`] with any [`GridDecoding`]: the shared control
/// drives a `GridPlant` until its belief converges or the actions run out.
pub fn run_grid_episode_with(
    start: Cell,
    goal: Cell,
    table: &QTable,
    params: &GridTaskParams,
    mut decoding: GridDecoding<'_>,
    seed: u64,
    record_steps: bool,
) -> Result<GridEpisodeResult> {
    let grid: Grid = *table.grid();
    for (name, cell) in [("start", start), ("goal", goal)] {
        if !grid.contains(cell) {
            return Err(SimError::Scenario(format!(
                "{name} {cell} is outside the {}x{} grid",
                grid.width, grid.height
            )));
        }
    }
    // A decoder calibrated on a recording knows its own accuracy.
    let control = match &decoding {
        GridDecoding::Builtin(AssessmentDecoder::OwnEeg(bank)) => own_eeg_control(params, bank)?,
        _ => params.control,
    };
    let mut controller = GridController::with_table(table.clone(), control);
    let mut rng_policy = labelled(seed, "grid/policy");
    let mut plant = GridPlant::new(grid, start, goal, &decoding, seed)?;
    if record_steps {
        plant.keep_steps();
    }
    let mut committed = None;
    let live = matches!(decoding, GridDecoding::Live(_));
    for _ in 0..params.max_actions {
        let action = controller.choose(plant.cell(), &mut rng_policy);
        // A live decoder shows the belief; the others need none.
        let belief = if live {
            controller.belief().probabilities()
        } else {
            Vec::new()
        };
        let mut judged = plant.act(
            &mut decoding,
            action,
            params,
            (record_steps, false),
            &belief,
        )?;
        // A decision missed leaves the belief as it was.
        if !judged.decoded.missed() {
            controller.observe(judged.from, action, judged.decoded.p_error)?;
        }
        plant.keep(&mut judged, || controller.belief().probabilities());
        if let Some(found) = controller.converged() {
            committed = Some(found);
            break;
        }
    }
    Ok(plant.into_result(committed, params.epoch_secs))
}
