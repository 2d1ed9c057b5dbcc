//! A grid recording's episodes recomputed from its table of actions, with
//! the episode's own tally.

use std::collections::BTreeMap;

use errp_robot::{Cell, Grid, GridAction};

use crate::grid::plant::GridTally;
use crate::grid::{GridEpisodeResult, GridStep};
use crate::inspect::rows::{check_run_order, index, run_rows};
use crate::record::data::Table;
use crate::record::schema::{Actions, ActionsView, Ends, EndsView, GridRuns, GridRunsView};

/// The grid episodes recomputed from their actions.
pub(super) fn grid_results(
    tables: &BTreeMap<String, Table>,
) -> Result<Vec<GridEpisodeResult>, String> {
    let grid = Grid::paper();
    let runs = GridRunsView::of(tables)?;
    let ends = EndsView::of(tables)?;
    // Absent when no episode took an action.
    let actions = ActionsView::of_or_empty(tables)?;
    let (run_col, a_run, end_run) = (runs.run, actions.run, ends.run);
    for (name, r) in [
        (GridRuns::ENTITY, run_col),
        (Actions::ENTITY, a_run),
        (Ends::ENTITY, end_run),
    ] {
        check_run_order(name, r)?;
    }
    let cell = |x: i64, y: i64| -> Result<Cell, String> {
        Ok(Cell::new(
            index(x, grid.width, "cell column")?,
            index(y, grid.height, "cell row")?,
        ))
    };
    let (belief, width) = actions.belief;
    if actions.rows > 0 && width != grid.n_cells() {
        return Err(format!(
            "its beliefs have {width} values, not one per cell ({})",
            grid.n_cells()
        ));
    }
    let a = &actions;
    let mut out = Vec::new();
    for (k, &r) in run_col.iter().enumerate() {
        if r != k as i64 {
            return Err(format!("its table {} skips run {k}", GridRuns::ENTITY));
        }
        let Some(e) = end_run.iter().position(|&x| x == r) else {
            break;
        };
        let start = cell(runs.start_x[k], runs.start_y[k])?;
        let goal = cell(runs.goal_x[k], runs.goal_y[k])?;
        // The episode's own tally, fed from the table of actions.
        let mut tally = GridTally::new(&grid, start);
        let mut steps = Vec::new();
        for i in run_rows(a_run, k) {
            let to = cell(a.to_x[i], a.to_y[i])?;
            // A live decision missed: no p(error), not scored.
            let decoded = (!a.p_error[i].is_nan()).then_some(a.decoded_error[i]);
            tally.action(&grid, to, a.error[i], decoded);
            let name = &a.action[i];
            let action = GridAction::ALL
                .into_iter()
                .find(|x| x.name() == name)
                .ok_or_else(|| format!("`{name}` is not an action of the grid"))?;
            steps.push(GridStep {
                onset_secs: a.t_s[i],
                from: cell(a.from_x[i], a.from_y[i])?,
                action,
                to,
                error: a.error[i],
                p_error: a.p_error[i],
                decoded_error: a.decoded_error[i],
                belief: belief[i * width..(i + 1) * width].to_vec(),
                fcz: Vec::new(),
            });
        }
        let committed = match ends.committed[e] {
            -1 => None,
            c => Some(grid.cell(index(c, grid.n_cells(), "committed cell")?)),
        };
        out.push(tally.result(goal, committed, runs.epoch_s[k], ends.t_s[e], steps));
    }
    Ok(out)
}
