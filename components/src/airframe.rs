//! Airframes as data (common.md §3): mass, inertia, rotor geometry, thrust and torque maps,
//! motor limits, the rotor power model (common.md §4), optional linear drag and the battery.
//!
//! A scenario names a preset ([`Airframe::preset`]) and may override any numeric field by name
//! ([`Airframe::apply_overrides`]); the models in `uavex-systems::flight` read nothing else, so
//! a new airframe is a new value of this type, never new code.
//!
//! Units are SI throughout (kg, m, s, rad/s, N, W, J); angles in rad. The body frame is the
//! ROS one: x forward, y left, z up.

use bevy_ecs::prelude::Component;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Gravity (m/s^2) every flight model uses (common.md §3).
pub const GRAVITY: f64 = 9.81;

/// One rotor: where its hub sits and which way its reaction torque turns the body.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rotor {
    /// Hub position along body x (forward), m.
    pub x: f64,
    /// Hub position along body y (left), m.
    pub y: f64,
    /// Sign (+1 or -1) of the yaw torque `kappa * f` the rotor exerts on the body about +z.
    /// A rotor spinning counter-clockwise seen from above turns the body clockwise: -1.
    pub yaw_sign: f64,
}

/// Electrical power of one rotor as a function of its speed w (rad/s), EAAE eq. 5.2 after
/// Bauersfeld & Scaramuzza: `P(w) = linear * w + cubic * w^3 + sextic * w^6` (W).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RotorPowerModel {
    pub linear: f64,
    pub cubic: f64,
    pub sextic: f64,
}

/// Optional linear drag (common.md §3: "no drag unless configured"): both terms default to
/// zero, as in the spec and in EAAE's simulation.
///
/// Two terms, both linear in the velocity of the centre of mass (no wind):
/// - body drag, isotropic in the world frame: `F = -body * v` (N), the linearised parasitic
///   drag of the frame;
/// - rotor drag (blade flapping and induced drag, the model of Faessler, Franchi & Scaramuzza,
///   RA-L 2018): `F = -m * R diag(rotor_xy, rotor_xy, rotor_z) R^T v`, with mass-normalised
///   coefficients in 1/s. It acts in the rotor plane, so a vehicle pitched forward gets an
///   upward share of it; the model is meant for moderate tilts (the speeds it was identified
///   at), not for cruise studies at large tilt.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct LinearDrag {
    /// Body drag coefficient (N s/m).
    pub body: f64,
    /// Rotor drag in the rotor plane, mass-normalised (1/s).
    pub rotor_xy: f64,
    /// Rotor drag along the thrust axis, mass-normalised (1/s).
    pub rotor_z: f64,
}

impl LinearDrag {
    /// No drag: the default of every preset (common.md §3).
    pub const NONE: LinearDrag = LinearDrag {
        body: 0.0,
        rotor_xy: 0.0,
        rotor_z: 0.0,
    };
}

/// The battery: its capacity and how much of it a mission may use.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BatterySpec {
    /// Nominal capacity (Wh) = nominal voltage x charge.
    pub capacity_wh: f64,
    /// Fraction of the capacity a mission may draw before the run ends as `battery_empty`
    /// (LiPo packs are not discharged fully; 0.8 is the usual rule).
    pub usable_fraction: f64,
}

/// A quadrotor airframe: everything the flight and energy models need.
#[derive(Component, Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Airframe {
    /// Preset it came from (overrides keep the name).
    pub name: String,
    /// Mass (kg).
    pub mass: f64,
    /// Principal moments of inertia about body x, y, z (kg m^2).
    pub inertia: [f64; 3],
    /// The four rotors, in the order rotor speeds are given everywhere.
    pub rotors: [Rotor; 4],
    /// Thrust map `f = thrust_coefficient * w^2` (N per (rad/s)^2).
    pub thrust_coefficient: f64,
    /// Yaw torque per unit thrust, kappa (m): `tau_z = yaw_sign * kappa * f`.
    pub torque_coefficient: f64,
    /// Largest thrust one rotor may produce (N).
    pub rotor_thrust_max: f64,
    /// Slowest and fastest rotor speeds (rad/s).
    pub rotor_speed_min: f64,
    pub rotor_speed_max: f64,
    /// First-order lag from commanded to actual rotor speed (s).
    pub motor_time_constant: f64,
    /// Planning limits: speed (m/s) and acceleration (m/s^2).
    pub max_velocity: f64,
    pub max_acceleration: f64,
    /// Electrical power of one rotor from its speed (common.md §4).
    pub power: RotorPowerModel,
    /// Optional linear drag; zero unless configured.
    pub drag: LinearDrag,
    /// Full extents of the collision box along body x, y, z (m), propellers included.
    pub size: [f64; 3],
    pub battery: BatterySpec,
}

