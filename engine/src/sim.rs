//! The simulation of one run: a bevy `World` built from one scenario and one seed, and the
//! `Tick` schedule with the pipeline stages (DESIGN.md "One tick").

use crate::exploration::setup::{StartCapsule, camera_of};
use crate::exploration::{Evaluate, add_exploration, explorer_components};
use crate::flight::{Physics, airframe_of, end_on_empty_battery, step_physics, waypoint_flight};
use crate::metrics::{RunRecord, record_metrics};
use crate::scenario::{BehaviourSpec, LoadedScenario, ScenarioErrors};
use crate::world::{build_world, check_starts_with_radii, sensor_bundle};
use bevy_ecs::prelude::*;
use bevy_ecs::system::ScheduleSystem;
use glam::{DVec3, Vec3};
use parry3d::shape::Capsule;
use std::time::{Duration, Instant};
use uavex_components::airframe::Airframe;
use uavex_components::map::{MapConfig, MapSettings};
use uavex_components::sensor::SensorId;
use uavex_components::sim::{Outcome, RunEnd, RunSeed, SimClock};
use uavex_components::uav::{QuadState, Uav, UavEnded};
use uavex_components::world::WorldGeometry;
use uavex_systems::behaviour::scripted::{ScriptedRoute, fly_scripted};
use uavex_systems::behaviour::waypoints::finish_waypoint_tours;
use uavex_systems::flight::track_references;
use uavex_systems::mapping::{insert_map_resources, integrate_scans};
use uavex_systems::sensing::sense;
use uavex_systems::stage_clock::{StageClock, time_stages};
use uavex_systems::stages::{Stage, tick_schedule};

/// How often (ticks) [`Sim::run_within`] looks at the wall clock: 3.4 s simulated at 300 Hz,
/// a fraction of a second of wall time.
pub const WALL_CHECK_TICKS: u64 = 1024;

/// One run in progress.
pub struct Sim {
    pub world: World,
    schedule: Schedule,
    time_limit_s: f64,
}

fn vec3(v: [f64; 3]) -> Vec3 {
    DVec3::from_array(v).as_vec3()
}

