//! A grid recording's episodes recomputed from its table of actions, with
//! the episode's own tally.

#[allow(clippy::wildcard_imports, unused_imports)]
use super::*;

/// A grid recording's table of actions, column by column (empty when no
/// episode took an action).
pub(super) struct ActionColumns<'a> {
    pub(super) t: &'a [f64],
    pub(super) from: (&'a [i64], &'a [i64]),
    pub(super) to: (&'a [i64], &'a [i64]),
    pub(super) error: &'a [bool],
    pub(super) p_error: &'a [f64],
    pub(super) decoded: &'a [bool],
    pub(super) names: &'a [String],
    pub(super) belief: &'a [f64],
    pub(super) width: usize,
}

impl<'a> ActionColumns<'a> {
    pub(super) fn of(actions: &View<'a>, grid: &Grid) -> Result<Self, String> {
        let n_actions = actions.table.rows();
        let (a_t, fx, fy, tx, ty, err, p, dec) = if n_actions == 0 {
            (
                &[][..],
                &[][..],
                &[][..],
                &[][..],
                &[][..],
                &[][..],
                &[][..],
                &[][..],
            )
        } else {
            (
                actions.f64("t_s")?,
                actions.i64("from_x")?,
                actions.i64("from_y")?,
                actions.i64("to_x")?,
                actions.i64("to_y")?,
                actions.bool("error")?,
                actions.f64("p_error")?,
                actions.bool("decoded_error")?,
            )
        };
        let names: &[String] = match actions.table.column("action") {
            Some(Column::Str(v)) => v,
            _ if n_actions == 0 => &[],
            _ => {
                return Err(format!(
                    "its table {} has no column `action`",
                    paths::ACTIONS
                ));
            }
        };
        let (belief, width) = if n_actions == 0 {
            (&[][..], grid.n_cells())
        } else {
            actions.rows("belief")?
        };
        if width != grid.n_cells() {
            return Err(format!(
                "its beliefs have {width} values, not one per cell ({})",
                grid.n_cells()
            ));
        }
        Ok(Self {
            t: a_t,
            from: (fx, fy),
            to: (tx, ty),
            error: err,
            p_error: p,
            decoded: dec,
            names,
            belief,
            width,
        })
    }
}

/// The grid episodes recomputed from their actions.
pub(super) fn grid_results(
    tables: &std::collections::BTreeMap<String, Table>,
) -> Result<Vec<GridEpisodeResult>, String> {
    let grid = Grid::paper();
    let runs = View::of(tables, paths::RUNS)?;
    let ends = View::of(tables, paths::ENDS)?;
    let empty = Table::default();
    let actions = View {
        name: paths::ACTIONS,
        table: tables.get(paths::ACTIONS).unwrap_or(&empty),
    };
    let run_col = runs.i64("run")?;
    let end_run = ends.i64("run")?;
    let a_run = if actions.table.rows() == 0 {
        &[][..]
    } else {
        actions.i64("run")?
    };
    for (name, r) in [
        (paths::RUNS, run_col),
        (paths::ACTIONS, a_run),
        (paths::ENDS, end_run),
    ] {
        check_run_order(name, r)?;
    }
    let cell = |x: i64, y: i64| -> Result<Cell, String> {
        Ok(Cell::new(
            index(x, grid.width, "cell column")?,
            index(y, grid.height, "cell row")?,
        ))
    };
    let (sx, sy, gx, gy, epoch) = (
        runs.i64("start_x")?,
        runs.i64("start_y")?,
        runs.i64("goal_x")?,
        runs.i64("goal_y")?,
        runs.f64("epoch_s")?,
    );
    let (end_t, end_committed) = (ends.f64("t_s")?, ends.i64("committed")?);
    let ActionColumns {
        t: a_t,
        from: (fx, fy),
        to: (tx, ty),
        error: err,
        p_error: p,
        decoded: dec,
        names,
        belief,
        width,
    } = ActionColumns::of(&actions, &grid)?;
    let mut out = Vec::new();
    for (k, &r) in run_col.iter().enumerate() {
        if r != k as i64 {
            return Err(format!("its table {} skips run {k}", paths::RUNS));
        }
        let Some(e) = end_run.iter().position(|&x| x == r) else {
            break;
        };
        let start = cell(sx[k], sy[k])?;
        let goal = cell(gx[k], gy[k])?;
        // The episode's own tally, fed from the table of actions.
        let mut tally = GridTally::new(&grid, start);
        let mut steps = Vec::new();
        for i in actions.run_rows(a_run, k) {
            let to = cell(tx[i], ty[i])?;
            tally.action(&grid, to, err[i], dec[i]);
            let action = GridAction::ALL
                .into_iter()
                .find(|a| a.name() == names[i])
                .ok_or_else(|| format!("`{}` is not an action of the grid", names[i]))?;
            steps.push(GridStep {
                onset_secs: a_t[i],
                from: cell(fx[i], fy[i])?,
                action,
                to,
                error: err[i],
                p_error: p[i],
                decoded_error: dec[i],
                belief: belief[i * width..(i + 1) * width].to_vec(),
                fcz: Vec::new(),
            });
        }
        let committed = match end_committed[e] {
            -1 => None,
            c => Some(grid.cell(index(c, grid.n_cells(), "committed cell")?)),
        };
        out.push(tally.result(goal, committed, epoch[k], end_t[e], steps));
    }
    Ok(out)
}
