//! The scenario's arena: its size, walls and obstacles, and where the
//! e-puck starts, checked and in SI units.

use std::path::Path;

use errp_robot::{GoalLayout, Pose};

use crate::epuck::schema::{EpuckFile, ObstacleFile, StartFile};
use crate::epuck::world::{ArenaSpec, Obstacle};
use crate::error::Result;
use crate::scenario_file::field_error;

/// Obstacle `k` of `[[arena.obstacle]]`: a box or a circle whose centre is
/// inside an arena of `size_cm`, in metres.
fn obstacle(k: usize, o: &ObstacleFile, size_cm: f64, path: &Path) -> Result<Obstacle> {
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

/// Most obstacles in the arena.
pub const MAX_OBSTACLES: usize = 100;

/// Where the e-puck starts: a city or a position inside the arena (the
/// body clear of the walls), and its heading.
pub(super) fn start_pose(
    file: &EpuckFile,
    layout: &GoalLayout,
    radius_m: f64,
    path: &Path,
) -> Result<Pose> {
    let bad =
        |field: &str, value: String, expected: &str| field_error(path, field, value, expected);
    let size_cm = layout.arena_size_m() * 100.0;
    let cities = || layout.names().join(", ");
    let (sx, sy) = match &file.start {
        StartFile::City(name) => {
            let i = layout.index_of(name).ok_or_else(|| {
                bad(
                    "start",
                    format!("{name:?}"),
                    &format!("a city ({}) or a position [x_cm, y_cm]", cities()),
                )
            })?;
            (layout.goals()[i].x_m, layout.goals()[i].y_m)
        }
        StartFile::Cm([x, y]) => {
            let lo = radius_m * 100.0;
            let inside = |v: f64| v.is_finite() && v >= lo && v <= size_cm - lo;
            if !(inside(*x) && inside(*y)) {
                return Err(bad(
                    "start",
                    format!("[{x}, {y}]"),
                    &format!(
                        "a position [x_cm, y_cm] with both in [{lo:.1}, {:.1}] so the \
                         e-puck's body is inside the {size_cm} cm arena",
                        size_cm - lo
                    ),
                ));
            }
            (x / 100.0, y / 100.0)
        }
    };
    if !file.start_heading_deg.is_finite() {
        return Err(bad(
            "start_heading_deg",
            file.start_heading_deg.to_string(),
            "an angle in degrees (0 = +x, 90 = up)",
        ));
    }
    Ok(Pose {
        x_m: sx,
        y_m: sy,
        heading_rad: errp_robot::wrap_angle(file.start_heading_deg.to_radians()),
    })
}