impl Sim {
    /// Builds the world of `loaded` for `seed`: geometry, map, UAVs with their airframes,
    /// sensors and behaviours (plans of dynamic behaviours included), the physics when a UAV
    /// flies dynamically, and the tick schedule. Problems that need the airframes or the
    /// geometry (an override that makes an airframe unflyable, a missing mesh file, a start
    /// inside an obstacle, a waypoint tour through a wall) come back located in the file.
    pub fn build(loaded: &LoadedScenario, seed: u64) -> Result<Sim, ScenarioErrors> {
        let scenario = &loaded.scenario;
        let run_seed = RunSeed(seed);
        let locate = |errors: Vec<crate::world::BuildError>| {
            loaded.errors(errors.into_iter().map(|e| (e.path, e.message)))
        };
        let mut airframes = Vec::with_capacity(scenario.uavs.len());
        let mut airframe_problems = Vec::new();
        for (index, spec) in scenario.uavs.iter().enumerate() {
            match airframe_of(spec, index) {
                Ok(airframe) => airframes.push(airframe),
                Err(mut problems) => airframe_problems.append(&mut problems),
            }
        }
        if !airframe_problems.is_empty() {
            return Err(locate(airframe_problems));
        }
        let starts: Vec<Vec3> = scenario
            .uavs
            .iter()
            .map(|u| vec3(u.start.position))
            .collect();
        let map = MapConfig::new(&MapSettings {
            resolution: scenario.map.resolution,
            bounds_min: DVec3::from_array(scenario.world.bounds.min),
            bounds_max: DVec3::from_array(scenario.world.bounds.max),
            p_min: scenario.map.p_min,
            p_max: scenario.map.p_max,
        })
        .map_err(|e| loaded.errors([("map", e.to_string())]))?;
        // What seeded fields leave free: every UAV's body where it starts (the start check
        // below could otherwise refuse a seed that drew a pillar into it, whatever the field's
        // `start_clearance`) and what explorers need clear ahead of their starts.
        let bodies = starts.iter().zip(&airframes).map(|(&start, airframe)| {
            Capsule::new(start, start, airframe.bounding_radius() as f32)
        });
        let capsules = scenario
            .uavs
            .iter()
            .zip(&airframes)
            .filter_map(|(spec, airframe)| {
                StartCapsule::of_explorer(spec, airframe, map.resolution())
            })
            .map(|capsule| capsule.shape());
        let kept_clear: Vec<Capsule> = bodies.chain(capsules).collect();
        let geometry = build_world(
            &scenario.world,
            run_seed,
            &starts,
            &kept_clear,
            &loaded.base_dir,
        )
        .map_err(locate)?;
        // Each UAV must fit, with its bounding sphere, where it starts.
        let radii: Vec<f32> = airframes
            .iter()
            .map(|a| a.bounding_radius() as f32)
            .collect();
        let start_problems = check_starts_with_radii(&geometry, &starts, &radii);
        if !start_problems.is_empty() {
            return Err(locate(start_problems));
        }
        let dynamic = scenario.uavs.iter().any(|u| {
            matches!(
                u.behaviour,
                BehaviourSpec::Waypoints { .. }
                    | BehaviourSpec::Coverage(_)
                    | BehaviourSpec::Explore(_)
            )
        });
        let mut physics = if dynamic {
            let physics = Physics::new(&geometry, 1.0 / scenario.physics_rate_hz)
                .map_err(|e| loaded.errors([("physics_rate_hz", e.to_string())]))?;
            Some(physics)
        } else {
            None
        };

        let mut world = World::new();
        world.insert_resource(SimClock::new(scenario.physics_rate_hz));
        world.insert_resource(run_seed);
        world.insert_resource(RunEnd::default());
        world.insert_resource(geometry);
        world.insert_resource(RunRecord::new(
            scenario.outputs.series_rate_hz,
            scenario.uavs.len(),
        ));
        insert_map_resources(&mut world, map);

        let mut problems = Vec::new();
        let mut next_sensor_id = 0;
        // The first explorer's camera, and every explorer's airframe.
        let mut exploration: Option<((f64, f64), Vec<&Airframe>)> = None;
        for (index, (spec, airframe)) in scenario.uavs.iter().zip(&airframes).enumerate() {
            let state = QuadState::at_rest(starts[index], spec.start.yaw as f32);
            let uav = world
                .spawn((
                    Uav {
                        name: spec.name.clone(),
                        index,
                    },
                    state,
                    airframe.clone(),
                ))
                .id();
            match &spec.behaviour {
                BehaviourSpec::Scripted {
                    speed,
                    waypoints,
                    yaw_rate,
                } => {
                    world.entity_mut(uav).insert(ScriptedRoute {
                        waypoints: waypoints.iter().map(|&w| vec3(w)).collect(),
                        speed: *speed as f32,
                        yaw_rate: *yaw_rate as f32,
                        next: 0,
                    });
                }
                BehaviourSpec::Coverage(coverage) => {
                    let Some(physics) = physics.as_mut() else {
                        continue;
                    };
                    match crate::coverage::behaviour::coverage_flight(
                        spec,
                        index,
                        airframe,
                        physics,
                        coverage,
                        &loaded.base_dir,
                        &loaded.path,
                    ) {
                        Ok(flight) => {
                            world.entity_mut(uav).insert(flight);
                        }
                        Err(e) => problems.push(e),
                    }
                }
                BehaviourSpec::Explore(explore) => {
                    let Some(physics) = physics.as_mut() else {
                        continue;
                    };
                    match explorer_components(
                        spec,
                        index,
                        airframe,
                        physics,
                        explore,
                        world.resource::<WorldGeometry>(),
                        world.resource::<MapConfig>(),
                    ) {
                        Ok((bundle, strategy)) => {
                            let mut entity = world.entity_mut(uav);
                            entity.insert(bundle);
                            strategy.insert(&mut entity, explore.evaluate == Evaluate::All);
                            if let Some(camera) = camera_of(spec) {
                                exploration
                                    .get_or_insert_with(|| (camera, Vec::new()))
                                    .1
                                    .push(airframe);
                            }
                        }
                        Err(e) => problems.push(e),
                    }
                }
                BehaviourSpec::Waypoints {
                    waypoints,
                    yaw,
                    collision_check,
                } => {
                    // `dynamic` made the physics for exactly this case.
                    let flight = physics.as_mut().map(|physics| {
                        waypoint_flight(
                            spec,
                            index,
                            airframe,
                            world.resource::<WorldGeometry>(),
                            physics,
                            waypoints,
                            yaw.as_deref(),
                            *collision_check,
                        )
                    });
                    match flight {
                        Some(Ok(flight)) => {
                            world.entity_mut(uav).insert(flight);
                        }
                        Some(Err(e)) => problems.push(e),
                        None => {}
                    }
                }
            }
            for (j, sensor) in spec.sensors.iter().enumerate() {
                let field = format!("uav[{index}].sensor[{j}]");
                let id = SensorId(next_sensor_id);
                next_sensor_id += 1;
                match sensor_bundle(sensor, &scenario.map, uav, id, run_seed, &field) {
                    Ok(bundle) => {
                        world.spawn(bundle);
                    }
                    Err(e) => problems.push(e),
                }
            }
        }
        if !problems.is_empty() {
            return Err(locate(problems));
        }

        let mut schedule = tick_schedule();
        world.insert_resource(StageClock::default());
        time_stages(&mut schedule);
        schedule.add_systems((
            sense.in_set(Stage::Sense),
            integrate_scans.in_set(Stage::Map),
            (fly_scripted, finish_waypoint_tours, track_references).in_set(Stage::Control),
            (record_metrics, end_when_every_uav_is_done)
                .chain()
                .in_set(Stage::Account),
        ));
        if let Some((camera, airframes)) = exploration {
            add_exploration(&mut world, &mut schedule, camera, &airframes);
        }
        if let Some(physics) = physics {
            world.insert_resource(physics);
            schedule.add_systems((
                step_physics.in_set(Stage::Physics),
                end_on_empty_battery
                    .before(end_when_every_uav_is_done)
                    .in_set(Stage::Account),
            ));
        }
        Ok(Sim {
            world,
            schedule,
            time_limit_s: scenario.time_limit_s,
        })
    }

