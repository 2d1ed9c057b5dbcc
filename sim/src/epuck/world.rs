//! The physical arena: a rapier2d world with walls, obstacles and the e-puck
//! as a dynamic body driven by its two wheels.
//!
//! The world is top-down (no gravity). Every step the e-puck's body gets the
//! velocity its wheels give it, along its heading only: a differential drive
//! cannot move sideways, and the wheels' grip removes any lateral velocity a
//! contact leaves behind. Walls and obstacles are fixed colliders, so a robot
//! driven into them is stopped by the contact solver, not by a check of ours.
//! Rapier computes in `f32`; poses leave the world as `f64`.

use errp_robot::{EpuckParams, Pose, Twist, wrap_angle};
use rapier2d::prelude::*;

use crate::error::{Result, SimError};

/// A fixed obstacle on the floor of the arena.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Obstacle {
    /// A rectangle: centre, half extents and rotation.
    Box {
        /// Centre, x (m).
        x_m: f64,
        /// Centre, y (m).
        y_m: f64,
        /// Half width along the box's own x axis (m).
        half_width_m: f64,
        /// Half height along the box's own y axis (m).
        half_height_m: f64,
        /// Rotation (rad, anticlockwise).
        angle_rad: f64,
    },
    /// A disc (a cylinder seen from above).
    Circle {
        /// Centre, x (m).
        x_m: f64,
        /// Centre, y (m).
        y_m: f64,
        /// Radius (m).
        radius_m: f64,
    },
}

impl Obstacle {
    /// The obstacle's outline, m: a box's four corners (the first again at
    /// the end), or 49 points round a circle.
    pub fn outline(&self) -> Vec<(f64, f64)> {
        match *self {
            Obstacle::Circle { x_m, y_m, radius_m } => (0..=48)
                .map(|k| {
                    let a = k as f64 / 48.0 * std::f64::consts::TAU;
                    (x_m + radius_m * a.cos(), y_m + radius_m * a.sin())
                })
                .collect(),
            Obstacle::Box {
                x_m,
                y_m,
                half_width_m,
                half_height_m,
                angle_rad,
            } => {
                let (s, c) = angle_rad.sin_cos();
                [
                    (-1.0, -1.0),
                    (1.0, -1.0),
                    (1.0, 1.0),
                    (-1.0, 1.0),
                    (-1.0, -1.0),
                ]
                .iter()
                .map(|(u, v)| {
                    let (lx, ly) = (u * half_width_m, v * half_height_m);
                    (x_m + c * lx - s * ly, y_m + s * lx + c * ly)
                })
                .collect()
            }
        }
    }

    /// The corners of the axis-aligned rectangle around the obstacle:
    /// ((x min, y min), (x max, y max)), m.
    pub fn bounds(&self) -> ((f64, f64), (f64, f64)) {
        if let Obstacle::Circle { x_m, y_m, radius_m } = *self {
            return (
                (x_m - radius_m, y_m - radius_m),
                (x_m + radius_m, y_m + radius_m),
            );
        }
        self.outline().iter().fold(
            (
                (f64::INFINITY, f64::INFINITY),
                (f64::NEG_INFINITY, f64::NEG_INFINITY),
            ),
            |((x0, y0), (x1, y1)), &(x, y)| ((x0.min(x), y0.min(y)), (x1.max(x), y1.max(y))),
        )
    }

    /// Distance from the point to the obstacle's boundary (negative inside).
    pub fn signed_distance(&self, x: f64, y: f64) -> f64 {
        match *self {
            Obstacle::Circle { x_m, y_m, radius_m } => {
                ((x - x_m).powi(2) + (y - y_m).powi(2)).sqrt() - radius_m
            }
            Obstacle::Box {
                x_m,
                y_m,
                half_width_m,
                half_height_m,
                angle_rad,
            } => {
                let (s, c) = angle_rad.sin_cos();
                let (dx, dy) = (x - x_m, y - y_m);
                let (lx, ly) = (c * dx + s * dy, -s * dx + c * dy);
                let (qx, qy) = (lx.abs() - half_width_m, ly.abs() - half_height_m);
                let outside = (qx.max(0.0).powi(2) + qy.max(0.0).powi(2)).sqrt();
                outside + qx.max(qy).min(0.0)
            }
        }
    }
}

/// The arena: a square floor closed by walls, with optional obstacles.
#[derive(Debug, Clone, PartialEq)]
pub struct ArenaSpec {
    /// Side of the square floor (m); the paper's is 2 m (sec. 5.1).
    pub size_m: f64,
    /// Wall thickness (m), outside the floor.
    pub wall_thickness_m: f64,
    /// Obstacles on the floor.
    pub obstacles: Vec<Obstacle>,
}

