//! The continuous e-puck task end to end: rapier2d arena, synthetic user,
//! streamed EEG, sliding-window SVM and shared control, with fixed seeds.

use errp_bci::{AssessmentKind, DetectorParams, EegGenerator, MeanAccuracy, SlidingWindow};
use errp_robot::{EpuckParams, Pose, Twist};
use errp_sim::epuck::{
    ArenaSpec, EpuckObserver, EpuckScenario, PhysicsFrame, World, finish_continuous_decoder,
    prepare_continuous_decoder, run_epuck_batch, run_epuck_once, summarise,
};
use rand::{Rng, SeedableRng};

pub(crate) fn scenario(name: &str) -> EpuckScenario {
    let path = format!("{}/../scenarios/{name}", env!("CARGO_MANIFEST_DIR"));
    errp_sim::ScenarioInput::load_as_written(errp_sim::ScenarioSource::File(path.into()))
        .unwrap()
        .into_epuck()
        .unwrap()
}

/// Checks every physics frame against the arena's walls.
struct Bounds {
    radius_m: f64,
    size_m: f64,
    worst_m: f64,
    frames: usize,
}

impl EpuckObserver for Bounds {
    fn on_physics(&mut self, f: &PhysicsFrame) {
        let p = f.pose;
        let clearance = [
            p.x_m - self.radius_m,
            p.y_m - self.radius_m,
            self.size_m - self.radius_m - p.x_m,
            self.size_m - self.radius_m - p.y_m,
        ];
        self.worst_m = clearance.iter().copied().fold(self.worst_m, f64::min);
        self.frames += 1;
    }
}

#[test]
fn at_95_percent_most_runs_reach_pisa_and_none_slides_sideways() {
    // The idealised user: the physics and the belief, not the task shift.
    let mut s = scenario("variants/mexico_to_pisa_ideal.toml");
    s.accuracy = MeanAccuracy::new(0.95).unwrap();
    s.seed = 11;
    let (decoder, report) = prepare_continuous_decoder(&s, |_| {}).unwrap();
    assert!(
        (report.calibrated.accuracy.mean() - 0.95).abs() < 0.03,
        "{:?}",
        report.calibrated.accuracy
    );
    let results = run_epuck_batch(&s, &decoder, 10).unwrap();
    // About 90 % of runs reach Pisa at 95 % (`errp fit epuck`): at least
    // 8 of 10 (a 93 % chance at 90 %; 35 % at 70 %).
    let reached = results.iter().filter(|r| r.reached()).count();
    assert!(reached >= 8, "{reached} of 10: {results:?}");
    for (k, r) in results.iter().enumerate() {
        // The body only ever moves along its heading (a differential drive).
        assert!(r.max_lateral_m_per_s < 2e-3, "run {k}: {r:?}");
        if r.reached() {
            assert!(r.time_secs < 400.0, "run {k}: {r:?}");
            assert!(r.path_m > 2.2, "at least the straight line: {r:?}");
        }
    }
    // The detector is mostly right at this accuracy.
    let detected: usize = results.iter().map(|r| r.detected_errors).sum();
    let false_: usize = results.iter().map(|r| r.false_detections).sum();
    assert!(
        detected > 0 && 4 * false_ < detected,
        "{detected} detected, {false_} false"
    );
}

#[test]
fn at_chance_the_belief_does_not_find_the_goal() {
    // A decoder calibrated at 55 % fires almost at random: the run should
    // rarely end on Pisa within two minutes.
    let mut s = scenario("mexico_to_pisa.toml");
    s.accuracy = MeanAccuracy::new(0.55).unwrap();
    s.params.max_secs = 120.0;
    let (decoder, _) = prepare_continuous_decoder(&s, |_| {}).unwrap();
    let results = run_epuck_batch(&s, &decoder, 6).unwrap();
    let reached = results.iter().filter(|r| r.reached()).count();
    assert!(reached <= 1, "{reached} of 6 reached Pisa at chance");
}

#[test]
fn walls_never_let_the_robot_out_even_driven_blindly() {
    let epuck = EpuckParams::default();
    let arena = ArenaSpec::paper();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2);
    let mut world = World::new(&arena, &epuck, Pose::new(1.0, 1.0, 0.3), 1.0 / 64.0).unwrap();
    let mut bounds = Bounds {
        radius_m: epuck.body_diameter_m / 2.0,
        size_m: arena.size_m,
        worst_m: f64::INFINITY,
        frames: 0,
    };
    // Five minutes of full speed with random turns, no obstacle reflex.
    let top = epuck.max_speed_m_per_s();
    for k in 0..64 * 300 {
        let w = if (k / 64) % 3 == 0 {
            rng.random_range(-2.0..2.0)
        } else {
            0.0
        };
        world.step(Twist {
            linear_m_per_s: top,
            angular_rad_per_s: w,
        });
        bounds.on_physics(&PhysicsFrame {
            time_secs: k as f64 / 64.0,
            pose: world.pose(),
            tracked: world.pose(),
            wheels: Default::default(),
            phase: 1,
            target: 0,
        });
    }
    assert!(
        bounds.worst_m > -0.005,
        "penetrated a wall by {} m",
        -bounds.worst_m
    );
}

