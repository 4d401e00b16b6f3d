//! Tests of scan integration over a plain [`ChunkStore`] (no World): log-odds semantics of
//! common.md §1 and exactness of the incremental statistics.

use super::dda::for_each_key;
use super::*;
use glam::{DVec3, IVec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeSet;
use uavex_components::map::{
    LogOddsIncrements, MapConfig, MapSettings, MapTotals, ScanCounter, StatSums, VoxelState,
};

pub(super) const OCTOMAP: LogOddsIncrements = LogOddsIncrements {
    hit: 847,
    miss: -405,
};

/// Integrates into `store` one scan from `origin` of the rays `(end, hit)` with the
/// increments `inc`, adding the change of the statistics to `totals`.
fn integrate_rays_with(
    store: &mut ChunkStore,
    counter: &mut ScanCounter,
    totals: &mut StatSums,
    (origin, rays): (Vec3, &[(Vec3, bool)]),
    inc: LogOddsIncrements,
) -> ScanReport {
    let (endpoints, hit): (Vec<Vec3>, Vec<bool>) = rays.iter().copied().unzip();
    let rays = ScanRays {
        origin,
        endpoints: &endpoints,
        hit: &hit,
    };
    let config = store.config().clone();
    integrate_scan_tallied(&config, counter.next_id(), rays, inc, store, totals).unwrap()
}

/// [`integrate_rays_with`] the OctoMap increments: a test of the consumers of the map update
/// (frontiers, traversability).
pub(crate) fn integrate_rays(
    store: &mut ChunkStore,
    counter: &mut ScanCounter,
    origin: Vec3,
    rays: &[(Vec3, bool)],
) {
    let mut totals = StatSums::default();
    integrate_rays_with(store, counter, &mut totals, (origin, rays), OCTOMAP);
}

/// [`integrate_rays`] with `rays` random rays (directions uniform in a cube, 0.2 to 4 m long,
/// half of them hits) from a random origin within `half_extent` m of 0 on each axis.
pub(crate) fn integrate_random_scan(
    store: &mut ChunkStore,
    counter: &mut ScanCounter,
    rng: &mut ChaCha8Rng,
    half_extent: f32,
    rays: usize,
) {
    let origin = Vec3::from_array([0; 3].map(|_| rng.random_range(-half_extent..half_extent)));
    let rays: Vec<(Vec3, bool)> = (0..rays)
        .map(|_| {
            let dir = Vec3::from_array([0; 3].map(|_| rng.random_range(-1.0..1.0)));
            let end = origin + dir.normalize_or(Vec3::X) * rng.random_range(0.2..4.0);
            (end, rng.random_bool(0.5))
        })
        .collect();
    integrate_rays(store, counter, origin, &rays);
}

/// Keys -32..=31 on each axis at 0.1 m: chunks -2..=1.
pub(super) fn config() -> MapConfig {
    MapConfig::new(&MapSettings {
        bounds_min: DVec3::splat(-3.2),
        bounds_max: DVec3::splat(3.2),
        ..MapSettings::default()
    })
    .unwrap()
}

/// A map, its totals and a scan counter, integrating scans one after the other.
pub(super) struct Mapper {
    config: MapConfig,
    pub(super) store: ChunkStore,
    pub(super) totals: MapTotals,
    counter: ScanCounter,
}

impl Mapper {
    fn new() -> Self {
        Self::with(config())
    }

    pub(super) fn with(config: MapConfig) -> Self {
        Self {
            store: ChunkStore::new(&config),
            config,
            totals: MapTotals::default(),
            counter: ScanCounter::default(),
        }
    }

    pub(super) fn scan_with(
        &mut self,
        origin: Vec3,
        rays: &[(Vec3, bool)],
        inc: LogOddsIncrements,
    ) -> ScanReport {
        integrate_rays_with(
            &mut self.store,
            &mut self.counter,
            &mut self.totals.0,
            (origin, rays),
            inc,
        )
    }

    pub(super) fn scan(&mut self, origin: Vec3, rays: &[(Vec3, bool)]) -> ScanReport {
        self.scan_with(origin, rays, OCTOMAP)
    }

    fn l(&self, x: i32, y: i32, z: i32) -> Option<i16> {
        self.store.log_odds_milli(IVec3::new(x, y, z))
    }

    fn state(&self, x: i32, y: i32, z: i32) -> VoxelState {
        self.store.state(IVec3::new(x, y, z))
    }
}

const ORIGIN: Vec3 = Vec3::new(0.05, 0.05, 0.05);

#[test]
fn one_hit_and_the_misses_before_it() {
    let mut m = Mapper::new();
    // The surface x = 1.0 m is the face between voxels 9 and 10: the hit lands in voxel 10.
    let report = m.scan(ORIGIN, &[(Vec3::new(1.0, 0.05, 0.05), true)]);
    assert_eq!(m.l(10, 0, 0), Some(847));
    for x in 0..10 {
        assert_eq!(m.l(x, 0, 0), Some(-405), "voxel {x}");
    }
    assert_eq!(m.l(11, 0, 0), None);
    assert_eq!(m.l(0, 1, 0), None);
    // p = 1 - 1 / (1 + e^0.847) = 0.699937.
    let p = m.store.probability(IVec3::new(10, 0, 0)).unwrap();
    assert!((p - 0.699937).abs() < 1e-6, "{p}");
    assert_eq!(report.rays, 1);
    assert_eq!(report.voxel_visits, 11);
    assert_eq!(report.changed_voxels, 11);
    // Approached from +x, the same face belongs to the obstacle's voxel 9.
    let mut m = Mapper::new();
    m.scan(
        Vec3::new(2.05, 0.05, 0.05),
        &[(Vec3::new(1.0, 0.05, 0.05), true)],
    );
    assert_eq!(m.l(9, 0, 0), Some(847));
    assert_eq!(m.l(10, 0, 0), Some(-405));
    assert_eq!(m.l(20, 0, 0), Some(-405));
}

#[test]
fn clamping_at_both_ends() {
    let mut m = Mapper::new();
    let ray = [(Vec3::new(1.0, 0.05, 0.05), true)];
    let mut expected_hit = 0;
    let mut expected_miss = 0;
    for _ in 0..7 {
        m.scan(ORIGIN, &ray);
        expected_hit = (expected_hit + 847).min(3476);
        expected_miss = (expected_miss - 405).max(-1992);
        assert_eq!(m.l(10, 0, 0), Some(expected_hit));
        assert_eq!(m.l(5, 0, 0), Some(expected_miss));
    }
    assert_eq!((m.l(10, 0, 0), m.l(5, 0, 0)), (Some(3476), Some(-1992)));
    // From the clamp, one miss moves it: 3476 - 405 (no memory of hits beyond the clamp).
    m.scan(
        Vec3::new(1.55, 0.05, 0.05),
        &[(Vec3::new(0.95, 0.05, 0.05), false)],
    );
    assert_eq!(m.l(10, 0, 0), Some(3071));
}

#[test]
fn occupied_wins_within_one_scan() {
    for reversed in [false, true] {
        let mut m = Mapper::new();
        // Ray a ends in voxel (5, 0, 0); ray b crosses it to end in voxel (12, 0, 0).
        let mut rays = vec![
            (Vec3::new(0.55, 0.05, 0.05), true),
            (Vec3::new(1.25, 0.05, 0.05), true),
        ];
        if reversed {
            rays.reverse();
        }
        m.scan(ORIGIN, &rays);
        assert_eq!(m.l(5, 0, 0), Some(847));
        assert_eq!(m.l(12, 0, 0), Some(847));
        assert_eq!(m.l(4, 0, 0), Some(-405));
        assert_eq!(m.l(6, 0, 0), Some(-405));
    }
}

#[test]
fn one_update_per_voxel_however_many_rays_cross_it() {
    let mut m = Mapper::new();
    // 200 rays fanning out from the origin; all cross the origin voxel, many share voxels near
    // it. Each voxel is updated once: every known voxel is exactly -405 or 847.
    let rays: Vec<(Vec3, bool)> = (0..200)
        .map(|i| {
            let a = i as f32 * 0.01;
            (ORIGIN + 2.0 * Vec3::new(a.cos(), a.sin(), 0.3), i % 3 != 0)
        })
        .collect();
    let report = m.scan(ORIGIN, &rays);
    assert_eq!(m.l(0, 0, 0), Some(-405));
    let known: Vec<_> = m.store.known_voxels().collect();
    assert!(known.iter().all(|&(_, l)| l == -0.405 || l == 0.847));
    assert_eq!(report.changed_voxels, known.len() as u64);
    assert!(report.voxel_visits > 3 * known.len() as u64);
}

#[test]
fn a_ray_cut_at_max_range_marks_free_space_only() {
    let mut m = Mapper::new();
    m.scan(ORIGIN, &[(Vec3::new(0.05, 0.75, 0.05), false)]);
    for y in 0..=7 {
        assert_eq!(m.state(0, y, 0), VoxelState::Free, "voxel y {y}");
    }
    assert_eq!(m.l(0, 7, 0), Some(-405));
    assert_eq!(m.state(0, 8, 0), VoxelState::Unknown);
    // A hit beyond the map: the ray leaves the box, its last voxel inside is free.
    let mut m = Mapper::new();
    m.scan(ORIGIN, &[(Vec3::new(0.05, 0.05, 9.0), true)]);
    assert_eq!(m.l(0, 0, 31), Some(-405));
    assert_eq!(m.store.known_voxels().count(), 32);
    // A hit exactly on the map's upper face lies outside (keys stop at 31): all free.
    let mut m = Mapper::new();
    m.scan(ORIGIN, &[(Vec3::new(0.05, 0.05, 3.2), true)]);
    assert_eq!(m.l(0, 0, 31), Some(-405));
}

#[test]
fn rays_from_outside_the_map_update_only_inside() {
    let mut m = Mapper::new();
    m.scan(
        Vec3::new(-5.0, 0.05, 0.05),
        &[(Vec3::new(-3.0, 0.05, 0.05), true)],
    );
    // Enters at x = -3.2 (key -32), hits in key -30 (-3.0 nudged inward).
    assert_eq!(m.l(-32, 0, 0), Some(-405));
    assert_eq!(m.l(-31, 0, 0), Some(-405));
    assert_eq!(m.l(-30, 0, 0), Some(847));
    assert_eq!(m.store.known_voxels().count(), 3);
    // Entirely outside: nothing.
    let mut m = Mapper::new();
    m.scan(
        Vec3::new(-5.0, 4.0, 0.0),
        &[(Vec3::new(5.0, 4.0, 0.0), true)],
    );
    assert_eq!(m.store.chunk_count(), 0);
}

#[test]
fn negative_coordinates_across_chunk_borders() {
    let mut m = Mapper::new();
    // -x from key 0: keys 0 (chunk 0), -1..=-16 (chunk -1), -17..=-20 free, hit at -2.0 m
    // nudged to key -21 (chunk -2).
    m.scan(
        Vec3::new(0.05, -0.05, 0.05),
        &[(Vec3::new(-2.0, -0.05, 0.05), true)],
    );
    for x in -20..=0 {
        assert_eq!(m.l(x, -1, 0), Some(-405), "voxel {x}");
    }
    assert_eq!(m.l(-21, -1, 0), Some(847));
    assert_eq!(m.l(-22, -1, 0), None);
    let written = m.store.take_written();
    let coords: Vec<IVec3> = written.iter().map(|c| c.0).collect();
    assert_eq!(
        coords,
        vec![
            IVec3::new(-2, -1, 0),
            IVec3::new(0, -1, 0),
            IVec3::new(-1, -1, 0)
        ]
    );
    assert!(m.store.take_written().is_empty());
}

#[test]
fn bad_scans_are_refused_before_writing() {
    let config = config();
    let mut store = ChunkStore::new(&config);
    let mut totals = StatSums::default();
    let mut counter = ScanCounter::default();
    let ends = [Vec3::ONE, Vec3::new(f32::NAN, 0.0, 0.0)];
    let mut run = |origin: Vec3, endpoints: &[Vec3], hit: &[bool]| {
        let rays = ScanRays {
            origin,
            endpoints,
            hit,
        };
        integrate_scan(
            &config,
            counter.next_id(),
            rays,
            OCTOMAP,
            &mut store,
            &mut totals,
        )
    };
    assert_eq!(
        run(ORIGIN, &ends[..1], &[true, false]),
        Err(ScanError::LengthMismatch {
            endpoints: 1,
            hits: 2
        })
    );
    assert!(matches!(
        run(ORIGIN, &ends, &[true, true]),
        Err(ScanError::NonFiniteEndpoint { index: 1, .. })
    ));
    assert!(matches!(
        run(Vec3::INFINITY, &ends[..1], &[true]),
        Err(ScanError::NonFiniteOrigin(_))
    ));
    assert_eq!(store.chunk_count(), 0);
    assert_eq!(totals, StatSums::default());
}

#[test]
fn accuracy_against_a_ground_truth() {
    let mut m = Mapper::new();
    m.scan(ORIGIN, &[(Vec3::new(1.0, 0.05, 0.05), true)]);
    // Truth: occupied for x >= 1.0 m (key 10): all 11 known voxels agree.
    assert_eq!(map_accuracy(&m.store, |k: IVec3| k.x >= 10), Some(1.0));
    assert_eq!(map_accuracy(&m.store, |_: IVec3| false), Some(10.0 / 11.0));
    assert_eq!(map_accuracy(&Mapper::new().store, |_: IVec3| true), None);
}

/// Against the world's obstacles, skipping the bricks the world says are open gives the
/// accuracy of asking every voxel.
#[test]
fn accuracy_against_the_world_skips_open_bricks_exactly() {
    use parry3d::math::Pose;
    use parry3d::shape::SharedShape;
    use uavex_components::world::{Obstacle, WorldGeometry};
    let geometry = WorldGeometry::new(vec![Obstacle::new(
        "box",
        "test",
        Pose::from_translation(Vec3::new(1.0, 1.0, 0.5)),
        SharedShape::cuboid(0.5, 0.7, 0.5),
    )])
    .unwrap();
    let mut store = ChunkStore::new(&config());
    let (mut counter, mut rng) = (ScanCounter::default(), ChaCha8Rng::seed_from_u64(3));
    for _ in 0..20 {
        integrate_random_scan(&mut store, &mut counter, &mut rng, 2.0, 200);
    }
    let resolution = 0.1;
    // The reference asks every known voxel.
    let (known, agree) = store.known_voxels().fold((0u64, 0u64), |(n, a), (key, l)| {
        let occupied = geometry.voxel_key_occupied(key, resolution);
        (n + 1, a + u64::from((l >= 0.0) == occupied))
    });
    let every_voxel = Some(agree as f64 / known as f64);
    let by_brick = map_accuracy(
        &store,
        WorldVoxels {
            geometry: &geometry,
            resolution,
        },
    );
    assert!(every_voxel.is_some_and(|a| a < 1.0));
    assert_eq!(by_brick, every_voxel);
}

/// After random scans (rays inside, leaving and entering the map, hits and max-range cuts,
/// two sensor qualities), every chunk's incremental statistics equal a recount from scratch,
/// the totals equal their sum, the written chunks are exactly those whose voxels changed, and
/// the metrics agree with a direct floating-point evaluation of common.md §5.
#[test]
fn incremental_statistics_equal_a_recount() {
    let mut m = Mapper::new();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let lidar = LogOddsIncrements {
        hit: 1386,
        miss: -847,
    };
    for scan in 0..60 {
        let origin = Vec3::new(
            rng.random_range(-3.0..3.0),
            rng.random_range(-3.0..3.0),
            rng.random_range(-3.0..3.0),
        );
        let rays: Vec<(Vec3, bool)> = (0..150)
            .map(|_| {
                let d = Vec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                (
                    origin + d * rng.random_range(0.0..4.0),
                    rng.random_bool(0.7),
                )
            })
            .collect();
        let before = m.store.clone();
        let inc = if scan % 4 == 3 { lidar } else { OCTOMAP };
        m.scan_with(origin, &rays, inc);

        let mut sum = StatSums::default();
        let mut changed = Vec::new();
        for (coord, chunk) in m.store.chunks() {
            let recount = StatSums::of_chunk(chunk, m.config.tables());
            assert_eq!(m.store.stats(coord), Some(&recount));
            sum.add(&recount);
            let old = before.chunk(coord);
            let differs = old.is_none_or(|old| {
                old.voxels()
                    .iter()
                    .zip(chunk.voxels().iter())
                    .any(|(a, b)| a.log_odds != b.log_odds)
            });
            if differs {
                changed.push(coord.0.to_array());
            }
        }
        assert_eq!(m.totals.0, sum);
        let mut written: Vec<_> = m
            .store
            .take_written()
            .iter()
            .map(|c| c.0.to_array())
            .collect();
        written.sort_unstable();
        changed.sort_unstable();
        assert_eq!(written, changed);
    }

    // Metrics against floating-point sums over the known voxels.
    let metrics = m.totals.metrics(&m.config);
    let (mut n, mut h, mut u) = (0.0, 0.0, 0.0);
    for (_, l) in m.store.known_voxels() {
        let p = 1.0 - 1.0 / (1.0 + f64::from(l).exp());
        n += 1.0;
        h += -p * p.log2() - (1.0 - p) * (1.0 - p).log2();
        u += (0.5 - (0.5 - p).abs()).powi(2);
    }
    let box_voxels = 64.0_f64.powi(3);
    assert_eq!(metrics.known_voxels as f64, n);
    assert!(n > 10_000.0);
    assert!((metrics.explored_fraction - n / box_voxels).abs() < 1e-12);
    assert!((metrics.mean_entropy_known.unwrap() - h / n).abs() < 1e-6);
    assert!((metrics.mean_entropy_box - (h + box_voxels - n) / box_voxels).abs() < 1e-6);
    let total_u = u + 0.25 * (box_voxels - n);
    assert!((metrics.uncertainty_total - total_u).abs() < 1e-3);
}

/// A one-ray scan updates exactly the voxels of the traversal (common.md §1): the DDA's voxels
/// of the clipped segment, minus the end voxel of a hit inside the map, plus that voxel as the
/// hit. Random rays inside and across the map, with ends on voxel boundaries (the last steps
/// then run in the counted tail of the walk) and off them.
#[test]
fn a_scan_updates_exactly_the_traversed_voxels() {
    let config = config();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for i in 0..600 {
        let mut point = |snap: bool| {
            let p = Vec3::new(
                rng.random_range(-4.0..4.0),
                rng.random_range(-4.0..4.0),
                rng.random_range(-4.0..4.0),
            );
            // Snap to the 0.1 m grid on some axes: ends exactly on voxel faces and edges.
            if snap { (p * 10.0).round() / 10.0 } else { p }
        };
        let origin = point(i % 5 == 0);
        let end = point(i % 3 != 0);
        let hit = i % 2 == 0;
        let mut m = Mapper::new();
        m.scan(origin, &[(end, hit)]);

        let (o, e) = (config.to_voxel_units(origin), config.to_voxel_units(end));
        let target = if hit && e != o {
            e + (e - o).normalize() * 1e-3
        } else {
            e
        };
        let mut expected = BTreeSet::new();
        for_each_key(o, target, config.key_min(), config.key_max(), |k| {
            expected.insert((k.to_array(), -405));
        });
        let hit_key = floor_key(target);
        if hit && config.contains_key(hit_key) {
            expected.retain(|(k, _)| *k != hit_key.to_array());
            expected.insert((hit_key.to_array(), 847));
        }
        let known: BTreeSet<([i32; 3], i16)> = m
            .store
            .known_voxels()
            .map(|(k, l)| (k.to_array(), (l * 1000.0).round() as i16))
            .collect();
        assert_eq!(known, expected, "ray {i}: {origin} -> {end}, hit {hit}");
    }
}

/// A walk that cannot leave its saturated brick before its end, yet ends past the brick's face
/// (within the end margin, where rounding is left to the counted walk), still updates its end
/// voxel: only a walk whose end lies inside the cube is cut short
/// (`super::cube::CubeMove::EndsInside`).
#[test]
fn a_walk_ending_just_past_a_saturated_brick_updates_its_end_voxel() {
    let mut m = Mapper::new();
    // Saturate bricks (0, 0, 0) and (1, 0, 0): keys x 0..8, y and z 0..4, a max-range ray to
    // each voxel's centre, six times (five misses reach the lower bound).
    let origin = Vec3::splat(0.15);
    let centres: Vec<(Vec3, bool)> = (0..8)
        .flat_map(|x| (0..4).flat_map(move |y| (0..4).map(move |z| IVec3::new(x, y, z))))
        .map(|k| ((k.as_vec3() + 0.5) * 0.1, false))
        .collect();
    for _ in 0..6 {
        m.scan(origin, &centres);
    }
    assert_eq!(m.l(7, 3, 3), Some(-1992));
    assert_eq!(m.l(8, 1, 1), None);
    // A ray along x ending one f32 step past x = 0.8 m, the face to key 8 (unknown): the face
    // comes within 1e-6 of the segment's end.
    let end = Vec3::new(f32::from_bits(0.8_f32.to_bits() + 1), 0.15, 0.15);
    m.scan(origin, &[(end, false)]);
    assert_eq!(m.l(8, 1, 1), Some(-405));
}

/// The key of a point in voxel units, as the map update computes it.
pub(super) fn floor_key(q: DVec3) -> IVec3 {
    q.floor().as_ivec3()
}