impl ArenaSpec {
    /// The paper's empty 200 x 200 cm arena.
    pub fn paper() -> Self {
        Self {
            size_m: 2.0,
            wall_thickness_m: 0.05,
            obstacles: Vec::new(),
        }
    }
}

/// The e-puck's eight infrared proximity sensors (ps0..ps7), simulated by ray
/// casts against every collider of the arena.
///
/// Angles follow the e-puck's layout (GCtronic documentation): two sensors
/// near the front at about ±17°, two at ±49°, two at the sides (±90°) and two
/// at the back (±150°); positive is anticlockwise (the robot's left). The
/// response is the e-puck's reflected-light count against the distance from
/// the body's edge: about 4000 at contact, 1000 at 1 cm, 300 at 2.5 cm and the
/// ambient level (~60) beyond 6 cm, interpolated linearly in a table shaped
/// like the published calibration curves (it falls roughly exponentially).
#[derive(Debug, Clone, PartialEq)]
pub struct ProximitySensors {
    /// Sensor directions relative to the heading (rad), ps0..ps7.
    pub angles_rad: [f64; 8],
    /// (distance from the body edge in m, reading) pairs, distance increasing.
    pub response: Vec<(f64, f64)>,
}

impl Default for ProximitySensors {
    fn default() -> Self {
        let deg = |d: f64| d.to_radians();
        Self {
            angles_rad: [
                deg(-17.0),
                deg(-49.0),
                deg(-90.0),
                deg(-150.0),
                deg(150.0),
                deg(90.0),
                deg(49.0),
                deg(17.0),
            ],
            response: vec![
                (0.0, 4000.0),
                (0.005, 2000.0),
                (0.01, 1000.0),
                (0.015, 650.0),
                (0.025, 300.0),
                (0.04, 130.0),
                (0.06, 60.0),
            ],
        }
    }
}

impl ProximitySensors {
    /// Sensing range beyond the body's edge (m).
    pub fn range_m(&self) -> f64 {
        self.response.last().map_or(0.0, |r| r.0)
    }

    /// The reading at `distance_m` from the body edge (`None`: nothing in
    /// range, the ambient reading).
    pub fn reading(&self, distance_m: Option<f64>) -> f64 {
        let ambient = self.response.last().map_or(0.0, |r| r.1);
        let Some(d) = distance_m else {
            return ambient;
        };
        for w in self.response.windows(2) {
            let ((d0, r0), (d1, r1)) = (w[0], w[1]);
            if d <= d1 {
                let t = ((d - d0) / (d1 - d0)).clamp(0.0, 1.0);
                return r0 + t * (r1 - r0);
            }
        }
        ambient
    }
}

/// The rapier2d world of one episode.
pub struct World {
    bodies: RigidBodySet,
    colliders: ColliderSet,
    pipeline: PhysicsPipeline,
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    islands: IslandManager,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    soft_bodies: SoftBodySet,
    ccd: CCDSolver,
    integration: IntegrationParameters,
    robot: RigidBodyHandle,
    radius_m: f64,
    arena: ArenaSpec,
    sensors: ProximitySensors,
}

impl std::fmt::Debug for World {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("World")
            .field("arena", &self.arena)
            .field("pose", &self.pose())
            .finish_non_exhaustive()
    }
}