/// Fastest planning speed an airframe may state (m/s): above the fastest multirotors flown. The
/// planners' collision sampling and time allocation take work in proportion to it.
pub const MAX_VELOCITY: f64 = 100.0;
/// Slowest planning speed (m/s) and acceleration (m/s^2) an airframe may state: below it a leg
/// of a few metres takes minutes, a typo rather than a study.
pub const MIN_PLANNING_LIMIT: f64 = 0.1;

/// Names of the presets [`Airframe::preset`] knows.
pub const PRESET_NAMES: [&str; 2] = ["kingfisher", "iris"];

/// Fields [`Airframe::apply_overrides`] accepts, each a number in SI units.
pub const OVERRIDE_NAMES: [&str; 25] = [
    "mass",
    "inertia_xx",
    "inertia_yy",
    "inertia_zz",
    "arm_x",
    "arm_y",
    "thrust_coefficient",
    "torque_coefficient",
    "rotor_thrust_max",
    "rotor_speed_min",
    "rotor_speed_max",
    "motor_time_constant",
    "max_velocity",
    "max_acceleration",
    "power_linear",
    "power_cubic",
    "power_sextic",
    "drag_body",
    "drag_rotor_xy",
    "drag_rotor_z",
    "size_x",
    "size_y",
    "size_z",
    "battery_capacity_wh",
    "battery_usable_fraction",
];

/// IRIS hover power (W): P(0) of the straight-flight polynomial Di Franco & Buttazzo measured
/// (coverage.md), used to calibrate the IRIS rotor power model.
pub const IRIS_MEASURED_HOVER_POWER_W: f64 = 221.278607;

/// Quad-X rotor layout shared by both presets (the PX4 / Agilicious order): front-right,
/// rear-left, front-left, rear-right; the first two spin counter-clockwise.
fn quad_x(front_x: f64, rear_x: f64, front_y: f64, rear_y: f64) -> [Rotor; 4] {
    [
        Rotor {
            x: front_x,
            y: -front_y,
            yaw_sign: -1.0,
        },
        Rotor {
            x: -rear_x,
            y: rear_y,
            yaw_sign: -1.0,
        },
        Rotor {
            x: front_x,
            y: front_y,
            yaw_sign: 1.0,
        },
        Rotor {
            x: -rear_x,
            y: -rear_y,
            yaw_sign: 1.0,
        },
    ]
}

impl Airframe {
    /// The Agilicious "kingfisher", the EAAE airframe: every number of the table in
    /// common.md §3 and the power model of common.md §4.
    ///
    /// Not in the spec, chosen here: the collision box (motor spacing 0.15 x 0.20 m plus 5-inch
    /// propellers, 8 cm tall) and the battery, a 4S 1800 mAh LiPo (14.8 V x 1.8 Ah = 26.64 Wh),
    /// the pack class of vehicles of this size; the EAAE thesis states none.
    pub fn kingfisher() -> Self {
        Self {
            name: "kingfisher".to_owned(),
            mass: 0.752,
            inertia: [2.5e-3, 2.1e-3, 4.3e-3],
            rotors: quad_x(0.075, 0.075, 0.10, 0.10),
            thrust_coefficient: 1.562522e-6,
            torque_coefficient: 0.022,
            rotor_thrust_max: 8.5,
            rotor_speed_min: 150.0,
            rotor_speed_max: 2800.0,
            motor_time_constant: 0.033,
            max_velocity: 5.0,
            max_acceleration: 4.0,
            power: RotorPowerModel {
                linear: 6.088e-3,
                cubic: 1.875e-8,
                sextic: 7.700e-20,
            },
            drag: LinearDrag::NONE,
            size: [0.28, 0.33, 0.08],
            battery: BatterySpec {
                capacity_wh: 26.64,
                usable_fraction: 0.8,
            },
        }
    }

