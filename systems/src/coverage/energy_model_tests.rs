use super::*;

/// Composite Simpson's rule with `n` (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let inner: f64 = (1..n)
        .map(|i| f(a + h * i as f64) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(a) + f(b) + inner) * h / 3.0
}

/// Energy of flying the rest-to-rest speed profile, integrated over time with the midpoint rule:
/// speed `a t` while accelerating, `v` while cruising, `v - b t` while decelerating.
fn flown_energy(model: &SpeedEnergyModel, d: f64, v: f64, dt: f64) -> (f64, f64) {
    let (a, b) = (model.acceleration, model.deceleration);
    let t_acc = v / a;
    let t_dec = v / b;
    let t_cruise = (d - v * v / (2.0 * a) - v * v / (2.0 * b)) / v;
    let mut energy = 0.0;
    let steps = |t: f64| (t / dt).ceil().max(1.0) as usize;
    let n = steps(t_acc);
    let h = t_acc / n as f64;
    energy += (0..n)
        .map(|i| model.accelerating.power(a * (i as f64 + 0.5) * h) * h)
        .sum::<f64>();
    energy += model.level.power(v) * t_cruise;
    let n = steps(t_dec);
    let h = t_dec / n as f64;
    energy += (0..n)
        .map(|i| model.decelerating.power(v - b * (i as f64 + 0.5) * h) * h)
        .sum::<f64>();
    (energy, t_acc + t_cruise + t_dec)
}

#[test]
fn iris_coefficients_by_hand() {
    let iris = SpeedEnergyModel::iris();
    iris.validate().unwrap();
    assert_eq!(iris.hover_power(), 221.278607);
    // P_dec(0) = q(15) = 1.07216605e-2 * 15^4 - 0.493828311 * 15^3 + 8.34385707 * 15^2
    //   - 57.7374016 * 15 + 341.872290 = 542.7841 - 1666.6705 + 1877.3678 - 866.0610
    //   + 341.8723 = 229.2927
    let q15 = 1.07216605e-02 * 50625.0 - 4.93828311e-01 * 3375.0 + 8.34385707e+00 * 225.0
        - 5.77374016e+01 * 15.0
        + 3.41872290e+02;
    assert!((iris.decelerating.power(0.0) - q15).abs() < 1e-9);
    assert!((q15 - 229.2927).abs() < 1e-3, "{q15}");
    // P_acc(0) is its constant term.
    assert_eq!(iris.accelerating.power(0.0), 233.597050);
    // Climbing 20 m: 249.01 W for 20 / 2.0912 s = 2381.5 J; descending: 212.47 * 20 / 1.2794.
    assert!((iris.climb_energy(20.0) - 2381.504).abs() < 1e-3);
    assert!((iris.descent_energy(20.0) - 3321.401).abs() < 1e-3);
    // A quarter turn: 225 W for (pi/2) / 2.1 s = 168.3 J.
    assert!((iris.turn_energy(std::f64::consts::FRAC_PI_2) - 168.2994).abs() < 1e-3);
}

#[test]
fn straight_time_by_hand() {
    let iris = SpeedEnergyModel::iris();
    // t = 2 v / a + (d - v^2 / a) / v = 10 + 75 / 5 = 25 s.
    assert!((iris.straight_time(100.0, 5.0).unwrap() - 25.0).abs() < 1e-12);
    // At v = sqrt(a d) the cruise vanishes: t = 2 * 10 = 20 s.
    assert!((iris.straight_time(100.0, 10.0).unwrap() - 20.0).abs() < 1e-12);
}

#[test]
fn straight_energy_matches_quadrature_of_the_same_polynomials() {
    let iris = SpeedEnergyModel::iris();
    for (d, v) in [
        (10.0, 1.0),
        (50.0, 5.0),
        (200.0, 12.0),
        (400.0, 15.0),
        (100.0, 10.0),
    ] {
        let closed = iris.straight_energy(d, v).unwrap();
        // Quadrature over speed of the spec's formula.
        let by_speed = simpson(|u| iris.accelerating.power(u), 0.0, v, 2000) / iris.acceleration
            + iris.level.power(v) * (d - v * v / iris.acceleration) / v
            + simpson(|u| iris.decelerating.power(u), 0.0, v, 2000) / iris.deceleration;
        assert!(
            (closed - by_speed).abs() < 1e-8 * closed,
            "{d} {v}: {closed} vs {by_speed}"
        );
        // The flown speed profile integrated over time.
        let (flown, time) = flown_energy(&iris, d, v, 1e-3);
        assert!(
            (closed - flown).abs() < 1e-6 * closed,
            "{d} {v}: {closed} vs {flown}"
        );
        assert!((iris.straight_time(d, v).unwrap() - time).abs() < 1e-9);
    }
}

