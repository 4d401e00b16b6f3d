//! Text reports: `uavex energy MODEL --distance D` ([`energy_report`]), `uavex cover SCENARIO`
//! ([`cover_report`]) and fitting from measurements ([`fit_report`]).

use std::fmt::Write;
use uavex_systems::coverage::{
    AltitudeOutcome, CurveFit, EnergyModelError, FittedModel, MAX_SHOTS, Polygon, SpeedEnergyModel,
    Verdict,
};

/// `v*(d)`, `E(d, v*)` and `t(d)` of a straight leg of `distance` flown from rest to rest.
pub fn energy_report(model: &SpeedEnergyModel, distance: f64) -> Result<String, EnergyModelError> {
    model.validate()?;
    let flight = model.straight(distance, f64::INFINITY)?;
    let cruise = model.cruise_optimum();
    let mut out = String::new();
    let w = &mut out;
    let _ = writeln!(w, "energy model `{}`", model.name);
    let _ = writeln!(
        w,
        "straight leg of {distance:.2} m from rest to rest (accelerating at {:.2} m/s^2, \
         decelerating at {:.2} m/s^2)",
        model.acceleration, model.deceleration
    );
    let _ = writeln!(
        w,
        "  optimal speed v*(d)  {:>10.3} m/s   (at most {:.3} m/s: reachable {:.3}, model {:.3})",
        flight.speed,
        model.reachable_speed(distance).min(model.max_speed),
        model.reachable_speed(distance),
        model.max_speed
    );
    let per_metre = if distance > 0.0 {
        flight.energy_j / distance
    } else {
        0.0
    };
    let _ = writeln!(
        w,
        "  energy E(d, v*)      {:>10.1} J     ({per_metre:.2} J/m)",
        flight.energy_j
    );
    let _ = writeln!(w, "  time t(d)            {:>10.2} s", flight.time_s);
    let _ = writeln!(w, "  hover power P(0)     {:>10.1} W", model.hover_power());
    let _ = writeln!(
        w,
        "  long legs tend to    {:>10.3} m/s   (argmin P(v)/v: {:.2} J/m)",
        cruise,
        model.level.power(cruise) / cruise
    );
    Ok(out)
}

/// The plan found by the altitude search: shape, altitude and resolution, the path's numbers,
/// time and energy (eq. 18) and the verdict against the battery.
pub fn cover_report(
    polygon: &Polygon,
    required_px_per_m: f64,
    outcome: &AltitudeOutcome,
) -> String {
    let plan = &outcome.plan;
    let survey = &plan.survey;
    let mut out = String::new();
    let w = &mut out;
    let verdict = match outcome.verdict {
        Verdict::Feasible => "feasible at the required resolution".to_owned(),
        Verdict::LowerResolution => {
            "feasible only above the required altitude, at less resolution than required".to_owned()
        }
        Verdict::Infeasible { flights } => {
            format!("NOT feasible on one battery: at least {flights} flights (or UAVs) are needed")
        }
    };
    let _ = writeln!(w, "coverage plan: {verdict}");
    let _ = writeln!(
        w,
        "  field           {} vertices, {:.0} m^2, perimeter {:.1} m",
        polygon.len(),
        polygon.area(),
        polygon.perimeter()
    );
    let _ = writeln!(
        w,
        "  altitude        {:.2} m (the required {required_px_per_m:.1} px/m allows up to {:.2} m)",
        survey.altitude_m, outcome.required_altitude_m
    );
    let _ = writeln!(
        w,
        "  resolution      {:.1} px/m",
        survey.resolution_px_per_m
    );
    let _ = writeln!(
        w,
        "  footprint       {:.2} m x {:.2} m; stripes at most {:.2} m apart, shots {:.2} m; v_max {:.2} m/s",
        survey.footprint.l_x, survey.footprint.l_y, survey.d_x, survey.d_y, survey.v_max
    );
    let _ = writeln!(
        w,
        "  areas           {} (1 + {} cut off at concavities)",
        plan.path.areas,
        plan.path.areas.saturating_sub(1)
    );
    let _ = writeln!(w, "  stripes         {}", plan.path.stripes);
    let _ = writeln!(
        w,
        "  waypoints       {} ({} shots)",
        plan.path.waypoints.len(),
        plan.path.shots().count()
    );
    let _ = writeln!(
        w,
        "  legs            {}, length {:.1} m",
        plan.legs.len(),
        plan.length_m()
    );
    let _ = writeln!(
        w,
        "  turns           {}, {:.1} rad in all",
        plan.turns.len(),
        plan.turns.iter().map(|t| t.angle_rad).sum::<f64>()
    );
    let legs_time: f64 = plan.legs.iter().map(|l| l.time_s).sum();
    let turns_time: f64 = plan.turns.iter().map(|t| t.time_s).sum();
    let _ = writeln!(
        w,
        "  time            {:.1} s (climb {:.1} + legs {:.1} + turns {:.1} + descent {:.1})",
        plan.time_s, plan.climb_time_s, legs_time, turns_time, plan.descent_time_s
    );
    let _ = writeln!(
        w,
        "  energy          {:.2} kJ = climb {:.2} + legs {:.2} + turns {:.2} + descent {:.2} kJ (eq. 18)",
        plan.energy_j / 1e3,
        plan.climb_energy_j / 1e3,
        plan.legs_energy_j() / 1e3,
        plan.turns_energy_j() / 1e3,
        plan.descent_energy_j / 1e3
    );
    let margin = outcome.available_energy_j - plan.energy_j;
    let _ = writeln!(
        w,
        "  available       {:.2} kJ: margin {:.2} kJ ({:.1} %)",
        outcome.available_energy_j / 1e3,
        margin / 1e3,
        100.0 * margin / outcome.available_energy_j
    );
    let _ = write!(
        w,
        "  altitude search {} re-plans from {:.2} m to {:.2} m",
        outcome.trials.len(),
        outcome.trials.first().map_or(0.0, |t| t.altitude_m),
        outcome.trials.last().map_or(0.0, |t| t.altitude_m)
    );
    let _ = match outcome.photo_limit_at_m {
        Some(h) => writeln!(w, ", stopped at {h:.2} m: more than {MAX_SHOTS} photos"),
        None => writeln!(w),
    };
    out
}

