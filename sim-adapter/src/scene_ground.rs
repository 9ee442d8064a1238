//! A scene's support surfaces as the kinematic simulator's ground: its feet touch down on the
//! treads and ramps the walk was post-processed on, so a walk on stairs means something without
//! MuJoCo (`walk-bench` on a scene's sequence, `walk-sim --physics kinematic --scene`).

use stance::Environment;

/// The kinematic simulator's [`kinematic_sim::Ground`] of an environment's surfaces (in the
/// simulator's world frame: a scene's [`stance::Scene::walk_environment`], the robot standing at
/// its origin).
#[derive(Debug, Clone)]
pub struct SceneGround(Environment);

impl SceneGround {
    /// The ground of `environment`'s support surfaces.
    pub fn new(environment: Environment) -> Self {
        Self(environment)
    }
}

impl kinematic_sim::Ground for SceneGround {
    fn height_at(&self, x: f64, y: f64) -> Option<f64> {
        self.0.highest_at(x, y)
    }
}
