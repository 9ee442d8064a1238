//! Held hands as supports in the static gait: how much of the weight each held hand is asked to
//! carry, and where that lets the CoM stand.
//!
//! A hand pressing down on a railing with a vertical force `f` at the point `p` (its palm, ground
//! plane) carries `s = f / W` of the robot's weight `W`; the feet carry the rest. For the robot to
//! stand still the moments balance, so the CoM `c` and the centre of pressure of the feet `z`
//! satisfy (Bretl and Lall 2008, for vertical contact forces)
//!
//! ```text
//! c = Σ sₕ pₕ + (1 − Σ sₕ) z,        z inside the feet's support polygon,
//! ```
//!
//! and the static equilibrium region of the CoM is the feet's polygon scaled by `1 − Σ sₕ` towards
//! the hands: with a fifth of the weight on a rail 0.45 m beside the path the CoM may stand 9 cm
//! closer to it than the feet alone allow, outside their polygon. [`HandLoad`] is that map. The
//! static gait plans and checks its CoM motion in the feet's terms (`z`, the point their load is
//! centred on, which is the CoM when no hand carries) and the QP maps its set-point and polygon
//! into the CoM's.
//!
//! The share counted is the *measured* one, at most what is asked (`min(f_measured, f_desired)`):
//! a hand that finds no railing, or slips, carries nothing, and the CoM then stays over the feet.
//! Each held hand is asked for `hand_support_share` of the weight, rising from the touch force
//! (`hand_force_n`) at `hand_support_rate` once it holds, and falling back to the touch at the same
//! rate while it is unloaded before it lets go (`Phase::Unload` of a hand); the hand's admittance
//! (`hand_press`) tracks the force asked. Pure and allocation-free.

use kinematics::robot::EndEffector;
use nalgebra::{Isometry3, Vector2};

use super::config::ControllerConfig;

/// The share of the weight the held hands carry and where (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct HandLoad {
    /// Σ sₕ: the hands' share of the weight, in [0, 1).
    share: f64,
    /// Σ sₕ pₕ (m, world ground plane).
    moment: Vector2<f64>,
    /// Which hands (left, right) carry some of the weight.
    carrying: [bool; 2],
}

/// The hands never carry more than this share of the weight in the balance's sums, so the feet
/// always carry some and the maps stay invertible.
const MAX_TOTAL_SHARE: f64 = 0.9;

impl HandLoad {
    /// No hand carries: the CoM is the feet's centre of pressure.
    pub const NONE: Self = Self {
        share: 0.0,
        moment: Vector2::new(0.0, 0.0),
        carrying: [false; 2],
    };

    /// The CoM that puts the feet's centre of pressure at `feet` (ground plane).
    pub fn com_of(&self, feet: Vector2<f64>) -> Vector2<f64> {
        self.moment + (1.0 - self.share) * feet
    }

    /// A velocity of the feet's centre of pressure as the CoM's (the map's linear part).
    pub fn com_velocity_of(&self, feet: Vector2<f64>) -> Vector2<f64> {
        (1.0 - self.share) * feet
    }

    /// The feet's centre of pressure under the CoM `com` (the inverse of [`HandLoad::com_of`]).
    pub fn feet_of(&self, com: Vector2<f64>) -> Vector2<f64> {
        (com - self.moment) / (1.0 - self.share)
    }

    /// The hands' share of the weight.
    pub fn share(&self) -> f64 {
        self.share
    }

    /// Whether `hand` carries some of the weight.
    pub fn carries(&self, hand: EndEffector) -> bool {
        self.carrying[hand_slot(hand)]
    }
}

/// The measured force a hand carries is low-passed with this time constant (s) before the
/// balance counts it. A wrist reading on a rigid rail swings by hundreds of newtons from tick to
/// tick; counted as it comes, it moved JVRC-1's CoM set-point centimetres from tick to tick, which
/// bounced the hand on the rail harder still (MuJoCo, `railing.toml`, 0–620 N within 0.2 s).
const LOAD_FILTER_S: f64 = 0.2;

/// The force each held hand is asked for, ramped, and what it carries (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct HandSupport {
    /// Vertical force asked of each hand (N; left, right), 0 for a hand not held.
    desired: [f64; 2],
    /// Vertical force each hand carries, measured, at most what it is asked, low-passed (N).
    carried: [f64; 2],
}

