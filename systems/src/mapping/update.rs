//! The log-odds update of one voxel by one scan (common.md §1, OctoMap semantics).

use uavex_components::map::{
    BrickSaturation, ChunkCells, StatSums, StatTables, UNKNOWN_LOG_ODDS, brick_of,
};

/// How one scan changes the voxels it updates with one kind of measurement (hit or miss).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UpdateRule {
    /// The scan's stamp ([`uavex_components::map::ScanId::stamp`]).
    pub stamp: u16,
    /// Log-odds increment (milli units): the sensor's hit or miss value.
    pub delta: i32,
    /// Clamping bounds (milli units), map-wide.
    pub min: i32,
    pub max: i32,
}

/// What one update did to a voxel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VoxelChange {
    /// Nothing: already updated by this scan, or held at a clamping bound.
    None,
    /// The log-odds moved within the voxel's state (unknown, free, occupied).
    LogOdds,
    /// The voxel's state changed (it became known, or crossed l = 0).
    State,
}

impl VoxelChange {
    #[inline(always)]
    pub fn changed(self) -> bool {
        self != Self::None
    }

    #[inline(always)]
    pub fn state_changed(self) -> bool {
        self == Self::State
    }
}

/// Applies `rule` to voxel `index` of a chunk's `cells` unless this scan already updated it
/// (or it is saturated and `rule` a miss, which changes nothing):
/// stamps it, adds the increment to its log-odds (an unknown voxel starts from l = 0, p = 0.5),
/// clamps, and keeps in step `stats` (old value out, new value in), `saturation`, which voxels
/// are at the lower bound ([`BrickSaturation`]), and the cells' states by row
/// ([`uavex_components::map::ChunkRows`]).
#[inline(always)]
pub fn update_voxel(
    cells: &mut ChunkCells,
    index: usize,
    saturation: &mut BrickSaturation,
    rule: UpdateRule,
    tables: &StatTables,
    stats: &mut StatSums,
) -> VoxelChange {
    let voxel = cells.voxel_mut(index);
    // A saturated voxel is left as it is, unstamped, by a non-positive increment (a miss): it
    // cannot change, and any later visit of this scan finds it saturated again. (A brick
    // partly outside the frustum never fills, so a camera at rest walks many such voxels.)
    if rule.delta <= 0 && i32::from(voxel.log_odds) == rule.min {
        return VoxelChange::None;
    }
    if voxel.stamp == rule.stamp {
        return VoxelChange::None;
    }
    voxel.stamp = rule.stamp;
    let old = voxel.log_odds;
    let known = old != UNKNOWN_LOG_ODDS;
    let base = if known { i32::from(old) } else { 0 };
    let new = (base + rule.delta).clamp(rule.min, rule.max) as i16;
    if known {
        if new == old {
            return VoxelChange::None;
        }
        stats.remove_voxel(old, tables);
        if i32::from(old) == rule.min {
            saturation.remove(brick_of(index));
        }
    }
    stats.add_voxel(new, tables);
    if i32::from(new) == rule.min {
        saturation.add(brick_of(index));
    }
    voxel.log_odds = new;
    // States: unknown (not `known`), free (l < 0), occupied (l >= 0).
    if known && (old < 0) == (new < 0) {
        VoxelChange::LogOdds
    } else {
        cells.set_known(index, new >= 0);
        VoxelChange::State
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use uavex_components::map::{Voxel, VoxelChunk};

    const TABLES_MIN: i16 = -1992;
    const TABLES_MAX: i16 = 3476;
    /// The voxel probed: local index 7, in brick 1.
    const INDEX: usize = 7;

    fn rule(stamp: u16, delta: i32) -> UpdateRule {
        UpdateRule {
            stamp,
            delta,
            min: i32::from(TABLES_MIN),
            max: i32::from(TABLES_MAX),
        }
    }

    /// One voxel of a chunk under updates, with its chunk's statistics.
    struct Probe {
        chunk: VoxelChunk,
        tables: StatTables,
        stats: StatSums,
    }

    impl Probe {
        fn new(min: i16, max: i16) -> Self {
            Self {
                chunk: VoxelChunk::new(),
                tables: StatTables::new(min, max),
                stats: StatSums::default(),
            }
        }

        fn change(&mut self, rule: UpdateRule) -> VoxelChange {
            let (cells, saturation) = self.chunk.voxels_for_update();
            update_voxel(
                cells,
                INDEX,
                saturation,
                rule,
                &self.tables,
                &mut self.stats,
            )
        }

        fn update(&mut self, rule: UpdateRule) -> bool {
            self.change(rule).changed()
        }

        fn voxel(&self) -> Voxel {
            self.chunk.voxels()[INDEX]
        }

        fn saturated(&mut self) -> u8 {
            self.chunk.saturation().count(brick_of(INDEX))
        }
    }

    #[test]
    fn hits_and_misses_accumulate_and_clamp() {
        let mut p = Probe::new(TABLES_MIN, TABLES_MAX);
        // One hit from unknown: l = 0.847.
        assert!(p.update(rule(1, 847)));
        assert_eq!(p.voxel().log_odds, 847);
        assert_eq!(p.stats.counts, [0, 1]);
        // Same scan again: no second update.
        assert!(!p.update(rule(1, 847)));
        assert_eq!(p.voxel().log_odds, 847);
        // Hits in later scans: 1694, 2541, 3388, then clamped at 3.476 and stays there.
        for (stamp, expected) in [(2, 1694), (3, 2541), (4, 3388), (5, 3476)] {
            assert!(p.update(rule(stamp, 847)));
            assert_eq!(p.voxel().log_odds, expected);
        }
        assert!(!p.update(rule(6, 847)));
        assert_eq!(p.voxel().log_odds, 3476);
        // Misses bring it down: 3071, ..., crossing 0 to free, then clamped at -1.992.
        let mut l = 3476;
        let mut stamp = 7;
        while l > -1992 {
            l = (l - 405).max(-1992);
            assert!(p.update(rule(stamp, -405)));
            assert_eq!(p.voxel().log_odds, l);
            stamp += 1;
        }
        assert_eq!(p.voxel().log_odds, -1992);
        assert_eq!(p.saturated(), 1, "the voxel reached the lower bound once");
        // A further miss changes nothing; a hit takes it off the bound, and the count back.
        assert!(!p.update(rule(stamp, -405)));
        assert!(p.update(rule(stamp + 1, 847)));
        assert_eq!((p.voxel().log_odds, p.saturated()), (-1145, 0));
        for s in stamp + 2..stamp + 5 {
            assert!(p.update(rule(s, -405)));
        }
        assert_eq!((p.voxel().log_odds, p.saturated()), (-1992, 1));
        assert_eq!(p.stats.counts, [1, 0]);
        assert_eq!(p.stats.entropy[0], i64::from(p.tables.entry(-1992).entropy));
        assert_eq!(p.stats.entropy[1], 0);
    }

    #[test]
    fn state_changes_are_told_apart_from_log_odds_changes() {
        use VoxelChange::*;
        let mut p = Probe::new(TABLES_MIN, TABLES_MAX);
        // Unknown -> free (-405), free -> free (-810), then a hit crosses l = 0 (37).
        assert_eq!(p.change(rule(1, -405)), State);
        assert_eq!(p.change(rule(1, -405)), None, "same scan");
        assert_eq!(p.change(rule(2, -405)), LogOdds);
        assert_eq!(p.change(rule(3, 847)), State);
        assert_eq!(p.voxel().log_odds, 37);
        assert_eq!(p.change(rule(4, 847)), LogOdds, "884");
        assert_eq!(p.change(rule(5, -405)), LogOdds, "479");
        assert_eq!(p.change(rule(6, -405)), LogOdds, "74: still occupied");
        assert_eq!(p.change(rule(7, -405)), State, "-331: free");
        // Unknown -> occupied.
        let mut q = Probe::new(TABLES_MIN, TABLES_MAX);
        assert_eq!(q.change(rule(1, 847)), State);
    }

    #[test]
    fn a_miss_on_unknown_gives_free() {
        let mut p = Probe::new(TABLES_MIN, TABLES_MAX);
        assert!(p.update(rule(9, -405)));
        assert_eq!((p.voxel().log_odds, p.voxel().stamp), (-405, 9));
        assert_eq!(p.stats.counts, [1, 0]);
        assert_eq!(
            p.stats.uncertainty[0],
            i64::from(p.tables.entry(-405).uncertainty)
        );
        assert_eq!(p.saturated(), 0);
    }

    #[test]
    fn an_increment_beyond_the_clamp_is_clamped_from_unknown() {
        let mut p = Probe::new(-200, 300);
        let r = UpdateRule {
            stamp: 1,
            delta: 847,
            min: -200,
            max: 300,
        };
        assert!(p.update(r));
        assert_eq!(p.voxel().log_odds, 300);
        // A miss as large as the range saturates an unknown voxel at once.
        let mut q = Probe::new(-200, 300);
        assert!(q.update(UpdateRule { delta: -847, ..r }));
        assert_eq!((q.voxel().log_odds, q.saturated()), (-200, 1));
    }

    /// The row states the update keeps are those of the voxels, after every update of random
    /// scans of hits and misses over a few rows (states become known and cross l = 0 both
    /// ways), and after a hand write through `voxels_mut` once the map update writes again.
    #[test]
    fn row_states_follow_every_update() {
        use rand::{Rng, SeedableRng};
        use uavex_components::map::ChunkRows;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let tables = StatTables::new(TABLES_MIN, TABLES_MAX);
        let mut stats = StatSums::default();
        let mut chunk = VoxelChunk::new();
        let rows_of =
            |chunk: &VoxelChunk| -> Vec<_> { (0..256).map(|row| chunk.row_states(row)).collect() };
        let expected = |chunk: &VoxelChunk| -> Vec<_> {
            let rows = ChunkRows::of(chunk.voxels());
            (0..256).map(|row| rows.get(row)).collect()
        };
        let mut state_changes = 0;
        for stamp in 1..=60u16 {
            let rule = rule(stamp, if rng.random_bool(0.5) { 847 } else { -405 });
            for _ in 0..40 {
                // Rows 0..4 only, so that voxels see many scans.
                let index = rng.random_range(0..64);
                let (cells, saturation) = chunk.voxels_for_update();
                let change = update_voxel(cells, index, saturation, rule, &tables, &mut stats);
                state_changes += usize::from(change.state_changed());
                assert_eq!(rows_of(&chunk), expected(&chunk), "scan {stamp}");
            }
        }
        assert!(
            state_changes > 64,
            "states crossed l = 0: {state_changes} changes"
        );
        chunk.voxels_mut()[5].log_odds = UNKNOWN_LOG_ODDS;
        chunk.voxels_mut()[300].log_odds = 10;
        assert_eq!(rows_of(&chunk), expected(&chunk));
        let (cells, saturation) = chunk.voxels_for_update();
        update_voxel(cells, 6, saturation, rule(61, 847), &tables, &mut stats);
        assert_eq!(rows_of(&chunk), expected(&chunk));
        assert_eq!(chunk.row_states(0).unknown & 0b110_0000, 1 << 5);
    }
}
