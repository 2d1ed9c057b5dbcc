//! The continuous e-puck task end to end: rapier2d arena, synthetic user,
//! streamed EEG, sliding-window SVM and shared control, with fixed seeds.

use errp_robot::{EpuckParams, Pose, Twist};
use errp_sim::{
    ArenaSpec, EpuckObserver, EpuckScenario, PhysicsFrame, World, prepare_continuous_decoder,
    run_epuck_batch, run_epuck_once,
};
use rand::{Rng, SeedableRng};

fn scenario(name: &str) -> EpuckScenario {
    let path = format!("{}/../scenarios/{name}", env!("CARGO_MANIFEST_DIR"));
    EpuckScenario::load(path).unwrap()
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
fn at_95_percent_the_robot_reaches_pisa_in_all_of_10_runs_and_never_slides_sideways() {
    let mut s = scenario("mexico_to_pisa.toml");
    s.accuracy = 0.95;
    s.seed = 11;
    let (decoder, report) = prepare_continuous_decoder(&s, |_| {}).unwrap();
    assert!(
        (report.calibrated.accuracy.mean() - 0.95).abs() < 0.03,
        "{:?}",
        report.calibrated.accuracy
    );
    let results = run_epuck_batch(&s, &decoder, 10).unwrap();
    for (k, r) in results.iter().enumerate() {
        assert!(r.reached(), "run {k}: {r:?}");
        assert!(r.time_secs < 400.0, "run {k}: {r:?}");
        // The body only ever moves along its heading (a differential drive).
        assert!(r.max_lateral_m_per_s < 2e-3, "run {k}: {r:?}");
        assert!(r.path_m > 2.2, "at least the straight line: {r:?}");
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
    s.accuracy = 0.55;
    s.params.max_secs = 120.0;
    let (decoder, _) = prepare_continuous_decoder(&s, |_| {}).unwrap();
    let results = run_epuck_batch(&s, &decoder, 6).unwrap();
    let reached = results.iter().filter(|r| r.reached()).count();
    assert!(reached <= 1, "{reached} of 6 reached Pisa at chance");
}

#[test]
fn the_same_seed_gives_the_same_run() {
    let mut s = scenario("lisbon_to_tokyo.toml");
    s.params.max_secs = 40.0;
    let (decoder, _) = prepare_continuous_decoder(&s, |_| {}).unwrap();
    let a = run_epuck_once(&s, &decoder, 3, &mut ()).unwrap();
    let b = run_epuck_once(&s, &decoder, 3, &mut ()).unwrap();
    assert_eq!(a, b);
    let c = run_epuck_once(&s, &decoder, 4, &mut ()).unwrap();
    assert_ne!(a, c, "another run index, another run");
    // The batch (parallel) gives the runs in order, identical to one by one.
    let batch = run_epuck_batch(&s, &decoder, 5).unwrap();
    assert_eq!(batch[3], a);
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
        });
    }
    assert!(
        bounds.worst_m > -0.005,
        "penetrated a wall by {} m",
        -bounds.worst_m
    );
}

#[test]
fn every_epuck_scenario_loads_and_runs_inside_the_arena() {
    let dir = format!("{}/../scenarios", env!("CARGO_MANIFEST_DIR"));
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        if !text.contains("task = \"epuck\"") {
            continue;
        }
        let mut s = EpuckScenario::load(&path).unwrap();
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
    assert!(n >= 3, "the two paper runs and an obstacle scenario");
}

#[test]
fn the_obstacle_reflex_keeps_the_robot_off_the_pillar() {
    let mut s = scenario("obstacles_havana_to_seoul.toml");
    s.params.max_secs = 90.0;
    let (decoder, _) = prepare_continuous_decoder(&s, |_| {}).unwrap();
    struct Clear {
        obstacles: Vec<errp_sim::Obstacle>,
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
