//! `errp fit epuck` end to end on a small grid, and the shipped defaults
//! against the committed fit (`fits/epuck.json`).

use std::path::Path;

use errp_bci::stop::WindDown;
use errp_sweep::fit::{
    EpuckFitSpec, FitOutcome, FitProvenance, GridFitOutcome, GridFitSpec, paper_runs,
    run_epuck_fit, run_grid_fit,
};

use errp_robot::Cell;
use errp_sim::grid::FIXED_PAIRS;

use crate::{cache, temp_dir};

fn repo(path: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(path)
}

fn provenance() -> FitProvenance {
    FitProvenance {
        command: "test".into(),
        errp_version: "test".into(),
        commit: "test".into(),
    }
}

/// A JSON array of numbers from a fit file; null (how JSON writes a
/// log-likelihood of minus infinity) reads as minus infinity.
fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap_or(f64::NEG_INFINITY))
        .collect()
}

fn scenario_accuracy(file: &str) -> f64 {
    let text = std::fs::read_to_string(repo(file)).unwrap();
    let table: toml::Table = toml::from_str(&text).unwrap();
    table["user"]["accuracy"].as_float().unwrap()
}

#[test]
fn the_shipped_e_puck_decoder_is_the_committed_fit() {
    let text = std::fs::read_to_string(repo("fits/epuck.json")).unwrap();
    let fit: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(fit["format"], 1);
    assert_eq!(fit["parameter"], "user.accuracy");
    let estimate = fit["estimate"].as_f64().unwrap();
    let (lo, hi) = (
        fit["interval_95"][0].as_f64().unwrap(),
        fit["interval_95"][1].as_f64().unwrap(),
    );
    assert!(
        lo <= estimate && estimate <= hi,
        "{estimate} in [{lo}, {hi}]"
    );
    // Made by a committed program, at its default settings.
    let commit = fit["provenance"]["commit"].as_str().unwrap();
    assert!(
        commit.len() == 40 && commit.chars().all(|c| c.is_ascii_hexdigit()),
        "fits/epuck.json was made by {commit:?}, not a clean commit"
    );
    assert_eq!(fit["spec"]["calibrations"], 5);
    assert_eq!(fit["spec"]["runs"], 100);
    // The grid's maximum is the estimate.
    let total = numbers(&fit["surface"]["total"]);
    let grid = numbers(&fit["surface"]["grid"]);
    assert!(grid.iter().all(|g| g.is_finite()), "{grid:?}");
    let best = errp_sweep::fit::argmax(&total);
    assert_eq!(grid[best], estimate);
    // Every shipped scenario with the paper's decoder uses it.
    for file in [
        "scenarios/mexico_to_pisa.toml",
        "scenarios/lisbon_to_tokyo.toml",
        "scenarios/obstacles_havana_to_seoul.toml",
        "scenarios/variants/mexico_to_pisa_literal.toml",
        "scenarios/variants/lisbon_to_tokyo_literal.toml",
    ] {
        assert_eq!(
            scenario_accuracy(file),
            estimate,
            "{file} and fits/epuck.json disagree"
        );
    }
    // The hand-picked decoder stays as a named variant.
    for file in [
        "scenarios/variants/mexico_to_pisa_optimistic.toml",
        "scenarios/variants/lisbon_to_tokyo_optimistic.toml",
    ] {
        assert_eq!(scenario_accuracy(file), 0.95, "{file}");
    }
}

#[test]
fn shipped_scenarios_have_distinct_seeds() {
    let mut seeds = Vec::new();
    for entry in std::fs::read_dir(repo("scenarios")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let table: toml::Table =
                toml::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
            seeds.push((table["seed"].as_integer().unwrap(), path));
        }
    }
    assert!(seeds.len() >= 5);
    seeds.sort();
    for w in seeds.windows(2) {
        assert_ne!(w[0].0, w[1].0, "{:?} and {:?} share a seed", w[0].1, w[1].1);
    }
}