    /// The 3DR IRIS of the coverage study (common.md §3: about 1.3 kg with GoPro and gimbal).
    ///
    /// Sources: the PX4 SITL Gazebo `iris` model for the geometry and the motor model (rotor
    /// hubs at (0.13, -0.22), (-0.13, 0.20), (0.13, 0.22), (-0.13, -0.20) m, `motorConstant` 5.84e-6 N/(rad/s)^2, `momentConstant`
    /// 0.06 m, `maxRotVelocity` 1100 rad/s, time constants 0.0125 s up / 0.025 s down (the
    /// slower one is used), collision box 0.47 x 0.47 x 0.11 m, inertia 0.029125 / 0.029125 /
    /// 0.055225 kg m^2 at 1.5 kg, scaled here to 1.3 kg); the stock 3S 5100 mAh pack
    /// (11.1 V x 5.1 Ah = 56.61 Wh). Its rotor power model is the cubic (ideal-rotor) term only,
    /// calibrated so that hover draws the 221.3 W Di Franco & Buttazzo measured
    /// ([`IRIS_MEASURED_HOVER_POWER_W`]). Idle speed 100 rad/s and the planning limits
    /// (10 m/s, 3 m/s^2, PX4's default horizontal acceleration) are choices.
    pub fn iris() -> Self {
        let mass = 1.3;
        let thrust_coefficient = 5.84e-6;
        let inertia_scale = mass / 1.5;
        let hover_speed = (mass * GRAVITY / (4.0 * thrust_coefficient)).sqrt();
        Self {
            name: "iris".to_owned(),
            mass,
            inertia: [
                0.029125 * inertia_scale,
                0.029125 * inertia_scale,
                0.055225 * inertia_scale,
            ],
            rotors: quad_x(0.13, 0.13, 0.22, 0.20),
            thrust_coefficient,
            torque_coefficient: 0.06,
            rotor_thrust_max: thrust_coefficient * 1100.0 * 1100.0,
            rotor_speed_min: 100.0,
            rotor_speed_max: 1100.0,
            motor_time_constant: 0.025,
            max_velocity: 10.0,
            max_acceleration: 3.0,
            power: RotorPowerModel {
                linear: 0.0,
                cubic: IRIS_MEASURED_HOVER_POWER_W / 4.0 / hover_speed.powi(3),
                sextic: 0.0,
            },
            drag: LinearDrag::NONE,
            size: [0.47, 0.47, 0.11],
            battery: BatterySpec {
                capacity_wh: 56.61,
                usable_fraction: 0.8,
            },
        }
    }

    /// A preset by name; the error lists the names there are.
    pub fn preset(name: &str) -> Result<Self, String> {
        match name {
            "kingfisher" => Ok(Self::kingfisher()),
            "iris" => Ok(Self::iris()),
            other => Err(format!(
                "unknown airframe preset `{other}`; presets: {}",
                PRESET_NAMES.join(", ")
            )),
        }
    }

