//! Electrical power of the rotors (common.md §4, EAAE eq. 5.2 after Bauersfeld & Scaramuzza).

use uavex_components::airframe::RotorPowerModel;

/// Power drawn by one rotor turning at `speed` rad/s:
/// `P(w) = c1 w + c3 w^3 + c6 w^6` (W).
pub fn rotor_power(model: &RotorPowerModel, speed: f64) -> f64 {
    let w = speed.abs();
    let w3 = w * w * w;
    w * model.linear + w3 * (model.cubic + w3 * model.sextic)
}

/// Total power of the four rotors (W): the sum of the per-rotor powers.
pub fn total_power(model: &RotorPowerModel, speeds: &[f64; 4]) -> f64 {
    speeds.iter().map(|&w| rotor_power(model, w)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use uavex_components::airframe::Airframe;

    #[test]
    fn kingfisher_hover_power_is_123_w() {
        let kingfisher = Airframe::kingfisher();
        let w = kingfisher.hover_rotor_speed();
        // 6.088e-3 * 1086.43 + 1.875e-8 * 1086.43^3 + 7.7e-20 * 1086.43^6
        //   = 6.614 + 24.044 + 0.126 = 30.785 W per rotor.
        let per_rotor = rotor_power(&kingfisher.power, w);
        assert!((per_rotor - 30.785).abs() < 0.01, "{per_rotor}");
        let total = total_power(&kingfisher.power, &[w; 4]);
        assert!((total - 123.14).abs() < 0.05, "{total}");
    }

    #[test]
    fn power_of_each_term() {
        let model = RotorPowerModel {
            linear: 2.0,
            cubic: 3.0,
            sextic: 5.0,
        };
        // w = 2: 2*2 + 3*8 + 5*64 = 348.
        assert_eq!(rotor_power(&model, 2.0), 348.0);
        assert_eq!(rotor_power(&model, -2.0), 348.0);
    }
}
