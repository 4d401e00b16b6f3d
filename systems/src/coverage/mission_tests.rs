use super::*;
use std::f64::consts::PI;

/// 90 deg camera, 4:3, 1 s shot period: at h, L_x = 2 h, L_y = 1.5 h, R = 2000 / h px/m.
fn problem(polygon: Polygon) -> CoverageProblem {
    CoverageProblem {
        polygon,
        start_vertex: 0,
        camera: Camera {
            angle_of_view: PI / 2.0,
            width_px: 4000,
            height_px: 3000,
            shot_period_s: 1.0,
        },
        overlaps: Overlaps { x: 0.2, y: 0.3 },
        required_resolution_px_per_m: 100.0, // h_max = 20 m
        direction: ScanDirection::LongestEdge,
    }
}

fn field() -> Polygon {
    Polygon::new(vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(300.0, 0.0),
        DVec2::new(300.0, 150.0),
        DVec2::new(0.0, 150.0),
    ])
    .unwrap()
}

#[test]
fn mission_energy_is_the_sum_of_eq_18() {
    let iris = SpeedEnergyModel::iris();
    let plan = plan_mission(&problem(field()), 20.0, &iris).unwrap();
    // Climb and descent at 20 m by hand.
    assert!((plan.climb_energy_j - 249.01 * 20.0 / 2.0912).abs() < 1e-9);
    assert!((plan.descent_energy_j - 212.47 * 20.0 / 1.2794).abs() < 1e-9);
    let sum =
        plan.climb_energy_j + plan.descent_energy_j + plan.turns_energy_j() + plan.legs_energy_j();
    assert!((plan.energy_j - sum).abs() < 1e-9 * sum);
    assert_eq!(plan.turns.len() + 1, plan.legs.len());
    for (leg, turn) in plan.legs.iter().zip(&plan.turns) {
        assert_eq!(turn.at, leg.end);
        assert!(turn.angle_rad > 0.0 && turn.angle_rad <= PI + 1e-12);
        assert!((turn.energy_j - 225.0 * turn.angle_rad / 2.1).abs() < 1e-9);
    }
    for leg in &plan.legs {
        let flight = iris.straight(leg.length_m, leg.speed_limit).unwrap();
        assert_eq!(leg.energy_j, flight.energy_j);
        assert!(leg.speed <= leg.speed_limit + 1e-9);
        assert!(leg.speed <= iris.reachable_speed(leg.length_m) + 1e-9);
    }
    assert!((plan.length_m() - plan.path.length()).abs() < 1e-6);
    assert!(plan.time_s > plan.length_m() / iris.max_speed);
}

#[test]
fn stripes_are_flown_at_the_shot_limited_speed() {
    let iris = SpeedEnergyModel::iris();
    let plan = plan_mission(&problem(field()), 20.0, &iris).unwrap();
    // At 20 m: L_y = 30 m, d_y = 21 m, v_max = 21 m/s (above the model's 15 m/s). Stripes of
    // 300 m: m = ceil(300 / 21) = 15 shots, Delta_y = (300 - 30) / 14 = 19.29 m, so the cap is
    // 19.29 m/s and v* = the long-leg optimum, below it.
    assert!((plan.survey.v_max - 21.0).abs() < 1e-9);
    let stripe = plan
        .legs
        .iter()
        .find(|l| l.length_m > 250.0)
        .expect("a stripe leg");
    assert!((stripe.speed_limit - 270.0 / 14.0).abs() < 1e-9);
    let v = iris.optimal_speed(stripe.length_m, f64::INFINITY).unwrap();
    assert!((stripe.speed - v).abs() < 1e-6);
    // A slower camera caps the stripes: T_s = 4 s gives 19.29 / 4 = 4.82 m/s.
    let mut slow = problem(field());
    slow.camera.shot_period_s = 4.0;
    let plan = plan_mission(&slow, 20.0, &iris).unwrap();
    let stripe = plan.legs.iter().find(|l| l.length_m > 250.0).unwrap();
    assert!(
        (stripe.speed - 270.0 / 14.0 / 4.0).abs() < 1e-6,
        "{}",
        stripe.speed
    );
}

