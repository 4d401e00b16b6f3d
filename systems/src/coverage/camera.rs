//! The downward camera: footprint on the ground, the altitude a required resolution allows, the
//! waypoint spacing from the overlaps and the speed the shot period allows (coverage.md, "Camera
//! and altitude").
//!
//! Convention (as in the paper): the image's `x` side (`I_x` pixels, angle of view `alpha`) lies
//! across the flight direction, its `y` side along it. Stripes are therefore `d_x` apart and shots
//! along a stripe `d_y` apart.

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Camera or survey parameters that make no sense.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CameraError {
    #[error("angle of view must lie in (0, pi) rad, got {0}")]
    AngleOfView(f64),
    #[error("image size must be at least 1 x 1 px, got {width} x {height}")]
    ImageSize { width: u32, height: u32 },
    #[error("shot period must be positive and finite (s), got {0}")]
    ShotPeriod(f64),
    #[error("overlap along {axis} must lie in [0, 1), got {value}")]
    Overlap { axis: char, value: f64 },
    #[error("altitude must be positive and finite (m), got {0}")]
    Altitude(f64),
    #[error("required resolution must be positive and finite (px/m), got {0}")]
    Resolution(f64),
}

/// A camera on a gimbal, looking straight down.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    /// Angle of view `alpha` across the image width (rad).
    pub angle_of_view: f64,
    /// Image width `I_x` (px).
    pub width_px: u32,
    /// Image height `I_y` (px).
    pub height_px: u32,
    /// Minimum period between two shots `T_s` (s).
    pub shot_period_s: f64,
}

/// Ground footprint of one image (m): `l_x` across the flight direction, `l_y` along it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Footprint {
    pub l_x: f64,
    pub l_y: f64,
}

/// Overlap between neighbouring images, as fractions in `[0, 1)`: `x` between stripes, `y`
/// between consecutive shots of a stripe.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Overlaps {
    pub x: f64,
    pub y: f64,
}

/// Everything the path planner needs to know about the camera at one altitude.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SurveyGeometry {
    /// Flight altitude above the ground `h` (m).
    pub altitude_m: f64,
    pub footprint: Footprint,
    /// Largest distance between stripes, `d_x = L_x (1 - ov_x)` (m).
    pub d_x: f64,
    /// Largest distance between shots along a stripe, `d_y = L_y (1 - ov_y)` (m).
    pub d_y: f64,
    /// Ground resolution `R = I_x / L_x` (px/m).
    pub resolution_px_per_m: f64,
    /// Speed at which shots `d_y` apart come exactly one shot period apart (m/s).
    pub v_max: f64,
    /// The camera's shot period `T_s` (s): a leg whose shots are closer than `d_y` must fly slower.
    pub shot_period_s: f64,
}

impl Camera {
    /// GoPro on the IRIS of the paper: 12 MP (4000 x 3000 px), 94.4 deg angle of view. The paper
    /// gives no shot period; 1 s, a common GoPro time-lapse interval, is assumed.
    pub fn gopro_12mp() -> Self {
        Self {
            angle_of_view: 94.4f64.to_radians(),
            width_px: 4000,
            height_px: 3000,
            shot_period_s: 1.0,
        }
    }

    pub fn validate(&self) -> Result<(), CameraError> {
        let alpha = self.angle_of_view;
        if !(alpha > 0.0 && alpha < std::f64::consts::PI) {
            return Err(CameraError::AngleOfView(alpha));
        }
        if self.width_px == 0 || self.height_px == 0 {
            return Err(CameraError::ImageSize {
                width: self.width_px,
                height: self.height_px,
            });
        }
        if !(self.shot_period_s > 0.0 && self.shot_period_s.is_finite()) {
            return Err(CameraError::ShotPeriod(self.shot_period_s));
        }
        Ok(())
    }

    /// Aspect ratio `rho = I_x / I_y`.
    pub fn aspect(&self) -> f64 {
        f64::from(self.width_px) / f64::from(self.height_px)
    }

    /// Footprint at height `h`: `L_x = 2 h tan(alpha / 2)`, `L_y = L_x / rho`.
    pub fn footprint(&self, altitude_m: f64) -> Footprint {
        let l_x = 2.0 * altitude_m * (self.angle_of_view / 2.0).tan();
        Footprint {
            l_x,
            l_y: l_x / self.aspect(),
        }
    }

    /// Ground resolution at height `h`: `R = I_x / L_x` (px/m).
    pub fn resolution(&self, altitude_m: f64) -> f64 {
        f64::from(self.width_px) / self.footprint(altitude_m).l_x
    }