    /// Sets fields by name (the scenario's `airframe_overrides`), then checks the result.
    /// `arm_x` / `arm_y` move every rotor to that distance from the body's x / y axis,
    /// keeping its side. An unknown name is refused with the list of valid ones.
    pub fn apply_overrides(&mut self, overrides: &BTreeMap<String, f64>) -> Result<(), String> {
        for (name, &value) in overrides {
            if !value.is_finite() {
                return Err(format!("airframe field `{name}` must be a finite number"));
            }
            match name.as_str() {
                "mass" => self.mass = value,
                "inertia_xx" => self.inertia[0] = value,
                "inertia_yy" => self.inertia[1] = value,
                "inertia_zz" => self.inertia[2] = value,
                "arm_x" => self
                    .rotors
                    .iter_mut()
                    .for_each(|r| r.x = value.copysign(r.x)),
                "arm_y" => self
                    .rotors
                    .iter_mut()
                    .for_each(|r| r.y = value.copysign(r.y)),
                "thrust_coefficient" => self.thrust_coefficient = value,
                "torque_coefficient" => self.torque_coefficient = value,
                "rotor_thrust_max" => self.rotor_thrust_max = value,
                "rotor_speed_min" => self.rotor_speed_min = value,
                "rotor_speed_max" => self.rotor_speed_max = value,
                "motor_time_constant" => self.motor_time_constant = value,
                "max_velocity" => self.max_velocity = value,
                "max_acceleration" => self.max_acceleration = value,
                "power_linear" => self.power.linear = value,
                "power_cubic" => self.power.cubic = value,
                "power_sextic" => self.power.sextic = value,
                "drag_body" => self.drag.body = value,
                "drag_rotor_xy" => self.drag.rotor_xy = value,
                "drag_rotor_z" => self.drag.rotor_z = value,
                "size_x" => self.size[0] = value,
                "size_y" => self.size[1] = value,
                "size_z" => self.size[2] = value,
                "battery_capacity_wh" => self.battery.capacity_wh = value,
                "battery_usable_fraction" => self.battery.usable_fraction = value,
                other => {
                    return Err(format!(
                        "unknown airframe field `{other}`; valid fields: {}",
                        OVERRIDE_NAMES.join(", ")
                    ));
                }
            }
        }
        self.validate()
    }

