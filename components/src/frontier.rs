//! Frontier data (EAAE steps 1-4, eaae.md "Exploration cycle"): the frontier voxels of the map,
//! the frontier clusters (one entity each) with their viewpoints, and the settings of detection
//! and clustering. The algorithms live in `uavex_systems::frontier`.

use crate::map::{CHUNK_EDGE, CHUNK_VOXELS, ChunkCoord, local_index, local_key};
use bevy_ecs::prelude::*;
use glam::{IVec3, Vec3};
use std::collections::BTreeMap;

/// Rows of 16 voxels (along x) in a chunk: one per (y, z).
const ROWS: usize = CHUNK_VOXELS / CHUNK_EDGE as usize;

/// One bit per voxel of a chunk, in [`local_index`] order: row `y + 16 z` holds bit `x`.
///
/// Rows of 16 bits let frontier detection work on whole rows at once (shifts for the x
/// neighbours, the rows above and below for y and z).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct VoxelMask(pub [u16; ROWS]);

impl Default for VoxelMask {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl VoxelMask {
    pub const EMPTY: VoxelMask = VoxelMask([0; ROWS]);

    #[inline]
    pub fn contains(&self, index: usize) -> bool {
        let index = index % CHUNK_VOXELS;
        self.0[index >> 4] & (1 << (index & 15)) != 0
    }

    #[inline]
    pub fn insert(&mut self, index: usize) {
        let index = index % CHUNK_VOXELS;
        self.0[index >> 4] |= 1 << (index & 15);
    }

    #[inline]
    pub fn remove(&mut self, index: usize) {
        let index = index % CHUNK_VOXELS;
        self.0[index >> 4] &= !(1 << (index & 15));
    }

    /// Number of voxels set.
    pub fn count(&self) -> u32 {
        self.0.iter().map(|row| row.count_ones()).sum()
    }

    pub fn is_empty(&self) -> bool {
        self.0.iter().all(|&row| row == 0)
    }

    /// This mask without the voxels of `other`.
    pub fn without(&self, other: &VoxelMask) -> VoxelMask {
        let mut out = self.clone();
        for (row, &drop) in out.0.iter_mut().zip(other.0.iter()) {
            *row &= !drop;
        }
        out
    }

    /// Local indices of the voxels set, ascending.
    pub fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        self.0.iter().enumerate().flat_map(|(r, &row)| {
            let mut bits = row;
            std::iter::from_fn(move || {
                (bits != 0).then(|| {
                    let x = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    (r << 4) | x
                })
            })
        })
    }
}

/// Orders chunks as the dense chunk grid does (`x + dx (y + dy z)`): by z, then y, then x.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
struct GridOrder([i32; 3]);

impl GridOrder {
    fn of(coord: ChunkCoord) -> Self {
        Self([coord.0.z, coord.0.y, coord.0.x])
    }

    fn coord(self) -> ChunkCoord {
        let [z, y, x] = self.0;
        ChunkCoord(IVec3::new(x, y, z))
    }
}

/// Frontier voxels of the map (EAAE step 1), kept per chunk so that the Frontier stage only
/// rewrites the chunks a scan changed. Deterministic order: chunk grid order, then key order
/// within a chunk ([`local_index`] order: x fastest, then y, then z).
///
/// What counts as a frontier voxel is decided in `uavex_systems::frontier::detect` (a known-free
/// voxel with an unknown 6-neighbour inside the map); this type only stores the result, minus
/// the voxels the exploration stage chose to [`FrontierSet::ignore`].
#[derive(Resource, Debug, Default, Clone)]
pub struct FrontierSet {
    chunks: BTreeMap<GridOrder, VoxelMask>,
    /// Voxels never to be counted as frontier again (rare, so kept apart).
    ignored: BTreeMap<GridOrder, VoxelMask>,
    len: usize,
    generation: u64,
}

