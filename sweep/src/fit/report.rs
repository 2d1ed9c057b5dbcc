//! A fit's results as text: what `errp fit epuck` and `errp fit grid`
//! print, as [`EpuckFitReport`] and [`GridFitReport`].

use std::fmt;

use errp_sim::task::ordinal_percent;

use crate::fit::{EpuckFit, GridFit, PairsFit, REACHED_LEVEL, TableStats, TrialLatencyFit};

/// An e-puck fit's table, estimate and held-out runs, as printed.
pub struct EpuckFitReport<'a>(pub &'a EpuckFit);

impl fmt::Display for EpuckFitReport<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        epuck_fit(f, self.0)
    }
}

/// A grid fit's table, estimates, points and profiles, as printed.
pub struct GridFitReport<'a>(pub &'a GridFit);

impl fmt::Display for GridFitReport<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        grid_fit(f, self.0)
    }
}

/// Percent with no decimals.
fn pct(v: f64) -> String {
    if v.is_finite() {
        format!("{:.0}", 100.0 * v)
    } else {
        "-".into()
    }
}

fn epuck_fit(f: &mut fmt::Formatter<'_>, fit: &EpuckFit) -> fmt::Result {
    let s = &fit.surface;
    writeln!(
        f,
        "E-puck decoder accuracy fitted to the paper's two runs ({} calibrations x {} runs of \
         each scenario per accuracy, seeds from {}):",
        fit.spec.calibrations, fit.spec.runs, fit.spec.seed
    )?;
    write!(f, "{:>8}  {:>16}", "accuracy", "log L (MC sd)")?;
    for (name, ..) in &fit.observations {
        write!(f, "  | {name:<43}")?;
    }
    writeln!(f)?;
    write!(f, "{:>8}  {:>16}", "", "")?;
    for _ in &fit.observations {
        write!(
            f,
            "  | {:>7} {:>11} {:>9} {:>6} {:>5}",
            "reached", "median t", "median d", "pct t", "pct d"
        )?;
    }
    writeln!(f)?;
    for j in 0..s.grid.len() {
        let mark = if j == s.estimate { "*" } else { " " };
        write!(
            f,
            "{mark}{:>7.3}  {:>8.2} ({:>5.2})",
            s.grid[j], s.total[j], s.total_sd[j]
        )?;
        for i in 0..fit.observations.len() {
            let st = &fit.stats[i][j];
            write!(
                f,
                "  | {:>6}% {:>9.1} s {:>9.1} {:>5}% {:>4}%",
                pct(st.p_reached()),
                st.time_secs[0],
                st.detections[0],
                pct(st.time_percentile),
                pct(st.detections_percentile)
            )?;
        }
        writeln!(f)?;
    }
    let edge = |at: bool| if at { " (the grid's end)" } else { "" };
    writeln!(
        f,
        "Estimate: accuracy {:.3}; 95 % likelihood-ratio interval {:.3}{}-{:.3}{}; Monte Carlo \
         spread of the estimate (5-95 % over {} bootstrap replicates) {:.3}-{:.3}.",
        fit.estimate.value,
        fit.estimate.interval_95.0,
        edge(fit.estimate.interval_at_edge.0),
        fit.estimate.interval_95.1,
        edge(fit.estimate.interval_at_edge.1),
        fit.spec.bootstrap,
        fit.estimate.mc_interval_90.0,
        fit.estimate.mc_interval_90.1
    )?;
    for (i, h) in fit.held_out.iter().enumerate() {
        let (_, _, t, d) = &fit.observations[i];
        writeln!(
            f,
            "Held out {}: fitted to the other run alone, accuracy {:.3}; there {} reaches the \
             goal in {} % of runs, and the paper's {t} s lie at the {} percentile of their times \
             and its {d} detections at the {}.",
            h.name,
            h.fitted_without,
            h.name,
            pct(h.stats.p_reached()),
            ordinal_percent(h.stats.time_percentile),
            ordinal_percent(h.stats.detections_percentile)
        )?;
    }
    Ok(())
}

