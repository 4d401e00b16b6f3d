//! 3D recordings of a run for the rerun viewer (`uavex run FILE --record OUT.rrd`): occupied
//! voxels, frontier clusters, each decision's candidate trajectories coloured by predicted
//! energy with the chosen one marked, the flown paths and poses, over simulated time.
//!
//! Behind the `record` cargo feature (the rerun crates add about 180 crates to the build).
//! Without it, [`start`] refuses with [`FEATURE_MISSING`]; only the plain data of [`colour`]
//! and [`path`] is built (and unit-tested) always.
//!
//! Layout (with the feature): `writer` is the `.rrd` file, `recorder` the resource that
//! remembers what was logged, `systems` the thin systems in the tick, and one module per thing
//! shown (`map`, `frontier`, `candidates`, `uav`, `plots`) turning uavex data into rerun
//! archetypes with plain functions.

pub mod colour;
pub mod path;

#[cfg(feature = "record")]
pub mod candidates;
#[cfg(feature = "record")]
pub mod frontier;
#[cfg(feature = "record")]
pub mod map;
#[cfg(feature = "record")]
pub mod plots;
#[cfg(feature = "record")]
pub mod recorder;
#[cfg(feature = "record")]
pub mod systems;
#[cfg(feature = "record")]
pub mod uav;
#[cfg(feature = "record")]
pub mod writer;

use crate::sim::Sim;
use std::path::Path;

/// Whether this build can record (the `record` feature).
pub const AVAILABLE: bool = cfg!(feature = "record");

/// Why a build without the feature cannot record.
pub const FEATURE_MISSING: &str = "recording needs uavex built with the `record` feature \
     (cargo build --release --features record)";

/// Regular logs per second of simulated time; decisions are logged when made, besides.
pub const RATE_HZ: f64 = 2.0;

/// The rerun crates the recording is made with, for code that logs more (a system of its own
/// writing through the [`recorder::Recorder`]) or reads a recording back.
#[cfg(feature = "record")]
pub mod external {
    pub use {re_chunk, re_log_encoding, re_log_types, re_sdk_types};
}

/// `a/b/c` from unescaped parts: a UAV name with a space or a slash stays one part.
#[cfg(feature = "record")]
fn entity_path(parts: &[&str]) -> re_chunk::EntityPath {
    re_chunk::EntityPath::new(
        parts
            .iter()
            .map(|&part| re_log_types::EntityPathPart::new(part))
            .collect(),
    )
}

/// Starts recording `sim` into `path` (created or replaced), named `name` in the viewer: logs
/// what never changes (axes, the map's box, the airframes) and adds the recorder's systems.
#[cfg(feature = "record")]
pub fn start(sim: &mut Sim, path: &Path, name: &str) -> Result<(), String> {
    use re_chunk::EntityPath;
    use re_sdk_types::archetypes::ViewCoordinates;
    use uavex_components::airframe::Airframe;
    use uavex_components::map::MapConfig;
    use uavex_components::uav::Uav;

    let writer = writer::RrdWriter::create(path, name)
        .map_err(|e| format!("could not create the recording {e}"))?;
    let world = &mut sim.world;
    let mut uavs: Vec<(usize, String, Option<Airframe>)> = world
        .query::<(&Uav, Option<&Airframe>)>()
        .iter(world)
        .map(|(uav, airframe)| (uav.index, uav.name.clone(), airframe.cloned()))
        .collect();
    uavs.sort_by_key(|(index, ..)| *index);
    let names = uavs.iter().map(|(_, name, _)| name.clone()).collect();
    let mut recorder = recorder::Recorder::new(writer, RATE_HZ, names);
    recorder.log_static(
        &EntityPath::from("world"),
        &ViewCoordinates::RIGHT_HAND_Z_UP(),
    );
    let bounds = map::bounds_box(world.resource::<MapConfig>());
    recorder.log_static(&EntityPath::from(map::BOUNDS), &bounds);
    for (_, name, airframe) in &uavs {
        if let Some(airframe) = airframe {
            let (body, axes) = uav::body_shape(airframe);
            let parts: [&dyn re_sdk_types::AsComponents; 2] = [&body, &axes];
            recorder.log_static(&uav::body_entity(name), &writer::Together(&parts));
        }
    }
    world.insert_resource(recorder);
    sim.add_systems(systems::recorder_systems());
    Ok(())
}

/// Logs the run's final state, closes the recording and returns its size (bytes).
#[cfg(feature = "record")]
pub fn finish(sim: &mut Sim) -> Result<u64, String> {
    use bevy_ecs::schedule::Schedule;
    let world = &mut sim.world;
    if !world.contains_resource::<recorder::Recorder>() {
        return Err("no recording was started".to_owned());
    }
    let mut last = Schedule::default();
    last.add_systems(systems::log_systems());
    last.run(world);
    let recorder = world
        .remove_resource::<recorder::Recorder>()
        .ok_or("the recorder vanished")?;
    recorder.finish()
}

#[cfg(not(feature = "record"))]
pub fn start(_sim: &mut Sim, _path: &Path, _name: &str) -> Result<(), String> {
    Err(FEATURE_MISSING.to_owned())
}

#[cfg(not(feature = "record"))]
pub fn finish(_sim: &mut Sim) -> Result<u64, String> {
    Err(FEATURE_MISSING.to_owned())
}
