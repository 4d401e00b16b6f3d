//! The thin ECS side of the Map stage: finds new scans, lends the touched chunk entities to
//! [`integrate_scan`], spawns the chunks a scan created, and keeps change detection exact.

use super::integrate::{ChunkAccess, HIT_NUDGE, ScanRays, integrate_scan};
use bevy_ecs::entity::EntityIndexSet;
use bevy_ecs::prelude::*;
use glam::{DVec3, IVec3};
use uavex_components::map::{
    ChunkCoord, ChunkIndex, ChunkStats, MapConfig, MapTotals, ScanCounter, StatSums, VoxelChunk,
    floor_to_key,
};
use uavex_components::sensor::{Scan, SensorId, SensorQuality};
use uavex_components::sim::{Outcome, RunEnd};

/// Inserts the map's resources (config, empty chunk index, zero totals, scan counter).
pub fn insert_map_resources(world: &mut World, config: MapConfig) {
    world.insert_resource(ChunkIndex::new(&config));
    world.insert_resource(MapTotals::default());
    world.insert_resource(ScanCounter::default());
    world.insert_resource(config);
}

/// Buffers kept between runs of [`integrate_scans`], so that the per-scan path does not
/// allocate after warm-up.
#[derive(Default)]
pub struct MappingScratch {
    pending: Vec<(SensorId, Entity)>,
    wanted: EntityIndexSet,
    /// Flat chunk index -> slot of the chunk in this run ([`NO_SLOT`] when not lent).
    slot_of: Vec<u32>,
    created: Vec<NewChunk>,
}

/// Integrates every sensor's new scan (a `Scan` whose `sequence` is newer than the last one
/// integrated) in [`SensorId`] order: with clamping, the order of updates matters, and a run
/// must not depend on ECS storage order.
///
/// Chunk data is reached without per-voxel ECS lookups: the chunks that may be touched (those
/// in the key box of each scan's rays) are borrowed once per run, written through
/// `bypass_change_detection`, and marked changed once if some voxel actually changed, so that
/// downstream `Changed<VoxelChunk>` (frontiers) sees exactly the chunks a scan changed. Chunks
/// created by a scan are spawned with Commands and registered in [`ChunkIndex`]. A scan that
/// cannot be integrated ends the run as failed (in [`RunEnd`]) with the reason.
#[allow(clippy::too_many_arguments)]
pub fn integrate_scans(
    mut commands: Commands,
    config: Res<MapConfig>,
    mut index: ResMut<ChunkIndex>,
    mut totals: ResMut<MapTotals>,
    mut counter: ResMut<ScanCounter>,
    mut run_end: ResMut<RunEnd>,
    sensors: Query<(Entity, &SensorId, &Scan, &SensorQuality), Changed<Scan>>,
    mut chunks: Query<(&ChunkCoord, &mut VoxelChunk, &mut ChunkStats)>,
    mut scratch: Local<MappingScratch>,
) {
    let scratch = &mut *scratch;
    scratch.pending.clear();
    for (entity, id, scan, _) in &sensors {
        if scan.sequence > counter.integrated_sequence(*id) {
            scratch.pending.push((*id, entity));
        }
    }
    if scratch.pending.is_empty() {
        return;
    }
    scratch.pending.sort_unstable();

    // Borrow every existing chunk a pending scan may touch.
    scratch.wanted.clear();
    for &(_, sensor) in &scratch.pending {
        let Ok((_, _, scan, _)) = sensors.get(sensor) else {
            continue;
        };
        if let Some((lo, hi)) = chunk_box(&config, scan) {
            for z in lo.z..=hi.z {
                for y in lo.y..=hi.y {
                    for x in lo.x..=hi.x {
                        if let Some(e) = index.get(ChunkCoord(IVec3::new(x, y, z))) {
                            scratch.wanted.insert(e);
                        }
                    }
                }
            }
        }
    }
    let grid = config.chunk_grid();
    scratch.slot_of.resize(grid.len(), NO_SLOT);
    let mut view = EcsChunks {
        config: &config,
        slot_of: &mut scratch.slot_of,
        existing: Vec::with_capacity(scratch.wanted.len()),
        created: &mut scratch.created,
    };
    for (coord, chunk, stats) in chunks.iter_many_unique_mut(&scratch.wanted).flatten() {
        if let Some(flat) = grid.flat(*coord) {
            view.lend(flat, chunk, stats);
        }
    }

    for &(id, sensor) in &scratch.pending {
        let Ok((_, _, scan, quality)) = sensors.get(sensor) else {
            continue;
        };
        counter.set_integrated_sequence(id, scan.sequence);
        let scan_id = counter.next_id();
        let result = config
            .increments(quality)
            .map_err(|e| e.to_string())
            .and_then(|increments| {
                integrate_scan(
                    &config,
                    scan_id,
                    ScanRays::of(scan),
                    increments,
                    &mut view,
                    &mut totals.0,
                )
                .map_err(|e| e.to_string())
            });
        if let Err(reason) = result
            && run_end.0.is_none()
        {
            run_end.0 = Some((
                Outcome::Failed,
                format!("mapping sensor {}: {reason}", id.0),
            ));
        }
    }
    view.finish(&mut commands, &mut index);
}

