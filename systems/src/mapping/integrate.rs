//! Integration of one scan into the map (common.md §1), as a plain function over any chunk
//! storage ([`ChunkAccess`]): the ECS system and the tests and benchmarks share it.
//!
//! - Pass 1: each ray that hit applies the hit to its end voxel and stamps it.
//! - Pass 2: each ray walks from the origin to its end (3D DDA), clipped to the map, and applies
//!   the miss to every voxel not yet stamped by this scan. A hit ray's end voxel is excluded; a
//!   ray cut at max range, or leaving the map, marks its whole segment free including its last
//!   voxel (OctoMap's maxrange semantics).
//!
//! Hence a voxel that is both an end point and crossed counts as occupied, and each voxel is
//! updated at most once per scan, with no per-scan clearing, sorting or allocation.
//!
//! Pass 2 skips space whose voxels are all saturated free, where a miss changes nothing, so the
//! map is the same as if each voxel had been visited: a walk leaves the scan's free boxes
//! around the sensor in one move each (`super::free_box`), then the run of full bricks ahead
//! of it on the scan's brick grid (`super::brick_run`), and crosses the saturated cubes it
//! meets after that (bricks, blocks of bricks, whole chunks) in one move each
//! ([`super::cube::cross_saturated`]).

use super::axes::per_axis;
use super::brick_run::{BrickRuns, RunMove};
use super::dda::{VoxelWalk, to_fixed};
use super::free_box::{FreeBox, FreeBoxes};
use super::full_bricks::FullBricks;
pub use super::rays::{HIT_NUDGE, ScanError, ScanRays};
use super::rays::{PreparedRays, prepare};
pub use super::report::ScanReport;
use super::update::{UpdateRule, update_voxel};
use super::walk::end_margin;
use glam::{DVec3, IVec3};
use uavex_components::map::{
    CHUNK_VOXELS, ChunkCoord, ChunkGrid, LogOddsIncrements, MapConfig, ScanId, StatSums,
    StatTables, VoxelChunk, brick_of, floor_to_key, local_index,
};

/// Mutable access to the map's chunks, by flat chunk index (see [`ChunkGrid::flat`]).
pub trait ChunkAccess {
    /// The chunk with flat index `flat` (at `coord`) and its statistics; if absent, a chunk of
    /// unknown voxels with zero statistics is created, made by [`VoxelChunk::in_map`] (a plain
    /// [`VoxelChunk::new`] would do too, at the cost of walking the map's border voxel by
    /// voxel).
    fn chunk_mut(&mut self, flat: usize, coord: ChunkCoord) -> (&mut VoxelChunk, &mut StatSums);

    /// Told once per visit of a chunk in which some voxel's log-odds changed.
    fn mark_written(&mut self, flat: usize);

    /// The full bricks of the chunk with flat index `flat` ([`BrickSaturation::full_bricks`];
    /// none for a chunk not created yet, all of whose voxels are unknown).
    ///
    /// [`BrickSaturation::full_bricks`]: uavex_components::map::BrickSaturation::full_bricks
    fn full_bricks(&self, flat: usize) -> u64;
}

/// Integrates one scan (common.md §1): see the module documentation. `totals` receives the
/// change of every chunk's statistics (the map-wide [`uavex_components::map::MapTotals`]).
/// The report holds the rays, visits and changes, not the tallies of the skips.
pub fn integrate_scan(
    config: &MapConfig,
    scan: ScanId,
    rays: ScanRays<'_>,
    increments: LogOddsIncrements,
    chunks: &mut impl ChunkAccess,
    totals: &mut StatSums,
) -> Result<ScanReport, ScanError> {
    integrate::<false>(config, scan, rays, increments, chunks, totals)
}

