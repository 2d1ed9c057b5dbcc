//! Property tests of the scenario loaders. Every shipped scenario is
//! changed field by field (any field it has or could have, to edge values
//! of every TOML type), and byte by byte as text: the result is loaded or
//! refused, never a panic; a refusal names the file; what loads stays
//! within the documented bounds; and the file's text and its table (the
//! path of command-line overrides and sweeps) agree on what they accept.

use std::path::Path;

use errp_sim::epuck::{MAX_OBSTACLES, MAX_RUN_SECS, MAX_RUNS, MAX_TRACKER_HZ};
use errp_sim::grid::{MAX_ACTIONS, MAX_BANK_PER_CLASS, MAX_EPISODES, MAX_INTERVAL_SECS};
use errp_sim::{AnyScenario, parse_scenario, parse_scenario_table};
use proptest::prelude::*;
use toml::{Table, Value};

const SHIPPED: [&str; 5] = [
    include_str!("../../../scenarios/grid_fixed_goals.toml"),
    include_str!("../../../scenarios/grid_free_goals.toml"),
    include_str!("../../../scenarios/mexico_to_pisa.toml"),
    include_str!("../../../scenarios/lisbon_to_tokyo.toml"),
    include_str!("../../../scenarios/obstacles_havana_to_seoul.toml"),
];

/// Fields a scenario may have (of either task), beside those it has.
const FIELDS: &[&str] = &[
    "task",
    "seed",
    "name",
    "decoder",
    "p_error",
    "eeg",
    "bank_per_class",
    "repeats",
    "runs",
    "max_secs",
    "start",
    "goal",
    "start_heading_deg",
    "user.accuracy",
    "user.subject",
    "user.goals",
    "user.hit_rate",
    "user.false_alarms_per_min",
    "user.fov_deg",
    "user.reaction_latency_ms",
    "user.reelicit_secs",
    "user.seed",
    "free_goals.count",
    "timing.interval_min_secs",
    "timing.interval_max_secs",
    "timing.epoch_secs",
    "timing.max_actions",
    "control.tau",
    "control.epsilon",
    "control.p_c",
    "control.t_e",
    "control.stop_secs",
    "control.goal_hold_secs",
    "control.strategy",
    "control.goal_reward",
    "control.wrong_goal_reward",
    "control.discount",
    "tracker.rate_hz",
    "tracker.position_noise_cm",
    "detector.mode",
    "detector.smooth_windows",
    "detector.refractory_secs",
    "avoidance.enabled",
    "episode.0.start",
    "episode.0.goal",
    "episode",
    "arena.obstacle.0.center_cm",
    "arena.obstacle.0.size_cm",
    "arena.obstacle.0.radius_cm",
    "arena.obstacle.0.shape",
    "arena.obstacle",
    "colour",
];

/// Values at the edges of every TOML type and of the fields' ranges.
fn edge_value() -> impl Strategy<Value = Value> {
    let number = prop_oneof![
        Just(0.0),
        Just(-0.0),
        Just(0.5),
        Just(1.0),
        Just(1.5),
        Just(-1.0),
        Just(1e9),
        Just(1e12),
        Just(1e300),
        Just(1e-300),
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        any::<f64>(),
        -1e4..1e4f64,
    ];
    let leaf = prop_oneof![
        prop_oneof![
            Just(0i64),
            Just(1),
            Just(-1),
            Just(2),
            Just(5),
            Just(1000),
            Just(20_001),
            Just(100_001),
            Just(1_000_000_000),
            Just(i64::MAX),
            Just(i64::MIN),
            any::<i64>(),
        ]
        .prop_map(Value::Integer),
        number.prop_map(Value::Float),
        prop_oneof![
            Just(String::new()),
            Just("x".to_string()),
            Just("greedy".to_string()),
            Just("thompson".to_string()),
            Just("oracle".to_string()),
            Just("bank".to_string()),
            Just("literal".to_string()),
            Just("Mexico".to_string()),
            Just("Pisa".to_string()),
            Just("box".to_string()),
            Just("circle".to_string()),
            Just("S2".to_string()),
            Just("a".repeat(100_000)),
            "\\PC{0,20}",
        ]
        .prop_map(Value::String),
        any::<bool>().prop_map(Value::Boolean),
    ];
    leaf.prop_recursive(2, 8, 4, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..4).prop_map(Value::Array),
            prop::collection::btree_map("[a-z_]{1,8}", inner, 0..3)
                .prop_map(|m| Value::Table(m.into_iter().collect())),
        ]
    })
}

