//! `errp fit grid` over the fixed pairs' total length: each length's
//! profile over the goal reward, the estimates, and the fit at the chosen
//! length.

use errp_bci::rng::{derive_seed, stream};
use errp_robot::Cell;
use errp_sim::grid::PairFamily;
use serde::Serialize;

use super::grid::{GridFit, GridFitSpec};
use super::surface::argmax;

/// The fixed pairs' total Manhattan length, profiled over the goal reward.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PairsFit {
    /// The candidate lengths.
    pub lengths: Vec<usize>,
    /// Per length: the fixed rows' log-likelihood maximised over the goal
    /// reward (the profile likelihood of the length).
    pub profile: Vec<f64>,
    /// Per length: the goal reward at that maximum.
    pub goal_reward: Vec<f64>,
    /// Per length: P(all 40 of the paper's goals reached) there.
    pub p_all_reached: Vec<f64>,
    /// Per length: the largest-likelihood goal reward among those that keep
    /// the paper's 40/40 (P >= [`REACHED_LEVEL`](super::REACHED_LEVEL)), and its log-likelihood.
    pub reached: Vec<Option<(f64, f64)>>,
    /// `fixed_actions[length][subject][goal reward]`: the mean actions of
    /// the fixed-goal runs.
    pub fixed_actions: Vec<Vec<Vec<f64>>>,
    /// `fixed_z[length][subject]`: the fixed rows' z at the length's
    /// maximum-likelihood goal reward.
    pub fixed_z: Vec<Vec<f64>>,
    /// `free_z[length][subject]`: the held-out free rows' z there.
    pub free_z: Vec<Vec<f64>>,
    /// The maximum-likelihood length.
    pub estimate: usize,
    /// Its 95 % likelihood-ratio interval (the profile within 1.92 of its
    /// maximum).
    pub interval_95: (usize, usize),
    /// The largest-likelihood (length, goal reward) that keeps the paper's
    /// 40/40; none if no point does.
    pub reached_estimate: Option<(usize, f64)>,
    /// The length the rest of the result is fitted at: the 40/40 estimate's,
    /// or the maximum-likelihood one if none keeps 40/40.
    pub chosen: usize,
    /// One set of the chosen length, drawn from the family with the fit's
    /// seed: a pair set that a scenario can take.
    pub example: Vec<(Cell, Cell)>,
}

/// The fit over the pairs' lengths: the profile of each length over the
/// goal reward, the estimates, and the fit at the chosen length.
pub(super) fn pairs_fit(spec: &GridFitSpec, family: &PairFamily, fits: Vec<GridFit>) -> GridFit {
    let lengths = spec.pair_lengths.clone();
    let best: Vec<usize> = fits.iter().map(|f| argmax(&f.surface.total)).collect();
    let profile: Vec<f64> = fits
        .iter()
        .zip(&best)
        .map(|(f, &j)| f.surface.total[j])
        .collect();
    let reached: Vec<Option<(f64, f64)>> = fits
        .iter()
        .map(|f| {
            f.reached_estimate.map(|g| {
                let j = spec
                    .goal_rewards
                    .iter()
                    .position(|&x| x == g)
                    .expect("the 40/40 estimate is a grid point");
                (g, f.surface.total[j])
            })
        })
        .collect();
    let top = argmax(&profile);
    let within: Vec<usize> = (0..lengths.len())
        .filter(|&k| profile[k] >= profile[top] - super::surface::CHI2_1_95 / 2.0)
        .collect();
    let reached_at = (0..lengths.len())
        .filter(|&k| reached[k].is_some())
        .max_by(|&a, &b| {
            let l = |k: usize| reached[k].map_or(f64::NEG_INFINITY, |r| r.1);
            l(a).total_cmp(&l(b))
        });
    let chosen = reached_at.unwrap_or(top);
    let mut rng = stream(derive_seed(spec.seed, "fit/grid/pairs/example", 0), "pairs");
    let example = family
        .draw(lengths[chosen], &mut rng)
        .expect("every fitted length has sets");
    let pairs = PairsFit {
        profile,
        goal_reward: best.iter().map(|&j| spec.goal_rewards[j]).collect(),
        p_all_reached: fits
            .iter()
            .zip(&best)
            .map(|(f, &j)| f.p_all_reached[j])
            .collect(),
        reached: reached.clone(),
        fixed_actions: fits
            .iter()
            .map(|f| {
                f.fixed_stats
                    .iter()
                    .map(|per_point| per_point.iter().map(|c| c.actions.0).collect())
                    .collect()
            })
            .collect(),
        fixed_z: fits
            .iter()
            .zip(&best)
            .map(|(f, &j)| f.fixed_stats.iter().map(|p| p[j].z).collect())
            .collect(),
        free_z: fits
            .iter()
            .zip(&best)
            .map(|(f, &j)| f.free_stats.iter().map(|p| p[j].z).collect())
            .collect(),
        estimate: lengths[top],
        interval_95: (
            lengths[*within.first().unwrap_or(&top)],
            lengths[*within.last().unwrap_or(&top)],
        ),
        reached_estimate: reached_at.and_then(|k| reached[k].map(|(g, _)| (lengths[k], g))),
        chosen: lengths[chosen],
        example,
        lengths,
    };
    let mut fit = fits.into_iter().nth(chosen).expect("one fit per length");
    fit.pairs = Some(pairs);
    fit
}
