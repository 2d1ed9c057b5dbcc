//! `errp fit grid` over the fixed pairs' total length: each length's
//! profile over the goal reward, the estimates, and the fit at the chosen
//! length.

use errp_bci::rng::{derive_seed, labelled};
use errp_sim::grid::PairFamily;

use super::result::{GridFit, PairsFit};
use super::spec::GridFitSpec;
use crate::fit::surface::{CHI2_1_95, argmax};

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
        .filter(|&k| profile[k] >= profile[top] - CHI2_1_95 / 2.0)
        .collect();
    let reached_at = (0..lengths.len())
        .filter(|&k| reached[k].is_some())
        .max_by(|&a, &b| {
            let l = |k: usize| reached[k].map_or(f64::NEG_INFINITY, |r| r.1);
            l(a).total_cmp(&l(b))
        });
    let chosen = reached_at.unwrap_or(top);
    let mut rng = labelled(derive_seed(spec.seed, "fit/grid/pairs/example", 0), "pairs");
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
