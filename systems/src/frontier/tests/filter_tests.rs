//! Reachability filter, viewpoints and cluster assembly on hand-made grids (eaae.md steps 3-4).

use super::super::*;
use super::{config, set};
use crate::mapping::ChunkStore;
use glam::{IVec3, Vec3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::f32::consts::{FRAC_PI_2, PI};
use uavex_components::frontier::{ClusterSettings, FrontierSet, Viewpoint};
use uavex_components::map::VoxelState;

/// Centre of voxel (0, 0, 10).
const CENTROID: Vec3 = Vec3::new(0.05, 0.05, 1.05);

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

#[test]
fn occupied_voxels_near_the_centroid_in_x_y_and_one_layer_up_or_down() {
    let occupied_at = |key: IVec3| {
        let mut store = ChunkStore::new(&config());
        set(&mut store, key, VoxelState::Occupied);
        occupied_near_centroid(&store, CENTROID, 0.1)
    };
    // Key (1, 0, 10) spans x 0.1..0.2: 0.05 m from the centroid; (2, 0, 10) 0.15 m.
    assert!(occupied_at(IVec3::new(1, 0, 10)));
    assert!(!occupied_at(IVec3::new(2, 0, 10)));
    assert!(occupied_at(IVec3::new(-1, 0, 10)));
    assert!(!occupied_at(IVec3::new(-2, 0, 10)));
    // Diagonal (1, 1): nearest corner (0.1, 0.1) at 0.0707 m; (2, 1): 0.158 m.
    assert!(occupied_at(IVec3::new(1, 1, 10)));
    assert!(!occupied_at(IVec3::new(2, 1, 10)));
    // z extent: the centroid's layer +-1 only (not the floor of the column).
    assert!(occupied_at(IVec3::new(0, 0, 11)));
    assert!(occupied_at(IVec3::new(0, 0, 9)));
    assert!(!occupied_at(IVec3::new(0, 0, 12)));
    assert!(!occupied_at(IVec3::new(0, 0, -32)));
    // Free voxels never count.
    let mut store = ChunkStore::new(&config());
    set(&mut store, IVec3::new(0, 0, 10), VoxelState::Free);
    assert!(!occupied_near_centroid(&store, CENTROID, 0.1));
}

#[test]
fn viewpoints_need_known_free_space_with_clearance() {
    let mut store = ChunkStore::new(&config());
    for x in -10..=10 {
        for y in -10..=10 {
            for z in 0..=20 {
                set(&mut store, IVec3::new(x, y, z), VoxelState::Free);
            }
        }
    }
    // +x viewpoint (0.55, 0.05, 1.05): an occupied voxel spanning x 0.7..0.8 is 0.15 m away.
    set(&mut store, IVec3::new(7, 0, 10), VoxelState::Occupied);
    // -x viewpoint (-0.45, ...): an occupied voxel spanning x -0.9..-0.8 is 0.35 m away: kept.
    set(&mut store, IVec3::new(-9, 0, 10), VoxelState::Occupied);
    // +y viewpoint (0.05, 0.55, 1.05) lies in voxel (0, 5, 10): unknown, dropped.
    set(&mut store, IVec3::new(0, 5, 10), VoxelState::Unknown);
    let settings = ClusterSettings::default();
    let vps = sample_viewpoints(&store, CENTROID, &settings);
    let expected = [
        (Vec3::new(-0.45, 0.05, 1.05), 0.0),
        (Vec3::new(0.05, -0.45, 1.05), FRAC_PI_2),
        (Vec3::new(0.05, 0.05, 1.55), 0.0),
        (Vec3::new(0.05, 0.05, 0.55), 0.0),
    ];
    assert_eq!(vps.len(), expected.len(), "{vps:?}");
    for (vp, (position, yaw)) in vps.iter().zip(expected) {
        assert!(close(vp.position, position), "{vp:?}");
        assert!((vp.yaw - yaw).abs() < 1e-6, "{vp:?}");
    }
}

#[test]
fn viewpoints_outside_or_at_the_edge_of_the_map_are_dropped() {
    let mut store = ChunkStore::new(&config());
    // Free column near the map's floor (keys z -32..=-20).
    for x in -5..=5 {
        for y in -5..=5 {
            for z in -32..=-20 {
                set(&mut store, IVec3::new(x, y, z), VoxelState::Free);
            }
        }
    }
    let settings = ClusterSettings::default();
    let below = |c: Vec3| {
        sample_viewpoints(&store, c, &settings)
            .iter()
            .any(|v| v.position.z < c.z)
    };
    // Centroid at z -2.85: the -z viewpoint (z -3.35) is outside the map (floor at -3.2).
    assert!(!below(Vec3::new(0.05, 0.05, -2.85)));
    // At z -2.65: -z viewpoint at -3.15, 0.05 m above the map's floor: too close.
    assert!(!below(Vec3::new(0.05, 0.05, -2.65)));
    // At z -2.35: -z viewpoint at -2.85, 0.35 m above it: kept.
    assert!(below(Vec3::new(0.05, 0.05, -2.35)));
    assert!(is_clear(&store, Vec3::new(0.05, 0.05, -2.85), 0.25));
}

/// A map whose only known voxels are the free ones of layer z = 10 (the centroid's) within
/// `half` voxels of the centroid's voxel on x and y.
fn free_layer(half: i32) -> ChunkStore {
    let mut store = ChunkStore::new(&config());
    for x in -half..=half {
        for y in -half..=half {
            set(&mut store, IVec3::new(x, y, 10), VoxelState::Free);
        }
    }
    store
}

#[test]
fn yaw_faces_the_centroid() {
    let store = free_layer(10);
    let settings = ClusterSettings {
        viewpoint_clearance_m: 0.0,
        ..ClusterSettings::default()
    };
    let vps = sample_viewpoints(&store, CENTROID, &settings);
    let yaws: Vec<f32> = vps.iter().map(|v| v.yaw).collect();
    // +x looks back along -x (pi), -x along +x (0), +y along -y, -y along +y.
    assert_eq!(yaws, vec![PI, 0.0, -FRAC_PI_2, FRAC_PI_2]);
    assert!(vps.iter().all(|v: &Viewpoint| v.position.z == CENTROID.z));
}

#[test]
fn clusters_of_a_hand_made_frontier() {
    let mut store = ChunkStore::new(&config());
    let mut changed = Vec::new();
    // A 20 x 20 slab of free voxels at z = 10 in unknown space: all 400 are frontier; one
    // cluster with centroid (1.0, 1.0, 1.05) and r_max sqrt(2) * 0.95 = 1.3435 m.
    for x in 0..20 {
        for y in 0..20 {
            changed.push(set(&mut store, IVec3::new(x, y, 10), VoxelState::Free));
        }
    }
    // A 3-voxel sliver far away (4+ m): its own cluster, below min_cluster_voxels (10).
    for x in -30..=-28 {
        changed.push(set(&mut store, IVec3::new(x, -30, 10), VoxelState::Free));
    }
    let mut fs = FrontierSet::default();
    update_frontier_set(&mut fs, &store, &changed);
    assert_eq!(fs.len(), 403);
    let settings = ClusterSettings::default();
    let found = cluster_frontier(&fs, &store, &settings, &mut ChaCha8Rng::seed_from_u64(5));
    assert_eq!(found.len(), 1, "{found:?}");
    let c = &found[0];
    assert_eq!(c.cluster.size, 400);
    assert!(close(c.cluster.centroid, Vec3::new(1.0, 1.0, 1.05)));
    assert!((c.cluster.r_max - 2f32.sqrt() * 0.95).abs() < 1e-4);
    assert!(close(c.cluster.bbox_min, Vec3::new(0.05, 0.05, 1.05)));
    assert!(close(c.cluster.bbox_max, Vec3::new(1.95, 1.95, 1.05)));
    assert_eq!(c.members.0.len(), 400);
    // Set order: chunk (0, 0, 0), local index x fastest.
    assert_eq!(c.members.0[0], IVec3::new(0, 0, 10));
    assert_eq!(c.members.0[1], IVec3::new(1, 0, 10));
    assert_eq!(c.members.0[16], IVec3::new(0, 1, 10));
    assert!(c.reachable);
    // Viewpoints: +-x and +-y stay in the slab (free, unknown around is allowed); +-z are in
    // unknown voxels.
    assert_eq!(c.viewpoints.0.len(), 4);
    assert!(close(c.viewpoints.0[0].position, Vec3::new(1.5, 1.0, 1.05)));
    // An occupied voxel in the layer above the centroid's column makes it unreachable.
    set(&mut store, IVec3::new(10, 10, 11), VoxelState::Occupied);
    let found = cluster_frontier(&fs, &store, &settings, &mut ChaCha8Rng::seed_from_u64(5));
    assert!(!found[0].reachable);
}

#[test]
fn matching_keeps_the_nearest_old_cluster_within_half_r_max() {
    let old = [
        (Vec3::new(0.0, 0.0, 1.0), 2.0),
        (Vec3::new(5.0, 0.0, 1.0), 2.0),
        (Vec3::new(0.4, 0.0, 1.0), 2.0),
    ];
    let new = [
        // 0.3 from old 2, 0.7 from old 0: old 2.
        (Vec3::new(0.7, 0.0, 1.0), 2.0),
        // 0.2 from old 0, old 2 is taken.
        (Vec3::new(0.2, 0.0, 1.0), 1.0),
        // 1.5 from old 1: beyond 0.5 * 2.0.
        (Vec3::new(6.5, 0.0, 1.0), 1.0),
        // 0.9 from old 1, within 0.5 * 2.0.
        (Vec3::new(5.9, 0.0, 1.0), 0.1),
    ];
    assert_eq!(
        match_clusters(&old, &new, 0.05),
        vec![Some(2), Some(0), None, Some(1)]
    );
    // Tiny clusters still match within min_radius / 2.
    let old = [(Vec3::ZERO, 0.0)];
    assert_eq!(
        match_clusters(&old, &[(Vec3::X * 0.02, 0.0)], 0.05),
        vec![Some(0)]
    );
    assert_eq!(
        match_clusters(&old, &[(Vec3::X * 0.03, 0.0)], 0.05),
        vec![None]
    );
}

#[test]
fn standoff_viewpoints_face_the_centroid_from_their_distance_nearest_first() {
    let mut store = free_layer(25);
    // The UAV west of the centroid.
    let from = CENTROID - Vec3::new(5.0, 0.0, 0.0);
    let vps = standoff_viewpoints(&store, CENTROID, 2.0, 0.0, from);
    assert_eq!(vps.len(), 8, "{vps:?}");
    // The nearest first: due west, facing east.
    assert!(
        close(vps[0].position, Vec3::new(-1.95, 0.05, 1.05)),
        "{vps:?}"
    );
    assert!(vps[0].yaw.abs() < 1e-6, "{vps:?}");
    for pair in vps.windows(2) {
        assert!(pair[0].position.distance(from) <= pair[1].position.distance(from));
    }
    for vp in &vps {
        let to_centroid = CENTROID - vp.position;
        assert_eq!(to_centroid.z, 0.0, "level with the centroid: {vp:?}");
        assert!((to_centroid.length() - 2.0).abs() < 1e-5, "{vp:?}");
        let facing = Vec3::new(vp.yaw.cos(), vp.yaw.sin(), 0.0);
        assert!(facing.dot(to_centroid.normalize()) > 1.0 - 1e-5, "{vp:?}");
    }
    // Equally far from the UAV: kept in bearing order (135 degrees before 225).
    assert!(
        vps[1].position.y > CENTROID.y && vps[2].position.y < CENTROID.y,
        "{vps:?}"
    );

    // An occupied voxel at the eastern viewpoint drops it alone.
    set(&mut store, IVec3::new(20, 0, 10), VoxelState::Occupied);
    let vps = standoff_viewpoints(&store, CENTROID, 2.0, 0.0, from);
    assert_eq!(vps.len(), 7, "{vps:?}");
    assert!(vps.iter().all(|v| v.position.x < 2.0), "{vps:?}");
}

#[test]
fn a_standoff_viewpoint_behind_a_wall_is_dropped() {
    let mut store = free_layer(25);
    // A wall voxel 1 m east of the centroid, between it and its eastern viewpoint only.
    set(&mut store, IVec3::new(10, 0, 10), VoxelState::Occupied);
    assert!(!in_sight(&store, Vec3::new(2.05, 0.05, 1.05), CENTROID));
    assert!(in_sight(&store, Vec3::new(-1.95, 0.05, 1.05), CENTROID));
    let vps = standoff_viewpoints(&store, CENTROID, 2.0, 0.0, CENTROID);
    assert_eq!(vps.len(), 7, "{vps:?}");
    assert!(
        vps.iter()
            .all(|v| v.position.y != CENTROID.y || v.position.x < 0.0),
        "{vps:?}"
    );
    // Unknown voxels do not block the sight.
    set(&mut store, IVec3::new(10, 0, 10), VoxelState::Unknown);
    assert!(in_sight(&store, Vec3::new(2.05, 0.05, 1.05), CENTROID));
}

/// The frontier viewpoint (beyond the thesis): the member nearest to the centroid, the first
/// of equals in the members' order, facing the centroid; none without members.
#[test]
fn the_frontier_viewpoint_is_the_member_nearest_to_the_centroid() {
    let config = config();
    // On the boundary of voxels (-1, 0, 10) and (0, 0, 10): both centres 0.05 m away.
    let centroid = Vec3::new(0.0, 0.05, 1.05);
    let far = IVec3::new(3, 0, 10);
    let (west, east) = (IVec3::new(-1, 0, 10), IVec3::new(0, 0, 10));
    let aside = IVec3::new(0, 2, 10);
    let viewpoint = |members: &[IVec3]| frontier_viewpoint(&config, centroid, members);
    let v = viewpoint(&[far, west, east, aside]).unwrap();
    assert_eq!(v.position, config.center_of(west));
    assert_eq!(v.yaw, 0.0, "from the west voxel the centroid lies along +x");
    let v = viewpoint(&[far, east, west, aside]).unwrap();
    assert_eq!(v.position, config.center_of(east));
    assert_eq!(v.yaw, PI, "from the east voxel the centroid lies along -x");
    let v = viewpoint(&[far, aside]).unwrap();
    assert_eq!(v.position, config.center_of(aside));
    // Toward the centroid: (-0.05, -0.2) m, atan2(-0.2, -0.05) = -1.8158 rad.
    assert!((v.yaw + 1.815_775).abs() < 1e-5, "{}", v.yaw);
    assert_eq!(viewpoint(&[]), None);
}