#[test]
fn spare_energy_buys_resolution() {
    let iris = SpeedEnergyModel::iris();
    let p = problem(field());
    let at_h_max = plan_mission(&p, 20.0, &iris).unwrap();
    let available = at_h_max.energy_j * 1.5;
    let search = AltitudeSearch {
        step_m: 1.0,
        tolerance_j: 500.0,
        min_altitude_m: 5.0,
        max_altitude_m: 120.0,
        accept_lower_resolution: false,
    };
    let outcome = search_altitude(&p, &iris, available, &search).unwrap();
    assert_eq!(outcome.verdict, Verdict::Feasible);
    // h_max = 4000 / (2 * 100 * tan(45 deg)) = 20 m (to rounding).
    assert!((outcome.required_altitude_m - 20.0).abs() < 1e-9);
    let h_max = outcome.required_altitude_m;
    let h = outcome.plan.survey.altitude_m;
    assert!(h < h_max);
    assert!(outcome.plan.survey.resolution_px_per_m > 100.0);
    assert!(outcome.plan.energy_j < available);
    // Every step was tried from the top down, and the lowest feasible one kept.
    for (i, t) in outcome.trials.iter().enumerate() {
        assert_eq!(t.altitude_m, h_max - i as f64);
    }
    let lowest_feasible = outcome
        .trials
        .iter()
        .filter(|t| t.feasible)
        .map(|t| t.altitude_m)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(h, lowest_feasible);
    // It stopped because the margin was used up or the floor reached.
    let last = outcome.trials.last().unwrap();
    assert!(available - outcome.plan.energy_j <= 500.0 || last.altitude_m - 1.0 < 5.0);
}

#[test]
fn lowering_stops_at_the_photo_limit_and_keeps_the_lowest_plan_above() {
    // 1000 px/m puts h_max at 2 m, where a photo covers 1.6 h x 1.05 h = 6.72 m^2 apart: the
    // 1.8 km square takes about 0.5 M photos at 2 m, 0.9 M at 1.5 m and 2 M at 1 m, beyond
    // the planner's limit of 1 M.
    let side = 1800.0;
    let square = Polygon::new(vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(side, 0.0),
        DVec2::new(side, side),
        DVec2::new(0.0, side),
    ])
    .unwrap();
    let p = CoverageProblem {
        required_resolution_px_per_m: 1000.0,
        ..problem(square)
    };
    let search = AltitudeSearch {
        step_m: 0.5,
        tolerance_j: 0.0,
        min_altitude_m: 0.5,
        max_altitude_m: 120.0,
        accept_lower_resolution: false,
    };
    let outcome = search_altitude(&p, &SpeedEnergyModel::iris(), 1e12, &search).unwrap();
    assert_eq!(outcome.verdict, Verdict::Feasible);
    // h_max is 2 m to rounding (4000 px / (2 * 1000 px/m * tan 45 deg)).
    let near = |h: f64, expected: f64| (h - expected).abs() < 1e-9;
    let tried: Vec<f64> = outcome.trials.iter().map(|t| t.altitude_m).collect();
    assert!(
        tried.len() == 2 && near(tried[0], 2.0) && near(tried[1], 1.5),
        "{tried:?}"
    );
    assert!(near(outcome.plan.survey.altitude_m, 1.5));
    assert!(outcome.photo_limit_at_m.is_some_and(|h| near(h, 1.0)));
    // The searches that never reach the limit say so.
    let outcome =
        search_altitude(&problem(field()), &SpeedEnergyModel::iris(), 1e12, &search).unwrap();
    assert_eq!(outcome.photo_limit_at_m, None);
}

#[test]
fn too_little_energy_is_infeasible_or_costs_resolution() {
    let iris = SpeedEnergyModel::iris();
    let p = problem(field());
    let at_h_max = plan_mission(&p, 20.0, &iris).unwrap();
    let available = at_h_max.energy_j * 0.9;
    let mut search = AltitudeSearch::default();
    let outcome = search_altitude(&p, &iris, available, &search).unwrap();
    assert_eq!(outcome.verdict, Verdict::Infeasible { flights: 2 });
    assert_eq!(outcome.plan.survey.altitude_m, outcome.required_altitude_m);
    assert_eq!(outcome.trials.len(), 1);
    search.accept_lower_resolution = true;
    let outcome = search_altitude(&p, &iris, available, &search).unwrap();
    assert_eq!(outcome.verdict, Verdict::LowerResolution);
    let h = outcome.plan.survey.altitude_m;
    assert!(h > outcome.required_altitude_m && outcome.plan.energy_j < available);
    // The first feasible altitude on the way up is kept.
    assert!(
        outcome.trials[1..outcome.trials.len() - 1]
            .iter()
            .all(|t| !t.feasible)
    );
    // Far too little energy even at the ceiling.
    let outcome = search_altitude(&p, &iris, 1000.0, &search).unwrap();
    assert!(matches!(outcome.verdict, Verdict::Infeasible { flights } if flights > 10));
}