/// Chunks of the key box spanned by a scan's origin and endpoints (hit points nudged by at
/// most [`HIT_NUDGE`]), clipped to the map: every voxel the scan can touch lies inside, since
/// each ray's clipped segment lies inside the box of its two ends.
fn chunk_box(config: &MapConfig, scan: &Scan) -> Option<(IVec3, IVec3)> {
    // The box of the points, then in voxel units: the conversion (a division) is monotonic,
    // so this is the box of the converted points, at two conversions instead of one a point.
    let (lo, hi) = scan
        .endpoints
        .iter()
        .fold((scan.origin, scan.origin), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let (lo, hi) = (config.to_voxel_units(lo), config.to_voxel_units(hi));
    let margin = DVec3::splat(2.0 * HIT_NUDGE);
    let klo = floor_to_key(lo - margin).max(config.key_min());
    let khi = floor_to_key(hi + margin).min(config.key_max());
    if klo.cmpgt(khi).any() {
        return None;
    }
    Some((ChunkCoord::of_key(klo).0, ChunkCoord::of_key(khi).0))
}

const NO_SLOT: u32 = u32::MAX;
/// Marks a slot of a chunk created during this run (the low bits index `created`).
const CREATED: u32 = 1 << 31;

/// A chunk created by a scan of this run, spawned when the run ends.
struct NewChunk {
    flat: usize,
    coord: ChunkCoord,
    chunk: VoxelChunk,
    stats: StatSums,
}

/// An existing chunk entity lent to this run.
struct LentChunk<'w> {
    flat: usize,
    chunk: Mut<'w, VoxelChunk>,
    stats: Mut<'w, ChunkStats>,
    written: bool,
}

/// [`ChunkAccess`] over the chunks lent from the ECS plus those created during the run.
struct EcsChunks<'a, 'w> {
    config: &'a MapConfig,
    slot_of: &'a mut [u32],
    existing: Vec<LentChunk<'w>>,
    created: &'a mut Vec<NewChunk>,
}

impl<'w> EcsChunks<'_, 'w> {
    fn lend(&mut self, flat: usize, chunk: Mut<'w, VoxelChunk>, stats: Mut<'w, ChunkStats>) {
        self.slot_of[flat] = self.existing.len() as u32;
        self.existing.push(LentChunk {
            flat,
            chunk,
            stats,
            written: false,
        });
    }

    /// Marks written chunks changed, spawns and registers the created ones, and resets the
    /// slot table for the next run.
    fn finish(self, commands: &mut Commands, index: &mut ChunkIndex) {
        for mut lent in self.existing {
            self.slot_of[lent.flat] = NO_SLOT;
            if lent.written {
                lent.chunk.set_changed();
                lent.stats.set_changed();
            }
        }
        for new in self.created.drain(..) {
            self.slot_of[new.flat] = NO_SLOT;
            let entity = commands
                .spawn((new.coord, new.chunk, ChunkStats(new.stats)))
                .id();
            index.set_flat(new.flat, entity);
        }
    }

    /// A chunk created during this run, made now if it is not yet (the map update's walks
    /// ask for a chunk at every chunk they enter: the lent ones are the hot path).
    #[cold]
    #[inline(never)]
    fn created_mut(&mut self, flat: usize, coord: ChunkCoord) -> (&mut VoxelChunk, &mut StatSums) {
        let mut slot = self.slot_of[flat];
        if slot == NO_SLOT {
            slot = CREATED | self.created.len() as u32;
            self.slot_of[flat] = slot;
            self.created.push(NewChunk {
                flat,
                coord,
                chunk: VoxelChunk::in_map(coord, self.config.key_min(), self.config.key_max()),
                stats: StatSums::default(),
            });
        }
        let new = &mut self.created[(slot & !CREATED) as usize];
        (&mut new.chunk, &mut new.stats)
    }
}