impl World {
    /// Builds the arena and places the e-puck at `start`. Errors if the
    /// start overlaps a wall or an obstacle.
    pub fn new(arena: &ArenaSpec, epuck: &EpuckParams, start: Pose, dt_secs: f64) -> Result<Self> {
        let radius_m = epuck.body_diameter_m / 2.0;
        let inside = start.x_m >= radius_m
            && start.y_m >= radius_m
            && start.x_m <= arena.size_m - radius_m
            && start.y_m <= arena.size_m - radius_m;
        if !inside {
            return Err(SimError::Scenario(format!(
                "the e-puck's start ({:.3}, {:.3}) m puts its body outside the {} m arena",
                start.x_m, start.y_m, arena.size_m
            )));
        }
        if let Some(o) = arena
            .obstacles
            .iter()
            .find(|o| o.signed_distance(start.x_m, start.y_m) < radius_m)
        {
            return Err(SimError::Scenario(format!(
                "the e-puck's start ({:.3}, {:.3}) m overlaps the obstacle {o:?}",
                start.x_m, start.y_m
            )));
        }
        let mut bodies = RigidBodySet::new();
        let mut colliders = ColliderSet::new();
        let (s, t) = (arena.size_m as f32, arena.wall_thickness_m as f32);
        // Four walls just outside the floor [0, s] x [0, s].
        for (cx, cy, hx, hy) in [
            (s / 2.0, -t / 2.0, s / 2.0 + t, t / 2.0),
            (s / 2.0, s + t / 2.0, s / 2.0 + t, t / 2.0),
            (-t / 2.0, s / 2.0, t / 2.0, s / 2.0 + t),
            (s + t / 2.0, s / 2.0, t / 2.0, s / 2.0 + t),
        ] {
            colliders.insert(
                ColliderBuilder::cuboid(hx, hy)
                    .translation(Vector::new(cx, cy))
                    .build(),
            );
        }
        for o in &arena.obstacles {
            let c = match *o {
                Obstacle::Box {
                    x_m,
                    y_m,
                    half_width_m,
                    half_height_m,
                    angle_rad,
                } => ColliderBuilder::cuboid(half_width_m as f32, half_height_m as f32)
                    .translation(Vector::new(x_m as f32, y_m as f32))
                    .rotation(angle_rad as f32),
                Obstacle::Circle { x_m, y_m, radius_m } => ColliderBuilder::ball(radius_m as f32)
                    .translation(Vector::new(x_m as f32, y_m as f32)),
            };
            colliders.insert(c.build());
        }
        let robot = bodies.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(start.x_m as f32, start.y_m as f32))
                .rotation(start.heading_rad as f32)
                .can_sleep(false),
        );
        colliders.insert_with_parent(
            ColliderBuilder::ball(radius_m as f32)
                .mass(epuck.mass_kg as f32)
                .friction(0.0)
                .restitution(0.0),
            robot,
            &mut bodies,
        );
        // One solver iteration: the only contacts are a 0.15 kg disc against
        // fixed walls at a few cm/s, which one pass resolves (the wall tests
        // hold to millimetres); rapier's default of 4 is for stacks.
        let integration = IntegrationParameters {
            dt: dt_secs as f32,
            num_solver_iterations: 1,
            ..IntegrationParameters::default()
        };
        let mut world = Self {
            bodies,
            colliders,
            pipeline: PhysicsPipeline::new(),
            broad_phase: BroadPhaseBvh::new(),
            narrow_phase: NarrowPhase::new(),
            islands: IslandManager::new(),
            impulse_joints: ImpulseJointSet::new(),
            multibody_joints: MultibodyJointSet::new(),
            soft_bodies: SoftBodySet::new(),
            ccd: CCDSolver::new(),
            integration,
            robot,
            radius_m,
            arena: arena.clone(),
            sensors: ProximitySensors::default(),
        };
        // One step at rest builds the broad phase, so sensors work at once.
        world.step(Twist {
            linear_m_per_s: 0.0,
            angular_rad_per_s: 0.0,
        });
        Ok(world)
    }

    /// The arena as built.
    pub fn arena(&self) -> &ArenaSpec {
        &self.arena
    }

    /// The physics time step (s).
    pub fn dt_secs(&self) -> f64 {
        f64::from(self.integration.dt)
    }

    /// Advances one time step with the body moving at `twist` (forward speed
    /// along the heading, turn rate). Lateral velocity is zero by
    /// construction and removed again after contacts (wheel grip).
    pub fn step(&mut self, twist: Twist) {
        // A robot at rest, told to stay at rest and touching nothing: the
        // step would change nothing, so it is skipped (about a third of a
        // run is spent in 1 s stops).
        let still = twist.linear_m_per_s == 0.0 && twist.angular_rad_per_s == 0.0;
        if still && self.at_rest() && self.clear_of_everything() {
            return;
        }
        let body = &mut self.bodies[self.robot];
        let heading = body.rotation().angle();
        let v = twist.linear_m_per_s as f32;
        body.set_linvel(Vector::new(v * heading.cos(), v * heading.sin()), true);
        body.set_angvel(twist.angular_rad_per_s as f32, true);
        self.pipeline.step(
            Vector::ZERO,
            &self.integration,
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &mut self.impulse_joints,
            &mut self.multibody_joints,
            &mut self.soft_bodies,
            &mut self.ccd,
            &(),
            &(),
        );
        let body = &mut self.bodies[self.robot];
        let heading = body.rotation().angle();
        let dir = Vector::new(heading.cos(), heading.sin());
        let forward = body.linvel().dot(dir);
        body.set_linvel(dir * forward, false);
    }

    fn at_rest(&self) -> bool {
        let body = &self.bodies[self.robot];
        body.linvel() == Vector::ZERO && body.angvel() == 0.0
    }

    /// True when no wall or obstacle is within the proximity sensors' reach
    /// of the body (so nothing can touch it or be seen by it).
    fn clear_of_everything(&self) -> bool {
        let p = self.pose();
        let reach = self.radius_m + self.sensors.range_m();
        let s = self.arena.size_m;
        let walls_far = p.x_m > reach && p.y_m > reach && s - p.x_m > reach && s - p.y_m > reach;
        walls_far
            && self
                .arena
                .obstacles
                .iter()
                .all(|o| o.signed_distance(p.x_m, p.y_m) > reach)
    }

    /// The e-puck's true pose.
    pub fn pose(&self) -> Pose {
        let body = &self.bodies[self.robot];
        let t = body.translation();
        Pose {
            x_m: f64::from(t.x),
            y_m: f64::from(t.y),
            heading_rad: wrap_angle(f64::from(body.rotation().angle())),
        }
    }

    /// The sensors' layout and response.
    pub fn sensors(&self) -> &ProximitySensors {
        &self.sensors
    }

    /// Distance from the body edge to the nearest collider along each
    /// proximity sensor's ray (`None`: nothing within range).
    pub fn proximity_distances(&self) -> [Option<f64>; 8] {
        let pose = self.pose();
        let filter = QueryFilter::default().exclude_rigid_body(self.robot);
        let query = self.broad_phase.as_query_pipeline(
            self.narrow_phase.query_dispatcher(),
            &self.bodies,
            &self.colliders,
            filter,
        );
        let range = self.sensors.range_m() as f32;
        let mut out = [None; 8];
        for (k, a) in self.sensors.angles_rad.iter().enumerate() {
            let dir = pose.heading_rad + a;
            let (s, c) = (dir.sin(), dir.cos());
            let origin = Vector::new(
                (pose.x_m + c * self.radius_m) as f32,
                (pose.y_m + s * self.radius_m) as f32,
            );
            let ray = Ray::new(origin, Vector::new(c as f32, s as f32));
            out[k] = query
                .cast_ray(&ray, range, true)
                .map(|(_, toi)| f64::from(toi));
        }
        out
    }

    /// The eight proximity readings (ps0..ps7). When no wall or obstacle is
    /// within the sensors' reach of the body, every reading is the ambient
    /// one and no ray is cast (the same answer, much cheaper).
    pub fn proximity(&self) -> [f64; 8] {
        if self.clear_of_everything() {
            return [self.sensors.reading(None); 8];
        }
        self.proximity_distances().map(|d| self.sensors.reading(d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn twist(v: f64, w: f64) -> Twist {
        Twist {
            linear_m_per_s: v,
            angular_rad_per_s: w,
        }
    }

    /// The paper's empty arena, with the default e-puck at (x, y), heading
    /// `h`, stepped at 64 Hz.
    fn free_world(x: f64, y: f64, h: f64) -> World {
        World::new(
            &ArenaSpec::paper(),
            &EpuckParams::default(),
            start(x, y, h),
            1.0 / 64.0,
        )
        .unwrap()
    }

    fn start(x: f64, y: f64, h: f64) -> Pose {
        Pose {
            x_m: x,
            y_m: y,
            heading_rad: h,
        }
    }

    #[test]
    fn a_free_robot_moves_along_its_heading_at_the_commanded_speed() {
        let mut w = free_world(1.0, 1.0, 0.5);
        for _ in 0..64 {
            w.step(twist(0.1, 0.0));
        }
        let p = w.pose();
        let moved = ((p.x_m - 1.0).powi(2) + (p.y_m - 1.0).powi(2)).sqrt();
        assert!((moved - 0.1).abs() < 1e-3, "moved {moved}");
        assert!((p.heading_rad - 0.5).abs() < 1e-4);
        let dir = (p.y_m - 1.0).atan2(p.x_m - 1.0);
        assert!((dir - 0.5).abs() < 1e-3, "moved along {dir}");
    }

    #[test]
    fn a_robot_told_to_stay_still_stays_exactly_still() {
        let mut w = free_world(1.0, 1.0, 0.2);
        for _ in 0..32 {
            w.step(twist(0.1, 0.3));
        }
        for _ in 0..2 {
            w.step(twist(0.0, 0.0));
        }
        let before = w.pose();
        for _ in 0..64 {
            w.step(twist(0.0, 0.0));
        }
        assert_eq!(w.pose(), before);
        w.step(twist(0.1, 0.0));
        assert!(w.pose().x_m > before.x_m, "moves again when told to");
    }

    #[test]
    fn turning_in_place_does_not_translate() {
        let mut w = free_world(1.0, 1.0, 0.0);
        for _ in 0..64 {
            w.step(twist(0.0, 1.0));
        }
        let p = w.pose();
        assert!((p.x_m - 1.0).abs() < 1e-5 && (p.y_m - 1.0).abs() < 1e-5);
        assert!((p.heading_rad - 1.0).abs() < 1e-3, "{}", p.heading_rad);
    }

    #[test]
    fn walls_and_obstacles_stop_the_robot() {
        let epuck = EpuckParams::default();
        let r = epuck.body_diameter_m / 2.0;
        // Straight into the right wall for 30 s.
        let mut w = free_world(1.8, 1.0, 0.0);
        for _ in 0..64 * 30 {
            w.step(twist(0.129, 0.0));
        }
        assert!(w.pose().x_m <= 2.0 - r + 2e-3, "{:?}", w.pose());
        // Into a disc obstacle.
        let arena = ArenaSpec {
            obstacles: vec![Obstacle::Circle {
                x_m: 1.5,
                y_m: 1.0,
                radius_m: 0.1,
            }],
            ..ArenaSpec::paper()
        };
        let mut w = World::new(&arena, &epuck, start(1.0, 1.0, 0.0), 1.0 / 64.0).unwrap();
        for _ in 0..64 * 10 {
            w.step(twist(0.129, 0.0));
        }
        assert!(w.pose().x_m <= 1.4 - r + 2e-3, "{:?}", w.pose());
    }

    #[test]
    fn proximity_sensors_see_a_wall_ahead_and_nothing_in_the_open() {
        let epuck = EpuckParams::default();
        let w = free_world(1.0, 1.0, 0.0);
        assert!(w.proximity_distances().iter().all(Option::is_none));
        let r = epuck.body_diameter_m / 2.0;
        let w = free_world(2.0 - r - 0.01, 1.0, 0.0);
        let d = w.proximity_distances();
        // ps0 and ps7 look 17 degrees off the front: 1 cm / cos 17.
        let expect = 0.01 / 17f64.to_radians().cos();
        for k in [0, 7] {
            let got = d[k].expect("wall in range");
            assert!((got - expect).abs() < 2e-3, "ps{k}: {got} vs {expect}");
        }
        assert!(d[3].is_none() && d[4].is_none(), "{d:?}");
        let readings = w.proximity();
        assert!(readings[0] > 800.0 && readings[3] < 61.0, "{readings:?}");
    }

    #[test]
    fn the_far_from_everything_shortcut_gives_the_ray_cast_readings() {
        let epuck = EpuckParams::default();
        let arena = ArenaSpec {
            obstacles: vec![Obstacle::Circle {
                x_m: 1.0,
                y_m: 1.0,
                radius_m: 0.1,
            }],
            ..ArenaSpec::paper()
        };
        for k in 0..200 {
            let (x, y) = (0.05 + 0.0095 * k as f64, 0.04 + 0.0096 * k as f64);
            let Ok(w) = World::new(&arena, &epuck, start(x, y, 0.1 * k as f64), 0.01) else {
                continue;
            };
            let cast = w.proximity_distances().map(|d| w.sensors().reading(d));
            assert_eq!(w.proximity(), cast, "at ({x}, {y})");
        }
    }

    #[test]
    fn the_response_curve_falls_with_distance() {
        let s = ProximitySensors::default();
        let mut last = f64::INFINITY;
        for k in 0..=70 {
            let r = s.reading(Some(k as f64 * 0.001));
            assert!(r <= last);
            last = r;
        }
        assert_eq!(s.reading(None), 60.0);
    }

    #[test]
    fn starts_inside_walls_or_obstacles_are_rejected() {
        let epuck = EpuckParams::default();
        assert!(World::new(&ArenaSpec::paper(), &epuck, start(0.01, 1.0, 0.0), 0.01).is_err());
        let arena = ArenaSpec {
            obstacles: vec![Obstacle::Box {
                x_m: 1.0,
                y_m: 1.0,
                half_width_m: 0.1,
                half_height_m: 0.1,
                angle_rad: 0.3,
            }],
            ..ArenaSpec::paper()
        };
        assert!(World::new(&arena, &epuck, start(1.05, 1.0, 0.0), 0.01).is_err());
    }
}