    /// Checks that the airframe can be flown: positive masses and limits, a rotor layout that
    /// controls roll, pitch and yaw, and enough thrust to hover.
    pub fn validate(&self) -> Result<(), String> {
        let positive = [
            ("mass", self.mass),
            ("inertia_xx", self.inertia[0]),
            ("inertia_yy", self.inertia[1]),
            ("inertia_zz", self.inertia[2]),
            ("thrust_coefficient", self.thrust_coefficient),
            ("torque_coefficient", self.torque_coefficient),
            ("rotor_thrust_max", self.rotor_thrust_max),
            ("rotor_speed_max", self.rotor_speed_max),
            ("motor_time_constant", self.motor_time_constant),
            ("max_velocity", self.max_velocity),
            ("max_acceleration", self.max_acceleration),
            ("size_x", self.size[0]),
            ("size_y", self.size[1]),
            ("size_z", self.size[2]),
            ("battery_capacity_wh", self.battery.capacity_wh),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(format!("airframe field `{name}` must be > 0, got {value}"));
            }
        }
        let non_negative = [
            ("rotor_speed_min", self.rotor_speed_min),
            ("power_linear", self.power.linear),
            ("power_cubic", self.power.cubic),
            ("power_sextic", self.power.sextic),
            ("drag_body", self.drag.body),
            ("drag_rotor_xy", self.drag.rotor_xy),
            ("drag_rotor_z", self.drag.rotor_z),
        ];
        for (name, value) in non_negative {
            if !(value.is_finite() && value >= 0.0) {
                return Err(format!("airframe field `{name}` must be >= 0, got {value}"));
            }
        }
        if self.power.linear + self.power.cubic + self.power.sextic <= 0.0 {
            return Err(
                "the rotor power model is zero (power_linear, power_cubic, power_sextic)".into(),
            );
        }
        if self.rotor_speed_min >= self.rotor_speed_max {
            return Err(format!(
                "rotor_speed_min ({}) must be below rotor_speed_max ({})",
                self.rotor_speed_min, self.rotor_speed_max
            ));
        }
        let usable = self.battery.usable_fraction;
        if !(usable > 0.0 && usable <= 1.0) {
            return Err(format!(
                "battery_usable_fraction must be in (0, 1], got {usable}"
            ));
        }
        for (i, rotor) in self.rotors.iter().enumerate() {
            if !(rotor.x.is_finite() && rotor.y.is_finite()) || rotor.yaw_sign.abs() != 1.0 {
                return Err(format!(
                    "rotor {i} needs a finite position and a yaw sign of +1 or -1"
                ));
            }
        }
        if self.allocation_determinant().abs() < 1e-12 {
            return Err(
                "the rotor layout (arm_x, arm_y, torque_coefficient) cannot produce independent \
                 roll, pitch and yaw torques"
                    .into(),
            );
        }
        let (thrust_min, thrust_max) = self.rotor_thrust_range();
        let weight = self.mass * GRAVITY;
        if 4.0 * thrust_max <= weight {
            return Err(format!(
                "the rotors lift at most {:.2} N (4 x the lower of rotor_thrust_max and \
                 thrust_coefficient x rotor_speed_max^2), less than the weight {weight:.2} N \
                 (mass x g)",
                4.0 * thrust_max
            ));
        }
        if 4.0 * thrust_min >= weight {
            return Err(format!(
                "the rotors' idle thrust ({:.3} N: 4 x thrust_coefficient x rotor_speed_min^2) \
                 is not below the weight {weight:.3} N (mass x g): the airframe can neither \
                 hover nor descend",
                4.0 * thrust_min
            ));
        }
        self.validate_planning_limits(thrust_max)
    }

    /// The planning limits within what a multirotor (and the planner's sampling) can take.
    fn validate_planning_limits(&self, thrust_max: f64) -> Result<(), String> {
        let v = self.max_velocity;
        if !(MIN_PLANNING_LIMIT..=MAX_VELOCITY).contains(&v) {
            return Err(format!(
                "max_velocity must be in [{MIN_PLANNING_LIMIT}, {MAX_VELOCITY}] m/s, got {v}"
            ));
        }
        // Thrust must carry the planned acceleration in every direction, straight up included:
        // |a + g| <= a_max + g <= 4 f_max / m.
        let climb = 4.0 * thrust_max / self.mass - GRAVITY;
        let a = self.max_acceleration;
        if !(MIN_PLANNING_LIMIT..=climb).contains(&a) {
            return Err(format!(
                "max_acceleration must be in [{MIN_PLANNING_LIMIT}, {climb:.2}] m/s^2 (the upper \
                 bound is what the rotors give straight up: 4 x rotor thrust max / mass - g), \
                 got {a}"
            ));
        }
        Ok(())
    }

    /// Thrust range of one rotor (N): from the idle speed to the lower of the thrust limit
    /// and the thrust at the top speed.
    pub fn rotor_thrust_range(&self) -> (f64, f64) {
        let k = self.thrust_coefficient;
        let min = k * self.rotor_speed_min * self.rotor_speed_min;
        let max = self
            .rotor_thrust_max
            .min(k * self.rotor_speed_max * self.rotor_speed_max);
        (min, max)
    }

    /// Rotor speed (rad/s) at which four equal thrusts carry the weight:
    /// `sqrt(m g / (4 k_f))` (common.md §3: ~1086 rad/s for the kingfisher).
    pub fn hover_rotor_speed(&self) -> f64 {
        (self.mass * GRAVITY / (4.0 * self.thrust_coefficient)).sqrt()
    }

    /// Radius of the sphere around the centre of mass that holds the collision box (m).
    pub fn bounding_radius(&self) -> f64 {
        0.5 * (self.size[0].powi(2) + self.size[1].powi(2) + self.size[2].powi(2)).sqrt()
    }

    /// Determinant of the map from rotor thrusts to (collective thrust, roll, pitch, yaw
    /// torque); zero when the layout cannot control the body.
    fn allocation_determinant(&self) -> f64 {
        let column =
            |r: &Rotor| glam::DVec4::new(1.0, r.y, -r.x, r.yaw_sign * self.torque_coefficient);
        glam::DMat4::from_cols(
            column(&self.rotors[0]),
            column(&self.rotors[1]),
            column(&self.rotors[2]),
            column(&self.rotors[3]),
        )
        .determinant()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kingfisher_hovers_near_1086_rad_s() {
        // sqrt(0.752 * 9.81 / (4 * 1.562522e-6)) = sqrt(1_180_322) = 1086.43
        let speed = Airframe::kingfisher().hover_rotor_speed();
        assert!((speed - 1086.43).abs() < 0.01, "{speed}");
    }

    #[test]
    fn presets_are_valid_and_unknown_preset_lists_names() {
        for name in PRESET_NAMES {
            Airframe::preset(name).unwrap().validate().unwrap();
        }
        let error = Airframe::preset("crazyflie").unwrap_err();
        assert!(
            error.contains("kingfisher") && error.contains("iris"),
            "{error}"
        );
    }

    #[test]
    fn iris_power_model_reproduces_measured_hover_power() {
        let iris = Airframe::iris();
        let w = iris.hover_rotor_speed();
        let p = &iris.power;
        let per_rotor = p.linear * w + p.cubic * w.powi(3) + p.sextic * w.powi(6);
        assert!((4.0 * per_rotor - IRIS_MEASURED_HOVER_POWER_W).abs() < 1e-9);
        // 1.3 kg on four 5.84e-6 rotors: sqrt(1.3 * 9.81 / 2.336e-5) = 738.87 rad/s.
        assert!((w - 738.87).abs() < 0.01, "{w}");
    }

    #[test]
    fn overrides_set_fields_by_name() {
        let mut airframe = Airframe::kingfisher();
        let overrides = BTreeMap::from([
            ("mass".to_owned(), 0.9),
            ("arm_y".to_owned(), 0.12),
            ("drag_rotor_xy".to_owned(), 0.3),
            ("battery_capacity_wh".to_owned(), 40.0),
        ]);
        airframe.apply_overrides(&overrides).unwrap();
        assert_eq!(airframe.mass, 0.9);
        assert_eq!(airframe.drag.rotor_xy, 0.3);
        assert_eq!(airframe.battery.capacity_wh, 40.0);
        let ys: Vec<f64> = airframe.rotors.iter().map(|r| r.y).collect();
        assert_eq!(ys, vec![-0.12, 0.12, 0.12, -0.12]);
    }

    #[test]
    fn unknown_override_lists_valid_names() {
        let mut airframe = Airframe::kingfisher();
        let error = airframe
            .apply_overrides(&BTreeMap::from([("weight".to_owned(), 1.0)]))
            .unwrap_err();
        assert!(error.contains("`weight`"), "{error}");
        for name in OVERRIDE_NAMES {
            assert!(error.contains(name), "{name} missing from: {error}");
        }
    }

    #[test]
    fn nonsense_overrides_are_refused() {
        let cases = [
            ("mass", -1.0),
            ("mass", f64::NAN),
            ("rotor_speed_min", 3000.0),
            ("battery_usable_fraction", 1.5),
            ("arm_x", 0.0),
            // 8.5 N per rotor cannot lift 4 kg.
            ("mass", 4.0),
            // Idle thrust 4 x 1.562522e-6 x 150^2 = 0.1406 N lifts more than 0.01 kg (0.098 N).
            ("mass", 0.01),
            ("mass", 1e-30),
            // Planning limits beyond a multirotor's (1e30 m/s made the collision sampling hang).
            ("max_velocity", 1e30),
            ("max_velocity", 100.5),
            ("max_velocity", 0.05),
            ("max_acceleration", 1e-9),
            // Straight up the rotors give 4 x 8.5 / 0.752 - 9.81 = 35.40 m/s^2.
            ("max_acceleration", 35.5),
        ];
        for (name, value) in cases {
            let mut airframe = Airframe::kingfisher();
            let result = airframe.apply_overrides(&BTreeMap::from([(name.to_owned(), value)]));
            assert!(result.is_err(), "{name} = {value} was accepted");
        }
    }

    #[test]
    fn limits_within_the_envelope_are_accepted() {
        let cases = [
            ("max_velocity", 100.0),
            ("max_velocity", 0.1),
            ("max_acceleration", 35.3),
            ("mass", 0.015),
        ];
        for (name, value) in cases {
            let mut airframe = Airframe::kingfisher();
            let result = airframe.apply_overrides(&BTreeMap::from([(name.to_owned(), value)]));
            assert!(result.is_ok(), "{name} = {value}: {result:?}");
        }
    }

    #[test]
    fn thrust_range_takes_the_lower_limit() {
        let kingfisher = Airframe::kingfisher();
        let (min, max) = kingfisher.rotor_thrust_range();
        // 1.562522e-6 * 150^2 = 0.035157 N; 8.5 N is below 1.562522e-6 * 2800^2 = 12.25 N.
        assert!((min - 0.035157).abs() < 1e-6, "{min}");
        assert_eq!(max, 8.5);
    }
}
