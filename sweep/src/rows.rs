//! The columns of `episodes.csv`, and one episode's row.

use errp_sim::task::{Task, overall, rate_field};
use errp_sim::{Result, SimError};

use crate::spec::{Level, SweepSpec, format_number, value_text};

/// The header of `episodes.csv` for `spec`.
pub fn episodes_header(spec: &SweepSpec) -> String {
    let mut cols = vec!["level".to_string(), "accuracy".into()];
    cols.extend(spec.axes.iter().map(|a| a.name.clone()));
    cols.extend(["episode", "seed", "success"].map(String::from));
    cols.extend(spec.task.info().columns.iter().map(|s| s.to_string()));
    cols.extend(["acc_correct", "acc_error", "online_accuracy"].map(String::from));
    cols.join(",")
}

/// Runs episode `k` of `level` and formats its CSV row.
pub(crate) fn run_row<T: Task>(
    spec: &SweepSpec,
    level: &Level,
    runner: &T::Runner,
    k: usize,
) -> Result<String> {
    let seed = spec.episode_seed(level.accuracy, k);
    let mut f = vec![level.index.to_string(), format_number(level.accuracy)];
    f.extend(level.values.iter().map(value_text));
    f.extend([k.to_string(), seed.to_string()]);
    let row = T::run_episode(runner, k, seed)?;
    if row.fields.len() != T::INFO.columns.len() {
        return Err(SimError::Sweep(format!(
            "the {} task gave {} fields for its {} columns",
            T::INFO.name,
            row.fields.len(),
            T::INFO.columns.len()
        )));
    }
    f.push(u8::from(row.success).to_string());
    f.extend(row.fields);
    let (_, _, acc) = overall(&row.online);
    f.extend([
        rate_field(row.online.correct),
        rate_field(row.online.error),
        rate_field(acc),
    ]);
    Ok(f.join(","))
}
