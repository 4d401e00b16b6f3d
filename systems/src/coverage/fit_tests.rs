use super::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The paper's experiments flown by a vehicle whose true model is `truth`, logged at 20 Hz with
/// power noise uniform in +-`noise_w` (standard deviation `noise_w / sqrt(3)`).
fn experiments(truth: &SpeedEnergyModel, noise_w: f64, seed: u64) -> Vec<Measurement> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut noise = move || {
        if noise_w > 0.0 {
            rng.random_range(-noise_w..noise_w)
        } else {
            0.0
        }
    };
    let dt = 0.05;
    let top = truth.max_speed;
    let mut rows = Vec::new();
    let mut t = 0.0;
    let log = |rows: &mut Vec<Measurement>, t: &mut f64, speed: f64, power: f64, phase| {
        rows.push(Measurement {
            time_s: *t,
            speed,
            power_w: power,
            phase,
        });
        *t += dt;
    };
    for _run in 0..2 {
        // Maximum acceleration from rest to the top speed, then maximum deceleration to rest.
        let steps = (top / truth.acceleration / dt).round() as usize;
        for i in 0..=steps {
            let v = truth.acceleration * i as f64 * dt;
            log(
                &mut rows,
                &mut t,
                v,
                truth.accelerating.power(v) + noise(),
                Phase::Accelerate,
            );
        }
        let steps = (top / truth.deceleration / dt).round() as usize;
        for i in 0..=steps {
            let v = top - truth.deceleration * i as f64 * dt;
            log(
                &mut rows,
                &mut t,
                v,
                truth.decelerating.power(v) + noise(),
                Phase::Decelerate,
            );
        }
    }
    for k in 1..=15 {
        let v = top * k as f64 / 15.0;
        for _ in 0..100 {
            log(
                &mut rows,
                &mut t,
                v,
                truth.level.power(v) + noise(),
                Phase::Cruise,
            );
        }
    }
    for _ in 0..100 {
        log(
            &mut rows,
            &mut t,
            0.0,
            truth.hover_power() + noise(),
            Phase::Hover,
        );
        log(
            &mut rows,
            &mut t,
            truth.climb.speed,
            truth.climb.power_w + noise(),
            Phase::Climb,
        );
        log(
            &mut rows,
            &mut t,
            -truth.descent.speed,
            truth.descent.power_w + noise(),
            Phase::Descend,
        );
        log(
            &mut rows,
            &mut t,
            truth.turn.rate,
            truth.turn.power_w + noise(),
            Phase::Turn,
        );
    }
    rows
}

#[test]
fn exact_measurements_give_back_the_published_model() {
    let iris = SpeedEnergyModel::iris();
    let fitted = fit_model(
        "iris-refit",
        &experiments(&iris, 0.0, 1),
        FitDegrees::default(),
    )
    .unwrap();
    let m = &fitted.model;
    let r = &fitted.report;
    for (fit, truth) in [
        (&m.level, &iris.level),
        (&m.accelerating, &iris.accelerating),
    ] {
        for (a, b) in fit.coefficients.iter().zip(&truth.coefficients) {
            assert!((a - b).abs() <= 1e-6 * b.abs().max(1.0), "{a} vs {b}");
        }
    }
    // The reflected deceleration curve comes back as a plain polynomial with the same values.
    for i in 0..=150 {
        let v = i as f64 / 10.0;
        assert!((m.decelerating.power(v) - iris.decelerating.power(v)).abs() < 1e-6);
    }
    assert!(r.level.rms_residual_w < 1e-6 && r.level.r_squared > 1.0 - 1e-12);
    assert!(r.accelerating.max_abs_residual_w < 1e-6);
    assert!((m.acceleration - 1.0).abs() < 1e-9 && (m.deceleration - 1.0).abs() < 1e-9);
    assert!((m.climb.power_w - iris.climb.power_w).abs() < 1e-9);
    assert!((m.climb.speed - iris.climb.speed).abs() < 1e-12);
    assert!((m.descent.speed - iris.descent.speed).abs() < 1e-12);
    assert!((m.turn.power_w - 225.0).abs() < 1e-9 && (m.turn.rate - 2.1).abs() < 1e-12);
    assert_eq!(m.max_speed, 15.0);
    assert_eq!(r.hover.unwrap().samples, 100);
    assert_eq!(r.level.samples, 1600);
    assert_eq!(r.acceleration.samples, 2 * 301);
}

