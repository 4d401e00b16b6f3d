//! Voxel chunks: fixed 16^3 blocks of voxels, each one ECS entity (common.md §1, "Chunks").

use super::rows::{ChunkRows, RowStates};
use super::saturation::BrickSaturation;
use bevy_ecs::prelude::*;
use glam::IVec3;

/// Voxels along each edge of a chunk.
pub const CHUNK_EDGE: i32 = 1 << CHUNK_SHIFT;
/// log2 of [`CHUNK_EDGE`]: chunk addressing is an arithmetic shift (which rounds towards -inf,
/// i.e. `div_euclid(16)`) and a mask (`rem_euclid(16)`), without branches.
const CHUNK_SHIFT: i32 = 4;
const CHUNK_MASK: i32 = CHUNK_EDGE - 1;
/// Voxels in one chunk (16^3).
pub const CHUNK_VOXELS: usize = 4096;

/// Stored log-odds of a voxel never observed. It lies below every clamped value, so it can
/// never be produced by an update.
pub const UNKNOWN_LOG_ODDS: i16 = i16::MIN;

/// Position of a chunk in the chunk grid: `key.div_euclid(16)` of any voxel key in it.
#[derive(Component, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ChunkCoord(pub IVec3);

impl ChunkCoord {
    /// The chunk holding voxel `key` (negative keys round towards -inf: key -1 is in chunk -1).
    #[inline]
    pub fn of_key(key: IVec3) -> Self {
        Self(key >> CHUNK_SHIFT)
    }

    /// Key of the chunk's voxel with local coordinates (0, 0, 0).
    #[inline]
    pub fn first_key(self) -> IVec3 {
        self.0 * CHUNK_EDGE
    }
}

/// Index of voxel `key` inside its chunk: `x + 16 (y + 16 z)` of `key.rem_euclid(16)`.
#[inline]
pub fn local_index(key: IVec3) -> usize {
    let l = key & CHUNK_MASK;
    (l.x | (l.y << CHUNK_SHIFT) | (l.z << (2 * CHUNK_SHIFT))) as usize
}

/// Key of the voxel at local index `index` (0..4096) of chunk `coord`; inverse of
/// [`local_index`] and [`ChunkCoord::of_key`].
#[inline]
pub fn local_key(coord: ChunkCoord, index: usize) -> IVec3 {
    let i = (index % CHUNK_VOXELS) as i32;
    coord.first_key() + IVec3::new(i % CHUNK_EDGE, (i / CHUNK_EDGE) % CHUNK_EDGE, i / 256)
}

/// What the map knows about a voxel (common.md §1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum VoxelState {
    /// Never observed.
    Unknown,
    /// Observed, log-odds < 0 (p < 0.5).
    Free,
    /// Observed, log-odds >= 0 (p >= 0.5).
    Occupied,
}

impl VoxelState {
    /// State of a stored log-odds value (milli units, [`UNKNOWN_LOG_ODDS`] for unknown).
    #[inline]
    pub fn of_milli(log_odds: i16) -> Self {
        if log_odds == UNKNOWN_LOG_ODDS {
            Self::Unknown
        } else if log_odds >= 0 {
            Self::Occupied
        } else {
            Self::Free
        }
    }
}

/// Identity of one integrated scan. Its low 16 bits are the per-voxel stamp (never 0) and the
/// bits above are the epoch a chunk's stamps belong to; see [`VoxelChunk::begin_scan`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ScanId(u64);

impl ScanId {
    /// The scan after `previous` (ids whose stamp would be 0 are skipped, since 0 is the value
    /// stamps are cleared to).
    pub fn after(previous: Option<ScanId>) -> Self {
        let mut id = previous.map_or(1, |p| p.0.wrapping_add(1));
        if id & 0xFFFF == 0 {
            id = id.wrapping_add(1);
        }
        Self(id)
    }

    pub fn raw(self) -> u64 {
        self.0
    }

    /// Stamp written into each voxel this scan updates; never 0.
    #[inline]
    pub fn stamp(self) -> u16 {
        self.0 as u16
    }

    /// Epoch of the stamp: a chunk's stamps are only meaningful for scans of its epoch.
    #[inline]
    pub fn epoch(self) -> u32 {
        (self.0 >> 16) as u32
    }
}

