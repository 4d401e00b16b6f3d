//! Motors: first-order lag from commanded to actual rotor speed (common.md §3,
//! time constant 0.033 s for the kingfisher), within the speed limits.

/// Speed limits and time constant of the four identical motors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorModel {
    /// s.
    pub time_constant: f64,
    /// rad/s.
    pub speed_min: f64,
    pub speed_max: f64,
}

impl MotorModel {
    pub fn new(airframe: &uavex_components::airframe::Airframe) -> Self {
        Self {
            time_constant: airframe.motor_time_constant,
            speed_min: airframe.rotor_speed_min,
            speed_max: airframe.rotor_speed_max,
        }
    }

    /// A command within the speed limits (NaN becomes the idle speed).
    pub fn clamp(&self, command: f64) -> f64 {
        if command.is_nan() {
            return self.speed_min;
        }
        command.clamp(self.speed_min, self.speed_max)
    }

    /// Rotor speed after `dt` seconds of lag toward a command held constant meanwhile:
    /// the exact solution of `dw/dt = (w_cmd - w) / tau`, so any step length is stable.
    pub fn advance(&self, speed: f64, command: f64, dt: f64) -> f64 {
        let target = self.clamp(command);
        let decay = (-dt / self.time_constant).exp();
        target + (speed - target) * decay
    }

    /// `dw/dt` of the lag, for integrators that step the motors with the rest of the state.
    pub fn rate(&self, speed: f64, command: f64) -> f64 {
        (self.clamp(command) - speed) / self.time_constant
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kingfisher_motor() -> MotorModel {
        MotorModel {
            time_constant: 0.033,
            speed_min: 150.0,
            speed_max: 2800.0,
        }
    }

    #[test]
    fn one_time_constant_covers_63_percent() {
        let motor = kingfisher_motor();
        // 1000 -> 2000 rad/s: after tau, 1000 + 1000 (1 - e^-1) = 1632.12.
        let w = motor.advance(1000.0, 2000.0, 0.033);
        assert!((w - 1632.12).abs() < 0.01, "{w}");
        // The same through many small steps.
        let mut w = 1000.0;
        for _ in 0..33 {
            w = motor.advance(w, 2000.0, 0.001);
        }
        assert!((w - 1632.12).abs() < 0.01, "{w}");
    }

    #[test]
    fn commands_are_clamped_to_the_limits() {
        let motor = kingfisher_motor();
        assert_eq!(motor.clamp(5000.0), 2800.0);
        assert_eq!(motor.clamp(-1.0), 150.0);
        assert_eq!(motor.clamp(f64::NAN), 150.0);
        // Long after a too-high command, the speed rests at the limit.
        let w = motor.advance(1000.0, 9000.0, 10.0);
        assert!((w - 2800.0).abs() < 1e-6);
        assert_eq!(motor.rate(1000.0, 9000.0), (2800.0 - 1000.0) / 0.033);
    }
}