impl ChunkAccess for EcsChunks<'_, '_> {
    #[inline]
    fn chunk_mut(&mut self, flat: usize, coord: ChunkCoord) -> (&mut VoxelChunk, &mut StatSums) {
        let slot = self.slot_of[flat];
        // `NO_SLOT` has the `CREATED` bit too: a chunk not lent is made or found apart.
        if slot & CREATED != 0 {
            return self.created_mut(flat, coord);
        }
        let lent = &mut self.existing[slot as usize];
        (
            lent.chunk.bypass_change_detection(),
            &mut lent.stats.bypass_change_detection().0,
        )
    }

    fn full_bricks(&self, flat: usize) -> u64 {
        let slot = self.slot_of[flat];
        let chunk = if slot == NO_SLOT {
            return 0;
        } else if slot & CREATED != 0 {
            &self.created[(slot & !CREATED) as usize].chunk
        } else {
            &*self.existing[slot as usize].chunk
        };
        chunk.saturation().full_bricks()
    }

    fn mark_written(&mut self, flat: usize) {
        let slot = self.slot_of[flat];
        if slot & CREATED == 0
            && let Some(lent) = self.existing.get_mut(slot as usize)
        {
            lent.written = true;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{ChunkStore, MapReader, OccupancyMap};
    use super::*;
    use bevy_ecs::system::RunSystemOnce;
    use glam::Vec3;
    use uavex_components::map::{LogOddsIncrements, MapSettings, StatSums};

    const ORIGIN: Vec3 = Vec3::new(0.05, 0.05, 0.05);

    fn config() -> MapConfig {
        MapConfig::new(&MapSettings {
            bounds_min: DVec3::splat(-3.2),
            bounds_max: DVec3::splat(3.2),
            ..MapSettings::default()
        })
        .unwrap()
    }

    /// Coordinates of the chunks `Changed<VoxelChunk>` reported after the last mapping run.
    #[derive(Resource, Default)]
    struct ChangedChunks(Vec<[i32; 3]>);

    fn record_changed(
        chunks: Query<&ChunkCoord, Changed<VoxelChunk>>,
        mut record: ResMut<ChangedChunks>,
    ) {
        record.0 = chunks.iter().map(|c| c.0.to_array()).collect();
        record.0.sort_unstable();
    }

    fn setup() -> (World, Schedule) {
        let mut world = World::new();
        insert_map_resources(&mut world, config());
        world.insert_resource(RunEnd::default());
        world.insert_resource(ChangedChunks::default());
        let mut schedule = Schedule::default();
        schedule.add_systems((integrate_scans, record_changed).chain());
        (world, schedule)
    }

    fn spawn_sensor(world: &mut World, id: u32) -> Entity {
        let quality = SensorQuality::from_probabilities(0.7, 0.4, 0.0);
        world.spawn((SensorId(id), Scan::default(), quality)).id()
    }

    /// Publishes a new sweep of `sensor` (as the sensing stage does).
    fn sweep(world: &mut World, sensor: Entity, rays: &[(Vec3, bool)]) {
        let mut scan = world.get_mut::<Scan>(sensor).unwrap();
        scan.origin = ORIGIN;
        scan.endpoints = rays.iter().map(|r| r.0).collect();
        scan.hit = rays.iter().map(|r| r.1).collect();
        scan.sequence += 1;
    }

    fn changed(world: &World) -> Vec<[i32; 3]> {
        world.resource::<ChangedChunks>().0.clone()
    }

    #[test]
    fn chunks_are_spawned_indexed_and_changed_exactly_when_written() {
        let (mut world, mut schedule) = setup();
        let sensor = spawn_sensor(&mut world, 0);
        // Keys 0..=19 free and 20 hit along x: chunks (0,0,0) and (1,0,0).
        let ray_x = (Vec3::new(2.05, 0.05, 0.05), true);
        sweep(&mut world, sensor, &[ray_x]);
        schedule.run(&mut world);
        assert_eq!(changed(&world), vec![[0, 0, 0], [1, 0, 0]]);
        let index = world.resource::<ChunkIndex>().clone();
        assert_eq!(index.len(), 2);
        for (coord, entity) in index.iter() {
            assert_eq!(world.get::<ChunkCoord>(entity), Some(&coord));
        }

        // Four more identical sweeps clamp every voxel of the ray (5 x 0.847 > 3.476,
        // 5 x 0.405 > 1.992); nothing new is spawned.
        for _ in 0..4 {
            sweep(&mut world, sensor, &[ray_x]);
            schedule.run(&mut world);
        }
        assert_eq!(world.resource::<ChunkIndex>().len(), 2);
        assert_eq!(
            world
                .resource::<ScanCounter>()
                .integrated_sequence(SensorId(0)),
            5
        );

        // The same ray again plus one along y inside chunk (0,0,0): (1,0,0) is visited but
        // unchanged (clamped), so only (0,0,0) is reported changed.
        let ray_y = (Vec3::new(0.05, 1.05, 0.05), true);
        sweep(&mut world, sensor, &[ray_x, ray_y]);
        schedule.run(&mut world);
        assert_eq!(changed(&world), vec![[0, 0, 0]]);

        // No new sweep: nothing integrated, nothing changed, even if the Scan is touched.
        let last = world.resource::<ScanCounter>().last_id();
        schedule.run(&mut world);
        assert_eq!(changed(&world), Vec::<[i32; 3]>::new());
        world.get_mut::<Scan>(sensor).unwrap().time_s += 1.0;
        schedule.run(&mut world);
        assert_eq!(changed(&world), Vec::<[i32; 3]>::new());
        assert_eq!(world.resource::<ScanCounter>().last_id(), last);

        // The ECS map equals the same scans integrated into a plain store, and the totals
        // equal the sum of the chunks' statistics.
        let mut store = ChunkStore::new(&config());
        let mut totals = StatSums::default();
        let mut counter = ScanCounter::default();
        let inc = LogOddsIncrements {
            hit: 847,
            miss: -405,
        };
        let mut rays = vec![vec![ray_x]; 5];
        rays.push(vec![ray_x, ray_y]);
        for scan in &rays {
            let endpoints: Vec<Vec3> = scan.iter().map(|r| r.0).collect();
            let hit: Vec<bool> = scan.iter().map(|r| r.1).collect();
            let r = ScanRays {
                origin: ORIGIN,
                endpoints: &endpoints,
                hit: &hit,
            };
            integrate_scan(
                &config(),
                counter.next_id(),
                r,
                inc,
                &mut store,
                &mut totals,
            )
            .unwrap();
        }
        let expected: Vec<(IVec3, f32)> = store.known_voxels().collect();
        let known = world
            .run_system_once(|map: MapReader| map.known_voxels().collect::<Vec<_>>())
            .unwrap();
        assert_eq!(known, expected);
        assert_eq!(known.len(), 21 + 10);
        assert_eq!(world.resource::<MapTotals>().0, totals);
        let mut sum = StatSums::default();
        for stats in world.query::<&ChunkStats>().iter(&world) {
            sum.add(&stats.0);
        }
        assert_eq!(sum, totals);
    }

    #[test]
    fn scans_of_one_tick_are_integrated_in_sensor_id_order() {
        let (mut world, mut schedule) = setup();
        // Spawned first, so ECS iteration meets it first; it must still go second.
        let a = spawn_sensor(&mut world, 1);
        let b = spawn_sensor(&mut world, 0);
        let hit_v = (Vec3::new(1.0, 0.05, 0.05), true); // ends in voxel (10, 0, 0)
        for _ in 0..5 {
            sweep(&mut world, a, &[hit_v]);
            schedule.run(&mut world);
        }
        let v = IVec3::new(10, 0, 0);
        let l = |world: &mut World| {
            world
                .run_system_once(move |map: MapReader| map.log_odds_milli(v))
                .unwrap()
        };
        assert_eq!(l(&mut world), Some(3476));
        // Same tick: a hits v again, b's max-range ray crosses v. In SensorId order b's miss
        // comes first (3476 - 405 = 3071) and a's hit clamps back to 3476; the other order
        // would leave 3071.
        sweep(&mut world, a, &[hit_v]);
        sweep(&mut world, b, &[(Vec3::new(1.55, 0.05, 0.05), false)]);
        schedule.run(&mut world);
        assert_eq!(l(&mut world), Some(3476));
    }

    #[test]
    fn a_bad_scan_fails_the_run_instead_of_panicking() {
        let (mut world, mut schedule) = setup();
        let sensor = spawn_sensor(&mut world, 4);
        sweep(&mut world, sensor, &[(Vec3::new(f32::NAN, 0.0, 0.0), true)]);
        schedule.run(&mut world);
        let end = world.resource::<RunEnd>().0.clone().unwrap();
        assert_eq!(end.0, Outcome::Failed);
        assert!(
            end.1
                .starts_with("mapping sensor 4: scan endpoint 0 is not finite"),
            "{}",
            end.1
        );
        assert!(world.resource::<ChunkIndex>().is_empty());
    }
}
