//! The ECS systems in a small World: frontier updates from changed chunk entities, and cluster
//! entities spawned, updated in place and despawned as the frontier changes.

use super::super::*;
use super::config;
use bevy_ecs::prelude::*;
use glam::{IVec3, Vec3};
use uavex_components::frontier::{
    ClusterMembers, ClusterSettings, ClusteringCounter, FrontierCluster, FrontierSet, Reachable,
    Viewpoints,
};
use uavex_components::map::{
    ChunkCoord, ChunkIndex, MapConfig, UNKNOWN_LOG_ODDS, VoxelChunk, VoxelState, local_index,
};
use uavex_components::sim::RunSeed;

fn setup() -> (World, Schedule) {
    let mut world = World::new();
    crate::mapping::insert_map_resources(&mut world, config());
    insert_frontier_resources(&mut world, ClusterSettings::default());
    world.insert_resource(RunSeed(42));
    let mut schedule = Schedule::default();
    schedule.add_systems((update_frontiers, refresh_clusters).chain());
    (world, schedule)
}

/// Writes voxel states into the chunk entities (spawning chunks as the mapping stage does), so
/// that `Changed<VoxelChunk>` reports them.
fn write(world: &mut World, keys: impl IntoIterator<Item = IVec3>, state: VoxelState) {
    for key in keys {
        let coord = ChunkCoord::of_key(key);
        let flat = world
            .resource::<MapConfig>()
            .chunk_grid()
            .flat(coord)
            .unwrap();
        let entity = match world.resource::<ChunkIndex>().get_flat(flat) {
            Some(e) => e,
            None => {
                let e = world.spawn((coord, VoxelChunk::new())).id();
                world.resource_mut::<ChunkIndex>().set_flat(flat, e);
                e
            }
        };
        let mut chunk = world.get_mut::<VoxelChunk>(entity).unwrap();
        chunk.voxels_mut()[local_index(key)].log_odds = match state {
            VoxelState::Unknown => UNKNOWN_LOG_ODDS,
            VoxelState::Free => -405,
            VoxelState::Occupied => 847,
        };
    }
}

fn slab(x: std::ops::Range<i32>, y: std::ops::Range<i32>) -> Vec<IVec3> {
    x.flat_map(|x| y.clone().map(move |y| IVec3::new(x, y, 10)))
        .collect()
}

/// (entity, size, centroid, reachable) of every cluster entity, by entity.
fn clusters(world: &mut World) -> Vec<(Entity, u32, Vec3, bool)> {
    let mut q = world.query::<(
        Entity,
        &FrontierCluster,
        &ClusterMembers,
        &Viewpoints,
        Has<Reachable>,
    )>();
    let mut out: Vec<_> = q
        .iter(world)
        .map(|(e, c, m, _, r)| {
            assert_eq!(m.0.len(), c.size as usize);
            (e, c.size, c.centroid, r)
        })
        .collect();
    out.sort_unstable_by_key(|c| c.0);
    out
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-4
}

#[test]
fn cluster_entities_follow_the_frontier() {
    let (mut world, mut schedule) = setup();
    // Nothing mapped: no frontier, clustering runs once (first run) and finds nothing.
    schedule.run(&mut world);
    assert!(clusters(&mut world).is_empty());
    assert_eq!(world.resource::<ClusteringCounter>().runs, 1);

    // Slab A: 20 x 20 free voxels at z = 10 (centroid (1.0, 1.0, 1.05)).
    write(&mut world, slab(0..20, 0..20), VoxelState::Free);
    schedule.run(&mut world);
    assert_eq!(world.resource::<FrontierSet>().len(), 400);
    let a = clusters(&mut world);
    assert_eq!(a.len(), 1);
    let (ea, size, centroid, reachable) = a[0];
    assert_eq!(size, 400);
    assert!(close(centroid, Vec3::new(1.0, 1.0, 1.05)));
    assert!(reachable);
    assert_eq!(world.get::<Viewpoints>(ea).unwrap().0.len(), 4);

    // No map change: the frontier set is untouched and clustering is skipped.
    let generation = world.resource::<FrontierSet>().generation();
    schedule.run(&mut world);
    assert_eq!(world.resource::<FrontierSet>().generation(), generation);
    assert_eq!(world.resource::<ClusteringCounter>().runs, 2);

    // Slab B, 10 x 10 far away (centroid (-2.5, -2.5, 1.05)): a new entity; A keeps its own.
    write(&mut world, slab(-30..-20, -30..-20), VoxelState::Free);
    schedule.run(&mut world);
    let ab = clusters(&mut world);
    assert_eq!(ab.len(), 2, "{ab:?}");
    let find = |cs: &[(Entity, u32, Vec3, bool)], e: Entity| *cs.iter().find(|c| c.0 == e).unwrap();
    assert_eq!(find(&ab, ea).1, 400);
    let eb = ab.iter().find(|c| c.0 != ea).unwrap().0;
    assert_eq!(find(&ab, eb).1, 100);
    assert!(close(find(&ab, eb).2, Vec3::new(-2.5, -2.5, 1.05)));

    // An obstacle above A's centroid (plus a frontier change elsewhere, a lone free voxel that
    // is below min_cluster_voxels): A is updated in place and loses Reachable.
    write(&mut world, [IVec3::new(10, 10, 11)], VoxelState::Occupied);
    write(&mut world, [IVec3::new(25, 25, 25)], VoxelState::Free);
    schedule.run(&mut world);
    assert_eq!(world.resource::<FrontierSet>().len(), 501);
    let now = clusters(&mut world);
    assert_eq!(now.len(), 2);
    assert!(!find(&now, ea).3);
    assert!(find(&now, eb).3);

    // B's voxels turn occupied: its entity is despawned, A's stays.
    write(&mut world, slab(-30..-20, -30..-20), VoxelState::Occupied);
    schedule.run(&mut world);
    let now = clusters(&mut world);
    assert_eq!(now.iter().map(|c| c.0).collect::<Vec<_>>(), vec![ea]);
    assert!(world.get_entity(eb).is_err());

    // Everything known: no frontier, no cluster.
    write(&mut world, slab(0..20, 0..20), VoxelState::Occupied);
    write(&mut world, [IVec3::new(25, 25, 25)], VoxelState::Occupied);
    schedule.run(&mut world);
    assert!(world.resource::<FrontierSet>().is_empty());
    assert!(clusters(&mut world).is_empty());
}

#[test]
fn runs_with_the_same_seed_give_the_same_clusters() {
    let run = || {
        let (mut world, mut schedule) = setup();
        // A ring of free voxels wider than 2 r_max, so the clustering must split (and uses the
        // random stream).
        let ring: Vec<IVec3> = (0..360)
            .map(|deg| {
                let a = (deg as f32).to_radians();
                IVec3::new((28.0 * a.cos()) as i32, (28.0 * a.sin()) as i32, 10)
            })
            .collect();
        write(&mut world, ring, VoxelState::Free);
        schedule.run(&mut world);
        let mut q = world.query::<(&FrontierCluster, &ClusterMembers)>();
        let mut out: Vec<_> = q
            .iter(&world)
            .map(|(c, m)| (c.clone(), m.clone()))
            .collect();
        out.sort_by(|a, b| a.1.0[0].to_array().cmp(&b.1.0[0].to_array()));
        out
    };
    let first = run();
    assert!(first.len() >= 3, "{}", first.len());
    assert!(first.iter().all(|c| c.0.r_max <= 2.731_512));
    assert_eq!(first, run());
}