impl FrontierSet {
    /// Number of frontier voxels (not ignored).
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    pub fn contains(&self, key: IVec3) -> bool {
        self.chunks
            .get(&GridOrder::of(ChunkCoord::of_key(key)))
            .is_some_and(|mask| mask.contains(local_index(key)))
    }

    /// Every frontier voxel not ignored, deterministic order (see the type's documentation).
    pub fn iter(&self) -> impl Iterator<Item = IVec3> + '_ {
        self.chunks.iter().flat_map(|(order, mask)| {
            let coord = order.coord();
            mask.iter().map(move |i| local_key(coord, i))
        })
    }

    /// The frontier voxels of the chunk at `coord` (ignored ones removed), if it has any.
    pub fn chunk(&self, coord: ChunkCoord) -> Option<&VoxelMask> {
        self.chunks.get(&GridOrder::of(coord))
    }

    /// Chunks holding frontier voxels, with their masks, in chunk grid order.
    pub fn chunks(&self) -> impl Iterator<Item = (ChunkCoord, &VoxelMask)> + '_ {
        self.chunks
            .iter()
            .map(|(order, mask)| (order.coord(), mask))
    }

    /// Never count `key` as a frontier again (a frontier the UAV went to and could not clear,
    /// e.g. a sliver beside a wall that no viewpoint sees). Used by the exploration stage.
    pub fn ignore(&mut self, key: IVec3) {
        let order = GridOrder::of(ChunkCoord::of_key(key));
        let index = local_index(key);
        self.ignored.entry(order).or_default().insert(index);
        if let Some(mask) = self.chunks.get_mut(&order)
            && mask.contains(index)
        {
            mask.remove(index);
            if mask.is_empty() {
                self.chunks.remove(&order);
            }
            self.len -= 1;
            self.generation += 1;
        }
    }

    /// Whether `key` was ignored with [`FrontierSet::ignore`].
    pub fn is_ignored(&self, key: IVec3) -> bool {
        self.ignored
            .get(&GridOrder::of(ChunkCoord::of_key(key)))
            .is_some_and(|mask| mask.contains(local_index(key)))
    }

    /// Bumped whenever the set changes (so clustering can be skipped when nothing changed).
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Sets the frontier voxels of the chunk at `coord` to `frontier` minus the ignored ones
    /// (the Frontier stage's write after re-examining a chunk). Returns whether the set changed;
    /// the generation is bumped only then.
    pub fn replace_chunk(&mut self, coord: ChunkCoord, frontier: &VoxelMask) -> bool {
        let order = GridOrder::of(coord);
        let new = match self.ignored.get(&order) {
            Some(ignored) => frontier.without(ignored),
            None => frontier.clone(),
        };
        let old_count = self.chunks.get(&order).map_or(0, |m| m.count() as usize);
        let changed = match self.chunks.get(&order) {
            Some(old) => *old != new,
            None => !new.is_empty(),
        };
        if !changed {
            return false;
        }
        self.len = self.len - old_count + new.count() as usize;
        if new.is_empty() {
            self.chunks.remove(&order);
        } else {
            self.chunks.insert(order, new);
        }
        self.generation += 1;
        true
    }
}

/// One frontier cluster (an entity): EAAE step 2.
#[derive(Component, Debug, Clone, PartialEq)]
pub struct FrontierCluster {
    /// Mean of the member voxel centres.
    pub centroid: Vec3,
    /// Number of frontier voxels = information gain IG(c) (EAAE step 5).
    pub size: u32,
    /// Largest member distance to the centroid (m); <= the stop rule's bound.
    pub r_max: f32,
    /// Box of the member voxel centres.
    pub bbox_min: Vec3,
    pub bbox_max: Vec3,
}

/// The member voxel keys, sorted in [`FrontierSet`] order: chunk grid order (chunk z, then y,
/// then x), then local index within the chunk (x fastest, then y, then z). That is the order
/// clustering sees them in, so no extra sort (~2 ms for a 45k-voxel frontier) is paid. (The
/// exploration stage checks whether a goal's frontier vanished.)
#[derive(Component, Debug, Clone, PartialEq)]
pub struct ClusterMembers(pub Vec<IVec3>);

