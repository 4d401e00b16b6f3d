//! Coverage planning speed: the path over a 50-vertex concave polygon (goal: <= 10 ms), the same
//! priced leg by leg (optimal speed, energy and time of every leg), and the whole altitude search.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec2;
use std::hint::black_box;
use uavex_systems::coverage::{
    AltitudeSearch, Camera, CoverageProblem, Overlaps, Polygon, ScanDirection, SpeedEnergyModel,
    plan_mission, plan_path, search_altitude,
};

/// A wobbly 50-vertex star, radius 120 m +- 45 m, every other vertex pulled in by 20 %: 28
/// sub-areas at a 20 m x 15 m footprint.
fn fifty_vertices() -> Polygon {
    let points = (0..50)
        .map(|i| {
            let theta = std::f64::consts::TAU * i as f64 / 50.0;
            let r = 120.0 + 30.0 * (3.0 * theta).sin() + 15.0 * (7.0 * theta + 1.0).cos();
            let r = if i % 2 == 0 { r } else { r * 0.8 };
            DVec2::new(r * theta.cos(), r * theta.sin())
        })
        .collect();
    Polygon::new(points).expect("a simple polygon")
}

fn problem() -> CoverageProblem {
    CoverageProblem {
        polygon: fifty_vertices(),
        start_vertex: 0,
        // 90 deg, 4:3: at 10 m the footprint is 20 m x 15 m.
        camera: Camera {
            angle_of_view: std::f64::consts::FRAC_PI_2,
            width_px: 4000,
            height_px: 3000,
            shot_period_s: 1.0,
        },
        overlaps: Overlaps { x: 0.2, y: 0.3 },
        required_resolution_px_per_m: 200.0,
        direction: ScanDirection::LongestEdge,
    }
}

fn planning(c: &mut Criterion) {
    let problem = problem();
    let survey = problem
        .camera
        .survey(10.0, problem.overlaps)
        .expect("valid camera");
    let iris = SpeedEnergyModel::iris();
    c.bench_function("coverage_path_50_vertices", |b| {
        b.iter(|| {
            plan_path(
                black_box(&problem.polygon),
                0,
                &survey,
                ScanDirection::LongestEdge,
            )
        })
    });
    c.bench_function("coverage_mission_50_vertices", |b| {
        b.iter(|| plan_mission(black_box(&problem), 10.0, &iris))
    });
    let search = AltitudeSearch {
        step_m: 1.0,
        ..AltitudeSearch::default()
    };
    let at_h_max = plan_mission(&problem, 10.0, &iris).expect("a plan");
    c.bench_function("coverage_altitude_search_50_vertices", |b| {
        b.iter(|| search_altitude(black_box(&problem), &iris, 1.2 * at_h_max.energy_j, &search))
    });
}

criterion_group!(benches, planning);
criterion_main!(benches);
