//! The thin ECS side of frontier detection and clustering.

use super::super::mapping::{MapReader, StateChange, StateChanges};
use super::assemble::{ClusterData, cluster_frontier, match_clusters};
use super::detect::update_frontier_set;
use bevy_ecs::prelude::*;
use glam::Vec3;
use uavex_components::frontier::{
    ClusterMembers, ClusterSettings, ClusteringCounter, FrontierCluster, FrontierSet, Reachable,
    Viewpoints,
};
use uavex_components::sim::{RunSeed, stream};

/// Inserts [`FrontierSet`] (empty), `settings`, and the [`ClusteringCounter`]. The clustering
/// system also reads [`RunSeed`] and the map's resources, which their own stages insert.
pub fn insert_frontier_resources(world: &mut World, settings: ClusterSettings) {
    world.insert_resource(FrontierSet::default());
    world.insert_resource(settings);
    world.insert_resource(ClusteringCounter::default());
}

/// Stage::Frontier: update [`FrontierSet`] from the chunks whose `VoxelChunk` changed this
/// tick (`Changed` includes chunks spawned since the last run) in a way that can move a
/// frontier: some voxel's state changed ([`StateChanges`]). The resource is marked changed
/// only when the set actually changed.
pub fn update_frontiers(
    mut changes: StateChanges,
    mut set: ResMut<FrontierSet>,
    map: MapReader,
    mut scratch: Local<Vec<StateChange>>,
) {
    scratch.clear();
    changes.collect_into(&mut scratch);
    if scratch.is_empty() {
        return;
    }
    let before = set.generation();
    update_frontier_set(set.bypass_change_detection(), &map, &scratch);
    if set.generation() != before {
        set.set_changed();
    }
}

/// Reclusters the whole frontier set (skipped when [`FrontierSet::generation`] is unchanged
/// since the last clustering and the settings did not change) and reconciles the cluster
/// entities: a new cluster continues the old entity [`match_clusters`] gives it (nearest old
/// centroid within half the larger r_max, at least half a voxel; old entities in `Entity`
/// order), whose components are updated in place (written only where they differ, so
/// `Changed` stays meaningful); unmatched old entities are despawned, new ones spawned, each
/// with [`FrontierCluster`], [`ClusterMembers`], [`Viewpoints`] and (if it passes)
/// [`Reachable`].
///
/// RNG: `RunSeed::stream(stream::CLUSTERING, k)`, k = how many times clustering ran (kept in
/// [`ClusteringCounter`]), so runs are deterministic. Spawns and despawns go through Commands:
/// readers of cluster entities must run after a command flush.
pub fn refresh_clusters(
    mut commands: Commands,
    set: Res<FrontierSet>,
    settings: Res<ClusterSettings>,
    seed: Res<RunSeed>,
    mut counter: ResMut<ClusteringCounter>,
    map: MapReader,
    mut clusters: Query<(
        Entity,
        &mut FrontierCluster,
        &mut ClusterMembers,
        &mut Viewpoints,
        Has<Reachable>,
    )>,
) {
    if counter.last_generation == Some(set.generation()) && !settings.is_changed() {
        return;
    }
    let mut rng = seed.stream(stream::CLUSTERING, counter.runs);
    counter.runs += 1;
    counter.last_generation = Some(set.generation());
    let found = cluster_frontier(&set, &map, &settings, &mut rng);

    let mut old: Vec<(Entity, Vec3, f32)> = clusters
        .iter()
        .map(|(e, c, ..)| (e, c.centroid, c.r_max))
        .collect();
    old.sort_unstable_by_key(|o| o.0);
    let old_shapes: Vec<(Vec3, f32)> = old.iter().map(|o| (o.1, o.2)).collect();
    let new_shapes: Vec<(Vec3, f32)> = found
        .iter()
        .map(|d| (d.cluster.centroid, d.cluster.r_max))
        .collect();
    let half_voxel = (map.config.resolution() / 2.0) as f32;
    let matches = match_clusters(&old_shapes, &new_shapes, half_voxel);

    let mut kept = vec![false; old.len()];
    for (data, matched) in found.into_iter().zip(matches) {
        let ClusterData {
            cluster,
            members,
            viewpoints,
            reachable,
        } = data;
        let target = matched.and_then(|j| Some((j, clusters.get_mut(old[j].0).ok()?)));
        match target {
            Some((j, (entity, mut c, mut m, mut v, was_reachable))) => {
                kept[j] = true;
                c.set_if_neq(cluster);
                m.set_if_neq(members);
                v.set_if_neq(viewpoints);
                if reachable && !was_reachable {
                    commands.entity(entity).insert(Reachable);
                } else if !reachable && was_reachable {
                    commands.entity(entity).remove::<Reachable>();
                }
            }
            None => {
                let mut entity = commands.spawn((cluster, members, viewpoints));
                if reachable {
                    entity.insert(Reachable);
                }
            }
        }
    }
    for (&(entity, ..), kept) in old.iter().zip(kept) {
        if !kept {
            commands.entity(entity).despawn();
        }
    }
}