/// [`integrate_scan`], the same map to the bit, with the whole [`ScanReport`]: how many rays
/// the free boxes held, how many cubes and runs the walks crossed, and so on (for the tests
/// that check each way of skipping is taken, and the benchmarks that report them). The map
/// update itself keeps no tallies: their registers slowed the walk by some 5 % (2026-12-06).
pub fn integrate_scan_tallied(
    config: &MapConfig,
    scan: ScanId,
    rays: ScanRays<'_>,
    increments: LogOddsIncrements,
    chunks: &mut impl ChunkAccess,
    totals: &mut StatSums,
) -> Result<ScanReport, ScanError> {
    integrate::<true>(config, scan, rays, increments, chunks, totals)
}

/// The integration, tallying the skips into the report when `TALLY`.
fn integrate<const TALLY: bool>(
    config: &MapConfig,
    scan: ScanId,
    rays: ScanRays<'_>,
    increments: LogOddsIncrements,
    chunks: &mut impl ChunkAccess,
    totals: &mut StatSums,
) -> Result<ScanReport, ScanError> {
    rays.validate()?;
    let rule = |delta: i16| UpdateRule {
        stamp: scan.stamp(),
        delta: i32::from(delta),
        min: i32::from(config.clamp_min()),
        max: i32::from(config.clamp_max()),
    };
    let mut run = Integration::<_, TALLY> {
        grid: config.chunk_grid(),
        tables: config.tables(),
        scan,
        chunks,
        totals,
        report: ScanReport {
            rays: rays.endpoints.len(),
            ..ScanReport::default()
        },
    };
    prepare(config, &rays, |prepared| {
        let PreparedRays {
            origin,
            ends,
            inverses,
            clips,
            bricks,
        } = prepared;
        // Pass 1: hits first, so that "occupied wins" over any miss of the same scan.
        let hit_rule = rule(increments.hit);
        let mut hits = ends
            .iter()
            .zip(rays.hit)
            .filter(|&(_, &hit)| hit)
            .map(|(&end, _)| floor_to_key(end))
            .filter(|&key| config.contains_key(key))
            .peekable();
        while let Some(key) = hits.next() {
            // Neighbouring rays mostly end in one chunk: a run of them is one chunk visit.
            let coord = ChunkCoord::of_key(key);
            let in_chunk = std::iter::once(key).chain(std::iter::from_fn(|| {
                hits.next_if(|&next| ChunkCoord::of_key(next) == coord)
            }));
            run.report.voxel_visits += run.update_in_chunk(coord, in_chunk, hit_rule);
        }

        // Pass 2: free space along every ray, skipping voxels this scan already updated. The
        // free boxes are grown after the hits (which may unsaturate a voxel) and stay valid:
        // misses only saturate more.
        let miss_rule = rule(increments.miss);
        let (free_boxes, gathered) = if miss_rule.delta <= 0 {
            run.free_boxes(config, origin, ends, bricks)
        } else {
            (FreeBoxes::default(), false)
        };
        let bricks = &*bricks;
        let prepared = ends.iter().zip(inverses.iter()).zip(clips.iter());
        for (((&end, &inverse), &clip), &hit) in prepared.zip(rays.hit) {
            let Some(clip) = clip else {
                continue;
            };
            let exclude_end = hit && clip.end_inside;
            if free_boxes.hold(clip.start_key, clip.end_key) {
                // No walk needed (a quarter of the rays of a camera in flight): its voxels
                // are the keys' L1 distance apart.
                let steps = (clip.end_key - clip.start_key).abs().element_sum() as u64;
                let visits = steps + 1 - u64::from(exclude_end);
                run.report.voxel_visits += visits;
                run.report.tally::<TALLY>(|r| {
                    r.skipped_voxels += visits;
                    r.free_box_rays += 1;
                });
                continue;
            }
            let mut walk =
                VoxelWalk::with_inverse(origin, end, inverse, clip.start_key, clip.end_key);
            let visits = walk.steps_left() + 1 - u64::from(exclude_end);
            run.report.voxel_visits += visits;
            let t_safe = clip.t_end - end_margin(&walk);
            let Some(visits) =
                run.leave_free_boxes(&free_boxes, &mut walk, clip.end_key, t_safe, visits)
            else {
                continue;
            };
            let visits = if gathered {
                let Some(visits) = run.leave_full_bricks(bricks, &mut walk, t_safe, visits) else {
                    continue;
                };
                visits
            } else {
                visits
            };
            run.update_walk(walk, t_safe, visits, miss_rule);
        }
    });
    Ok(run.report)
}