/// One voxel: its log-odds and the stamp of the last scan that updated it.
///
/// Log-odds are **fixed point in milli-log-odds** (0.847 -> 847), [`UNKNOWN_LOG_ODDS`] when
/// unknown. Why fixed point:
/// - the per-chunk statistics (entropy, uncertainty) are kept incrementally by subtracting the
///   old and adding the new voxel's value from lookup tables indexed by the quantised log-odds,
///   which stays exact (integer sums never drift) only if the log-odds are exact integers;
/// - 4 bytes per voxel with the stamp, so a chunk is 16 KiB and the ray traversal stays in cache.
///
/// Each increment and each clamping bound is rounded to the nearest 0.001, an error below 5e-4
/// per update, far below anything a sensor model distinguishes (OctoMap's own p_hit = 0.7 is a
/// guess to one digit). Exports convert back to f32 with [`super::milli_to_log_odds`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(C)]
pub struct Voxel {
    pub log_odds: i16,
    pub stamp: u16,
}

impl Voxel {
    pub const UNKNOWN: Voxel = Voxel {
        log_odds: UNKNOWN_LOG_ODDS,
        stamp: 0,
    };

    #[inline]
    pub fn state(self) -> VoxelState {
        VoxelState::of_milli(self.log_odds)
    }

    /// Never observed (`state() == Unknown`, as one compare).
    #[inline]
    pub fn is_unknown(self) -> bool {
        self.log_odds == UNKNOWN_LOG_ODDS
    }

    /// Known with l < 0 (`state() == Free`).
    #[inline]
    pub fn is_free(self) -> bool {
        self.log_odds < 0 && !self.is_unknown()
    }

    /// Known with l >= 0 (`state() == Occupied`; the unknown marker is negative).
    #[inline]
    pub fn is_occupied(self) -> bool {
        self.log_odds >= 0
    }
}

/// The voxels of one chunk, indexed by [`local_index`], plus the stamp epoch and, per brick,
/// how many of its voxels are saturated free.
///
/// One scan updates each voxel at most once (common.md §1): the update stamps the voxel with the
/// scan's [`ScanId::stamp`] and skips voxels already stamped. Stamps are valid only while
/// `epoch == scan.epoch()`; the first touch in a new epoch clears them (once every 65,535 scans
/// per chunk), so no per-scan clearing or sorting is ever needed.
///
/// **Saturation.** A miss cannot change a voxel already at the lower clamping bound, so the map
/// update crosses saturated bricks (and blocks and chunks of them) without visiting their
/// voxels ([`BrickSaturation`]). The map update keeps the counts
/// ([`Self::voxels_for_update`]); writes through [`Self::voxels_mut`] forget them.
///
/// **State version.** Most updates only move a voxel's log-odds within its state (a free voxel
/// seen free again); frontiers and traversability depend on the states alone (unknown, free,
/// occupied). [`Self::state_version`] changes whenever some voxel's state may have changed (the
/// map update bumps it when one did, a write through [`Self::voxels_mut`] always), so such
/// consumers skip chunks that are `Changed` but whose states are not
/// (`uavex_systems::mapping::StateChanges`). The chunk also remembers *where* the last scan
/// that changed states here changed them ([`Self::state_changed_bricks_since`]), so that they
/// re-examine only the neighbours those bricks can reach.
///
/// **Row states.** The states of the voxels by x-row ([`Self::row_states`]), which frontiers
/// and traversability read by the thousand, are kept as bits beside the voxels
/// ([`ChunkCells`], the `rows` module): the map update sets a voxel's bits when it changes its
/// state; after a write through [`Self::voxels_mut`] rows are read from the voxels until the
/// map update's next write rebuilds them.
#[derive(Component, Debug, Clone)]
pub struct VoxelChunk {
    cells: Box<ChunkCells>,
    epoch: u32,
    saturation: BrickSaturation,
    state_version: u32,
    state_log: StateLog,
    /// A write through [`Self::voxels_mut`] left the cells' rows behind: rows are read from
    /// the voxels until the map update's next write rebuilds them.
    rows_stale: bool,
}

