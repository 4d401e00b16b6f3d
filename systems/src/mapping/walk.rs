//! The walk proper: the voxels of one ray after the free boxes and the brick runs, updated one
//! by one inside a chunk, with the saturated cubes met on the way crossed in one move each
//! (`super::cube`), and the last voxels before the end taken by the counted walk.

use super::axes::{mask, per_axis};
use super::cube::{Cube, CubeLimit, CubeMove, WalkInChunk, cross_saturated, leave_cube};
use super::cursor::{CURSOR_X, CURSOR_Y, CURSOR_Z, Cursor};
use super::dda::{T_ONE, VoxelWalk, to_fixed};
use super::integrate::{ChunkAccess, Integration};
use super::update::{UpdateRule, update_voxel};
use glam::IVec3;
use uavex_components::map::{CHUNK_EDGE, ChunkCoord, brick_of};

impl<C: ChunkAccess, const TALLY: bool> Integration<'_, C, TALLY> {
    /// Updates the first `visits` voxels of `walk` (all inside the map), whose segment is safe
    /// until parameter `t_safe` ([`end_margin`]).
    ///
    /// Most steps run in [`Self::walk_fast`]; the last steps, whose boundaries lie within a
    /// margin of the end (where rounding could order a boundary beyond the end key before a
    /// real one), take the counted walk of [`VoxelWalk::advance`], voxel by voxel.
    pub(super) fn update_walk(
        &mut self,
        mut walk: VoxelWalk,
        t_safe: f64,
        visits: u64,
        rule: UpdateRule,
    ) {
        // `walk` stays at the last voxel updated.
        let mut visits = self.walk_fast(&mut walk, t_safe, visits, rule);
        while visits > 0 {
            walk.advance();
            self.update_one(walk.key(), rule);
            visits -= 1;
        }
    }

    /// Walks and updates voxels while the next boundary comes before `t_safe`; returns the
    /// visits left, with `walk` moved to the last voxel updated.
    ///
    /// No step taken here can overshoot the end key: every boundary crossed lies before the
    /// segment's end, so no per-axis step counts are needed. The inner loop runs while the walk
    /// stays in one chunk and keeps everything in registers:
    /// - boundary times are fixed-point integers (see `dda`): which axis comes next is as good
    ///   as random, so it is chosen with compares and masks, not branches (mispredicted every
    ///   other step); integer compare, mask and add take a cycle each on the step-to-step
    ///   dependency, floating-point compare and add three to four (measured: the same loop on
    ///   f64 took 1.2 to 1.4 times as long);
    /// - one integer `cursor` holds both the voxel index in the chunk and the chunk-local
    ///   coordinates, biased so that leaving the chunk shows in one mask test;
    /// - in a brick of saturated free voxels the walk crosses the largest saturated cube
    ///   around it (brick, block or chunk) in one move ([`cross_saturated`]), as long as a
    ///   miss cannot change them (a non-positive miss increment) and the cube's face comes
    ///   before `t_safe` (a saturated voxel in a brick that is not full costs one compare:
    ///   [`update_voxel`]); a walk whose end lies in such a cube is done there (every voxel
    ///   left is in it: [`CubeMove::EndsInside`]).
    ///
    /// No lookups, no bounds checks.
    fn walk_fast(
        &mut self,
        walk: &mut VoxelWalk,
        t_safe: f64,
        mut visits: u64,
        rule: UpdateRule,
    ) -> u64 {
        let [mut tx, mut ty, mut tz] = walk.boundary_times();
        let [dtx, dty, dtz] = walk.boundary_intervals();
        let t_safe = to_fixed(t_safe);
        let [mx, my, mz] = per_axis(walk.steps(), i64::from);
        let [cx, cy, cz] = [mx * CURSOR_X, my * CURSOR_Y, mz * CURSOR_Z];
        let mut key = walk.key();
        let last_key = walk.last_key();
        let mut stop = false;
        // Saturated voxels stay unchanged by a non-positive increment only (a miss, always in
        // practice).
        let mut cubes_left = if rule.delta <= 0 {
            CubeLimit::ANY
        } else {
            CubeLimit::NONE
        };
        while visits > 0 && !stop {
            let coord = ChunkCoord::of_key(key);
            let flat = self.grid.flat_unchecked(coord);
            let (chunk, stats) = self.chunks.chunk_mut(flat, coord);
            self.report.tally::<TALLY>(|r| r.chunk_visits += 1);
            let in_chunk = WalkInChunk {
                steps: [mx, my, mz],
                dt: [dtx, dty, dtz],
                t_safe,
                end: (last_key - coord.first_key()).as_i64vec3().to_array(),
            };
            // A chunk saturated whole is crossed without entering it: no voxel, stamp or
            // statistic of it is touched (the same move as `cross_saturated`'s chunk case).
            if cubes_left.allows(Cube::Chunk) && chunk.saturation().full_bricks() == u64::MAX {
                let local = (key & (CHUNK_EDGE - 1)).as_i64vec3().to_array();
                match leave_cube::<{ CHUNK_EDGE as i64 }>(
                    Cube::Chunk,
                    &in_chunk,
                    local,
                    [tx, ty, tz],
                    &mut cubes_left,
                ) {
                    CubeMove::Cross(_, crossing) => {
                        let passed = crossing.voxels_passed() as u64;
                        debug_assert!(passed <= visits);
                        visits -= passed;
                        self.report.tally::<TALLY>(|r| {
                            r.skipped_voxels += passed;
                            r.cubes_crossed[Cube::Chunk as usize] += 1;
                        });
                        [tx, ty, tz] = crossing.boundary_times;
                        let [kx, ky, kz] = crossing.crossings;
                        key += IVec3::new((kx * mx) as i32, (ky * my) as i32, (kz * mz) as i32);
                        continue;
                    }
                    CubeMove::EndsInside => {
                        self.report.tally::<TALLY>(|r| {
                            r.skipped_voxels += visits;
                            r.ends_in_cubes += 1;
                        });
                        visits = 0;
                        break;
                    }
                    CubeMove::Step => {}
                }
            }
            chunk.begin_scan(self.scan);
            let before = *stats;
            let (cells, saturation) = chunk.voxels_for_update();
            let mut cursor = Cursor::at(key);
            let mut changed = 0u64;
            let mut skipped = 0u64;
            let mut cubes = [0u64; 3];
            let mut ends_in_cubes = 0u64;
            // The bricks where a voxel's state changed (`VoxelChunk::note_state_changes_in`).
            let mut state_bricks = 0u64;
            loop {
                let index = cursor.index();
                let brick = brick_of(index);
                let full_bricks = saturation.full_bricks();
                if cubes_left.open() && full_bricks >> brick & 1 == 1 {
                    match cross_saturated(
                        full_bricks,
                        brick,
                        &in_chunk,
                        cursor.local_array(),
                        [tx, ty, tz],
                        &mut cubes_left,
                    ) {
                        CubeMove::Cross(cube, crossing) => {
                            if TALLY {
                                cubes[cube as usize] += 1;
                            }
                            // Every crossing is before `t_safe`, hence before the segment's
                            // end: the voxels passed are on the walk, and the one entered is
                            // too, unless it is the excluded end voxel of a hit (then no visit
                            // is left).
                            let passed = crossing.voxels_passed() as u64;
                            debug_assert!(passed <= visits);
                            visits -= passed;
                            if TALLY {
                                skipped += passed;
                            }
                            [tx, ty, tz] = crossing.boundary_times;
                            let [kx, ky, kz] = crossing.crossings;
                            cursor.0 = cursor.0.wrapping_add(
                                kx.wrapping_mul(cx)
                                    .wrapping_add(ky.wrapping_mul(cy))
                                    .wrapping_add(kz.wrapping_mul(cz))
                                    as u64,
                            );
                            if visits == 0 || cursor.left_chunk() {
                                break;
                            }
                            continue;
                        }
                        CubeMove::EndsInside => {
                            if TALLY {
                                skipped += visits;
                                ends_in_cubes += 1;
                            }
                            visits = 0;
                            break;
                        }
                        CubeMove::Step => {}
                    }
                }
                let change = update_voxel(cells, index, saturation, rule, self.tables, stats);
                changed += u64::from(change.changed());
                state_bricks |= u64::from(change.state_changed()) << brick;
                visits -= 1;
                if visits == 0 {
                    break;
                }
                if (tx >= t_safe) & (ty >= t_safe) & (tz >= t_safe) {
                    stop = true;
                    break;
                }
                let x = mask((tx <= ty) & (tx <= tz));
                let y = !x & mask(ty <= tz);
                let z = !x & !y;
                tx += x & dtx;
                ty += y & dty;
                tz += z & dtz;
                cursor.0 = cursor
                    .0
                    .wrapping_add(((x & cx) | (y & cy) | (z & cz)) as u64);
                if cursor.left_chunk() {
                    break;
                }
            }
            key = coord.first_key() + cursor.local();
            self.report.tally::<TALLY>(|r| {
                r.skipped_voxels += skipped;
                r.ends_in_cubes += ends_in_cubes;
                for (total, crossed) in r.cubes_crossed.iter_mut().zip(cubes) {
                    *total += crossed;
                }
            });
            chunk.note_state_changes_in(self.scan, state_bricks);
            if changed > 0 {
                // Statistics change only with log-odds: most visits (crossings of saturated
                // cubes, voxels seen again) change none.
                self.totals.add_change(&before, stats);
                self.report.changed_voxels += changed;
                self.chunks.mark_written(flat);
            }
        }
        walk.resume(key, [tx, ty, tz]);
        visits
    }
}

/// The margin before the end of `walk`'s segment (segment parameter) within which its
/// boundaries are left to the counted walk: [`END_MARGIN`] plus twice the worst accumulated
/// truncation of the fixed-point boundary times ([`T_ONE`]): 2^-44 per step, below 6e-8
/// after 2^20 steps.
pub(super) fn end_margin(walk: &VoxelWalk) -> f64 {
    END_MARGIN + 2.0 * (walk.steps_left() + 1) as f64 / T_ONE
}

/// Base margin (segment parameter) before the end of a segment within which boundaries are
/// left to the counted walk; far above the accumulated rounding, and small enough that the
/// counted walk rarely runs (boundaries within 1e-6 of a ray's end, a few voxels at most).
const END_MARGIN: f64 = 1e-6;