/// The fitted curves and constants with their residuals.
pub fn fit_report(fitted: &FittedModel) -> String {
    let m = &fitted.model;
    let r = &fitted.report;
    let mut out = String::new();
    let w = &mut out;
    let _ = writeln!(w, "fitted energy model `{}`", m.name);
    let curve = |w: &mut String, name: &str, coefficients: &[f64], fit: &CurveFit| {
        let list: Vec<String> = coefficients.iter().map(|c| format!("{c:.8e}")).collect();
        let _ = writeln!(
            w,
            "  {name:<13} degree {}, {} samples: [{}]\n  {:<13} residuals: rms {:.3} W, max {:.3} W, R^2 {:.5}",
            fit.degree,
            fit.samples,
            list.join(", "),
            "",
            fit.rms_residual_w,
            fit.max_abs_residual_w,
            fit.r_squared
        );
    };
    curve(w, "P(v)", &m.level.coefficients, &r.level);
    curve(w, "P_acc(v)", &m.accelerating.coefficients, &r.accelerating);
    curve(w, "P_dec(v)", &m.decelerating.coefficients, &r.decelerating);
    let _ = writeln!(
        w,
        "  acceleration  {:.4} m/s^2 ({} samples, rms {:.4} m/s); deceleration {:.4} m/s^2 ({} samples, rms {:.4} m/s)",
        r.acceleration.value,
        r.acceleration.samples,
        r.acceleration.rms_residual,
        r.deceleration.value,
        r.deceleration.samples,
        r.deceleration.rms_residual
    );
    for (name, fit, unit) in [
        ("climb", &r.climb, "m/s"),
        ("descent", &r.descent, "m/s"),
        ("turn", &r.turn, "rad/s"),
    ] {
        let _ = writeln!(
            w,
            "  {name:<13} {:.2} W at {:.4} {unit} ({} samples, rms {:.3} W)",
            fit.power_w, fit.speed, fit.samples, fit.rms_residual_w
        );
    }
    if let Some(hover) = &r.hover {
        let _ = writeln!(
            w,
            "  hover         {:.2} W measured ({} samples), P(0) = {:.2} W",
            hover.power_w,
            hover.samples,
            m.hover_power()
        );
    }
    let _ = writeln!(w, "  valid up to   {:.3} m/s", m.max_speed);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;
    use uavex_systems::coverage::{
        AltitudeSearch, Camera, CoverageProblem, Overlaps, ScanDirection, search_altitude,
    };

    #[test]
    fn energy_report_prints_the_optimum() {
        let iris = SpeedEnergyModel::iris();
        let text = energy_report(&iris, 1000.0).unwrap();
        let v = iris.optimal_speed(1000.0, f64::INFINITY).unwrap();
        let e = iris.straight_energy(1000.0, v).unwrap();
        assert!(text.contains(&format!("{v:.3} m/s")), "{text}");
        assert!(text.contains(&format!("{e:.1} J")), "{text}");
        assert!(text.contains("hover power P(0)          221.3 W"), "{text}");
        assert!(energy_report(&iris, -3.0).is_err());
    }

    #[test]
    fn cover_report_gives_the_verdict_and_numbers() {
        let polygon = Polygon::new(vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(200.0, 0.0),
            DVec2::new(200.0, 100.0),
            DVec2::new(0.0, 100.0),
        ])
        .unwrap();
        let problem = CoverageProblem {
            polygon: polygon.clone(),
            start_vertex: 0,
            camera: Camera::gopro_12mp(),
            overlaps: Overlaps { x: 0.3, y: 0.6 },
            required_resolution_px_per_m: 100.0,
            direction: ScanDirection::LongestEdge,
        };
        let iris = SpeedEnergyModel::iris();
        let search = AltitudeSearch::default();
        let outcome = search_altitude(&problem, &iris, 1e6, &search).unwrap();
        let text = cover_report(&polygon, 100.0, &outcome);
        assert!(
            text.starts_with("coverage plan: feasible at the required resolution"),
            "{text}"
        );
        assert!(
            text.contains("4 vertices, 20000 m^2, perimeter 600.0 m"),
            "{text}"
        );
        assert!(text.contains(&format!("{:.2} kJ = climb", outcome.plan.energy_j / 1e3)));
        let outcome = search_altitude(&problem, &iris, 5000.0, &search).unwrap();
        let text = cover_report(&polygon, 100.0, &outcome);
        assert!(
            text.contains("NOT feasible on one battery: at least"),
            "{text}"
        );
    }
}