#[test]
#[ignore = "slow (an e-puck fit, 38 s): `cargo test --workspace -- --ignored` and CI run it"]
fn a_small_fit_writes_its_files_resumes_to_the_same_bytes_and_guards_its_directory() {
    let out = temp_dir("fit");
    let spec = EpuckFitSpec {
        accuracies: vec![0.8, 0.95],
        calibrations: 1,
        runs: 5,
        seed: 3,
        bootstrap: 20,
    };
    let wind_down = WindDown::new();
    let mut sweeps = Vec::new();
    let run = |sweeps: &mut Vec<u64>| {
        run_epuck_fit(
            &spec,
            &out,
            &cache(),
            provenance(),
            &wind_down,
            &(),
            |_, _, _, seed| sweeps.push(seed),
        )
        .unwrap()
    };
    let FitOutcome::Complete(fit, files) = run(&mut sweeps) else {
        panic!("not interrupted")
    };
    assert_eq!(sweeps, vec![3, 3]);
    assert_eq!(files.len(), 4);
    assert_eq!(fit.stats.len(), 2);
    assert!(fit.stats.iter().flatten().all(|s| s.runs == 5));
    assert!(spec.accuracies.contains(&fit.estimate.value));
    let first = std::fs::read(out.join("fit.json")).unwrap();
    let csv = std::fs::read_to_string(out.join("surface.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
    assert!(
        std::fs::read(out.join("fit.png"))
            .unwrap()
            .starts_with(b"\x89PNG")
    );
    // A rerun finds every run on disk and writes the same bytes.
    let FitOutcome::Complete(..) = run(&mut sweeps) else {
        panic!("not interrupted")
    };
    assert_eq!(std::fs::read(out.join("fit.json")).unwrap(), first);
    // A directory holding anything else is refused, untouched.
    let foreign = temp_dir("fit-foreign");
    std::fs::create_dir_all(&foreign).unwrap();
    std::fs::write(foreign.join("mine.txt"), "mine").unwrap();
    let e = run_epuck_fit(
        &spec,
        &foreign,
        &cache(),
        provenance(),
        &wind_down,
        &(),
        |_, _, _, _| {},
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("mine.txt") && e.contains("--out"), "{e}");
    assert_eq!(std::fs::read_dir(&foreign).unwrap().count(), 1);
    // Bad settings name their flag and range.
    let bad = EpuckFitSpec {
        runs: 2,
        ..spec.clone()
    };
    let e = run_epuck_fit(
        &bad,
        &out,
        &cache(),
        provenance(),
        &wind_down,
        &(),
        |_, _, _, _| {},
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("--runs 2") && e.contains("5 to"), "{e}");
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(&foreign);
    assert_eq!(paper_runs().len(), 2);
}

/// The median time to Pisa with a run that converged on a wrong city
/// counted as never reaching it (the median over the successful runs alone
/// is not monotonic: at a poor accuracy only runs that happened to be
/// quick reach Pisa before a wrong city takes them).
fn median_time_to_goal(rows: &[(bool, f64)]) -> f64 {
    let mut t: Vec<f64> = rows
        .iter()
        .map(|&(ok, t)| if ok { t } else { f64::INFINITY })
        .collect();
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

#[test]
#[ignore = "slow (2500 e-puck runs, 67 s): `cargo test --workspace -- --ignored` and CI run it"]
fn the_median_time_to_pisa_does_not_rise_with_accuracy() {
    use errp_sim::TaskKind;
    use errp_sweep::{Shard, SweepOptions, SweepSpec, run_sweep, sweep_fixed};
    let out = temp_dir("monotonic");
    let names = errp_sim::Names::CLI;
    let spec = SweepSpec {
        task: TaskKind::Epuck,
        // The idealised user: one calibration per accuracy, whose online
        // operating point varies less than the realistic user's.
        scenario_path: "scenarios/variants/mexico_to_pisa_ideal.toml".into(),
        scenario_toml: include_str!("../../../scenarios/variants/mexico_to_pisa_ideal.toml")
            .to_string(),
        accuracies: vec![0.75, 0.8, 0.85, 0.9, 0.95],
        axes: vec![],
        fixed: sweep_fixed(
            TaskKind::Epuck,
            std::path::Path::new("mexico_to_pisa_ideal.toml"),
            None,
            &names,
        )
        .unwrap(),
        episodes: 500,
        seed: 1,
    };
    let opts = SweepOptions {
        out: out.clone(),
        cache: cache(),
        shard: Shard::ALL,
        chunk: 0,
        repair: false,
    };
    run_sweep(&spec.checked(&names).unwrap(), &opts, &WindDown::new(), &()).unwrap();
    let text = std::fs::read_to_string(out.join("episodes.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| header.iter().position(|c| *c == n).unwrap();
    let (lv, ok, t) = (col("level"), col("success"), col("time_secs"));
    let mut levels = vec![Vec::new(); 5];
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        levels[f[lv].parse::<usize>().unwrap()].push((f[ok] == "1", f[t].parse::<f64>().unwrap()));
    }
    // Monte Carlo error of each median: the sd over 200 bootstrap samples.
    let mut rng = errp_bci::rng::labelled(1, "test/bootstrap");
    let stats: Vec<(f64, f64, f64)> = levels
        .iter()
        .map(|rows| {
            use rand::Rng;
            let boots: Vec<f64> = (0..200)
                .map(|_| {
                    let b: Vec<(bool, f64)> = (0..rows.len())
                        .map(|_| rows[rng.random_range(0..rows.len())])
                        .collect();
                    median_time_to_goal(&b)
                })
                .filter(|v| v.is_finite())
                .collect();
            let m = boots.iter().sum::<f64>() / boots.len().max(1) as f64;
            let sd = (boots.iter().map(|v| (v - m).powi(2)).sum::<f64>()
                / boots.len().max(2) as f64)
                .sqrt();
            let reached = rows.iter().filter(|r| r.0).count() as f64 / rows.len() as f64;
            (median_time_to_goal(rows), sd, reached)
        })
        .collect();
    for w in stats.windows(2) {
        let ((m0, s0, _), (m1, s1, _)) = (w[0], w[1]);
        let tolerance = 2.0 * (s0.max(0.0).hypot(s1.max(0.0)));
        assert!(
            m1 <= m0 + tolerance || m0.is_infinite(),
            "median time to Pisa rose with accuracy: {stats:?}"
        );
    }
    // And the share that reaches Pisa rises (within 2 binomial sd).
    for w in stats.windows(2) {
        let (p0, p1) = (w[0].2, w[1].2);
        let sd = ((p0 * (1.0 - p0) + p1 * (1.0 - p1)) / 500.0).sqrt();
        assert!(p1 >= p0 - 2.0 * sd, "{stats:?}");
    }
    // At the top of the range the median is finite: most runs reach Pisa.
    assert!(stats[4].0.is_finite() && stats[4].2 > 0.8, "{stats:?}");
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn the_shipped_grid_q_scale_is_the_committed_fit() {
    let text = std::fs::read_to_string(repo("fits/grid.json")).unwrap();
    let fit: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(fit["format"], 1);
    assert_eq!(fit["parameter"], "control.goal_reward");
    let commit = fit["provenance"]["commit"].as_str().unwrap();
    assert!(
        commit.len() == 40 && commit.chars().all(|c| c.is_ascii_hexdigit()),
        "fits/grid.json was made by {commit:?}, not a clean commit"
    );
    // At the command's defaults.
    assert_eq!(fit["spec"]["calibrations"], 5);
    assert_eq!(fit["spec"]["repeats"], 40);
    assert_eq!(fit["spec"]["epsilon"], 0.1);
    let total = numbers(&fit["surface"]["total"]);
    let grid = numbers(&fit["surface"]["grid"]);
    assert!(grid.iter().all(|g| g.is_finite()), "{grid:?}");
    let estimate = fit["estimate"].as_f64().unwrap();
    assert_eq!(grid[errp_sweep::fit::argmax(&total)], estimate);
    // The shipped scale: the largest likelihood where the paper's 40/40 is
    // not rejected.
    let p_all = numbers(&fit["p_all_reached"]);
    let kept: Vec<usize> = (0..grid.len())
        .filter(|&j| p_all[j] >= errp_sweep::fit::REACHED_LEVEL)
        .collect();
    let best = kept
        .iter()
        .copied()
        .max_by(|&a, &b| total[a].total_cmp(&total[b]))
        .unwrap();
    let shipped = fit["reached_estimate"].as_f64().unwrap();
    assert_eq!(grid[best], shipped);
    let defaults = errp_sim::grid::GridTaskParams::default().control;
    assert_eq!(defaults.goal_reward, shipped);
    assert_eq!(defaults.epsilon, 0.1);
    let control = |file: &str| -> toml::Table {
        let text = std::fs::read_to_string(repo(file)).unwrap();
        let table: toml::Table = toml::from_str(&text).unwrap();
        table["control"].as_table().unwrap().clone()
    };
    for file in [
        "scenarios/grid_fixed_goals.toml",
        "scenarios/grid_free_goals.toml",
    ] {
        assert_eq!(
            control(file)["goal_reward"].as_float(),
            Some(shipped),
            "{file} and fits/grid.json disagree"
        );
    }
    assert_eq!(
        control("scenarios/variants/grid_fixed_goals_mle.toml")["goal_reward"].as_float(),
        Some(estimate)
    );
    // The fixed pairs: fitted over the default lengths, the shipped ones
    // are the fit's set of the chosen length, in the scenario files, in
    // `FIXED_PAIRS` (what `errp table1` runs), and in the ten-seed Table 1.
    let pairs = &fit["pairs"];
    let lengths: Vec<f64> = numbers(&fit["spec"]["pair_lengths"]);
    assert_eq!(lengths, (5..=28).map(f64::from).collect::<Vec<_>>());
    let example: Vec<(Cell, Cell)> = pairs["example"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let cell = |c: &serde_json::Value| {
                Cell::new(
                    c["x"].as_u64().unwrap() as usize,
                    c["y"].as_u64().unwrap() as usize,
                )
            };
            (cell(&p[0]), cell(&p[1]))
        })
        .collect();
    assert_eq!(example, FIXED_PAIRS.to_vec());
    assert_eq!(
        pairs["chosen"].as_u64(),
        Some(errp_sim::grid::total_length(&FIXED_PAIRS) as u64)
    );
    assert_eq!(
        pairs["reached_estimate"][1].as_f64(),
        Some(shipped),
        "the 40/40 point's goal reward is the shipped one"
    );
    let episodes = |file: &str| -> Vec<(Cell, Cell)> {
        let text = std::fs::read_to_string(repo(file)).unwrap();
        let table: toml::Table = toml::from_str(&text).unwrap();
        table["episode"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| {
                let cell = |k: &str| {
                    let v = e[k].as_array().unwrap();
                    Cell::new(
                        v[0].as_integer().unwrap() as usize,
                        v[1].as_integer().unwrap() as usize,
                    )
                };
                (cell("start"), cell("goal"))
            })
            .collect()
    };
    for file in [
        "scenarios/grid_fixed_goals.toml",
        "scenarios/variants/grid_fixed_goals_ideal.toml",
        "scenarios/variants/grid_fixed_goals_mle.toml",
    ] {
        assert_eq!(episodes(file), FIXED_PAIRS.to_vec(), "{file}");
    }
    let seeds = std::fs::read_to_string(repo("docs/figures/table1_seeds.txt")).unwrap();
    let header = seeds.lines().next().unwrap();
    assert!(
        header.contains(&errp_sim::grid::pairs_text(&FIXED_PAIRS))
            && header.contains(&format!(
                "goal reward {}",
                errp_sim::task::format_number(shipped)
            )),
        "docs/figures/table1_seeds.txt was run with other pairs or another goal reward: {header}"
    );
}

/// Runs the grid fit of `spec` into `out` to its end.
fn complete_grid_fit(spec: &GridFitSpec, out: &std::path::Path) -> Box<errp_sweep::fit::GridFit> {
    let wind_down = WindDown::new();
    let GridFitOutcome::Complete(fit, _) =
        run_grid_fit(spec, out, &cache(), provenance(), &wind_down, &()).unwrap()
    else {
        panic!("not interrupted")
    };
    fit
}

/// A grid fit small enough for a test: two goal rewards, one calibration
/// per subject and goal set, two groups, the shipped pairs.
fn small_grid_spec() -> GridFitSpec {
    GridFitSpec {
        goal_rewards: vec![1.0, 8.0],
        epsilon: 0.1,
        calibrations: 1,
        repeats: 2,
        seed: 5,
        bootstrap: 10,
        realism: errp_bci::Realism::published(),
        pair_lengths: Vec::new(),
        trial_latency_sds: Vec::new(),
    }
}

#[test]
fn a_small_grid_fit_writes_its_files_and_refuses_bad_settings() {
    let out = temp_dir("fit-grid");
    let spec = small_grid_spec();
    let wind_down = WindDown::new();
    let GridFitOutcome::Complete(fit, files) =
        run_grid_fit(&spec, &out, &cache(), provenance(), &wind_down, &()).unwrap()
    else {
        panic!("not interrupted")
    };
    assert_eq!(files.len(), 4);
    assert!(spec.goal_rewards.contains(&fit.estimate.value));
    // 4 subjects x 2 points, 2 groups of 5 runs each.
    assert_eq!(fit.fixed_stats.len(), 4);
    assert!(
        fit.fixed_stats
            .iter()
            .chain(&fit.free_stats)
            .flatten()
            .all(|s| s.runs == 10 && s.groups.0 == 2)
    );
    assert!(fit.fixed_tables.iter().all(|t| t.tables == 2));
    // A larger Q scale moves the belief further per action: fewer actions
    // for the subject with the best decoder (S1), on both goal sets.
    for stats in [&fit.fixed_stats, &fit.free_stats] {
        assert!(stats[0][1].actions.0 < stats[0][0].actions.0, "{stats:?}");
    }
    let csv = std::fs::read_to_string(out.join("surface.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
    assert!(csv.starts_with("goal_reward,log_lik,"), "{csv}");
    // A directory holding anything else is refused, untouched.
    let foreign = temp_dir("fit-grid-foreign");
    std::fs::create_dir_all(&foreign).unwrap();
    std::fs::write(foreign.join("mine.txt"), "mine").unwrap();
    let e = run_grid_fit(&spec, &foreign, &cache(), provenance(), &wind_down, &())
        .unwrap_err()
        .to_string();
    assert!(e.contains("mine.txt") && e.contains("--out"), "{e}");
    assert_eq!(std::fs::read_dir(&foreign).unwrap().count(), 1);
    for (bad, flag) in [
        (
            GridFitSpec {
                epsilon: 1.0,
                ..spec.clone()
            },
            "--epsilon 1",
        ),
        (
            GridFitSpec {
                goal_rewards: vec![2.0, 1.0],
                ..spec.clone()
            },
            "--goal-reward",
        ),
        (
            GridFitSpec {
                repeats: 1,
                ..spec.clone()
            },
            "--repeats 1",
        ),
        (
            GridFitSpec {
                pair_lengths: vec![4],
                ..spec.clone()
            },
            "--pair-length 4 is invalid",
        ),
        (
            GridFitSpec {
                pair_lengths: vec![12, 8],
                ..spec.clone()
            },
            "--pair-length must list increasing",
        ),
        (
            GridFitSpec {
                trial_latency_sds: vec![150.0],
                ..spec.clone()
            },
            "--trial-latency-sd 150 is invalid",
        ),
        (
            GridFitSpec {
                trial_latency_sds: vec![21.3, 16.7],
                ..spec.clone()
            },
            "--trial-latency-sd must list increasing",
        ),
    ] {
        let e = run_grid_fit(&bad, &out, &cache(), provenance(), &wind_down, &())
            .unwrap_err()
            .to_string();
        assert!(e.contains(flag), "{e}");
    }
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(&foreign);
}

/// The fixed pairs' length fitted with the goal reward: a profile per
/// length, shorter pairs taking fewer actions at every goal reward, and the
/// chosen length's example set of that length, with run 3 central.
#[test]
#[ignore = "slow (a grid fit over two pair lengths, 108 s): `cargo test --workspace -- --ignored` and CI run it"]
fn a_grid_fit_over_pair_lengths_profiles_each_length() {
    let out = temp_dir("fit-grid-pairs");
    let spec = GridFitSpec {
        repeats: 4,
        pair_lengths: vec![8, 28],
        ..small_grid_spec()
    };
    let fit = complete_grid_fit(&spec, &out);
    let pairs = fit.pairs.as_ref().expect("fitted over lengths");
    assert_eq!(pairs.lengths, vec![8, 28]);
    assert!(pairs.profile.iter().all(|l| !l.is_nan()), "{pairs:?}");
    for subject in 0..4 {
        for point in 0..2 {
            let (short, long) = (
                pairs.fixed_actions[0][subject][point],
                pairs.fixed_actions[1][subject][point],
            );
            assert!(short < long, "S{}: {short} against {long}", subject + 1);
        }
    }
    assert!(spec.pair_lengths.contains(&pairs.chosen));
    let family = errp_sim::grid::PairFamily::paper();
    assert!(family.contains(&pairs.example));
    assert_eq!(errp_sim::grid::total_length(&pairs.example), pairs.chosen);
    let json = std::fs::read_to_string(out.join("fit.json")).unwrap();
    assert!(json.contains("\"pair_lengths\"") && json.contains("\"example\""));
    let _ = std::fs::remove_dir_all(&out);
}

/// The single-trial latency SD fitted with the rest: one whole fit per SD,
/// each at its own users (with common random numbers, users that ignored
/// the SD would give the same runs bit for bit), and the result at the
/// chosen SD.
#[test]
#[ignore = "slow (two grid fits, 108 s): `cargo test --workspace -- --ignored` and CI run it"]
fn a_grid_fit_over_trial_latency_sds_runs_each_users() {
    let out = temp_dir("fit-grid-trial");
    let spec = GridFitSpec {
        trial_latency_sds: vec![5.0, 60.0],
        ..small_grid_spec()
    };
    let fit = complete_grid_fit(&spec, &out);
    let trial = fit.trial_latency.as_ref().expect("fitted over SDs");
    assert_eq!(trial.sds, vec![5.0, 60.0]);
    assert!(trial.profile.iter().all(|l| !l.is_nan()), "{trial:?}");
    assert!(trial.sds.contains(&trial.chosen) && trial.sds.contains(&trial.estimate));
    assert_ne!(trial.fixed_z[0], trial.fixed_z[1], "{trial:?}");
    assert_ne!(trial.free_z[0], trial.free_z[1], "{trial:?}");
    assert_eq!(fit.spec, spec);
    let json = std::fs::read_to_string(out.join("fit.json")).unwrap();
    assert!(json.contains("\"trial_latency\"") && json.contains("\"trial_latency_sds\""));
    let _ = std::fs::remove_dir_all(&out);
}