#[test]
#[ignore = "slow (every shipped e-puck scenario, 13 s): `cargo test --workspace -- --ignored` and CI run it"]
fn every_epuck_scenario_loads_and_runs_inside_the_arena() {
    let dir = format!("{}/../scenarios", env!("CARGO_MANIFEST_DIR"));
    let mut n = 0;
    let variants = format!("{dir}/variants");
    let mut paths: Vec<std::path::PathBuf> = Vec::new();
    for d in [&dir, &variants] {
        for entry in std::fs::read_dir(d).unwrap() {
            paths.push(entry.unwrap().path());
        }
    }
    for path in paths {
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        if !text.contains("task = \"epuck\"") {
            continue;
        }
        let mut s =
            errp_sim::ScenarioInput::load_as_written(errp_sim::ScenarioSource::File(path.clone()))
                .unwrap()
                .into_epuck()
                .unwrap();
        s.params.max_secs = 30.0;
        let (decoder, _) = prepare_continuous_decoder(&s, |_| {}).unwrap();
        let mut bounds = Bounds {
            radius_m: s.params.control.epuck.body_diameter_m / 2.0,
            size_m: s.arena.size_m,
            worst_m: f64::INFINITY,
            frames: 0,
        };
        let r = run_epuck_once(&s, &decoder, 0, &mut bounds).unwrap();
        assert!(
            bounds.frames > 0 && bounds.worst_m > -0.005,
            "{path:?}: {r:?}"
        );
        assert!(r.max_lateral_m_per_s < 2e-3, "{path:?}: {r:?}");
        n += 1;
    }
    assert!(
        n >= 7,
        "the two paper runs, an obstacle scenario and four variants"
    );
}

#[test]
fn the_obstacle_reflex_keeps_the_robot_off_the_pillar() {
    let mut s = scenario("obstacles_havana_to_seoul.toml");
    s.params.max_secs = 90.0;
    let (decoder, _) = prepare_continuous_decoder(&s, |_| {}).unwrap();
    struct Clear {
        obstacles: Vec<errp_sim::epuck::Obstacle>,
        radius_m: f64,
        closest_m: f64,
    }
    impl EpuckObserver for Clear {
        fn on_physics(&mut self, f: &PhysicsFrame) {
            for o in &self.obstacles {
                let d = o.signed_distance(f.pose.x_m, f.pose.y_m) - self.radius_m;
                self.closest_m = self.closest_m.min(d);
            }
        }
    }
    let mut clear = Clear {
        obstacles: s.arena.obstacles.clone(),
        radius_m: s.params.control.epuck.body_diameter_m / 2.0,
        closest_m: f64::INFINITY,
    };
    run_epuck_once(&s, &decoder, 0, &mut clear).unwrap();
    assert!(
        clear.closest_m > 0.0,
        "touched an obstacle: {}",
        clear.closest_m
    );
    assert!(
        clear.closest_m < 0.05,
        "the run never came near an obstacle"
    );
}

/// Sec. 5.3's first run at the shipped decoder (the accuracy fitted to the
/// paper's runs), and the paper's literal per-window reading beside it, on
/// the same calibration and the same seeds.
#[test]
fn the_default_detector_reproduces_section_5_3_where_the_literal_reading_fails() {
    // The idealised user at its own fit (90 %), whose figures these are
    // (docs/figures/epuck_mexico_ideal.txt).
    let s = scenario("variants/mexico_to_pisa_ideal.toml");
    let (decoder, report) = prepare_continuous_decoder(&s, |_| {}).unwrap();
    let online = decoder.online.clone().unwrap();
    assert!(
        online.point.hit_rate > 0.55 && online.point.false_alarms_per_min < 1.0,
        "{online}"
    );
    // 200 runs give 165 reached, a median of 60.7 s and 11 detections,
    // 0.22 detections a second (docs/guide/epuck.md, the ideal user); 60 of them, with
    // room for their sampling error.
    let runs = run_epuck_batch(&s, &decoder, 60).unwrap();
    let sum = summarise(&runs);
    assert!(sum.reached >= 42, "{sum:?}");
    assert!((45.0..=80.0).contains(&sum.median_secs), "{sum:?}");
    assert!((7.0..=16.0).contains(&sum.median_detected), "{sum:?}");
    assert!((0.15..=0.3).contains(&sum.detections_per_sec), "{sum:?}");

    let mut literal = s.clone();
    literal.params.detector = DetectorParams::literal();
    let literal_decoder = finish_continuous_decoder(&literal, &report).unwrap();
    let lit = literal_decoder.online.as_ref().unwrap();
    assert!(
        lit.point.false_alarms_per_min > online.point.false_alarms_per_min + 1.0,
        "{lit}"
    );
    let lruns = run_epuck_batch(&literal, &literal_decoder, 60).unwrap();
    let lsum = summarise(&lruns);
    assert!(
        lsum.median_detected > 16.0 || lsum.reached < 42 || lsum.median_secs > 80.0,
        "the literal reading meets the bounds too: {lsum:?}"
    );
}