/// A chunk's voxels and their states by row, in one allocation: the map update reaches the
/// rows at a fixed offset from the voxels it writes (no pointer more to keep in its walk,
/// whose every register counts).
#[derive(Debug, Clone)]
pub struct ChunkCells {
    voxels: [Voxel; CHUNK_VOXELS],
    rows: ChunkRows,
}

impl ChunkCells {
    /// Voxel `index` (a local index, taken modulo [`CHUNK_VOXELS`]).
    #[inline(always)]
    pub fn voxel_mut(&mut self, index: usize) -> &mut Voxel {
        &mut self.voxels[index % CHUNK_VOXELS]
    }

    /// Voxel `index` now holds the state `occupied` (or free, if not): see
    /// [`ChunkRows::set_known`].
    #[inline(always)]
    pub fn set_known(&mut self, index: usize, occupied: bool) {
        self.rows.set_known(index, occupied);
    }
}

/// Equal voxels, stamps, saturation and state history; the row states follow from the voxels.
impl PartialEq for VoxelChunk {
    fn eq(&self, other: &Self) -> bool {
        self.cells.voxels == other.cells.voxels
            && self.epoch == other.epoch
            && self.saturation == other.saturation
            && self.state_version == other.state_version
            && self.state_log == other.state_log
    }
}

impl Eq for VoxelChunk {}

/// The bricks (bit `b` for brick `b`, as [`super::brick_of`] numbers them) in which the scan
/// `scan` (a raw [`ScanId`], 0 for none) changed voxel states, and the state version before its
/// first change here.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct StateLog {
    scan: u64,
    base: u32,
    bricks: u64,
}

impl Default for VoxelChunk {
    fn default() -> Self {
        Self::new()
    }
}

impl VoxelChunk {
    /// A chunk of unknown voxels.
    pub fn new() -> Self {
        Self {
            cells: Box::new(ChunkCells {
                voxels: [Voxel::UNKNOWN; CHUNK_VOXELS],
                rows: ChunkRows::UNKNOWN,
            }),
            epoch: 0,
            saturation: BrickSaturation::NONE,
            state_version: 0,
            state_log: StateLog::default(),
            rows_stale: false,
        }
    }

    /// A chunk of unknown voxels at `coord` in a map of keys `key_min..=key_max`: its voxels
    /// outside the map count as saturated ([`BrickSaturation::outside`]). The map update
    /// makes its chunks this way.
    pub fn in_map(coord: ChunkCoord, key_min: IVec3, key_max: IVec3) -> Self {
        let first = coord.first_key();
        Self {
            saturation: BrickSaturation::outside(
                (key_min - first).to_array(),
                (key_max - first).to_array(),
            ),
            ..Self::new()
        }
    }

    #[inline]
    pub fn voxels(&self) -> &[Voxel; CHUNK_VOXELS] {
        &self.cells.voxels
    }

    /// Mutable voxels, for tools and tests that write a map by hand. Forgets the saturation
    /// counts (they stay a lower bound whatever is written) and the row states (read from the
    /// voxels until the map update writes again), and bumps the state version (any state may
    /// change); the map update uses [`Self::voxels_for_update`] instead.
    #[inline]
    pub fn voxels_mut(&mut self) -> &mut [Voxel; CHUNK_VOXELS] {
        self.saturation.forget();
        self.note_state_change();
        self.rows_stale = true;
        &mut self.cells.voxels
    }

    /// A counter that changes whenever some voxel's state may have changed (see the type's
    /// documentation); equal versions mean equal states.
    #[inline]
    pub fn state_version(&self) -> u32 {
        self.state_version
    }

    /// Records that some voxel's state may have changed, anywhere in the chunk.
    #[inline]
    pub fn note_state_change(&mut self) {
        self.note_state_changes_in(ScanId(0), u64::MAX);
    }

    /// Records that scan `scan` changed the states of voxels in `bricks` (a set of brick bits;
    /// the map update calls it after writing through [`Self::voxels_for_update`], once
    /// per visit of the chunk).
    #[inline]
    pub fn note_state_changes_in(&mut self, scan: ScanId, bricks: u64) {
        if bricks == 0 {
            return;
        }
        if self.state_log.scan != scan.0 || scan.0 == 0 {
            self.state_log = StateLog {
                scan: scan.0,
                base: self.state_version,
                bricks: 0,
            };
        }
        self.state_log.bricks |= bricks;
        self.state_version = self.state_version.wrapping_add(1);
    }

