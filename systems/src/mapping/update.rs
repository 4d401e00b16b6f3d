//! The log-odds update of one voxel by one scan (common.md §1, OctoMap semantics).

use uavex_components::map::{StatSums, StatTables, UNKNOWN_LOG_ODDS, Voxel};

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

/// Applies `rule` to `voxel` unless this scan already updated it: stamps it, adds the increment
/// to its log-odds (an unknown voxel starts from l = 0, p = 0.5), clamps, and keeps `stats` in
/// step (old value out, new value in). Returns whether the log-odds changed.
#[inline(always)]
pub fn update_voxel(
    voxel: &mut Voxel,
    rule: UpdateRule,
    tables: &StatTables,
    stats: &mut StatSums,
) -> bool {
    if voxel.stamp == rule.stamp {
        return false;
    }
    voxel.stamp = rule.stamp;
    let old = voxel.log_odds;
    let known = old != UNKNOWN_LOG_ODDS;
    let base = if known { i32::from(old) } else { 0 };
    let new = (base + rule.delta).clamp(rule.min, rule.max) as i16;
    if known {
        if new == old {
            return false;
        }
        stats.remove_voxel(old, tables);
    }
    stats.add_voxel(new, tables);
    voxel.log_odds = new;
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    const TABLES_MIN: i16 = -1992;
    const TABLES_MAX: i16 = 3476;

    fn rule(stamp: u16, delta: i32) -> UpdateRule {
        UpdateRule {
            stamp,
            delta,
            min: i32::from(TABLES_MIN),
            max: i32::from(TABLES_MAX),
        }
    }

    #[test]
    fn hits_and_misses_accumulate_and_clamp() {
        let tables = StatTables::new(TABLES_MIN, TABLES_MAX);
        let mut stats = StatSums::default();
        let mut v = Voxel::UNKNOWN;
        // One hit from unknown: l = 0.847.
        assert!(update_voxel(&mut v, rule(1, 847), &tables, &mut stats));
        assert_eq!(v.log_odds, 847);
        assert_eq!(stats.counts, [0, 1]);
        // Same scan again: no second update.
        assert!(!update_voxel(&mut v, rule(1, 847), &tables, &mut stats));
        assert_eq!(v.log_odds, 847);
        // Hits in later scans: 1694, 2541, 3388, then clamped at 3.476 and stays there.
        for (stamp, expected) in [(2, 1694), (3, 2541), (4, 3388), (5, 3476)] {
            assert!(update_voxel(&mut v, rule(stamp, 847), &tables, &mut stats));
            assert_eq!(v.log_odds, expected);
        }
        assert!(!update_voxel(&mut v, rule(6, 847), &tables, &mut stats));
        assert_eq!(v.log_odds, 3476);
        // Misses bring it down: 3071, ..., crossing 0 to free, then clamped at -1.992.
        let mut l = 3476;
        let mut stamp = 7;
        while l > -1992 {
            l = (l - 405).max(-1992);
            assert!(update_voxel(&mut v, rule(stamp, -405), &tables, &mut stats));
            assert_eq!(v.log_odds, l);
            stamp += 1;
        }
        assert_eq!(v.log_odds, -1992);
        assert_eq!(stats.counts, [1, 0]);
        assert_eq!(stats.entropy[0], i64::from(tables.entry(-1992).entropy));
        assert_eq!(stats.entropy[1], 0);
    }

    #[test]
    fn a_miss_on_unknown_gives_free() {
        let tables = StatTables::new(TABLES_MIN, TABLES_MAX);
        let mut stats = StatSums::default();
        let mut v = Voxel::UNKNOWN;
        assert!(update_voxel(&mut v, rule(9, -405), &tables, &mut stats));
        assert_eq!((v.log_odds, v.stamp), (-405, 9));
        assert_eq!(stats.counts, [1, 0]);
        assert_eq!(
            stats.uncertainty[0],
            i64::from(tables.entry(-405).uncertainty)
        );
    }

    #[test]
    fn an_increment_beyond_the_clamp_is_clamped_from_unknown() {
        let tables = StatTables::new(-200, 300);
        let mut stats = StatSums::default();
        let mut v = Voxel::UNKNOWN;
        let r = UpdateRule {
            stamp: 1,
            delta: 847,
            min: -200,
            max: 300,
        };
        assert!(update_voxel(&mut v, r, &tables, &mut stats));
        assert_eq!(v.log_odds, 300);
    }
}