    /// Adds systems to the tick (how users and later behaviours extend a run).
    pub fn add_systems<M>(&mut self, systems: impl IntoScheduleConfigs<ScheduleSystem, M>) {
        self.schedule.add_systems(systems);
    }

    /// Runs one tick (all stages) and advances the clock by one step.
    pub fn step(&mut self) {
        self.schedule.run(&mut self.world);
        self.world.resource_mut::<SimClock>().tick += 1;
    }

    /// Simulated time (s).
    pub fn time_s(&self) -> f64 {
        self.world.resource::<SimClock>().time_s()
    }

    /// How the run ended, if it has.
    pub fn ended(&self) -> Option<&(Outcome, String)> {
        self.world.resource::<RunEnd>().0.as_ref()
    }

    /// Steps until a system ends the run or the time limit is reached.
    pub fn run_to_end(&mut self) -> (Outcome, String) {
        self.run_within(None)
    }

    /// [`Self::run_to_end`], and a run still going after `wall_limit` of wall-clock time
    /// ends `failed`, with that reason: a safety net against a run that would take forever on
    /// this machine (a sweep goes on with the others). The clock is read every
    /// [`WALL_CHECK_TICKS`] ticks and never by a decision, so a run that finishes within the
    /// limit is the same as without it.
    pub fn run_within(&mut self, wall_limit: Option<Duration>) -> (Outcome, String) {
        let deadline = wall_limit.map(|limit| (Instant::now() + limit, limit));
        loop {
            if let Some(end) = self.ended() {
                return end.clone();
            }
            let tick = self.world.resource::<SimClock>().tick;
            if let Some((deadline, limit)) = deadline
                && tick > 0
                && tick.is_multiple_of(WALL_CHECK_TICKS)
                && Instant::now() >= deadline
            {
                // The simulated time it stopped at is the summary's `mission_time_s`.
                let reason = format!("wall-clock limit of {} s exceeded", limit.as_secs_f64());
                self.world.resource_mut::<RunEnd>().0 = Some((Outcome::Failed, reason.clone()));
                return (Outcome::Failed, reason);
            }
            if self.time_s() >= self.time_limit_s {
                let reason = format!("time limit of {} s reached", self.time_limit_s);
                self.world.resource_mut::<RunEnd>().0 = Some((Outcome::TimeLimit, reason.clone()));
                return (Outcome::TimeLimit, reason);
            }
            self.step();
        }
    }
}

/// Account stage: the run is complete once every UAV has ended its behaviour; `returned_home`
/// when some UAV ended by flying home on its energy budget.
pub fn end_when_every_uav_is_done(
    mut run_end: ResMut<RunEnd>,
    uavs: Query<Option<&UavEnded>, With<Uav>>,
) {
    if run_end.0.is_some() || uavs.is_empty() || uavs.iter().any(|ended| ended.is_none()) {
        return;
    }
    let home = uavs.iter().flatten().find_map(|ended| match ended {
        UavEnded::ReturnedHome { time_s } => Some(*time_s),
        _ => None,
    });
    run_end.0 = Some(match home {
        Some(time_s) => (
            Outcome::ReturnedHome,
            format!(
                "no further goal was affordable within the energy budget; home at {time_s:.1} s"
            ),
        ),
        None => (
            Outcome::Complete,
            "every UAV completed its behaviour".to_owned(),
        ),
    });
}
