//! Energy per metre of the kingfisher against cruise speed, with linear body drag.
//!
//! Each point is a straight, level flight on the true (rapier) quadrotor: a smooth ramp to the
//! cruise speed (at most 4 m/s^2), 12 s of cruise, a ramp down. The power is averaged over the
//! steady part of the cruise; energy per metre is that power over the speed. Without drag the
//! rotors carry only the weight at any constant speed, so power stays at hover power and
//! energy per metre falls as 1/v; drag `c v` tilts the thrust and raises it to
//! `sqrt((m g)^2 + (c v)^2)`, which gives the curve a minimum: the optimal cruise speed.
//! The rotor power model (common.md §4) depends on rotor speed only (no translational lift),
//! so that optimum is set by the drag alone: were rotor power ~ thrust^(3/2) (ideal rotor), it
//! would lie at `sqrt(2) m g / c`; the kingfisher's linear power term makes power grow slower
//! with thrust and moves it somewhat higher. The drag of the kingfisher is not published; the
//! sweep over `c` shows where the optimum lies for each value.
//!
//! Rotor drag (the other linear term of `LinearDrag`) is left out: it acts in the rotor plane,
//! which at the large tilts of fast cruise gives it an upward share that the model was not
//! made for.
//!
//! Run: `cargo run --release --example energy_per_metre` (writes docs/energy_per_metre.svg and
//! docs/energy_per_metre.md).

use glam::DVec3;
use plotters::prelude::*;
use std::fmt::Write as _;
use uavex_components::airframe::{Airframe, LinearDrag};
use uavex_components::trajectory::{Trajectory, TrajectoryPoint};
use uavex_engine::physics::{FlightWorld, FlightWorldConfig, UavStatus, fly_trajectory};
use uavex_systems::flight::{Completion, ControllerGains, FlightState, GeometricController};

/// Straight level flight along +x: ramp up over `ramp` s (quintic smoothstep in speed), cruise
/// at `speed` for `cruise` s, ramp down.
#[derive(Debug)]
struct Cruise {
    speed: f64,
    ramp: f64,
    cruise: f64,
    height: f64,
}

impl Cruise {
    fn new(speed: f64, max_acceleration: f64, cruise: f64) -> Self {
        // The smoothstep's steepest slope is 15/8: peak acceleration 1.875 v / ramp.
        let ramp = (1.875 * speed / max_acceleration).max(1.0);
        Self {
            speed,
            ramp,
            cruise,
            height: 2.0,
        }
    }
}

impl Trajectory for Cruise {
    fn duration(&self) -> f64 {
        2.0 * self.ramp + self.cruise
    }

    fn sample(&self, t: f64) -> TrajectoryPoint {
        let (v, tr) = (self.speed, self.ramp);
        let t = t.clamp(0.0, self.duration());
        // S(x) = 6x^5 - 15x^4 + 10x^3, its derivatives, and its integral I(x).
        let s = |x: f64| x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
        let s1 = |x: f64| 30.0 * x * x * (1.0 - x) * (1.0 - x);
        let s2 = |x: f64| 60.0 * x * (1.0 - x) * (1.0 - 2.0 * x);
        let integral = |x: f64| x.powi(4) * (2.5 + x * (-3.0 + x));
        let (x, speed, acceleration, jerk) = if t < tr {
            let u = t / tr;
            (
                v * tr * integral(u),
                v * s(u),
                v * s1(u) / tr,
                v * s2(u) / (tr * tr),
            )
        } else if t < tr + self.cruise {
            (v * tr * 0.5 + v * (t - tr), v, 0.0, 0.0)
        } else {
            let u = (t - tr - self.cruise) / tr;
            (
                v * tr * 0.5 + v * self.cruise + v * tr * (0.5 - integral(1.0 - u)),
                v * s(1.0 - u),
                -v * s1(1.0 - u) / tr,
                v * s2(1.0 - u) / (tr * tr),
            )
        };
        TrajectoryPoint {
            position: DVec3::new(x, 0.0, self.height),
            velocity: DVec3::new(speed, 0.0, 0.0),
            acceleration: DVec3::new(acceleration, 0.0, 0.0),
            jerk: DVec3::new(jerk, 0.0, 0.0),
            ..TrajectoryPoint::default()
        }
    }
}