#[test]
fn bad_search_settings_are_errors() {
    let iris = SpeedEnergyModel::iris();
    let p = problem(field());
    let search = AltitudeSearch::default();
    assert_eq!(
        search_altitude(&p, &iris, -1.0, &search),
        Err(MissionError::AvailableEnergy(-1.0))
    );
    let zero_step = AltitudeSearch {
        step_m: 0.0,
        ..search
    };
    assert!(matches!(
        search_altitude(&p, &iris, 1e6, &zero_step),
        Err(MissionError::Search { .. })
    ));
    let high_floor = AltitudeSearch {
        min_altitude_m: 30.0,
        ..search
    };
    assert!(matches!(
        search_altitude(&p, &iris, 1e6, &high_floor),
        Err(MissionError::ResolutionUnreachable { .. })
    ));
}

#[test]
fn a_step_below_what_altitude_resolves_is_refused_not_looped_on() {
    // min = max and a step far below the ulp of 10 m: h - k step rounds back to h for ever.
    let search = AltitudeSearch {
        step_m: 1e-30,
        tolerance_j: 0.0,
        min_altitude_m: 10.0,
        max_altitude_m: 10.0,
        accept_lower_resolution: false,
    };
    let iris = SpeedEnergyModel::iris();
    let err = search_altitude(&problem(field()), &iris, 1e9, &search).unwrap_err();
    assert!(matches!(err, MissionError::StepTooSmall { .. }), "{err}");
    assert!(err.to_string().contains("below 0.001 m"), "{err}");
    // A step that resolves, with nothing to lower into: exactly one plan, at 10 m.
    let outcome = search_altitude(
        &problem(field()),
        &iris,
        1e9,
        &AltitudeSearch {
            step_m: 1e-3,
            ..search
        },
    )
    .unwrap();
    assert_eq!(outcome.trials.len(), 1);
    assert_eq!(outcome.plan.survey.altitude_m, 10.0);
}

#[test]
fn altitude_steps_are_counted_up_front() {
    assert_eq!(altitude_steps(10.0, 10.0, -1e-3).count(), 0);
    let down: Vec<f64> = altitude_steps(20.0, 17.5, -1.0).collect();
    assert_eq!(down, vec![19.0, 18.0]);
    let up: Vec<f64> = altitude_steps(20.0, 22.0, 1.0).collect();
    assert_eq!(up, vec![21.0, 22.0]);
    assert_eq!(altitude_steps(20.0, f64::NAN, 1.0).count(), 0);
    // Never more than the limit, whatever the ratio.
    assert_eq!(altitude_steps(0.0, 1e30, 1.0).count(), MAX_ALTITUDE_STEPS);
}

#[test]
fn too_many_altitude_steps_name_the_step() {
    let search = AltitudeSearch {
        step_m: 1e-3,
        min_altitude_m: 5.0,
        max_altitude_m: 120.0,
        ..AltitudeSearch::default()
    };
    let err =
        search_altitude(&problem(field()), &SpeedEnergyModel::iris(), 1e9, &search).unwrap_err();
    assert!(matches!(err, MissionError::TooManySteps { .. }), "{err}");
}

#[test]
fn a_crawling_plan_is_refused_rather_than_given_a_saturated_flight_count() {
    // A shot period of 1e30 s caps every leg at about 1e-29 m/s: the plan needs ~1e33 J.
    let mut slow = problem(field());
    slow.camera.shot_period_s = 1e30;
    let err = search_altitude(
        &slow,
        &SpeedEnergyModel::iris(),
        76_700.0,
        &AltitudeSearch::default(),
    )
    .unwrap_err();
    assert!(
        matches!(err, MissionError::FarBeyondBattery { .. }),
        "{err}"
    );
    assert!(err.to_string().contains("no count of flights"), "{err}");
    // A plan a few batteries long still gets its count.
    let outcome = search_altitude(
        &problem(field()),
        &SpeedEnergyModel::iris(),
        10_000.0,
        &AltitudeSearch::default(),
    )
    .unwrap();
    let Verdict::Infeasible { flights } = outcome.verdict else {
        panic!("{:?}", outcome.verdict)
    };
    assert_eq!(
        f64::from(flights),
        (outcome.plan.energy_j / 10_000.0).ceil().max(2.0)
    );
}

#[test]
fn a_model_pricing_a_leg_below_zero_energy_is_refused() {
    // `price` takes any model; one drawing negative power must not give a "feasible" plan.
    let mut negative = SpeedEnergyModel::iris();
    negative.level = super::super::power_curve::PowerCurve::polynomial(vec![-123.0]);
    let problem = problem(field());
    let survey = problem.camera.survey(20.0, problem.overlaps).unwrap();
    let path = plan_path(&problem.polygon, 0, &survey, problem.direction).unwrap();
    let err = price(survey, path, &negative).unwrap_err();
    assert!(matches!(err, MissionError::LegEnergy { .. }), "{err}");
}