/// Sets `key` (dotted; a number indexes an array of tables) in `t`,
/// creating what is missing; a path through a value that is not a table is
/// left as it is.
fn set(t: &mut Table, key: &str, value: Value) {
    let parts: Vec<&str> = key.split('.').collect();
    let mut here = t;
    let mut i = 0;
    while i + 1 < parts.len() {
        let part = parts[i];
        let entry = here
            .entry(part.to_string())
            .or_insert_with(|| Value::Table(Table::new()));
        let next = match entry {
            Value::Array(items) if parts[i + 1].parse::<usize>().is_ok() => {
                let k: usize = parts[i + 1].parse().unwrap();
                i += 1;
                if items.is_empty() {
                    items.push(Value::Table(Table::new()));
                }
                let n = items.len();
                items[k.min(n - 1)].as_table_mut()
            }
            Value::Table(table) => Some(table),
            _ => None,
        };
        match next {
            Some(n) => here = n,
            None => return,
        }
        i += 1;
    }
    if i < parts.len() {
        here.insert(parts[i].to_string(), value);
    }
}

/// What every accepted scenario must keep to: the documented bounds.
fn within_bounds(s: &AnyScenario) {
    match s {
        AnyScenario::Grid(g) => {
            assert!(!g.episodes.is_empty() && g.episodes.len() <= MAX_EPISODES);
            assert!((1..=MAX_BANK_PER_CLASS as usize).contains(&g.bank_per_class));
            let p = &g.params;
            assert!((1..=MAX_ACTIONS as usize).contains(&p.max_actions));
            assert!(p.interval_max_secs <= MAX_INTERVAL_SECS);
            assert!(p.epoch_secs > 0.0 && p.epoch_secs <= p.interval_min_secs);
            if let Some(a) = g.accuracy.requested() {
                assert!(a.get() > 0.5 && a.get() <= 1.0);
                assert_eq!(p.control.assumed_accuracy, a.get());
            }
        }
        AnyScenario::Epuck(e) => {
            assert!((1..=MAX_RUNS as usize).contains(&e.runs));
            assert!(e.params.max_secs > 0.0 && e.params.max_secs <= MAX_RUN_SECS);
            assert!(e.params.tracker.rate_hz <= MAX_TRACKER_HZ);
            assert!(e.arena.obstacles.len() <= MAX_OBSTACLES);
            for o in &e.arena.obstacles {
                let ((x0, y0), (x1, y1)) = o.bounds();
                assert!(x0 >= -1e-6 && y0 >= -1e-6 && x1 <= 2.0 + 1e-6 && y1 <= 2.0 + 1e-6);
            }
        }
    }
}

/// The edge values of [`edge_value`], listed: every one is tried in every
/// field of every shipped scenario.
fn edge_values() -> Vec<Value> {
    let mut v: Vec<Value> = [
        0i64,
        1,
        -1,
        2,
        5,
        16,
        17,
        1000,
        10_001,
        20_001,
        100_001,
        1_000_000_000,
        i64::MAX,
        i64::MIN,
    ]
    .map(Value::Integer)
    .to_vec();
    v.extend(
        [
            0.0,
            -0.0,
            0.5,
            0.75,
            1.0,
            1.5,
            -1.0,
            60.5,
            3600.5,
            1e9,
            1e12,
            1e300,
            1e-300,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ]
        .map(Value::Float),
    );
    v.extend(
        [
            "", "x", "greedy", "thompson", "oracle", "bank", "literal", "Mexico", "box",
        ]
        .map(|s| Value::String(s.into())),
    );
    v.push(Value::String("a".repeat(100_000)));
    v.push(Value::Boolean(true));
    for items in [vec![], vec![1], vec![1, 2], vec![0, 0, 7], vec![300, 300]] {
        v.push(Value::Array(
            items.into_iter().map(Value::Integer).collect(),
        ));
    }
    v.push(Value::Array(vec![
        Value::Float(60.0),
        Value::Float(f64::NAN),
    ]));
    v.push(Value::Table(Table::new()));
    v
}