/// Mean power (W) of steady cruise at `speed` on the true flight.
fn cruise_power(airframe: &Airframe, speed: f64) -> f64 {
    let cruise = Cruise::new(speed, airframe.max_acceleration, 12.0);
    let mut world = FlightWorld::from_shapes([], FlightWorldConfig::default()).unwrap();
    let start = FlightState::hovering(airframe, cruise.sample(0.0).position, 0.0);
    let uav = world.add_uav(airframe, &start).unwrap();
    let controller = GeometricController::new(airframe, ControllerGains::default()).unwrap();
    // Average over the cruise after 3 s of settling, up to 1 s before the ramp down.
    let window = (cruise.ramp + 3.0, cruise.ramp + cruise.cruise - 1.0);
    let (mut energy, mut time) = (0.0, 0.0);
    let dt = world.config().dt;
    let record = fly_trajectory(
        &mut world,
        uav,
        &controller,
        &cruise,
        &Completion::default(),
        &mut |t, _, power| {
            if t > window.0 && t <= window.1 {
                energy += power * dt;
                time += dt;
            }
        },
    );
    assert_eq!(record.status, UavStatus::Flying, "speed {speed}");
    energy / time
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Body drag coefficients (N s/m); each curve stops where the drag would need more than
    // 25 N of the 34 N the rotors give.
    let coefficients = [0.0, 0.5, 1.0, 2.0];
    let speeds: Vec<f64> = (1..=30).map(f64::from).collect();
    let mut curves = Vec::new();
    for c in coefficients {
        let mut airframe = Airframe::kingfisher();
        airframe.drag = LinearDrag {
            body: c,
            ..LinearDrag::NONE
        };
        let curve: Vec<(f64, f64, f64)> = speeds
            .iter()
            .filter(|&&v| c * v <= 25.0)
            .map(|&v| {
                let power = cruise_power(&airframe, v);
                (v, power, power / v)
            })
            .collect();
        curves.push((c, curve));
    }

    let mut table = String::new();
    writeln!(
        table,
        "Kingfisher, level cruise on the true flight with linear body drag c (N s/m): \
         energy per metre (J/m), and power (W) in brackets.\n"
    )?;
    write!(table, "| speed (m/s) |")?;
    for (c, _) in &curves {
        write!(table, " c = {c} |")?;
    }
    writeln!(table)?;
    writeln!(table, "|---|{}", "---|".repeat(curves.len()))?;
    for v in &speeds {
        write!(table, "| {v:.0} |")?;
        for (_, curve) in &curves {
            match curve.iter().find(|p| p.0 == *v) {
                Some(p) => write!(table, " {:.2} ({:.0}) |", p.2, p.1)?,
                None => write!(table, " - |")?,
            }
        }
        writeln!(table)?;
    }
    writeln!(table)?;
    for (c, curve) in &curves {
        let best = curve
            .iter()
            .min_by(|a, b| a.2.total_cmp(&b.2))
            .expect("speeds");
        let last = curve.last().expect("speeds").0;
        let note = if best.0 == last {
            " (the fastest speed flown: still falling)"
        } else {
            ""
        };
        let estimate = if *c > 0.0 {
            format!(
                " (ideal-rotor estimate sqrt(2) m g / c = {:.1} m/s)",
                2f64.sqrt() * 0.752 * 9.81 / c
            )
        } else {
            String::new()
        };
        writeln!(
            table,
            "- c = {c} N s/m: lowest energy per metre {:.2} J/m at {:.0} m/s{note}{estimate}",
            best.2, best.0
        )?;
    }
    print!("{table}");
    std::fs::create_dir_all("docs")?;
    std::fs::write("docs/energy_per_metre.md", &table)?;

    let root = SVGBackend::new("docs/energy_per_metre.svg", (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Kingfisher: energy per metre vs cruise speed",
            ("sans-serif", 22),
        )
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..31.0, 0.0..60.0)?;
    chart
        .configure_mesh()
        .x_desc("cruise speed (m/s)")
        .y_desc("energy per metre (J/m)")
        .draw()?;
    let colours = [BLACK, BLUE, RED, GREEN];
    for ((c, curve), colour) in curves.iter().zip(colours) {
        chart
            .draw_series(LineSeries::new(
                curve.iter().map(|p| (p.0, p.2)),
                colour.stroke_width(2),
            ))?
            .label(format!("body drag c = {c} N s/m"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        chart.draw_series(
            curve
                .iter()
                .map(|p| Circle::new((p.0, p.2), 3, colour.filled())),
        )?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    println!("wrote docs/energy_per_metre.svg and docs/energy_per_metre.md");
    Ok(())
}
