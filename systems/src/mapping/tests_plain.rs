//! The map update against a plain one (common.md §1 applied voxel by voxel to every voxel a
//! ray crosses): whatever it skips (saturated cubes, free boxes around the sensor and beyond
//! it, runs of full bricks), the map is the same, voxel for voxel.

use super::dda::for_each_key;
use super::tests::{Mapper, OCTOMAP, config, floor_key};
use super::*;
use glam::{DVec3, IVec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeSet;
use uavex_components::map::{LogOddsIncrements, MapConfig, MapSettings, ScanCounter, StatSums};

/// The update with saturated cubes crossed in one move gives the same map, voxel for voxel,
/// as a plain reference that applies common.md §1 to every traversed voxel: hits first, then one
/// miss for every other voxel any ray crossed, each clamped. Scans from a small region over and
/// over (so that free space saturates and most of the walk is skipped), two sensor qualities.
/// The reference shares only the traversal (`for_each_key`, tested against sampling in `dda`).
#[test]
fn crossing_saturated_cubes_leaves_the_map_as_a_plain_update_would() {
    crossing_leaves_the_map_as_a_plain_update_would(config());
}

/// The same in a map whose border does not fall on chunk faces (keys -31..=29 on each axis):
/// the border chunks' voxels outside the map count as saturated, and rays reaching past the
/// border are cut there, inside cubes that hold outside voxels.
#[test]
fn crossing_saturated_cubes_at_a_border_inside_chunks_leaves_the_map_as_a_plain_update_would() {
    let config = MapConfig::new(&MapSettings {
        bounds_min: DVec3::splat(-3.05),
        bounds_max: DVec3::splat(2.95),
        ..MapSettings::default()
    })
    .unwrap();
    assert_eq!(
        (config.key_min(), config.key_max()),
        (IVec3::splat(-31), IVec3::splat(29))
    );
    crossing_leaves_the_map_as_a_plain_update_would(config);
}

fn crossing_leaves_the_map_as_a_plain_update_would(config: MapConfig) {
    let mut m = Mapper::with(config.clone());
    let mut reference = PlainMap::new(&config);
    // The same scans without the tallies, as the map update runs them.
    let mut untallied = ChunkStore::new(&config);
    let (mut untallied_totals, mut untallied_counter) =
        (StatSums::default(), ScanCounter::default());
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    let lidar = LogOddsIncrements {
        hit: 1386,
        miss: -847,
    };
    let (mut visits, mut skipped, mut cubes) = (0, 0, [0; 3]);
    let (mut box_rays, mut box_exits, mut ends_in_cubes, mut runs) = (0, 0, 0, 0);
    for scan in 0..310 {
        let rays: Vec<(Vec3, bool)>;
        let origin;
        if scan < 10 {
            // First, dense free scans from near the centre of chunk (0, 0, 0), [0, 1.6)^3 m,
            // reaching past its corners: they saturate the whole chunk.
            origin = Vec3::new(0.8 + rng.random_range(-0.05..0.05), 0.8, 0.8);
            rays = sphere_of_rays(origin, 8000, 1.5);
        } else {
            origin = Vec3::new(
                rng.random_range(-0.5..0.5),
                rng.random_range(-0.5..0.5),
                rng.random_range(-0.5..0.5),
            );
            // Surfaces 2.5 to 4 m away, free space (and max-range cuts) before them.
            rays = random_rays(&mut rng, origin, 80, 0.3, 0.0..2.5, 2.5..4.0);
        }
        let inc = if scan % 4 == 3 { lidar } else { OCTOMAP };
        let report = m.scan_with(origin, &rays, inc);
        let (endpoints, hit): (Vec<Vec3>, Vec<bool>) = rays.iter().copied().unzip();
        let plain_report = integrate_scan(
            &config,
            untallied_counter.next_id(),
            ScanRays {
                origin,
                endpoints: &endpoints,
                hit: &hit,
            },
            inc,
            &mut untallied,
            &mut untallied_totals,
        )
        .unwrap();
        assert_eq!(
            plain_report,
            ScanReport {
                rays: report.rays,
                voxel_visits: report.voxel_visits,
                changed_voxels: report.changed_voxels,
                ..ScanReport::default()
            },
            "scan {scan}: the untallied update reports the visits and changes alone"
        );
        visits += report.voxel_visits;
        skipped += report.skipped_voxels;
        box_rays += report.free_box_rays;
        box_exits += report.free_box_exits;
        ends_in_cubes += report.ends_in_cubes;
        runs += report.brick_runs;
        for (total, crossed) in cubes.iter_mut().zip(report.cubes_crossed) {
            *total += crossed;
        }
        reference.scan(origin, &rays, inc);
    }
    reference.assert_equals(&m.store);
    reference.assert_equals(&untallied);
    assert_eq!(untallied_totals, m.totals.0);
    // The skipping was exercised: a quarter of the work at least (far voxels, crossed by few
    // rays, rarely saturate here).
    assert!(
        skipped * 4 > visits,
        "{skipped} of {visits} voxel visits skipped"
    );
    // Every size of cube was crossed: bricks, blocks and whole chunks.
    assert!(cubes.iter().all(|&n| n > 0), "cubes crossed {cubes:?}");
    // Walks ended inside saturated cubes, the rest of their visits skipped.
    assert!(ends_in_cubes > 0, "no walk ended inside a saturated cube");
    // And scans from inside the saturated chunk had a free box: rays ended in it, others left
    // it in one move.
    assert!(
        box_rays > 0 && box_exits > 0,
        "free box: {box_rays} rays ended in it, {box_exits} left it"
    );
    // And walks went on along runs of full bricks past the boxes.
    assert!(runs > 5000, "{runs} runs of full bricks crossed");
}

/// The boxes beyond the faces of the sensor's free box (`free_box::FreeBoxes::grow`): in a
/// saturated ball whose few bricks that are not full stop the sensor's box early on every side,
/// walks go on into the boxes beyond, end in them or leave them, and the map is the one a plain
/// update gives.
#[test]
fn walks_through_the_boxes_beyond_leave_the_map_as_a_plain_update_would() {
    let config = config();
    let mut m = Mapper::with(config.clone());
    let mut reference = PlainMap::new(&config);
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let centre = Vec3::splat(0.05);
    let (mut beyond, mut runs) = (0, 0);
    for scan in 0..70 {
        let origin = centre + Vec3::from_array([0; 3].map(|_| rng.random_range(-0.04..0.04)));
        let rays = match scan {
            // A ball of free space 2.8 m in radius, saturated (five misses).
            0..6 => sphere_of_rays(origin, 12_000, 2.8),
            // A few surfaces 0.8 to 1.5 m away: their bricks are not full.
            6 => random_rays(&mut rng, origin, 12, 1.0, 0.8..1.5, 0.8..1.5),
            _ => random_rays(&mut rng, origin, 300, 0.3, 0.3..2.6, 1.0..2.6),
        };
        let report = m.scan(origin, &rays);
        if scan > 6 {
            beyond += report.free_box_beyond;
            runs += report.brick_runs;
        }
        reference.scan(origin, &rays, OCTOMAP);
    }
    reference.assert_equals(&m.store);
    assert!(
        beyond > 1000 && runs > 1000,
        "walks reached the boxes beyond {beyond} times, crossed {runs} runs of full bricks"
    );
}

/// `n` free rays of length `length` from `origin`, spread evenly over the sphere.
fn sphere_of_rays(origin: Vec3, n: usize, length: f32) -> Vec<(Vec3, bool)> {
    (0..n)
        .map(|i| (origin + fibonacci_direction(i, n) * length, false))
        .collect()
}

/// `n` rays from `origin` in random directions, each a hit with probability `hit_share`, at a
/// distance in `hits`, else free (cut at max range) at a distance in `free`.
fn random_rays(
    rng: &mut ChaCha8Rng,
    origin: Vec3,
    n: usize,
    hit_share: f64,
    free: std::ops::Range<f32>,
    hits: std::ops::Range<f32>,
) -> Vec<(Vec3, bool)> {
    (0..n)
        .map(|_| {
            let d = Vec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
            .normalize();
            let hit = rng.random_bool(hit_share);
            let range = if hit { hits.clone() } else { free.clone() };
            (origin + d * rng.random_range(range), hit)
        })
        .collect()
}

/// The map of common.md §1 kept plainly, voxel by voxel: per scan, a hit for every end voxel
/// and a miss for every other voxel any ray crossed, each clamped. It shares only the traversal
/// (`for_each_key`, tested against sampling in `dda`) with the map update.
struct PlainMap {
    config: MapConfig,
    log_odds: std::collections::HashMap<[i32; 3], i16>,
}

impl PlainMap {
    fn new(config: &MapConfig) -> Self {
        Self {
            config: config.clone(),
            log_odds: Default::default(),
        }
    }

    fn scan(&mut self, origin: Vec3, rays: &[(Vec3, bool)], inc: LogOddsIncrements) {
        let config = &self.config;
        let o = config.to_voxel_units(origin);
        let mut hits = BTreeSet::new();
        let mut misses = BTreeSet::new();
        for &(end, hit) in rays {
            let e = config.to_voxel_units(end);
            let target = if hit && e != o {
                e + (e - o).normalize() * 1e-3
            } else {
                e
            };
            let hit_key = floor_key(target);
            let exclude = hit && config.contains_key(hit_key);
            if exclude {
                hits.insert(hit_key.to_array());
            }
            for_each_key(o, target, config.key_min(), config.key_max(), |k| {
                if !(exclude && k == hit_key) {
                    misses.insert(k.to_array());
                }
            });
        }
        let (min, max) = (i32::from(config.clamp_min()), i32::from(config.clamp_max()));
        let mut apply = |key: [i32; 3], delta: i16| {
            let l = self.log_odds.entry(key).or_insert(0);
            *l = (i32::from(*l) + i32::from(delta)).clamp(min, max) as i16;
        };
        for &key in &hits {
            apply(key, inc.hit);
        }
        for &key in misses.difference(&hits) {
            apply(key, inc.miss);
        }
    }

    fn assert_equals(&self, store: &ChunkStore) {
        let known: std::collections::HashMap<[i32; 3], i16> = store
            .known_voxels()
            .map(|(k, l)| (k.to_array(), (l * 1000.0).round() as i16))
            .collect();
        assert_eq!(known.len(), self.log_odds.len());
        for (key, l) in &self.log_odds {
            assert_eq!(known.get(key), Some(l), "voxel {key:?}");
        }
    }
}

/// Direction `i` of `n` spread evenly over the sphere (a Fibonacci lattice).
fn fibonacci_direction(i: usize, n: usize) -> Vec3 {
    let z = 1.0 - (2.0 * i as f32 + 1.0) / n as f32;
    let r = (1.0 - z * z).sqrt();
    let azimuth = i as f32 * std::f32::consts::PI * (3.0 - 5.0_f32.sqrt());
    Vec3::new(r * azimuth.cos(), r * azimuth.sin(), z)
}