#[test]
fn noisy_measurements_predict_fresh_legs_within_half_a_percent() {
    let iris = SpeedEnergyModel::iris();
    let noise_w = 5.0;
    let fitted = fit_model(
        "noisy",
        &experiments(&iris, noise_w, 7),
        FitDegrees::default(),
    )
    .unwrap();
    let m = &fitted.model;
    let r = &fitted.report;
    // The residuals are the noise: standard deviation 5 / sqrt(3) = 2.89 W.
    let sigma = noise_w / 3f64.sqrt();
    for fit in [&r.level, &r.accelerating, &r.decelerating] {
        assert!((fit.rms_residual_w - sigma).abs() < 0.15 * sigma, "{fit:?}");
        assert!(fit.max_abs_residual_w < noise_w + 1.0);
    }
    for d in [30.0, 120.0, 400.0, 2000.0] {
        let v = iris.optimal_speed(d, f64::INFINITY).unwrap();
        let truth = iris.straight_energy(d, v).unwrap();
        let predicted = m.straight_energy(d, v).unwrap();
        assert!(
            (predicted - truth).abs() < 0.005 * truth,
            "{d} m: {predicted} vs {truth}"
        );
    }
    assert!((m.climb.power_w - 249.01).abs() < 1.0);
}

#[test]
fn chosen_degrees_are_honoured_and_a_poor_fit_shows_in_the_residuals() {
    let iris = SpeedEnergyModel::iris();
    let rows = experiments(&iris, 0.0, 3);
    let degrees = FitDegrees {
        level: 1,
        accelerating: 2,
        decelerating: 3,
    };
    let fitted = fit_model("straight-lines", &rows, degrees).unwrap();
    assert_eq!(fitted.model.level.coefficients.len(), 2);
    assert_eq!(fitted.model.accelerating.coefficients.len(), 3);
    assert_eq!(fitted.model.decelerating.coefficients.len(), 4);
    assert_eq!(fitted.report.level.degree, 1);
    // A straight line cannot follow the quartic level curve (221 W at rest, 206 W at 8 m/s,
    // 332 W at 15 m/s).
    assert!(fitted.report.level.rms_residual_w > 10.0);
    assert!(fitted.report.level.r_squared < 0.9);
}

#[test]
fn missing_or_bad_measurements_are_errors() {
    let iris = SpeedEnergyModel::iris();
    let rows = experiments(&iris, 0.0, 5);
    let without_turns: Vec<Measurement> = rows
        .iter()
        .copied()
        .filter(|m| m.phase != Phase::Turn)
        .collect();
    assert_eq!(
        fit_model("x", &without_turns, FitDegrees::default()),
        Err(FitError::Missing { phase: "turn" })
    );
    let mut nan = rows.clone();
    nan[10].power_w = f64::NAN;
    assert_eq!(
        fit_model("x", &nan, FitDegrees::default()),
        Err(FitError::NonFinite { row: 10 })
    );
    let few_speeds: Vec<Measurement> = rows
        .iter()
        .copied()
        .filter(|m| m.phase != Phase::Cruise || m.speed <= 3.0)
        .collect();
    assert_eq!(
        fit_model("x", &few_speeds, FitDegrees::default()),
        Err(FitError::TooFew {
            phase: "cruise",
            degree: 4,
            needed: 5,
            got: 4
        })
    );
    assert_eq!("Cruise".parse::<Phase>(), Ok(Phase::Cruise));
    assert!(
        "glide"
            .parse::<Phase>()
            .unwrap_err()
            .contains("unknown phase `glide`")
    );
}