/// `x` to three decimals: a bootstrap quantile is interpolated between grid
/// points, and its last bits are noise.
fn round3(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

fn grid_fit(f: &mut fmt::Formatter<'_>, fit: &GridFit) -> fmt::Result {
    let s = &fit.surface;
    writeln!(
        f,
        "Grid Q-value scale (goal reward at tau = 0.3) fitted to Table 1's fixed goals{}{} ({} \
         calibrations x {} groups of 5 runs per subject and point, epsilon {}, seed {}):",
        fit.pairs.as_ref().map_or(String::new(), |p| format!(
            ", at the fixed pairs' fitted total length {} (below)",
            p.chosen
        )),
        fit.trial_latency
            .as_ref()
            .map_or(String::new(), |t| format!(
                ", with the fitted single-trial latency SD {} ms (below)",
                errp_sim::task::format_number(t.chosen)
            )),
        fit.spec.calibrations,
        fit.spec.repeats,
        fit.spec.epsilon,
        fit.spec.seed
    )?;
    write!(
        f,
        "{:>6}  {:>15}  {:>8}",
        "reward", "log L (MC sd)", "free L"
    )?;
    for row in &fit.fixed {
        write!(
            f,
            "  | {:<27}",
            format!("{} fixed [{}]", row.subject, row.actions_mean)
        )?;
    }
    writeln!(f, "  | r<0 fixed/free")?;
    for j in 0..s.grid.len() {
        let mark = if j == s.estimate { "*" } else { " " };
        write!(
            f,
            "{mark}{:>5}  {:>7.2} ({:>5.2})  {:>8.2}",
            errp_sim::task::format_number(s.grid[j]),
            s.total[j],
            s.total_sd[j],
            fit.free_log_lik[j]
        )?;
        for per_point in &fit.fixed_stats {
            let st = &per_point[j];
            write!(
                f,
                "  | {:>5.1} +- {:>5.1} {:>4}% z{:>+5.1}",
                st.actions.0,
                st.actions.1,
                pct(st.reached as f64 / st.runs.max(1) as f64),
                st.z
            )?;
        }
        let share = |t: &TableStats| pct(t.r_negative as f64 / t.tables.max(1) as f64);
        writeln!(
            f,
            "  | {:>3}% / {:>3}%",
            share(&fit.fixed_tables[j]),
            share(&fit.free_tables[j])
        )?;
    }
    grid_estimates(f, fit)?;
    grid_point(f, fit, s.estimate, "the estimate")?;
    let kept = fit
        .reached_estimate
        .and_then(|g| s.grid.iter().position(|&x| x == g));
    if let Some(j) = kept.filter(|&j| j != s.estimate) {
        grid_point(f, fit, j, "the goal reward that keeps the paper's 40/40")?;
    }
    if let Some(p) = &fit.pairs {
        pairs_fit(f, p)?;
    }
    if let Some(t) = &fit.trial_latency {
        trial_latency_fit(f, t)?;
    }
    Ok(())
}

/// The goal reward's estimates: the maximum likelihood with its intervals,
/// each subject's own, and the one that keeps the paper's 40/40.
fn grid_estimates(f: &mut fmt::Formatter<'_>, fit: &GridFit) -> fmt::Result {
    let s = &fit.surface;
    let edge = |at: bool| if at { " (the grid's end)" } else { "" };
    let num = errp_sim::task::format_number;
    writeln!(
        f,
        "Estimate: goal reward {}; 95 % likelihood-ratio interval {}{}-{}{}; Monte Carlo spread \
         of the estimate (5-95 % over {} bootstrap replicates) {}-{}.",
        num(fit.estimate.value),
        num(fit.estimate.interval_95.0),
        edge(fit.estimate.interval_at_edge.0),
        num(fit.estimate.interval_95.1),
        edge(fit.estimate.interval_at_edge.1),
        fit.spec.bootstrap,
        num(round3(fit.estimate.mc_interval_90.0)),
        num(round3(fit.estimate.mc_interval_90.1))
    )?;
    let own: Vec<String> = fit
        .fixed
        .iter()
        .zip(&fit.own_estimates)
        .map(|(row, e)| format!("{} {}", row.subject, num(*e)))
        .collect();
    writeln!(f, "Each subject alone: {}.", own.join(", "))?;
    let p40: Vec<String> = s
        .grid
        .iter()
        .zip(&fit.p_all_reached)
        .map(|(g, p)| format!("{} {:.3}", num(*g), p))
        .collect();
    writeln!(
        f,
        "P(all 40 of the paper's goals reached), from the tables: {}.",
        p40.join(", ")
    )?;
    match fit.reached_estimate {
        Some(g) => writeln!(
            f,
            "Keeping the paper's 40/40 (P >= {}): goal reward {}, the largest likelihood among \
             the goal rewards where P(all 40 reached) >= {}.",
            REACHED_LEVEL,
            num(g),
            REACHED_LEVEL
        )?,
        None => writeln!(
            f,
            "No goal reward of the grid keeps the paper's 40/40 (P(all 40 reached) >= {}).",
            REACHED_LEVEL
        )?,
    }
    Ok(())
}

/// Per-subject z values in one column each (`+2.1 -0.4 ...`).
fn z_row(z: &[f64]) -> String {
    z.iter()
        .map(|v| format!("{v:+5.1}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The single-trial latency SD, profiled over the rest.
fn trial_latency_fit(f: &mut fmt::Formatter<'_>, t: &TrialLatencyFit) -> fmt::Result {
    let num = errp_sim::task::format_number;
    writeln!(
        f,
        "The ErrP's single-trial latency SD, fitted jointly with the rest (the whole fit at each \
         SD; published range 16.7-21.3 ms, Fidencio et al. 2024; the EEG model's own: 25 ms):"
    )?;
    writeln!(
        f,
        " SD ms  log L (profile)  40/40 log L  length  reward  P(all 40)  fixed z S1..S4        \
         free z S1..S4 (held out)"
    )?;
    for k in 0..t.sds.len() {
        let (length, reward) = t.point[k];
        writeln!(
            f,
            "{}{:>5}  {:>15.2}  {:>11}  {:>6}  {:>6}  {:>9.3}  {}   {}",
            if t.sds[k] == t.chosen { "*" } else { " " },
            num(t.sds[k]),
            t.profile[k],
            t.reached[k].map_or("none".to_string(), |l| format!("{l:.2}")),
            length.map_or("-".to_string(), |l| l.to_string()),
            num(reward),
            t.p_all_reached[k],
            z_row(&t.fixed_z[k]),
            z_row(&t.free_z[k])
        )?;
    }
    writeln!(
        f,
        "Estimate: {} ms (95 % likelihood-ratio interval {}-{} ms among the values tried); the \
         fit above is at {} ms (*), the largest 40/40 likelihood.",
        num(t.estimate),
        num(t.interval_95.0),
        num(t.interval_95.1),
        num(t.chosen)
    )?;
    Ok(())
}

/// The fixed pairs' length, profiled over the goal reward.
fn pairs_fit(f: &mut fmt::Formatter<'_>, p: &PairsFit) -> fmt::Result {
    let num = errp_sim::task::format_number;
    writeln!(
        f,
        "The fixed pairs' total Manhattan length, fitted jointly with the goal reward (each \
         group of five runs draws a set of that length whose third pair keeps to the centre; \
         the corner pairs of earlier versions: 28, random pairs: about 17):"
    )?;
    writeln!(
        f,
        "length  best reward  log L (profile)  P(all 40)  40/40 reward (log L)  fixed z S1..S4 \
         at best            free z S1..S4 (held out)"
    )?;
    for k in 0..p.lengths.len() {
        let reached = p.reached[k].map_or("none".to_string(), |(g, l)| {
            format!("{} ({:.2})", num(g), l)
        });
        writeln!(
            f,
            "{}{:>5}  {:>11}  {:>15.2}  {:>9.3}  {:>20}  {}       {}",
            if p.lengths[k] == p.chosen { "*" } else { " " },
            p.lengths[k],
            num(p.goal_reward[k]),
            p.profile[k],
            p.p_all_reached[k],
            reached,
            z_row(&p.fixed_z[k]),
            z_row(&p.free_z[k])
        )?;
    }
    let (lo, hi) = p.interval_95;
    writeln!(
        f,
        "Estimate: length {} (95 % likelihood-ratio interval {lo}-{hi}); keeping the paper's \
         40/40: {}. The fit above is at length {} (*); a set of that length from the family: {}.",
        p.estimate,
        p.reached_estimate
            .map_or("no point".to_string(), |(l, g)| format!(
                "length {l} at goal reward {}",
                num(g)
            )),
        p.chosen,
        errp_sim::grid::pairs_text(&p.example)
    )?;
    Ok(())
}

/// The fitted and held-out rows of grid point `j`, against the paper's.
fn grid_point(f: &mut fmt::Formatter<'_>, fit: &GridFit, j: usize, what: &str) -> fmt::Result {
    writeln!(
        f,
        "At {what}, goal reward {} (ours [paper], z = difference in standard errors):",
        errp_sim::task::format_number(fit.surface.grid[j])
    )?;
    for (set, rows, stats) in [
        ("fixed (fitted)", &fit.fixed, &fit.fixed_stats),
        ("free (held out)", &fit.free, &fit.free_stats),
    ] {
        for (row, per_point) in rows.iter().zip(stats) {
            let st = &per_point[j];
            writeln!(
                f,
                "  {} {set}: actions {:.1} +- {:.1} [{} +- {}], z {:+.1}; reached {}/{}; online \
                 accuracy {:.1} % [{:.2}]",
                row.subject,
                st.actions.0,
                st.actions.1,
                row.actions_mean,
                row.actions_sd,
                st.z,
                st.reached,
                st.runs,
                100.0 * st.online_accuracy,
                100.0 * row.accuracy
            )?;
        }
    }
    for (set, t) in [
        ("fixed", &fit.fixed_tables[j]),
        ("free", &fit.free_tables[j]),
    ] {
        writeln!(
            f,
            "  Tables of 20 runs ({set} goals, held out): all 20 reached in {}/{}; r negative in \
             {}/{}, median r {:.2}.",
            t.all_reached, t.tables, t.r_negative, t.tables, t.median_r
        )?;
    }
    Ok(())
}