#[test]
fn unequal_acceleration_and_deceleration_match_the_flown_profile() {
    let model = SpeedEnergyModel {
        acceleration: 2.0,
        deceleration: 0.5,
        ..SpeedEnergyModel::iris()
    };
    // Reachable: v^2 (1/4 + 1) = 100 -> v = sqrt(80).
    assert!((model.reachable_speed(100.0) - 80f64.sqrt()).abs() < 1e-12);
    for (d, v) in [(100.0, 4.0), (300.0, 9.0)] {
        let (flown, time) = flown_energy(&model, d, v, 1e-3);
        let closed = model.straight_energy(d, v).unwrap();
        assert!(
            (closed - flown).abs() < 1e-6 * closed,
            "{closed} vs {flown}"
        );
        assert!((model.straight_time(d, v).unwrap() - time).abs() < 1e-9);
    }
}

/// `v*(d)` over legs from 1 m to 1000 km, checked against a fine scan of `E(d, v)`.
fn optimal_speeds(model: &SpeedEnergyModel) -> Vec<(f64, f64)> {
    let mut speeds = Vec::new();
    let mut d = 1.0;
    while d < 1e6 {
        let v = model.optimal_speed(d, f64::INFINITY).unwrap();
        assert!(v <= model.reachable_speed(d) + 1e-12);
        let e = model.straight_energy(d, v).unwrap();
        let top = model.reachable_speed(d).min(model.max_speed);
        for i in 1..=400 {
            let u = top * i as f64 / 400.0;
            assert!(
                model.straight_energy(d, u).unwrap() >= e - 1e-9 * e,
                "v*({d}) = {v}, {u} better"
            );
        }
        speeds.push((d, v));
        d *= 1.25;
    }
    speeds
}

/// The constant-speed optimum solves `P'(v) v = P(v)`.
fn assert_stationary(model: &SpeedEnergyModel, v: f64) {
    let h = 1e-6;
    let slope = (model.level.power(v + h) - model.level.power(v - h)) / (2.0 * h);
    assert!((slope * v - model.level.power(v)).abs() < 1e-4);
}

/// With a model where speeding up costs more than cruising (as physics says), `v*(d)` grows with
/// `d` and tends to `argmin P(v)/v` from below.
#[test]
fn optimal_speed_grows_with_distance_towards_the_cruise_optimum() {
    let iris = SpeedEnergyModel::iris();
    let mut level_plus_60w = iris.level.coefficients.clone();
    *level_plus_60w.last_mut().unwrap() += 60.0;
    let physical = SpeedEnergyModel {
        accelerating: PowerCurve::polynomial(level_plus_60w),
        decelerating: iris.level.clone(),
        ..iris
    };
    let cruise = physical.cruise_optimum();
    assert_stationary(&physical, cruise);
    assert!((cruise - 12.1787).abs() < 1e-3, "{cruise}");
    let speeds = optimal_speeds(&physical);
    for w in speeds.windows(2) {
        assert!(
            w[1].1 >= w[0].1 - 1e-9,
            "v*({}) = {} < v*({}) = {}",
            w[1].0,
            w[1].1,
            w[0].0,
            w[0].1
        );
    }
    let (_, longest) = *speeds.last().unwrap();
    assert!(
        longest <= cruise && cruise - longest < 0.01,
        "{longest} vs {cruise}"
    );
}

