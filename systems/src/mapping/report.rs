//! What one scan's integration did ([`ScanReport`]): its rays, visits and changes, and, when
//! asked for, the tallies of how its walks skipped saturated space.

/// What one integration did. The first three fields are always filled; the rest, the tallies
/// of how the walks skipped saturated space, only by [`super::integrate_scan_tallied`] (zero
/// from [`super::integrate_scan`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ScanReport {
    pub rays: usize,
    /// Voxels visited: end voxels of hits inside the map plus every voxel the walks visited
    /// (the traversal's work, counting voxels skipped because already updated by this scan).
    pub voxel_visits: u64,
    /// Voxels whose log-odds changed.
    pub changed_voxels: u64,
    /// Of the visits, those passed over in saturated cubes (no update needed).
    pub skipped_voxels: u64,
    /// Saturated cubes crossed in one move, by size (indexed by [`super::cube::Cube`]).
    pub cubes_crossed: [u64; 3],
    /// Walks that ended inside a saturated cube they reached (the rest of the walk skipped:
    /// [`super::cube::CubeMove::EndsInside`]).
    pub ends_in_cubes: u64,
    /// Chunks the walks entered or crossed (one per chunk per ray).
    pub chunk_visits: u64,
    /// Runs of full bricks crossed in one move, each past the free boxes (`brick_run`).
    pub brick_runs: u64,
    /// Voxels in the scan's first free box (`super::free_box`; 0 when it had none).
    pub free_box_voxels: u64,
    /// Rays that ended inside a free box (skipped whole).
    pub free_box_rays: u64,
    /// Moves out of a free box (a ray may leave more than one).
    pub free_box_exits: u64,
    /// Walks that reached a free box beyond the sensor's
    /// ([`super::free_box::FreeBoxes::grow`]), once per box: each then ended in it or left it
    /// in one move (unless its face came within the end margin).
    pub free_box_beyond: u64,
}

impl ScanReport {
    /// Adds to the tallies with `add` when the integration keeps them (`TALLY`; compiled
    /// away when it does not).
    #[inline(always)]
    pub(super) fn tally<const TALLY: bool>(&mut self, add: impl FnOnce(&mut Self)) {
        if TALLY {
            add(self);
        }
    }
}
