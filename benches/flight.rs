//! Flight benchmarks: physics + control steps per second for one UAV on rapier, offline
//! rollouts per second of a 10 s trajectory at the EAAE step of 0.02 s, and whole-run ticks per
//! second of a dynamic UAV's waypoint tour.
//!
//! Run: `cargo bench --bench flight`. Figures are reported in the README.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use rapier3d::prelude::{Pose, SharedShape};
use std::hint::black_box;
use uavex_components::airframe::Airframe;
use uavex_components::sim::{Outcome, RunSeed, SimClock};
use uavex_components::trajectory::{Trajectory, TrajectoryPoint};
use uavex_engine::physics::{FlightWorld, FlightWorldConfig, UavHandle, UavStatus};
use uavex_engine::scenario;
use uavex_engine::sim::Sim;
use uavex_engine::world::build_world;
use uavex_systems::flight::{
    ControllerGains, FlightState, GeometricController, RolloutConfig, rollout, rollout_batch,
};
use uavex_systems::trajectory::{
    CurveReference, DynamicLimits, Waypoint, min_snap_with_durations, plan_collision_free,
};

/// The EAAE "Pillars" scene as shipped (`scenarios/eaae_pillars.toml`), ground included: the
/// same geometry the runs use, built by the same world builder.
fn pillars() -> Vec<(Pose, SharedShape)> {
    let loaded = scenario::load("scenarios/eaae_pillars.toml").expect("the shipped scene loads");
    let spec = &loaded.scenario;
    let world = build_world(&spec.world, RunSeed(spec.seed), &[], &[], &loaded.base_dir)
        .expect("the shipped scene builds");
    world
        .obstacles()
        .iter()
        .map(|o| (o.pose, o.shape.clone()))
        .collect()
}

/// One UAV in the Pillars scene, flying `reference` with the controller, one step per call.
struct Flight<T: Trajectory> {
    world: FlightWorld,
    uav: UavHandle,
    controller: GeometricController,
    reference: T,
    steps: u64,
}

impl<T: Trajectory> Flight<T> {
    fn new(reference: T, config: FlightWorldConfig) -> Self {
        let mut airframe = Airframe::kingfisher();
        // Criterion runs millions of ticks: a battery that never empties keeps the UAV flying.
        airframe.battery.capacity_wh = 1e12;
        let mut world = FlightWorld::from_shapes(pillars(), config).unwrap();
        let start = FlightState::hovering(&airframe, reference.sample(0.0).position, 0.0);
        let uav = world.add_uav(&airframe, &start).unwrap();
        let controller = GeometricController::new(&airframe, ControllerGains::default()).unwrap();
        Self {
            world,
            uav,
            controller,
            reference,
            steps: 0,
        }
    }

    /// Control, then physics: one 1/300 s tick of one UAV.
    fn tick(&mut self) {
        let t = self.steps as f64 * self.world.config().dt;
        let state = self.world.state(self.uav);
        let command = self.controller.command(&state, &self.reference.sample(t));
        self.world
            .set_commands(self.uav, command.rotor_speed_commands);
        self.world.step();
        self.steps += 1;
    }
}