    /// Highest altitude that still gives `R >= R_d`: `h_max = I_x / (2 R_d tan(alpha / 2))`.
    pub fn max_altitude(&self, required_px_per_m: f64) -> Result<f64, CameraError> {
        self.validate()?;
        if !(required_px_per_m > 0.0 && required_px_per_m.is_finite()) {
            return Err(CameraError::Resolution(required_px_per_m));
        }
        Ok(f64::from(self.width_px) / (2.0 * required_px_per_m * (self.angle_of_view / 2.0).tan()))
    }

    /// Footprint, spacings, resolution and speed limit at `altitude_m` with the given overlaps.
    pub fn survey(
        &self,
        altitude_m: f64,
        overlaps: Overlaps,
    ) -> Result<SurveyGeometry, CameraError> {
        self.validate()?;
        overlaps.validate()?;
        if !(altitude_m > 0.0 && altitude_m.is_finite()) {
            return Err(CameraError::Altitude(altitude_m));
        }
        let footprint = self.footprint(altitude_m);
        let d_x = footprint.l_x * (1.0 - overlaps.x);
        let d_y = footprint.l_y * (1.0 - overlaps.y);
        Ok(SurveyGeometry {
            altitude_m,
            footprint,
            d_x,
            d_y,
            resolution_px_per_m: self.resolution(altitude_m),
            // v_max = L_y (1 - ov_y) / T_s.
            v_max: d_y / self.shot_period_s,
            shot_period_s: self.shot_period_s,
        })
    }
}

impl Overlaps {
    pub fn validate(&self) -> Result<(), CameraError> {
        for (axis, value) in [('x', self.x), ('y', self.y)] {
            if !(0.0..1.0).contains(&value) {
                return Err(CameraError::Overlap { axis, value });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera_90deg() -> Camera {
        // tan(45 deg) = 1 makes every formula easy to do by hand.
        Camera {
            angle_of_view: std::f64::consts::FRAC_PI_2,
            width_px: 4000,
            height_px: 2000,
            shot_period_s: 2.0,
        }
    }

    #[test]
    fn footprint_and_resolution_by_hand() {
        let camera = camera_90deg();
        // L_x = 2 * 10 * tan(45 deg) = 20 m, rho = 2, L_y = 10 m, R = 4000 / 20 = 200 px/m.
        let footprint = camera.footprint(10.0);
        assert!((footprint.l_x - 20.0).abs() < 1e-12);
        assert!((footprint.l_y - 10.0).abs() < 1e-12);
        assert!((camera.resolution(10.0) - 200.0).abs() < 1e-9);
    }

    #[test]
    fn max_altitude_by_hand() {
        let camera = camera_90deg();
        // h_max = 4000 / (2 * 100 * 1) = 20 m, and at 20 m the resolution is exactly 100 px/m.
        let h = camera.max_altitude(100.0).unwrap();
        assert!((h - 20.0).abs() < 1e-12);
        assert!((camera.resolution(h) - 100.0).abs() < 1e-9);
        // The GoPro: tan(47.2 deg) = 1.080, h_max = 4000 / (2 * 50 * 1.0799) = 37.04 m.
        let gopro = Camera::gopro_12mp().max_altitude(50.0).unwrap();
        assert!((gopro - 37.040).abs() < 1e-3, "{gopro}");
    }

    #[test]
    fn spacing_and_speed_limit_by_hand() {
        let survey = camera_90deg()
            .survey(10.0, Overlaps { x: 0.25, y: 0.5 })
            .unwrap();
        // d_x = 20 * 0.75 = 15 m, d_y = 10 * 0.5 = 5 m, v_max = 5 / 2 = 2.5 m/s.
        assert!((survey.d_x - 15.0).abs() < 1e-12);
        assert!((survey.d_y - 5.0).abs() < 1e-12);
        assert!((survey.v_max - 2.5).abs() < 1e-12);
    }

    #[test]
    fn bad_parameters_are_refused() {
        let camera = camera_90deg();
        let ok = Overlaps { x: 0.2, y: 0.2 };
        assert_eq!(
            camera.survey(10.0, Overlaps { x: 1.0, y: 0.2 }),
            Err(CameraError::Overlap {
                axis: 'x',
                value: 1.0
            })
        );
        assert_eq!(camera.survey(-1.0, ok), Err(CameraError::Altitude(-1.0)));
        assert_eq!(camera.max_altitude(0.0), Err(CameraError::Resolution(0.0)));
        let flat = Camera {
            angle_of_view: 4.0,
            ..camera
        };
        assert_eq!(flat.survey(10.0, ok), Err(CameraError::AngleOfView(4.0)));
        let blind = Camera {
            height_px: 0,
            ..camera
        };
        assert!(matches!(
            blind.survey(10.0, ok),
            Err(CameraError::ImageSize { .. })
        ));
    }
}