/// The published IRIS curves put the power while accelerating and decelerating near 12 m/s
/// below the cruise power (P_acc + P_dec < 2 P there), so `v*(d)` is not monotonic: up to about
/// 225 m the best leg barely cruises (`v*` within 3 % of `sqrt(a d)`, and equal to it from 150 m
/// on: ramps only); beyond, `v*` drops to about 12.5 m/s and tends to `argmin P(v)/v` from above.
#[test]
fn iris_optimal_speed_tends_to_the_cruise_optimum() {
    let iris = SpeedEnergyModel::iris();
    let cruise = iris.cruise_optimum();
    assert_stationary(&iris, cruise);
    assert!((cruise - 12.1787).abs() < 1e-3, "{cruise}");
    let speeds = optimal_speeds(&iris);
    for &(d, v) in &speeds {
        let top = iris.reachable_speed(d);
        if d <= 220.0 {
            assert!(v >= 0.97 * top, "v*({d}) = {v}");
        }
        if (150.0..=220.0).contains(&d) {
            assert!((v - top).abs() < 1e-6, "v*({d}) = {v}");
        }
        if d >= 300.0 {
            assert!(v >= cruise && v < 12.45, "v*({d}) = {v}");
        }
    }
    for w in speeds.windows(2).filter(|w| w[0].0 >= 300.0) {
        assert!(w[1].1 <= w[0].1 + 1e-9);
    }
    let (_, longest) = *speeds.last().unwrap();
    assert!((longest - cruise).abs() < 0.01, "{longest} vs {cruise}");
}

#[test]
fn speed_limit_caps_the_optimum() {
    let iris = SpeedEnergyModel::iris();
    let flight = iris.straight(1000.0, 6.0).unwrap();
    assert!((flight.speed - 6.0).abs() < 1e-6);
    assert_eq!(iris.straight(0.0, 6.0).unwrap().energy_j, 0.0);
}

#[test]
fn bad_requests_are_errors() {
    let iris = SpeedEnergyModel::iris();
    assert!(matches!(
        iris.straight_energy(100.0, 11.0),
        Err(EnergyModelError::Speed { .. })
    ));
    assert!(matches!(
        iris.straight_energy(-1.0, 1.0),
        Err(EnergyModelError::Distance(_))
    ));
    assert!(matches!(
        iris.optimal_speed(f64::NAN, 1.0),
        Err(EnergyModelError::Distance(_))
    ));
    assert!(matches!(
        iris.optimal_speed(10.0, 0.0),
        Err(EnergyModelError::SpeedLimit(_))
    ));
    let broken = SpeedEnergyModel {
        acceleration: 0.0,
        ..SpeedEnergyModel::iris()
    };
    assert!(matches!(
        broken.validate(),
        Err(EnergyModelError::NotPositive {
            what: "acceleration",
            ..
        })
    ));
    let empty = SpeedEnergyModel {
        level: PowerCurve::polynomial(vec![]),
        ..SpeedEnergyModel::iris()
    };
    assert!(matches!(
        empty.validate(),
        Err(EnergyModelError::Curve { .. })
    ));
}

#[test]
fn power_must_be_positive_wherever_a_curve_is_used() {
    assert_eq!(SpeedEnergyModel::iris().validate(), Ok(()));
    // The fuzzed model: level power -123 W at every speed ("feasible", -9e10 kJ).
    let mut negative = SpeedEnergyModel::iris();
    negative.level = PowerCurve::polynomial(vec![0.0, 0.0, 0.0, 0.0, -123.0]);
    let err = negative.validate().unwrap_err();
    assert!(
        matches!(
            err,
            EnergyModelError::NonPositivePower {
                curve: "level",
                speed: 0.0,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("level.coefficients"), "{err}");
    // Positive at hover, negative near the top speed: found at the speed where it dips.
    let mut dips = SpeedEnergyModel::iris();
    dips.decelerating = PowerCurve::polynomial(vec![-10.0, 100.0]);
    let Err(EnergyModelError::NonPositivePower { curve, speed, .. }) = dips.validate() else {
        panic!("a curve crossing zero at 10 m/s was accepted")
    };
    assert_eq!(curve, "decelerating");
    assert!((10.0..10.1).contains(&speed), "{speed}");
    // Beyond max_speed the curve is never used, so it may do what it likes there.
    dips.max_speed = 9.0;
    assert_eq!(dips.validate(), Ok(()));
}

#[test]
fn power_curves_have_bounded_degree() {
    let mut long = SpeedEnergyModel::iris();
    long.accelerating = PowerCurve::polynomial(vec![1e-30; 1000]);
    assert!(matches!(
        long.validate(),
        Err(EnergyModelError::TooManyCoefficients { count: 1000, .. })
    ));
}
