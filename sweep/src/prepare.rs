//! Preparing every level's decoder, on the path `errp run` takes, each distinct one once.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use errp_sim::Result;
use errp_sim::task::{DecoderInfo, Task};

use crate::cache::TargetCache;
use crate::observer::SweepObserver;

/// Prepares the decoders of `scenarios` on every thread of the current pool,
/// the likely slowest first (`cost`: targeting far from 75 % takes the most
/// search steps). Results are in `scenarios` order, whatever the thread
/// count.
pub(crate) fn prepare_all<T: Task>(
    scenarios: &[&T::Scenario],
    cost: impl Fn(usize) -> f64,
    cache: &TargetCache,
    shared: &T::Shared,
    observer: &dyn SweepObserver,
) -> Result<Vec<(T::Decoder, DecoderInfo)>> {
    let n = scenarios.len();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| cost(b).total_cmp(&cost(a)).then(a.cmp(&b)));
    let next = AtomicUsize::new(0);
    let ready = AtomicUsize::new(0);
    type Slot<D> = Mutex<Option<Result<(D, DecoderInfo)>>>;
    let slots: Vec<Slot<T::Decoder>> = (0..n).map(|_| Mutex::new(None)).collect();
    rayon::scope(|scope| {
        for _ in 0..rayon::current_num_threads().min(n) {
            scope.spawn(|_| {
                loop {
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(&k) = order.get(i) else { break };
                    let warn = |w: &str| observer.warning(w);
                    let result = T::prepare(scenarios[k], shared, &cache.reporting(&warn));
                    if let Ok((_, info)) = &result {
                        let done = ready.fetch_add(1, Ordering::SeqCst) + 1;
                        observer.decoder_ready(info, done, n);
                    }
                    *slots[k].lock().expect("no panic while holding the slot") = Some(result);
                }
            });
        }
    });
    slots
        .into_iter()
        .map(|slot| {
            slot.into_inner()
                .expect("no panic while holding the slot")
                .expect("every decoder was prepared")
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use errp_sim::epuck::EpuckTask;

    use super::*;
    use crate::spec::{Level, SweepSpec, parse_accuracies, parse_axis};
    use errp_sim::{Names, TaskKind};

    fn epuck_levels(param: &str) -> Vec<Level> {
        SweepSpec {
            task: TaskKind::Epuck,
            scenario_path: "mexico_to_pisa.toml".into(),
            scenario_toml: include_str!("../../scenarios/mexico_to_pisa.toml").into(),
            accuracies: parse_accuracies("0.9", &Names::CLI).unwrap(),
            axes: vec![parse_axis(TaskKind::Epuck, param, &Names::CLI).unwrap()],
            fixed: vec![],
            episodes: 1,
            seed: 1,
        }
        .levels(&Names::CLI)
        .unwrap()
    }

    fn key(level: &Level) -> String {
        EpuckTask::decoder_key(level.scenario.get().unwrap())
    }

    #[test]
    fn levels_share_a_decoder_only_when_it_would_be_the_same() {
        // T_e sets the held-out operating point the decoder carries.
        let t_e = epuck_levels("t_e=0.7,0.8");
        assert_ne!(key(&t_e[0]), key(&t_e[1]));
        // The user's field of view does not touch the decoder.
        let fov = epuck_levels("fov_deg=60,90");
        assert_eq!(key(&fov[0]), key(&fov[1]));
    }
}