/// The span over which detections are attributed to an ErrP is where the
/// decoder responds: measured on the held-out session, it holds the
/// training alignment (window end 0.8 s after time zero) and reaches past it,
/// and a strong single ErrP at a known time peaks inside it.
#[test]
fn detections_are_scored_over_the_span_where_the_decoder_responds() {
    let s = scenario("mexico_to_pisa.toml");
    let (decoder, _) = prepare_continuous_decoder(&s, |_| {}).unwrap();
    let span = decoder.online.as_ref().unwrap().window_span;
    assert!(
        (0.4..=0.75).contains(&span.from_secs) && (0.85..=1.3).contains(&span.to_secs),
        "{span:?}"
    );
    assert!(
        decoder.detection_span().to_secs > span.to_secs,
        "smoothing delays detections"
    );
    // ErrPs at known times, 5 s apart, in the user's own EEG.
    let generator = EegGenerator::new(&decoder.generator, &decoder.montage, 40).unwrap();
    let mut w = SlidingWindow::start(
        generator,
        &decoder.preprocessor,
        &decoder.features,
        &decoder.montage,
    )
    .unwrap();
    let errps: Vec<f64> = (0..30).map(|k| 3.0 + 5.0 * k as f64).collect();
    for &o in &errps {
        w.schedule(o, AssessmentKind::Error);
    }
    let t_e = 0.8;
    let mut first: Vec<Option<f64>> = vec![None; errps.len()];
    let mut last = vec![0.0f64; errps.len()];
    let mut trained_fires = 0;
    for i in 0..((155.0 / 0.0625) as usize) {
        w.advance();
        let t = (i + 1) as f64 * 0.0625;
        let p = w.p_error(&decoder.model);
        for (k, &o) in errps.iter().enumerate() {
            let lag = t - o;
            if (0.0..2.0).contains(&lag) && p >= t_e {
                first[k].get_or_insert(lag);
                last[k] = lag;
            }
            // The window aligned as in training starts at the ErrP.
            if (lag - 0.8).abs() <= 0.03125 + 1e-9 && p >= t_e {
                trained_fires += 1;
            }
        }
    }
    assert!(
        trained_fires >= 18,
        "{trained_fires} of 30 at the trained alignment"
    );
    let mut lags: Vec<f64> = first.iter().flatten().copied().collect();
    lags.sort_by(f64::total_cmp);
    let inside = lags.iter().filter(|&&l| span.contains(0.0, l)).count();
    assert!(
        inside * 10 >= lags.len() * 7,
        "{inside} of {} first crossings inside {span:?}: {lags:?}",
        lags.len()
    );
    assert!(span.contains(0.0, lags[lags.len() / 2]), "{lags:?}");
    // Windows go on responding after 0.8 s, where the old span ended and
    // called such detections false.
    last.sort_by(f64::total_cmp);
    assert!(last[last.len() / 2] > 0.8, "{last:?}");
}

/// A scenario can ask for an online operating point instead of an
/// accuracy: the ratio and T_e are calibrated until the held-out session
/// shows it.
#[test]
fn an_online_operating_point_is_calibrated_for() {
    let mut s = scenario("mexico_to_pisa.toml");
    s.online_target = Some(
        errp_bci::Valid::new(errp_bci::OnlineTarget {
            hit_rate: 0.7,
            false_alarms_per_min: Some(1.0),
        })
        .unwrap(),
    );
    let (decoder, _) = prepare_continuous_decoder(&s, |_| {}).unwrap();
    let online = decoder.online.as_ref().unwrap();
    assert!((online.point.hit_rate - 0.7).abs() <= 0.05, "{online}");
    assert!(
        (online.point.false_alarms_per_min - 1.0).abs() <= 0.35,
        "{online}"
    );
    assert_ne!(online.t_e, 0.8, "T_e is calibrated");
    assert_eq!(decoder.detector_t_e(&s.params, false), online.t_e);
    assert_eq!(decoder.detector_t_e(&s.params, true), s.params.control.t_e);
}
