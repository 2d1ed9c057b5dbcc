//! The quadratic potentials whose descent is each goal's optimal policy
//! (eq. 5 of the paper).

use serde::{Deserialize, Serialize};

/// Eq. (5) of the paper: U_i(u, v) = [u, v]' A_i [u, v] + b_i' [u, v] + c_i,
/// a 2D quadratic whose minimum is goal i. Its negative gradient is the
/// direction of the greedy policy for goal i (sec. 5.2), ignoring the
/// robot's non-holonomic constraint.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct QuadraticPotential {
    /// A_i, row-major, 1/m^2.
    pub a: [[f64; 2]; 2],
    /// b_i, 1/m.
    pub b: [f64; 2],
    /// c_i, dimensionless.
    pub c: f64,
}

impl QuadraticPotential {
    /// The potential of the goal at (x, y) in an arena of side `arena_size_m`
    /// (the paper: "A_i, b_i and c_i depend on the position of target i and
    /// the size of the map"): A_i = I / L^2, b_i = -2 A_i g_i,
    /// c_i = g_i' A_i g_i, so U_i = |p - g_i|^2 / L^2, 0 at the goal and at
    /// most 2 inside the arena.
    pub fn for_goal(x_m: f64, y_m: f64, arena_size_m: f64) -> Self {
        let k = 1.0 / (arena_size_m * arena_size_m);
        let a = [[k, 0.0], [0.0, k]];
        let b = [
            -2.0 * (a[0][0] * x_m + a[0][1] * y_m),
            -2.0 * (a[1][0] * x_m + a[1][1] * y_m),
        ];
        let c = x_m * (a[0][0] * x_m + a[0][1] * y_m) + y_m * (a[1][0] * x_m + a[1][1] * y_m);
        Self { a, b, c }
    }

    /// U(x, y), eq. (5).
    pub fn value(&self, x_m: f64, y_m: f64) -> f64 {
        let [[a00, a01], [a10, a11]] = self.a;
        x_m * (a00 * x_m + a01 * y_m)
            + y_m * (a10 * x_m + a11 * y_m)
            + self.b[0] * x_m
            + self.b[1] * y_m
            + self.c
    }

    /// grad U(x, y) = (A + A') p + b, 1/m.
    pub fn gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let [[a00, a01], [a10, a11]] = self.a;
        [
            2.0 * a00 * x_m + (a01 + a10) * y_m + self.b[0],
            (a01 + a10) * x_m + 2.0 * a11 * y_m + self.b[1],
        ]
    }

    /// The greedy policy's heading at (x, y) (sec. 5.2: the robot "rotated
    /// ... to align it with the direction of the gradient of U_i"): the
    /// direction of -grad U, rad from +x counter-clockwise, in (-pi, pi].
    /// Undefined at the minimum itself, where it returns atan2(0, 0) = 0.
    pub fn greedy_heading_rad(&self, x_m: f64, y_m: f64) -> f64 {
        let [gx, gy] = self.gradient(x_m, y_m);
        let h = (-gy).atan2(-gx);
        // atan2(-0, -x) is -pi; keep (-pi, pi].
        if h <= -std::f64::consts::PI {
            std::f64::consts::PI
        } else {
            h
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimum_is_the_goal() {
        let u = QuadraticPotential::for_goal(1.4, 0.6, 2.0);
        assert!(u.value(1.4, 0.6).abs() < 1e-12);
        let [gx, gy] = u.gradient(1.4, 0.6);
        assert!(gx.abs() < 1e-12 && gy.abs() < 1e-12);
        for (x, y) in [(0.0, 0.0), (2.0, 2.0), (1.5, 0.6), (1.4, 0.59)] {
            assert!(u.value(x, y) > 0.0);
            let expected = ((x - 1.4f64).powi(2) + (y - 0.6f64).powi(2)) / 4.0;
            assert!((u.value(x, y) - expected).abs() < 1e-12);
        }
        assert_eq!(u.a[0][1], u.a[1][0], "symmetric");
    }

    #[test]
    fn greedy_heading_points_at_the_goal() {
        let (gx, gy) = (0.6, 1.8);
        let u = QuadraticPotential::for_goal(gx, gy, 2.0);
        for (x, y) in [(0.2, 0.2), (1.8, 1.8), (0.6, 0.2), (1.9, 1.8), (0.1, 1.79)] {
            let h = u.greedy_heading_rad(x, y);
            let direct = (gy - y).atan2(gx - x);
            assert!((h - direct).abs() < 1e-12, "({x}, {y}): {h} vs {direct}");
        }
        // Exactly behind along -x: pi, not -pi.
        assert_eq!(u.greedy_heading_rad(1.0, 1.8), std::f64::consts::PI);
    }
}