impl HandSupport {
    /// Advances the forces asked by `dt` (s): a held hand's (`contacts`) rises towards its share
    /// of `weight_n`, or falls towards the touch while `unloading`; a hand not held is asked for
    /// nothing. Never below the touch for a held hand.
    pub fn update(
        &mut self,
        contacts: &[bool; 4],
        unloading: Option<EndEffector>,
        config: &ControllerConfig,
        weight_n: f64,
        dt: f64,
    ) {
        let touch = config.hand_force_n;
        let support = touch.max(config.hand_support_share * weight_n);
        let step = config.hand_support_rate * weight_n * dt;
        for (desired, hand) in self.desired.iter_mut().zip(EndEffector::HANDS) {
            if !contacts[hand as usize] {
                *desired = 0.0;
                continue;
            }
            let goal = if unloading == Some(hand) {
                touch
            } else {
                support
            };
            let from = desired.max(touch);
            *desired = from + (goal - from).clamp(-step, step);
        }
    }

    /// The vertical force (N) asked of each hand (left, right): what its admittance tracks.
    pub fn desired(&self) -> [f64; 2] {
        self.desired
    }

    /// How long (s) bringing `hand`'s force asked back to the touch takes at the rate.
    pub fn unload_s(&self, hand: EndEffector, config: &ControllerConfig, weight_n: f64) -> f64 {
        let excess = (self.desired[hand_slot(hand)] - config.hand_force_n).max(0.0);
        excess / (config.hand_support_rate * weight_n)
    }

    /// Whether `hand`'s force asked is back at the touch (its unloading is done).
    pub fn unloaded(&self, hand: EndEffector, config: &ControllerConfig) -> bool {
        self.desired[hand_slot(hand)] <= config.hand_force_n
    }

    /// Takes this tick's measured vertical forces (`forces`, N, `EndEffector` order) into what
    /// each hand carries: at most what it is asked, low-passed over `dt` (s).
    pub fn sense(&mut self, forces: &[f64; 4], dt: f64) {
        let alpha = (dt / LOAD_FILTER_S).min(1.0);
        for ((carried, desired), hand) in self
            .carried
            .iter_mut()
            .zip(self.desired)
            .zip(EndEffector::HANDS)
        {
            let measured = forces[hand as usize].clamp(0.0, desired);
            *carried = (*carried + alpha * (measured - *carried)).min(desired);
        }
    }

    /// The load the held hands carry now ([`HandSupport::sense`]), at their anchors
    /// (`anchors`).
    pub fn load(&self, anchors: &[Isometry3<f64>; 4], weight_n: f64) -> HandLoad {
        let mut load = HandLoad::NONE;
        for ((carried, hand), carrying) in self
            .carried
            .iter()
            .zip(EndEffector::HANDS)
            .zip(&mut load.carrying)
        {
            let room = MAX_TOTAL_SHARE - load.share;
            let share = (carried / weight_n).min(room).max(0.0);
            *carrying = share > 0.0;
            load.share += share;
            load.moment += share * anchors[hand as usize].translation.vector.xy();
        }
        load
    }
}

