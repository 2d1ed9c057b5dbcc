//! The scenario's camera tracker, obstacles and arena, checked and in SI units.

#[allow(clippy::wildcard_imports, unused_imports)]
use super::*;

/// The ceiling camera of a `[tracker]` table, on the defaults.
pub(super) fn tracker_params(t: Option<&TrackerFile>, path: &Path) -> Result<TrackerParams> {
    let bad =
        |field: &str, value: String, expected: &str| field_error(path, field, value, expected);
    let mut tracker = TrackerParams::default();
    if let Some(t) = t {
        if let Some(v) = t.rate_hz {
            if !(v.is_finite() && (1.0..=MAX_TRACKER_HZ).contains(&v)) {
                return Err(bad(
                    "tracker.rate_hz",
                    v.to_string(),
                    &format!("a frame rate from 1 to {MAX_TRACKER_HZ} Hz (default 30)"),
                ));
            }
            tracker.rate_hz = v;
        }
        if let Some(v) = t.position_noise_cm {
            if !(v.is_finite() && (0.0..=50.0).contains(&v)) {
                return Err(bad(
                    "tracker.position_noise_cm",
                    v.to_string(),
                    "a standard deviation from 0 to 50 cm (default 0.2)",
                ));
            }
            tracker.position_noise_m = v / 100.0;
        }
        if let Some(v) = t.heading_noise_deg {
            if !(v.is_finite() && (0.0..=180.0).contains(&v)) {
                return Err(bad(
                    "tracker.heading_noise_deg",
                    v.to_string(),
                    "a standard deviation from 0 to 180 degrees (default 1)",
                ));
            }
            tracker.heading_noise_rad = v.to_radians();
        }
    }
    tracker
        .validate()
        .map_err(|e| SimError::Scenario(format!("{}: {e}", path.display())))?;
    Ok(tracker)
}

/// Obstacle `k` of `[[arena.obstacle]]`: a box or a circle whose centre is
/// inside an arena of `size_cm`, in metres.
pub(super) fn obstacle(k: usize, o: &ObstacleFile, size_cm: f64, path: &Path) -> Result<Obstacle> {
    let bad =
        |field: &str, value: String, expected: &str| field_error(path, field, value, expected);
    let field = |f: &str| format!("arena.obstacle[{k}].{f}");
    let [cx, cy] = o.center_cm.0;
    if !(cx.is_finite()
        && cy.is_finite()
        && (0.0..=size_cm).contains(&cx)
        && (0.0..=size_cm).contains(&cy))
    {
        return Err(bad(
            &field("center_cm"),
            format!("[{cx}, {cy}]"),
            &format!("a point inside the arena, both coordinates in [0, {size_cm}]"),
        ));
    }
    // A size of the other shape would be ignored: refused instead.
    let foreign = match o.shape.as_str() {
        "box" => o.radius_cm.map(|r| ("radius_cm", r.to_string(), "a box")),
        "circle" => o
            .size_cm
            .map(|s| ("size_cm", format!("[{}, {}]", s.0[0], s.0[1]), "a circle")),
        _ => None,
    };
    if let Some((name, value, shape)) = foreign {
        return Err(bad(
            &field(name),
            value,
            &format!(
                "no {name} for {shape} (a box takes size_cm = [width_cm, height_cm], a circle \
                 radius_cm)"
            ),
        ));
    }
    match o.shape.as_str() {
        "box" => {
            let [w, h] = o
                .size_cm
                .ok_or_else(|| bad(&field("size_cm"), "missing".into(), "[width_cm, height_cm]"))?
                .0;
            if !(w.is_finite() && h.is_finite() && w > 0.0 && h > 0.0) {
                return Err(bad(
                    &field("size_cm"),
                    format!("[{w}, {h}]"),
                    "two sizes > 0 cm",
                ));
            }
            if !o.angle_deg.is_finite() {
                return Err(bad(
                    &field("angle_deg"),
                    o.angle_deg.to_string(),
                    "an angle in degrees",
                ));
            }
            Ok(Obstacle::Box {
                x_m: cx / 100.0,
                y_m: cy / 100.0,
                half_width_m: w / 200.0,
                half_height_m: h / 200.0,
                angle_rad: o.angle_deg.to_radians(),
            })
        }
        "circle" => {
            let r = o
                .radius_cm
                .ok_or_else(|| bad(&field("radius_cm"), "missing".into(), "a radius in cm"))?;
            if !(r.is_finite() && r > 0.0) {
                return Err(bad(&field("radius_cm"), r.to_string(), "a radius > 0 cm"));
            }
            Ok(Obstacle::Circle {
                x_m: cx / 100.0,
                y_m: cy / 100.0,
                radius_m: r / 100.0,
            })
        }
        other => Err(bad(
            &field("shape"),
            format!("{other:?}"),
            "\"box\" or \"circle\"",
        )),
    }
}