/// The state of one scan's integration (tallying its skips when `TALLY`).
pub(super) struct Integration<'a, C, const TALLY: bool> {
    pub(super) grid: ChunkGrid,
    pub(super) tables: &'a StatTables,
    pub(super) scan: ScanId,
    pub(super) chunks: &'a mut C,
    pub(super) totals: &'a mut StatSums,
    pub(super) report: ScanReport,
}

impl<C: ChunkAccess, const TALLY: bool> Integration<'_, C, TALLY> {
    /// Updates the single voxel `key` (inside the map).
    pub(super) fn update_one(&mut self, key: IVec3, rule: UpdateRule) {
        self.update_in_chunk(ChunkCoord::of_key(key), std::iter::once(key), rule);
    }

    /// Updates the voxels `keys`, all inside the map and in the chunk at `coord`, in one visit
    /// of the chunk: how many there were.
    #[inline]
    fn update_in_chunk(
        &mut self,
        coord: ChunkCoord,
        keys: impl Iterator<Item = IVec3>,
        rule: UpdateRule,
    ) -> u64 {
        let flat = self.grid.flat_unchecked(coord);
        let (chunk, stats) = self.chunks.chunk_mut(flat, coord);
        chunk.begin_scan(self.scan);
        let before = *stats;
        let (cells, saturation) = chunk.voxels_for_update();
        let (mut visits, mut changed, mut state_bricks) = (0, 0, 0u64);
        for key in keys {
            debug_assert_eq!(ChunkCoord::of_key(key), coord);
            let index = local_index(key) & (CHUNK_VOXELS - 1);
            let change = update_voxel(cells, index, saturation, rule, self.tables, stats);
            visits += 1;
            changed += u64::from(change.changed());
            state_bricks |= u64::from(change.state_changed()) << brick_of(index);
        }
        chunk.note_state_changes_in(self.scan, state_bricks);
        if changed > 0 {
            // Statistics change only with log-odds.
            self.totals.add_change(&before, stats);
            self.report.changed_voxels += changed;
            self.chunks.mark_written(flat);
        }
        visits
    }

    /// The scan's free boxes ([`FreeBoxes::grow`]) around the sensor at `origin` (voxel
    /// units), within the key box of the rays' ends `ends`, grown on the bricks of that box
    /// gathered into `bricks`; none when the sensor is outside the map.
    fn free_boxes(
        &mut self,
        config: &MapConfig,
        origin: DVec3,
        ends: &[DVec3],
        bricks: &mut FullBricks,
    ) -> (FreeBoxes, bool) {
        let origin_key = floor_to_key(origin);
        if !config.contains_key(origin_key) {
            return (FreeBoxes::default(), false);
        }
        // The keys' box from the points' box: `floor` is monotonic.
        let (lo, hi) = ends.iter().fold((origin, origin), |(lo, hi), &end| {
            (lo.min(end), hi.max(end))
        });
        let lo = floor_to_key(lo).max(config.key_min());
        let hi = floor_to_key(hi).min(config.key_max());
        let chunks = &*self.chunks;
        bricks.gather(self.grid, lo, hi, |flat| chunks.full_bricks(flat));
        let boxes = FreeBoxes::grow(origin_key, lo, hi, |from, to| bricks.all_full(from, to));
        self.report.tally::<TALLY>(|r| {
            r.free_box_voxels = boxes
                .iter()
                .next()
                .map_or(0, |b| (b.hi - b.lo + IVec3::ONE).element_product() as u64);
        });
        (boxes, true)
    }

    /// Moves `walk` out of each of the scan's free boxes it is in, in turn
    /// ([`Self::leave_free_box`]): the visits left, or `None` when it ends inside one (all its
    /// visits would change nothing). Once out of a box a walk never re-enters it (a box is
    /// convex, and each axis of a walk moves one way).
    #[inline]
    fn leave_free_boxes(
        &mut self,
        boxes: &FreeBoxes,
        walk: &mut VoxelWalk,
        end_key: IVec3,
        t_safe: f64,
        mut visits: u64,
    ) -> Option<u64> {
        for (index, free) in boxes.iter().enumerate() {
            if visits == 0 {
                break;
            }
            if !free.contains(walk.key()) {
                continue;
            }
            self.report
                .tally::<TALLY>(|r| r.free_box_beyond += u64::from(index >= boxes.around()));
            if free.contains(end_key) {
                self.report.tally::<TALLY>(|r| {
                    r.skipped_voxels += visits;
                    r.free_box_rays += 1;
                });
                return None;
            }
            visits = self.leave_free_box(free, walk, t_safe, visits);
        }
        Some(visits)
    }

    /// Moves `walk` (in the scan's free box `free`, which does not hold its end; `visits`
    /// voxels to visit, its segment safe until `t_safe`) out of the box in one move: the visits
    /// left. A walk that leaves the box only within the end margin stays where it is.
    #[inline]
    fn leave_free_box(
        &mut self,
        free: &FreeBox,
        walk: &mut VoxelWalk,
        t_safe: f64,
        visits: u64,
    ) -> u64 {
        let key = walk.key();
        let crossing = free.cross(
            key,
            per_axis(walk.steps(), i64::from),
            walk.boundary_times(),
            walk.boundary_intervals(),
        );
        if crossing.face_time >= to_fixed(t_safe) {
            return visits;
        }
        // Every crossing is before `t_safe`: the voxels passed are on the walk, and the one
        // entered is too (unless it is a hit's excluded end voxel: then no visit is left).
        let passed = crossing.voxels_passed() as u64;
        debug_assert!(passed <= visits);
        self.report.tally::<TALLY>(|r| {
            r.skipped_voxels += passed;
            r.free_box_exits += 1;
        });
        let [kx, ky, kz] = crossing.crossings;
        let [mx, my, mz] = walk.steps();
        let moved = IVec3::new(kx as i32 * mx, ky as i32 * my, kz as i32 * mz);
        walk.resume(key + moved, crossing.boundary_times);
        visits - passed
    }

    /// Moves `walk` (`visits` voxels to visit, its segment safe until `t_safe`) along the run
    /// of full bricks it stands in on the scan's grid `bricks` ([`BrickRuns`]): the visits
    /// left, or `None` when it ends in a full brick.
    #[inline]
    fn leave_full_bricks(
        &mut self,
        bricks: &FullBricks,
        walk: &mut VoxelWalk,
        t_safe: f64,
        visits: u64,
    ) -> Option<u64> {
        if visits == 0 {
            return Some(0);
        }
        let steps = per_axis(walk.steps(), i64::from);
        let dt = walk.boundary_intervals();
        let runs = BrickRuns::new(bricks, steps, dt, walk.last_key(), to_fixed(t_safe));
        let key = walk.key();
        match runs.cross(key, walk.boundary_times(), dt) {
            RunMove::Cross(crossing) => {
                let passed = crossing.voxels_passed() as u64;
                debug_assert!(passed <= visits);
                self.report.tally::<TALLY>(|r| {
                    r.skipped_voxels += passed;
                    r.brick_runs += 1;
                });
                let [kx, ky, kz] = crossing.crossings;
                let [mx, my, mz] = steps;
                let moved = IVec3::new((kx * mx) as i32, (ky * my) as i32, (kz * mz) as i32);
                walk.resume(key + moved, crossing.boundary_times);
                Some(visits - passed)
            }
            RunMove::EndsInside => {
                self.report.tally::<TALLY>(|r| {
                    r.skipped_voxels += visits;
                    r.ends_in_cubes += 1;
                });
                None
            }
            RunMove::Stuck | RunMove::NotFull => Some(visits),
        }
    }
}