fn physics_and_control(c: &mut Criterion) {
    let mut group = c.benchmark_group("flight_step");
    group.throughput(Throughput::Elements(1));
    // A 3 m/s circle in the open middle of the scene, for as long as the benchmark runs.
    let circle = || CurveReference::circle(DVec3::new(2.0, -1.0, 1.5), 3.0, 3.0, 1e6, 2.0);
    let mut free = Flight::new(circle(), FlightWorldConfig::default());
    group.bench_function("one_uav_open_space", |b| b.iter(|| free.tick()));
    assert_eq!(free.world.counts().pipeline_steps, 0);
    assert_eq!(free.world.status(free.uav), UavStatus::Flying);
    let mut full = Flight::new(
        circle(),
        FlightWorldConfig {
            always_full_pipeline: true,
            ..FlightWorldConfig::default()
        },
    );
    group.bench_function("one_uav_full_pipeline_every_step", |b| {
        b.iter(|| full.tick())
    });
    assert_eq!(full.world.status(full.uav), UavStatus::Flying);
    // Hovering 5 cm from the east wall's face: every step needs rapier's pipeline.
    let near_wall = TrajectoryPoint::at_rest(DVec3::new(10.589 - 0.14 - 0.05, 0.0, 1.25), 0.0);
    let mut near = Flight::new(
        uavex_components::trajectory::Hold {
            position: near_wall.position,
            yaw: 0.0,
            duration: 1e9,
        },
        FlightWorldConfig::default(),
    );
    group.bench_function("one_uav_near_a_wall", |b| b.iter(|| near.tick()));
    assert_eq!(near.world.counts().free_steps, 0);
    assert_eq!(near.world.status(near.uav), UavStatus::Flying);
    group.finish();

    // A collision-free tour of the Pillars scene (past pillars, along walls), counted in ticks
    // per second.
    let airframe = Airframe::kingfisher();
    let shapes = pillars();
    let inflation = (airframe.bounding_radius() + 0.1) as f32;
    let blocked = |p: DVec3| {
        shapes
            .iter()
            .any(|(pose, shape)| shape.distance_to_point(pose, p.as_vec3(), true) < inflation)
    };
    let tour: Vec<Waypoint> = [
        (8.0, -8.0, 1.0),
        (9.8, 0.0, 1.5),
        (5.0, 8.5, 1.0),
        (-2.0, 2.0, 2.0),
        (-8.0, -3.0, 1.0),
        (-3.0, -9.5, 1.5),
        (0.0, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Waypoint::new(DVec3::new(x, y, z)))
    .collect();
    let trajectory = plan_collision_free(
        &TrajectoryPoint::at_rest(DVec3::new(0.0, 0.0, 1.0), 0.0),
        &tour,
        &DynamicLimits::of(&airframe),
        &blocked,
        0.05,
    )
    .unwrap();
    let ticks = (trajectory.duration() * 300.0).ceil() as u64;
    let mut group = c.benchmark_group("flight_tour");
    group.throughput(Throughput::Elements(ticks));
    group.sample_size(10);
    group.bench_function("pillars_tour_ticks", |b| {
        b.iter(|| {
            let mut flight = Flight::new(trajectory.clone(), FlightWorldConfig::default());
            for _ in 0..ticks {
                flight.tick();
            }
            assert_eq!(flight.world.status(flight.uav), UavStatus::Flying);
            black_box(flight.world.counts())
        })
    });
    group.finish();
}

/// A 10 s minimum-snap trajectory: a 5 m square at 1.5 m, 2.5 s per side.
fn ten_second_trajectory() -> impl Trajectory {
    let start = TrajectoryPoint::at_rest(DVec3::new(0.0, 0.0, 1.5), 0.0);
    let corners = [(5.0, 0.0), (5.0, 5.0), (0.0, 5.0), (0.0, 0.0)];
    let waypoints: Vec<Waypoint> = corners
        .iter()
        .map(|&(x, y)| Waypoint::new(DVec3::new(x, y, 1.5)))
        .collect();
    min_snap_with_durations(&start, &waypoints, &[2.5; 4]).unwrap()
}

fn rollouts(c: &mut Criterion) {
    let airframe = Airframe::kingfisher();
    let trajectory = ten_second_trajectory();
    assert!((trajectory.duration() - 10.0).abs() < 1e-9);
    let start = FlightState::hovering(&airframe, DVec3::new(0.0, 0.0, 1.5), 0.0);
    let config = RolloutConfig::default();
    let mut group = c.benchmark_group("rollout");
    group.throughput(Throughput::Elements(1));
    group.bench_function("10s_trajectory_step_0.02", |b| {
        b.iter(|| rollout(&airframe, &start, black_box(&trajectory), &config).unwrap())
    });
    let jobs: Vec<(FlightState, &dyn Trajectory)> = (0..64)
        .map(|_| (start, &trajectory as &dyn Trajectory))
        .collect();
    group.throughput(Throughput::Elements(jobs.len() as u64));
    group.bench_function("64_rollouts_rayon", |b| {
        b.iter(|| rollout_batch(&airframe, black_box(&jobs), &config))
    });
    group.finish();
}

/// The whole tick of a run (every stage's systems, the ECS, the physics) on the shipped
/// waypoint tour of the Pillars scene with its camera taken off, build included, in ticks per
/// second: what a dynamic UAV costs a run besides its sensing and mapping.
fn whole_run(c: &mut Criterion) {
    let mut loaded = uavex_engine::scenario::load("scenarios/pillars_waypoints.toml").unwrap();
    loaded.scenario.uavs[0].sensors.clear();
    let ticks = {
        let mut sim = Sim::build(&loaded, loaded.scenario.seed).unwrap();
        let (outcome, reason) = sim.run_to_end();
        assert_eq!(outcome, Outcome::Complete, "{reason}");
        sim.world.resource::<SimClock>().tick
    };
    let mut group = c.benchmark_group("run");
    group.throughput(Throughput::Elements(ticks));
    group.sample_size(10);
    group.bench_function("pillars_waypoints_ticks_without_camera", |b| {
        b.iter(|| {
            let mut sim = Sim::build(&loaded, loaded.scenario.seed).unwrap();
            black_box(sim.run_to_end())
        })
    });
    group.finish();
}

criterion_group!(benches, physics_and_control, rollouts, whole_run);
criterion_main!(benches);