    /// The bricks in which voxel states may have changed since the chunk's state version was
    /// `seen`: none if it still is; the last scan's bricks if `seen` is the version that scan
    /// started from (a consumer that looks after every scan); otherwise, or for a consumer that
    /// never saw the chunk (`None`), all of them.
    #[inline]
    pub fn state_changed_bricks_since(&self, seen: Option<u32>) -> u64 {
        match seen {
            Some(seen) if seen == self.state_version => 0,
            Some(seen) if seen == self.state_log.base => self.state_log.bricks,
            _ => u64::MAX,
        }
    }

    /// Mutable voxels with their row states, and the saturation of their bricks, for the map
    /// update, which keeps the rows, the counts (and [`super::ChunkStats`]) in step with every
    /// write.
    #[inline]
    pub fn voxels_for_update(&mut self) -> (&mut ChunkCells, &mut BrickSaturation) {
        if std::mem::take(&mut self.rows_stale) {
            self.cells.rows = ChunkRows::of(&self.cells.voxels);
        }
        (&mut self.cells, &mut self.saturation)
    }

    /// Which bricks are saturated free.
    #[inline]
    pub fn saturation(&self) -> &BrickSaturation {
        &self.saturation
    }

    /// Bit x of the voxel (x, y, z) for which `pred` holds, in the x-row `row = y + 16 z`
    /// (local indices `16 row ..= 16 row + 15`): one row as a machine word, for the consumers
    /// that work on 16 voxels at a time (frontiers, traversability).
    #[inline]
    pub fn row_bits(&self, row: usize, pred: impl Fn(Voxel) -> bool) -> u16 {
        let start = (row * CHUNK_EDGE as usize) % CHUNK_VOXELS;
        self.cells.voxels[start..start + CHUNK_EDGE as usize]
            .iter()
            .enumerate()
            .fold(0u16, |bits, (x, &v)| bits | (u16::from(pred(v)) << x))
    }

    /// The states of the voxels of row `row` (as [`Self::row_bits`]), kept as bits by the map
    /// update (the `rows` module).
    #[inline]
    pub fn row_states(&self, row: usize) -> RowStates {
        if self.rows_stale {
            let start = (row * CHUNK_EDGE as usize) % CHUNK_VOXELS;
            RowStates::of(&self.cells.voxels[start..start + CHUNK_EDGE as usize])
        } else {
            self.cells.rows.get(row)
        }
    }

    /// Stored log-odds (milli units) at local index `index`.
    #[inline]
    pub fn log_odds_milli(&self, index: usize) -> i16 {
        self.cells.voxels[index % CHUNK_VOXELS].log_odds
    }

    #[inline]
    pub fn state(&self, index: usize) -> VoxelState {
        VoxelState::of_milli(self.log_odds_milli(index))
    }

    pub fn epoch(&self) -> u32 {
        self.epoch
    }

    /// Makes the stamps valid for `scan`: on the first touch in a new epoch, clears them.
    #[inline]
    pub fn begin_scan(&mut self, scan: ScanId) {
        if self.epoch != scan.epoch() {
            self.epoch = scan.epoch();
            for voxel in self.cells.voxels.iter_mut() {
                voxel.stamp = 0;
            }
        }
    }