/// A pose from which to look at a cluster.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Viewpoint {
    pub position: Vec3,
    /// Faces the centroid (rad, about +z from +x); 0 for viewpoints straight above or below it.
    pub yaw: f32,
}

/// EAAE step 4: candidate viewpoints around the centroid in known free space.
#[derive(Component, Debug, Clone, PartialEq, Default)]
pub struct Viewpoints(pub Vec<Viewpoint>);

/// Marker: the cluster passed the reachability filter (EAAE step 3, first rule).
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reachable;

/// Why [`ClusterSettings`] cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ClusterSettingsError {
    #[error("cluster setting {name} must be a finite length >= 0 m, got {value}")]
    InvalidLength { name: &'static str, value: f32 },
}

/// Settings of detection and clustering (a resource).
#[derive(Resource, Debug, Clone, PartialEq)]
pub struct ClusterSettings {
    /// Stop rule bound tan(FoV_h/2) * d_max (m): 2.73 m for the EAAE camera.
    pub r_max_m: f32,
    /// Drop clusters with known-occupied voxels within this x-y distance of the centroid (0.1 m).
    pub occupied_radius_xy_m: f32,
    /// Viewpoint offsets along each axis (0.5 m).
    pub viewpoint_offset_m: f32,
    /// A viewpoint needs a known-free voxel with no known-occupied voxel (and no voxel outside
    /// the map) within this distance.
    pub viewpoint_clearance_m: f32,
    /// Clusters smaller than this are not kept (noise slivers).
    pub min_cluster_voxels: u32,
}

impl ClusterSettings {
    /// EAAE's settings (eaae.md steps 2-4) for a camera of horizontal field of view `hfov_rad`
    /// and range `range_max_m`.
    ///
    /// Choices of ours (the thesis fixes none of them):
    /// - `viewpoint_clearance_m` 0.25 m: the kingfisher's rotor tips lie ~0.19 m from its
    ///   centre (rotor at 0.125 m plus a 5-inch propeller's 0.064 m), plus half a voxel.
    /// - `min_cluster_voxels` 10: at 0.1 m, a frontier patch under 0.1 m^2. Smaller clusters are
    ///   slivers left beside walls, in corners and under obstacles that no viewpoint clears;
    ///   kept, they would draw the UAV back forever and the mission would never complete.
    pub fn for_camera(hfov_rad: f64, range_max_m: f64) -> Self {
        Self {
            r_max_m: ((hfov_rad / 2.0).tan() * range_max_m) as f32,
            occupied_radius_xy_m: 0.1,
            viewpoint_offset_m: 0.5,
            viewpoint_clearance_m: 0.25,
            min_cluster_voxels: 10,
        }
    }

    /// Refuses non-finite or negative lengths (a NaN stop-rule bound would split every cluster
    /// down to single voxels).
    pub fn validate(&self) -> Result<(), ClusterSettingsError> {
        for (name, value) in [
            ("r_max_m", self.r_max_m),
            ("occupied_radius_xy_m", self.occupied_radius_xy_m),
            ("viewpoint_offset_m", self.viewpoint_offset_m),
            ("viewpoint_clearance_m", self.viewpoint_clearance_m),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(ClusterSettingsError::InvalidLength { name, value });
            }
        }
        Ok(())
    }
}

impl Default for ClusterSettings {
    /// The EAAE depth camera: FoV_h 1.0 rad, range 5 m (common.md §2).
    fn default() -> Self {
        Self::for_camera(1.0, 5.0)
    }
}

/// Bookkeeping of the clustering system: how many times it ran (the index of its random
/// stream) and the [`FrontierSet::generation`] it last clustered.
#[derive(Resource, Debug, Clone, Default, PartialEq, Eq)]
pub struct ClusteringCounter {
    pub runs: u64,
    pub last_generation: Option<u64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mask(indices: &[usize]) -> VoxelMask {
        let mut m = VoxelMask::EMPTY;
        for &i in indices {
            m.insert(i);
        }
        m
    }