/// The arena of `[[arena.obstacle]]`: the paper's walls and the obstacles,
/// each inside the walls and clear of every goal and of the start.
pub(super) fn arena(
    file: &EpuckFile,
    layout: &GoalLayout,
    start: Pose,
    radius_m: f64,
    path: &Path,
) -> Result<ArenaSpec> {
    let bad =
        |field: &str, value: String, expected: &str| field_error(path, field, value, expected);
    let size_m = layout.arena_size_m();
    let size_cm = size_m * 100.0;
    let obstacles = file.arena.as_ref().map_or(0, |a| a.obstacle.len());
    if obstacles > MAX_OBSTACLES {
        return Err(bad(
            "arena.obstacle",
            format!("{obstacles} obstacles"),
            &format!("at most {MAX_OBSTACLES} [[arena.obstacle]] tables"),
        ));
    }
    let mut arena = ArenaSpec {
        size_m,
        ..ArenaSpec::paper()
    };
    for (k, o) in file
        .arena
        .iter()
        .flat_map(|a| a.obstacle.iter())
        .enumerate()
    {
        let field = |f: &str| format!("arena.obstacle[{k}].{f}");
        let [cx, cy] = o.center_cm.0;
        let obstacle = obstacle(k, o, size_cm, path)?;
        // Inside the walls: an obstacle through a wall is a wall the
        // arena does not have.
        let (lo, hi) = obstacle.bounds();
        let inside = |v: f64| (-1e-9..=size_m + 1e-9).contains(&v);
        if !(inside(lo.0) && inside(lo.1) && inside(hi.0) && inside(hi.1)) {
            return Err(bad(
                &field("center_cm"),
                format!("[{cx}, {cy}]"),
                &format!(
                    "an obstacle inside the walls: this one spans x {:.1} to {:.1} cm and \
                     y {:.1} to {:.1} cm, beyond the arena's 0 to {size_cm} cm",
                    100.0 * lo.0,
                    100.0 * hi.0,
                    100.0 * lo.1,
                    100.0 * hi.1
                ),
            ));
        }
        // Every goal must stay reachable: the robot has to fit on it.
        if let Some(g) = layout
            .goals()
            .iter()
            .find(|g| obstacle.signed_distance(g.x_m, g.y_m) < radius_m + 0.01)
        {
            return Err(bad(
                &field("center_cm"),
                format!("[{cx}, {cy}]"),
                &format!(
                    "an obstacle clear of every goal: this one covers {} (keep its edge \
                     at least {:.1} cm from the goal)",
                    g.name,
                    (radius_m + 0.01) * 100.0
                ),
            ));
        }
        if obstacle.signed_distance(start.x_m, start.y_m) < radius_m {
            return Err(bad(
                &field("center_cm"),
                format!("[{cx}, {cy}]"),
                "an obstacle clear of the e-puck's start",
            ));
        }
        arena.obstacles.push(obstacle);
    }
    Ok(arena)
}
