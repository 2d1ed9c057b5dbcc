//! The rows of a recording's data tables, run by run: which rows are a
//! run's, that the runs come in order, and indices checked against their
//! range.

/// The row indices of run `r` in a table's `runs` column (runs are
/// written in order).
pub(super) fn run_rows(runs: &[i64], r: usize) -> std::ops::Range<usize> {
    let lo = runs.partition_point(|&x| x < r as i64);
    let hi = runs.partition_point(|&x| x <= r as i64);
    lo..hi
}

/// Checks that `runs` counts 0, 1, ... in order (each run's rows together).
pub(super) fn check_run_order(name: &str, runs: &[i64]) -> Result<(), String> {
    if runs.windows(2).any(|w| w[1] < w[0]) || runs.first().is_some_and(|&r| r < 0) {
        return Err(format!("its table {name} is not in run order"));
    }
    Ok(())
}

/// An index in `0..n`, or an error naming the column.
pub(super) fn index(v: i64, n: usize, what: &str) -> Result<usize, String> {
    usize::try_from(v)
        .ok()
        .filter(|&i| i < n)
        .ok_or_else(|| format!("{what} {v} is out of range (0 to {})", n.saturating_sub(1)))
}