/// Index of `hand` in a per-hand array (left, right).
pub(crate) fn hand_slot(hand: EndEffector) -> usize {
    hand as usize - EndEffector::LeftHand as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    const WEIGHT: f64 = 600.0;

    fn config() -> ControllerConfig {
        ControllerConfig {
            hand_support_share: 0.2,
            hand_support_rate: 0.5,
            ..ControllerConfig::default()
        }
    }

    fn right_hand_held() -> [bool; 4] {
        [true, true, false, true]
    }

    /// Support whose right hand, held, is asked for its whole share (ticks of `dt`).
    fn asked_in_full(dt: f64) -> HandSupport {
        let mut support = HandSupport::default();
        for _ in 0..1000 {
            support.update(&right_hand_held(), None, &config(), WEIGHT, dt);
        }
        support
    }

    /// Anchors with the right palm on a rail 0.45 m to the right at 0.86 m, `x` along it.
    fn right_palm_at(x: f64) -> [Isometry3<f64>; 4] {
        let mut anchors = [Isometry3::identity(); 4];
        anchors[3] = Isometry3::translation(x, -0.45, 0.86);
        anchors
    }

    #[test]
    fn a_held_hand_is_asked_for_its_share_at_the_rate_and_back_to_the_touch_when_unloaded() {
        let config = config();
        let mut support = HandSupport::default();
        let dt = 0.01;
        // 0.5 of the weight per second: 3 N a tick, from the 10 N touch to 120 N in 37 ticks.
        support.update(&right_hand_held(), None, &config, WEIGHT, dt);
        assert!((support.desired()[1] - 13.0).abs() < 1e-9);
        assert_eq!(support.desired()[0], 0.0);
        for _ in 0..100 {
            support.update(&right_hand_held(), None, &config, WEIGHT, dt);
        }
        assert!((support.desired()[1] - 120.0).abs() < 1e-9);
        assert!(!support.unloaded(EndEffector::RightHand, &config));
        let unloading = Some(EndEffector::RightHand);
        support.update(&right_hand_held(), unloading, &config, WEIGHT, dt);
        assert!((support.desired()[1] - 117.0).abs() < 1e-9);
        for _ in 0..100 {
            support.update(&right_hand_held(), unloading, &config, WEIGHT, dt);
        }
        assert_eq!(support.desired()[1], config.hand_force_n);
        assert!(support.unloaded(EndEffector::RightHand, &config));
        // Let go: nothing asked.
        support.update(&[true, true, false, false], None, &config, WEIGHT, dt);
        assert_eq!(support.desired(), [0.0, 0.0]);
    }

    #[test]
    fn with_no_share_configured_a_held_hand_only_touches() {
        let config = ControllerConfig {
            hand_support_share: 0.0,
            ..config()
        };
        let mut support = HandSupport::default();
        for _ in 0..100 {
            support.update(&right_hand_held(), None, &config, WEIGHT, 0.01);
        }
        assert_eq!(support.desired()[1], config.hand_force_n);
    }

    #[test]
    fn the_load_counts_what_the_hand_carries_at_most_what_it_was_asked_and_lets_the_com_lean() {
        let support = asked_in_full(0.01);
        let anchors = right_palm_at(0.2);
        let forces = |right: f64| [300.0, 300.0, 55.0, right];
        let carrying = |right: f64| {
            let mut support = support;
            for _ in 0..1000 {
                support.sense(&forces(right), 0.01);
            }
            support.load(&anchors, WEIGHT)
        };
        // Measured 60 N of the 120 N asked: a tenth of the weight; the left hand is not held.
        let load = carrying(60.0);
        assert!((load.share() - 0.1).abs() < 1e-9);
        // Feet centred on the left sole (y = 0.1): the CoM stands 5.5 cm towards the rail.
        let com = load.com_of(Vector2::new(0.0, 0.1));
        assert!(
            (com - Vector2::new(0.02, 0.09 - 0.045)).norm() < 1e-9,
            "{com}"
        );
        assert!((load.feet_of(com) - Vector2::new(0.0, 0.1)).norm() < 1e-12);
        // More than asked counts as asked; pulling up (negative) counts as nothing.
        assert!((carrying(500.0).share() - 0.2).abs() < 1e-9);
        assert_eq!(carrying(-80.0), HandLoad::NONE);
        // No railing under the hand: no load, the CoM is the feet's centre of pressure.
        let none = carrying(0.0);
        assert_eq!(none.com_of(Vector2::new(0.3, 0.1)), Vector2::new(0.3, 0.1));
    }

    #[test]
    fn a_force_that_swings_from_tick_to_tick_is_counted_by_its_mean() {
        let mut support = asked_in_full(0.001);
        let anchors = right_palm_at(0.0);
        // 0 and 120 N by turns (a hand bouncing on the rail): about half the share, steadily.
        let mut shares = Vec::new();
        for tick in 0..2000 {
            let right = if tick % 2 == 0 { 0.0 } else { 120.0 };
            support.sense(&[300.0, 300.0, 0.0, right], 0.001);
            shares.push(support.load(&anchors, WEIGHT).share());
        }
        let late = &shares[1000..];
        assert!(
            late.iter().all(|s| (s - 0.1).abs() < 0.002),
            "{:?}",
            &late[..4]
        );
    }
}