    /// Number of voxels that are not unknown.
    pub fn known_count(&self) -> usize {
        self.cells
            .voxels
            .iter()
            .filter(|v| v.log_odds != UNKNOWN_LOG_ODDS)
            .count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::BRICK_VOXELS;

    /// The one-compare state predicates agree with `state()` on every log-odds value.
    #[test]
    fn state_predicates_agree_with_the_state() {
        for log_odds in i16::MIN..=i16::MAX {
            let v = Voxel { log_odds, stamp: 0 };
            let state = v.state();
            assert_eq!(v.is_unknown(), state == VoxelState::Unknown, "{log_odds}");
            assert_eq!(v.is_free(), state == VoxelState::Free, "{log_odds}");
            assert_eq!(v.is_occupied(), state == VoxelState::Occupied, "{log_odds}");
        }
    }

    /// Row bits hold bit x for voxel x of the row: every 16-bit pattern of a predicate, each
    /// written into row `pattern % 256`.
    #[test]
    fn row_bits_hold_bit_x_for_voxel_x_of_the_row() {
        let mut chunk = VoxelChunk::new();
        for pattern in 0..=u16::MAX {
            let row = usize::from(pattern) % 256;
            for x in 0..16 {
                let index = row * 16 + x;
                chunk.voxels_mut()[index].log_odds = if pattern >> x & 1 == 1 { 100 } else { -100 };
            }
            let bits = chunk.row_bits(row, |v| v.log_odds > 0);
            assert_eq!(bits, pattern, "row {row}");
        }
    }

    /// Row states agree with the voxel predicates on every state pattern of a row.
    #[test]
    fn row_states_agree_with_the_voxel_predicates() {
        let mut chunk = VoxelChunk::new();
        let values = [UNKNOWN_LOG_ODDS, -1992, -1, 0, 847];
        for pattern in 0..5u32.pow(6) {
            let row = pattern as usize % 256;
            for x in 0..16 {
                let value = values[(pattern / 5u32.pow(x as u32 % 6)) as usize % 5];
                chunk.voxels_mut()[row * 16 + x].log_odds = value;
            }
            let states = chunk.row_states(row);
            assert_eq!(states.unknown, chunk.row_bits(row, Voxel::is_unknown));
            assert_eq!(states.occupied, chunk.row_bits(row, Voxel::is_occupied));
            assert_eq!(states.free(), chunk.row_bits(row, Voxel::is_free));
        }
    }

    #[test]
    fn negative_keys_address_the_chunk_below() {
        // key -1 lies in chunk -1 at local 15; key -16 in chunk -1 at local 0; -17 in chunk -2.
        assert_eq!(
            ChunkCoord::of_key(IVec3::new(-1, 0, 0)).0,
            IVec3::new(-1, 0, 0)
        );
        assert_eq!(local_index(IVec3::new(-1, 0, 0)), 15);
        assert_eq!(ChunkCoord::of_key(IVec3::splat(-16)).0, IVec3::splat(-1));
        assert_eq!(local_index(IVec3::splat(-16)), 0);
        assert_eq!(
            ChunkCoord::of_key(IVec3::new(-17, 0, 0)).0,
            IVec3::new(-2, 0, 0)
        );
        assert_eq!(local_index(IVec3::new(-17, 0, 0)), 15);
        // (-1, -1, -1) is the last voxel of chunk (-1, -1, -1): 15 + 16 (15 + 16 * 15) = 4095.
        assert_eq!(local_index(IVec3::splat(-1)), 4095);
        // chunk borders on the positive side: 15 -> chunk 0, 16 -> chunk 1 local 0.
        assert_eq!(ChunkCoord::of_key(IVec3::new(0, 15, 0)).0, IVec3::ZERO);
        assert_eq!(local_index(IVec3::new(0, 15, 0)), 240);
        assert_eq!(
            ChunkCoord::of_key(IVec3::new(0, 0, 16)).0,
            IVec3::new(0, 0, 1)
        );
        assert_eq!(local_index(IVec3::new(3, 2, 17)), 3 + 16 * (2 + 16));
    }

    #[test]
    fn shifts_agree_with_euclidean_division() {
        for k in -100..100 {
            let key = IVec3::new(k, -k, 3 * k);
            let edge = IVec3::splat(CHUNK_EDGE);
            assert_eq!(ChunkCoord::of_key(key).0, key.div_euclid(edge));
            let l = key.rem_euclid(edge);
            assert_eq!(local_index(key), (l.x + 16 * (l.y + 16 * l.z)) as usize);
        }
    }

    #[test]
    fn local_key_inverts_local_index() {
        for key in [
            IVec3::new(-1, -16, -17),
            IVec3::new(0, 15, 16),
            IVec3::new(-33, 47, 5),
            IVec3::new(1000, -1000, 7),
        ] {
            let coord = ChunkCoord::of_key(key);
            assert_eq!(local_key(coord, local_index(key)), key);
        }
    }

    #[test]
    fn scan_ids_never_stamp_zero() {
        let first = ScanId::after(None);
        assert_eq!((first.stamp(), first.epoch()), (1, 0));
        let last_of_epoch = ScanId(0xFFFF);
        let next = ScanId::after(Some(last_of_epoch));
        assert_eq!(next.raw(), 0x1_0001);
        assert_eq!((next.stamp(), next.epoch()), (1, 1));
    }

    #[test]
    fn a_new_epoch_clears_the_stamps_once() {
        let mut chunk = VoxelChunk::new();
        let scan = ScanId(0x2_0005);
        chunk.begin_scan(scan);
        chunk.voxels_mut()[7].stamp = scan.stamp();
        // Same epoch: the stamp survives.
        chunk.begin_scan(ScanId(0x2_0006));
        assert_eq!(chunk.voxels()[7].stamp, 5);
        // Next epoch: cleared, so stamp 5 of epoch 3 is not mistaken for "already updated".
        chunk.begin_scan(ScanId(0x3_0005));
        assert_eq!(chunk.voxels()[7].stamp, 0);
        assert_eq!(chunk.epoch(), 3);
    }

    #[test]
    fn writing_voxels_by_hand_forgets_saturation_and_bumps_the_state_version() {
        let mut chunk = VoxelChunk::new();
        let saturation = chunk.voxels_for_update().1;
        for _ in 0..BRICK_VOXELS {
            saturation.add(3);
        }
        assert!(chunk.saturation().brick_full(3));
        let version = chunk.state_version();
        chunk.voxels_mut()[0].log_odds = 100;
        assert!(!chunk.saturation().brick_full(3));
        assert_ne!(chunk.state_version(), version);
    }

    #[test]
    fn the_state_log_keeps_the_last_scans_bricks_and_falls_back_to_all() {
        let mut chunk = VoxelChunk::new();
        let v0 = chunk.state_version();
        assert_eq!(chunk.state_changed_bricks_since(Some(v0)), 0);
        assert_eq!(chunk.state_changed_bricks_since(None), u64::MAX);
        // One scan, two visits: their union, for a consumer that saw the version before it.
        let scan = ScanId::after(None);
        chunk.note_state_changes_in(scan, 1 << 3);
        chunk.note_state_changes_in(scan, 1 << 40);
        chunk.note_state_changes_in(scan, 0);
        let v1 = chunk.state_version();
        assert_eq!(chunk.state_changed_bricks_since(Some(v0)), 1 << 3 | 1 << 40);
        assert_eq!(chunk.state_changed_bricks_since(Some(v1)), 0);
        // The next scan starts a new log: a consumer that saw `v1` gets its bricks only, one
        // that last looked at `v0` (it missed a scan) gets every brick.
        let next = ScanId::after(Some(scan));
        chunk.note_state_changes_in(next, 1 << 7);
        assert_eq!(chunk.state_changed_bricks_since(Some(v1)), 1 << 7);
        assert_eq!(chunk.state_changed_bricks_since(Some(v0)), u64::MAX);
        // A change of unknown place (a write by hand) means every brick.
        let v2 = chunk.state_version();
        chunk.voxels_mut()[0].log_odds = 100;
        assert_eq!(chunk.state_changed_bricks_since(Some(v2)), u64::MAX);
        // A scan after it is precise again for a consumer that saw the write.
        let v3 = chunk.state_version();
        chunk.note_state_changes_in(ScanId::after(Some(next)), 1 << 9);
        assert_eq!(chunk.state_changed_bricks_since(Some(v3)), 1 << 9);
    }

    #[test]
    fn states_follow_the_sign_of_the_log_odds() {
        assert_eq!(VoxelState::of_milli(UNKNOWN_LOG_ODDS), VoxelState::Unknown);
        assert_eq!(VoxelState::of_milli(0), VoxelState::Occupied);
        assert_eq!(VoxelState::of_milli(-1), VoxelState::Free);
        assert_eq!(VoxelState::of_milli(847), VoxelState::Occupied);
    }
}