    #[test]
    fn masks_iterate_in_local_index_order() {
        let m = mask(&[4095, 0, 17, 16, 300]);
        assert_eq!(m.iter().collect::<Vec<_>>(), vec![0, 16, 17, 300, 4095]);
        assert_eq!(m.count(), 5);
        // Index 17 = x 1 of row 1 (y 1, z 0).
        assert_eq!(m.0[1], 0b11);
        assert_eq!(m.without(&mask(&[16, 4095])).count(), 3);
    }

    #[test]
    fn set_orders_chunks_by_grid_order_and_counts() {
        let mut set = FrontierSet::default();
        // Chunk (5, 0, 0) comes before (0, 1, 0) and (0, 0, 1) in grid order (z, then y, then x).
        let a = ChunkCoord(IVec3::new(0, 0, 1));
        let b = ChunkCoord(IVec3::new(0, 1, 0));
        let c = ChunkCoord(IVec3::new(5, 0, 0));
        assert!(set.replace_chunk(a, &mask(&[0])));
        assert!(set.replace_chunk(b, &mask(&[1, 2])));
        assert!(set.replace_chunk(c, &mask(&[3])));
        assert_eq!(set.generation(), 3);
        assert!(!set.replace_chunk(c, &mask(&[3])));
        assert_eq!(set.generation(), 3);
        let keys: Vec<IVec3> = set.iter().collect();
        assert_eq!(
            keys,
            vec![
                IVec3::new(83, 0, 0),
                IVec3::new(1, 16, 0),
                IVec3::new(2, 16, 0),
                IVec3::new(0, 0, 16),
            ]
        );
        assert_eq!(set.len(), 4);
        assert!(set.contains(IVec3::new(2, 16, 0)));
        assert!(!set.contains(IVec3::new(3, 16, 0)));
        // Emptying a chunk drops it.
        assert!(set.replace_chunk(b, &VoxelMask::EMPTY));
        assert_eq!(set.len(), 2);
        assert_eq!(set.chunks().count(), 2);
    }

    #[test]
    fn ignored_keys_stay_out() {
        let mut set = FrontierSet::default();
        let coord = ChunkCoord(IVec3::new(-1, 0, 0));
        // Key (-16, 0, 0) is local 0 of chunk -1; (-15, 0, 0) local 1.
        set.replace_chunk(coord, &mask(&[0, 1]));
        let g = set.generation();
        set.ignore(IVec3::new(-16, 0, 0));
        assert_eq!((set.len(), set.generation()), (1, g + 1));
        assert!(!set.contains(IVec3::new(-16, 0, 0)));
        assert!(set.is_ignored(IVec3::new(-16, 0, 0)));
        // Re-detection does not bring it back; ignoring a non-frontier key changes nothing.
        assert!(!set.replace_chunk(coord, &mask(&[0, 1])));
        set.ignore(IVec3::new(40, 0, 0));
        assert_eq!((set.len(), set.generation()), (1, g + 1));
        assert_eq!(set.iter().collect::<Vec<_>>(), vec![IVec3::new(-15, 0, 0)]);
    }

    #[test]
    fn eaae_camera_bound_is_2_73_m() {
        let s = ClusterSettings::for_camera(1.0, 5.0);
        // tan(0.5) = 0.546302 -> 2.73151 m.
        assert!((s.r_max_m - 2.731_512).abs() < 1e-5, "{}", s.r_max_m);
        assert_eq!(s.validate(), Ok(()));
        let bad = ClusterSettings {
            r_max_m: f32::NAN,
            ..s
        };
        assert!(matches!(
            bad.validate(),
            Err(ClusterSettingsError::InvalidLength {
                name: "r_max_m",
                ..
            })
        ));
    }
}