/// Every field (of either task) of every shipped scenario, set to every
/// edge value, one at a time: 5 x 51 x 48 = 12 240 scenarios.
#[test]
fn every_field_at_every_edge_value_loads_within_bounds_or_is_refused_naming_the_file() {
    let path = Path::new("fuzzed.toml");
    let (mut accepted, mut refused) = (0, 0);
    for text in SHIPPED {
        let base: Table = toml::from_str(text).unwrap();
        for field in FIELDS {
            for value in edge_values() {
                let mut table = base.clone();
                set(&mut table, field, value.clone());
                match parse_scenario_table(&table, path) {
                    Ok(s) => {
                        within_bounds(&s);
                        accepted += 1;
                    }
                    Err(e) => {
                        let e = e.to_string();
                        assert!(e.contains("fuzzed.toml"), "{field} = {value}: {e}");
                        for rust in ["usize", "u64", "f64", "i64", "untagged", "struct "] {
                            assert!(!e.contains(rust), "{field} = {value}: {e}");
                        }
                        refused += 1;
                    }
                }
            }
        }
    }
    assert_eq!(
        accepted + refused,
        SHIPPED.len() * FIELDS.len() * edge_values().len()
    );
    assert!(accepted > 500 && refused > 5000, "{accepted} {refused}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    /// Up to three fields of a shipped scenario set to edge values.
    #[test]
    fn any_field_changed_loads_within_bounds_or_is_refused_naming_the_file(
        which in 0..SHIPPED.len(),
        changes in prop::collection::vec((0..FIELDS.len(), edge_value()), 1..4),
    ) {
        let mut table: Table = toml::from_str(SHIPPED[which]).unwrap();
        for (field, value) in changes {
            set(&mut table, FIELDS[field], value);
        }
        let path = Path::new("fuzzed.toml");
        let from_table = parse_scenario_table(&table, path);
        match &from_table {
            Ok(s) => within_bounds(s),
            Err(e) => prop_assert!(e.to_string().contains("fuzzed.toml"), "{e}"),
        }
        // Written out and read as a file, it is accepted or refused alike.
        if let Ok(text) = toml::to_string(&table) {
            let from_text = parse_scenario(&text, path);
            prop_assert_eq!(from_text.is_ok(), from_table.is_ok(), "{:?}", from_text.err());
        }
    }

    /// A shipped scenario's text with bytes changed, inserted or removed.
    #[test]
    fn any_text_edit_loads_within_bounds_or_is_refused_naming_the_file(
        which in 0..SHIPPED.len(),
        edits in prop::collection::vec((any::<prop::sample::Index>(), 0..3u8, any::<u8>()), 1..6),
    ) {
        let mut bytes = SHIPPED[which].as_bytes().to_vec();
        for (at, kind, byte) in edits {
            let i = at.index(bytes.len());
            match kind {
                0 => bytes[i] = byte,
                1 => bytes.insert(i, byte),
                _ => {
                    bytes.remove(i);
                }
            }
        }
        let Ok(text) = String::from_utf8(bytes) else {
            return Ok(()); // read_scenario refuses what is not UTF-8
        };
        match parse_scenario(&text, Path::new("edited.toml")) {
            Ok(s) => within_bounds(&s),
            Err(e) => prop_assert!(e.to_string().contains("edited.toml"), "{e}"),
        }
    }
}
