//! Tests of the path searches: A* and the multi-goal Dijkstra against each other and against
//! shortest lattice distances, the moves they skip, and how query points join the lattice.

use super::tests::{FREE, OCCUPIED, TestMap, wall_room};
use super::*;
use glam::{DVec3, IVec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[test]
fn a_star_goes_around_the_wall_by_the_shortest_lattice_path() {
    let mut map = wall_room();
    let grid = map.grid(0.0);
    // Cells (5, 5, 3) to (25, 5, 3); the wall fills cell column x = 15 for y cells 0..=19.
    // Without corner cutting the path passes (14, 20), (15, 20), (16, 20): 9 diagonals and
    // 6 straight moves on each side, plus 2 straight moves across: 18 sqrt 2 + 14 cells.
    let (from, to) = (DVec3::new(1.1, 1.1, 0.7), DVec3::new(5.1, 1.1, 0.7));
    let path = find_path(&grid, from, to, usize::MAX).unwrap();
    let expected = (18.0 * 2f64.sqrt() + 14.0) * 0.2;
    assert!(
        (path_length(&path) - expected).abs() < 1e-9,
        "{}",
        path_length(&path)
    );
    assert_eq!((path[0], *path.last().unwrap()), (from, to));
    // Every leg crosses traversable voxels only.
    assert!(path.windows(2).all(|w| grid.line_of_sight(w[0], w[1])));
    // The shortened path: chords of sight only, no longer than the lattice path, no shorter
    // than the way around the wall's end (1.1, 1.1) -> (3.0, 4.0) -> (3.2, 4.0) -> (5.1, 1.1).
    let short = shortcut(&grid, &path);
    assert!(short.windows(2).all(|w| grid.line_of_sight(w[0], w[1])));
    let around = 2.0 * (1.9f64.powi(2) + 2.9f64.powi(2)).sqrt() + 0.2;
    let length = path_length(&short);
    assert!(around <= length && length < expected, "{length}");
    assert!(short.len() < path.len());
    // In the open, the shortened path is the straight chord.
    let open = find_path(
        &grid,
        DVec3::new(4.1, 5.1, 0.7),
        DVec3::new(6.1, 0.5, 1.3),
        10_000,
    );
    assert_eq!(shortcut(&grid, &open.unwrap()).len(), 2);
}

#[test]
fn enclosed_goals_and_limits_give_none() {
    let mut map = wall_room();
    // A hollow box around (1.1 .. 1.4 m): occupied shell, free inside.
    map.fill(IVec3::new(5, 5, 2), IVec3::new(20, 20, 13), OCCUPIED);
    map.fill(IVec3::new(6, 6, 3), IVec3::new(19, 19, 12), FREE);
    let grid = map.grid(0.0);
    let inside = DVec3::new(1.3, 1.3, 0.7);
    let outside = DVec3::new(5.1, 1.1, 0.7);
    assert!(grid.is_traversable_point(inside));
    assert_eq!(find_path(&grid, outside, inside, usize::MAX), None);
    assert_eq!(find_path(&grid, inside, outside, usize::MAX), None);
    // Reachable, but not within 10 expansions.
    let far = DVec3::new(5.1, 5.1, 0.7);
    assert!(find_path(&grid, outside, far, usize::MAX).is_some());
    assert_eq!(find_path(&grid, outside, far, 10), None);
    let both = find_paths(&grid, outside, &[inside, far, DVec3::NAN], usize::MAX);
    assert_eq!(
        (both[0].is_none(), both[1].is_some(), both[2].is_none()),
        (true, true, true)
    );
}

/// A 6.4 x 6.4 x 2.4 m room of free space with a dozen random pillars (inflated by 0.27 m), a
/// traversable start and a dozen random goals.
fn random_room(rng: &mut ChaCha8Rng) -> (TraversableGrid, DVec3, Vec<DVec3>) {
    let mut map = TestMap::new(DVec3::ZERO, DVec3::new(6.4, 6.4, 2.4));
    map.fill_all(FREE);
    for _ in 0..12 {
        let lo = IVec3::new(rng.random_range(0..60), rng.random_range(0..60), 0);
        let size = IVec3::new(rng.random_range(2..14), rng.random_range(2..14), 23);
        map.fill(lo, lo + size, OCCUPIED);
    }
    let grid = map.grid(0.27);
    let random_point = |rng: &mut ChaCha8Rng| {
        DVec3::new(
            rng.random_range(0.0..6.4),
            rng.random_range(0.0..6.4),
            rng.random_range(0.0..2.4),
        )
    };
    let from = (0..1000)
        .map(|_| random_point(rng))
        .find(|&p| grid.is_traversable_point(p))
        .unwrap();
    let goals = (0..12).map(|_| random_point(rng)).collect();
    (grid, from, goals)
}

#[test]
fn find_paths_agrees_with_find_path_on_random_maps() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for _ in 0..3 {
        let (grid, from, goals) = random_room(&mut rng);
        let many = find_paths(&grid, from, &goals, usize::MAX);
        let mut found = 0;
        for (goal, path) in goals.iter().zip(&many) {
            let single = find_path(&grid, from, *goal, usize::MAX);
            assert_eq!(single.is_some(), path.is_some(), "{goal}");
            if let (Some(a), Some(b)) = (single, path) {
                assert!((path_length(&a) - path_length(b)).abs() < 1e-6);
                assert_eq!((a[0], a.last()), (b[0], b.last()));
                found += 1;
            }
        }
        assert!(found > 0);
    }
}

/// A goal on the way to another: the search stops at the first, and must expand it when it
/// goes on (in a corridor one cell wide, nothing else leads on).
#[test]
fn a_search_goes_on_through_the_goal_it_stopped_at() {
    let mut map = TestMap::new(DVec3::ZERO, DVec3::new(6.4, 2.4, 0.8));
    map.fill_all(OCCUPIED);
    // Voxels y 10..=11, z 2..=3: one lattice cell across.
    map.fill(IVec3::new(0, 10, 2), IVec3::new(63, 11, 3), FREE);
    let grid = map.grid(0.0);
    let at = |x: f64| DVec3::new(x, 1.1, 0.3);
    let goals = [at(3.1), at(5.9)];
    let all = find_paths(&grid, at(0.3), &goals, usize::MAX);
    assert!(all.iter().all(Option::is_some));
    let mut search = PathSearch::new(&grid, at(0.3), &goals, usize::MAX);
    assert_eq!(search.paths(&[0])[0], all[0]);
    assert_eq!(search.paths(&[1])[0], all[1]);
}

/// Goals asked for a few at a time, in any order and again, get exactly the paths of one
/// search for all of them (with and without a limit on expansions, which counts over the
/// whole search), and the search stops as soon as the goals asked for so far are settled.
#[test]
fn a_search_asked_goal_by_goal_gives_the_paths_of_one_search() {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    for _ in 0..4 {
        let (grid, from, goals) = random_room(&mut rng);
        let full = PathSearch::new(&grid, from, &goals, usize::MAX);
        let expanded_for_all = {
            let mut full = full;
            full.paths(&(0..goals.len()).collect::<Vec<_>>());
            full.expanded_cells()
        };
        for limit in [usize::MAX, expanded_for_all / 2] {
            let all = find_paths(&grid, from, &goals, limit);
            let mut search = PathSearch::new(&grid, from, &goals, limit);
            let mut asked: Vec<usize> = (0..goals.len()).chain([0, 5]).collect();
            asked.sort_by_key(|_| rng.random_range(0..100));
            for batch in asked.chunks(rng.random_range(1..4)) {
                for (&goal, path) in batch.iter().zip(search.paths(batch)) {
                    assert_eq!(path, all[goal], "goal {goal} with limit {limit}");
                }
            }
        }
        // The nearest goal with a path, alone: a fraction of the cells.
        let nearest = (0..goals.len())
            .filter(|&g| find_path(&grid, from, goals[g], usize::MAX).is_some())
            .min_by(|&a, &b| goals[a].distance(from).total_cmp(&goals[b].distance(from)))
            .unwrap();
        let mut search = PathSearch::new(&grid, from, &goals, usize::MAX);
        assert!(search.paths(&[nearest])[0].is_some());
        assert!(
            search.expanded_cells() < expanded_for_all,
            "{} of {expanded_for_all} cells for the nearest goal",
            search.expanded_cells()
        );
    }
}

/// The pruning of the searches (`pruning::relaxed_by_parent`), bit by bit: it is linear in the
/// parent's moves, so one parent move at a time covers every case. From a cell reached by move
/// `d`, move `e` is skipped exactly when the parent allows `d + e`.
#[test]
fn a_parents_moves_prune_the_moves_they_already_relaxed() {
    let grid = TestMap::new(DVec3::ZERO, DVec3::ONE).grid(0.1);
    let moves = grid.lattice().moves();
    for (k, d) in moves.iter().enumerate() {
        for (j, f) in moves.iter().enumerate() {
            let expected = moves
                .iter()
                .enumerate()
                .filter(|(_, e)| e.delta + d.delta == f.delta)
                .fold(0u32, |bits, (i, _)| bits | 1 << i);
            assert_eq!(
                pruning::relaxed_by_parent(k, 1 << j),
                expected,
                "arrival {}, parent move {}",
                d.delta,
                f.delta
            );
        }
    }
}

/// A lattice cell is open exactly when its 8 voxels are traversable (and the border cells
/// never are), in rooms whose boxes leave cells of every kind: checks the packing of voxel
/// rows into cell rows.
#[test]
fn lattice_cells_are_open_exactly_when_their_eight_voxels_are_traversable() {
    for grid in rooms_with_boxes(17) {
        let lattice = grid.lattice();
        let (mut open, mut closed) = (0, 0);
        for index in 0..lattice.len() {
            let cell = lattice.cell(index);
            let expected = lattice.index(cell).is_some()
                && (0..8).all(|corner| {
                    let offset = IVec3::new(corner & 1, corner >> 1 & 1, corner >> 2);
                    grid.is_traversable(cell * lattice::CELL_VOXELS + offset)
                });
            assert_eq!(lattice.is_open(index), expected, "cell {cell}");
            if expected {
                open += 1;
            } else {
                closed += 1;
            }
        }
        assert!(open > 1000 && closed > 1000, "{open} open, {closed} closed");
    }
}

/// The grids (inflated by 0.15 m) of three rooms of [`boxes_in_a_room`], drawn from `seed`.
fn rooms_with_boxes(seed: u64) -> impl Iterator<Item = TraversableGrid> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..3).map(move |_| boxes_in_a_room(&mut rng).grid(0.15))
}

/// A known room of 4.8 x 4.8 x 2.4 m, free but for ten boxes of random places and sizes.
fn boxes_in_a_room(rng: &mut ChaCha8Rng) -> TestMap {
    let mut map = TestMap::new(DVec3::ZERO, DVec3::new(4.8, 4.8, 2.4));
    map.fill_all(FREE);
    for _ in 0..10 {
        let lo = IVec3::new(
            rng.random_range(0..44),
            rng.random_range(0..44),
            rng.random_range(0..20),
        );
        let size = IVec3::new(
            rng.random_range(1..10),
            rng.random_range(1..10),
            rng.random_range(1..16),
        );
        map.fill(lo, lo + size, OCCUPIED);
    }
    map
}

/// The open cells of a lattice, by index.
fn open_cells(lattice: &lattice::Lattice) -> Vec<usize> {
    (0..lattice.len()).filter(|&c| lattice.is_open(c)).collect()
}

/// Skipping the moves that cannot lower a cost changes nothing a search does: the pruned
/// Dijkstra closes the same cells in the same order, with the same costs and arrivals, as
/// the one that relaxes every move. The rooms have both cells with all 26 neighbours open
/// (`pruning::DOMINATED_IN_OPEN`) and cells near the boxes and walls (the parent's rule and
/// `pruning::DOMINATED_BY_TWO_MOVES`).
#[test]
fn pruning_changes_no_cost_arrival_or_order() {
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    for _ in 0..3 {
        let grid = boxes_in_a_room(&mut rng).grid(0.15);
        let lattice = grid.lattice();
        let open = open_cells(lattice);
        let surrounded = open
            .iter()
            .filter(|&&c| lattice.allowed_moves(c).count_ones() == 26)
            .count();
        assert!(
            surrounded > 1000 && open.len() - surrounded > 1000,
            "{surrounded} of {} open cells surrounded",
            open.len()
        );
        for _ in 0..2 {
            let start = open[rng.random_range(0..open.len())];
            let pruned = best_first::closing_order(lattice, start, true);
            assert!(pruned.len() > 1000, "{} cells closed", pruned.len());
            assert!(
                pruned == best_first::closing_order(lattice, start, false),
                "from cell {start}"
            );
        }
    }
}

/// The pruned Dijkstra's costs are the shortest lattice distances: every reached cell's cost
/// is no more than any neighbour's plus the move (so no improving relaxation was skipped), and
/// equals one of them (or is the start's 0). The searches on `u32` and `u64` words find the
/// same costs (four searches from different starts on one thread: the `u32` words' marks run
/// out after three and the words are cleared).
#[test]
fn pruned_searches_keep_every_cost_shortest() {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    for _ in 0..3 {
        let grid = boxes_in_a_room(&mut rng).grid(0.15);
        let lattice = grid.lattice();
        let open = open_cells(lattice);
        let starts: Vec<usize> = (0..4)
            .map(|_| open[rng.random_range(0..open.len())])
            .collect();
        for &start in &starts[1..] {
            assert_eq!(
                best_first::all_costs(lattice, start, false),
                best_first::all_costs(lattice, start, true),
                "from cell {start}"
            );
        }
        let start = starts[0];
        let costs = best_first::all_costs(lattice, start, false);
        let mut reached = 0;
        for cell in (0..lattice.len()).filter(|&c| costs[c] != u64::MAX) {
            reached += 1;
            let mut allowed = lattice.allowed_moves(cell);
            let mut via = u64::MAX;
            while allowed != 0 {
                let mv = &lattice.moves()[allowed.trailing_zeros() as usize];
                allowed &= allowed - 1;
                let next = cell.wrapping_add_signed(mv.offset);
                assert!(costs[next] <= costs[cell] + mv.cost, "cell {cell}");
                // Moves are symmetric: `next` reaches `cell` by the opposite move.
                via = via.min(costs[next].saturating_add(mv.cost));
            }
            assert!(cell == start || costs[cell] == via, "cell {cell}");
        }
        assert!(reached > 1000, "{reached} cells reached");
    }
}

/// Attaching a point by looking at the cells nearest first finds what the scan of the whole
/// cube finds: the same cell, or none, for points open, blocked, in unknown space and outside
/// the map, with the radii of starts and goals.
#[test]
fn nearest_first_attachment_agrees_with_the_full_scan() {
    use super::search::{Around, attach, attach_by_scan};
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let (mut open, mut blocked, mut none) = (0, 0, 0);
    for _ in 0..3 {
        let mut map = boxes_in_a_room(&mut rng);
        // A slab of unknown space, as frontier goals face.
        map.fill(
            IVec3::new(0, 0, 10),
            IVec3::new(47, 20, 14),
            uavex_components::map::UNKNOWN_LOG_ODDS,
        );
        let grid = map.grid(0.15);
        for i in 0..600 {
            // Random points, and corners shared by cells, as near to several centres as to
            // any (ties broken by index).
            let point = if i % 3 == 0 {
                DVec3::new(
                    0.2 * rng.random_range(0..24) as f64,
                    0.2 * rng.random_range(0..24) as f64,
                    0.2 * rng.random_range(0..12) as f64,
                )
            } else {
                DVec3::new(
                    rng.random_range(-0.6..5.4),
                    rng.random_range(-0.6..5.4),
                    rng.random_range(-0.4..2.8),
                )
            };
            for radius in [SNAP_RADIUS_M, super::search::GOAL_SNAP_RADIUS_M] {
                let around = Around::of(&grid, point, radius).unwrap();
                let expected = attach_by_scan(&grid, point, radius, &around);
                assert_eq!(attach(&grid, point, radius), expected, "{point} {radius}");
                match expected {
                    Some(end) if end.traversable => open += 1,
                    Some(_) => blocked += 1,
                    None => none += 1,
                }
            }
        }
    }
    assert!(
        open > 100 && blocked > 100 && none > 100,
        "{open} {blocked} {none}"
    );
}

#[test]
fn a_blocked_start_is_attached_to_the_nearest_open_cell() {
    let mut map = wall_room();
    let grid = map.grid(0.27);
    // 0.2 m from the wall's face (x = 3.0): inside the inflation.
    let start = DVec3::new(2.85, 1.0, 0.8);
    assert!(!grid.is_traversable_point(start));
    let path = find_path(&grid, start, DVec3::new(1.0, 1.0, 0.8), usize::MAX).unwrap();
    assert_eq!(path[0], start);
    assert!(path[1].distance(start) <= SNAP_RADIUS_M);
    assert!(path[1..].windows(2).all(|w| grid.line_of_sight(w[0], w[1])));
    // A goal inside the inflation ends at the nearest open cell's centre instead.
    let path = find_path(&grid, DVec3::new(1.0, 1.0, 0.8), start, usize::MAX).unwrap();
    let end = *path.last().unwrap();
    assert!(grid.is_traversable_point(end) && end.distance(start) <= SNAP_RADIUS_M);
    // Far outside the map: no open cell within reach.
    assert_eq!(
        find_path(&grid, DVec3::new(8.0, 1.0, 0.8), end, usize::MAX),
        None
    );
}

/// A start on traversable voxels whose nearest open cell lies beyond `SNAP_RADIUS_M` (a tube
/// one voxel wide, as a pocket of traversable voxels between a wall and unobserved space is)
/// joins the lattice at the nearest open cell it sees within `START_SEE_RADIUS_M`, over
/// traversable voxels; before, no path left it.
#[test]
fn a_start_in_a_narrow_pocket_sees_its_way_to_the_lattice() {
    let mut map = TestMap::new(DVec3::ZERO, DVec3::new(6.4, 6.4, 1.6));
    map.fill_all(OCCUPIED);
    // A room x < 2.0 m, and a tube of single voxels from it along +x at y 3.0-3.1, z 0.8-0.9.
    map.fill(IVec3::new(0, 0, 0), IVec3::new(19, 63, 15), FREE);
    map.fill(IVec3::new(20, 30, 8), IVec3::new(26, 30, 8), FREE);
    let grid = map.grid(0.0);
    let start = DVec3::new(2.65, 3.05, 0.85);
    let goal = DVec3::new(1.0, 3.0, 0.8);
    assert!(grid.is_traversable_point(start));
    // The nearest open cell's centre, (1.9, 3.1, 0.9), is 0.75 m away.
    assert!(DVec3::new(1.9, 3.1, 0.9).distance(start) > SNAP_RADIUS_M);
    let path = find_path(&grid, start, goal, usize::MAX).unwrap();
    assert_eq!((path[0], *path.last().unwrap()), (start, goal));
    assert!(path[1].distance(start) <= super::search::START_SEE_RADIUS_M);
    assert!(path.windows(2).all(|w| grid.line_of_sight(w[0], w[1])));
    let paths = find_paths(&grid, start, &[goal], usize::MAX);
    assert_eq!(paths[0].as_ref(), Some(&path));
}

/// A start whose open cells form an island (a pocket of 4 x 4 x 4 free voxels whose only way
/// out is a lane one voxel wide that turns a corner) reaches the room the lane leads to: over
/// traversable voxels to the nearest open cell that is not an island, every leg in line of
/// sight. Before, it attached to its pocket's cells, and no path left them.
#[test]
fn a_start_on_an_island_of_the_lattice_takes_the_way_out_over_voxels() {
    let mut map = TestMap::new(DVec3::ZERO, DVec3::new(6.4, 6.4, 1.6));
    map.fill_all(OCCUPIED);
    // The room x < 2.0 m; the pocket x, y 3.0-3.4 m, z 0.8-1.2 m; the lane from the pocket
    // along -x to x = 2.5 m, along -y to y = 2.7 m, then along -x into the room.
    map.fill(IVec3::new(0, 0, 0), IVec3::new(19, 63, 15), FREE);
    map.fill(IVec3::new(30, 30, 8), IVec3::new(33, 33, 11), FREE);
    map.fill(IVec3::new(25, 31, 9), IVec3::new(29, 31, 9), FREE);
    map.fill(IVec3::new(25, 27, 9), IVec3::new(25, 30, 9), FREE);
    map.fill(IVec3::new(20, 27, 9), IVec3::new(24, 27, 9), FREE);
    let grid = map.grid(0.0);
    let start = DVec3::new(3.15, 3.15, 0.95);
    let goal = DVec3::new(1.0, 3.0, 0.8);
    let lattice = grid.lattice();
    let pocket = lattice.index(IVec3::new(15, 15, 4)).unwrap();
    assert!(lattice.is_open(pocket) && super::escape::is_island(lattice, pocket));
    let room = lattice.index(IVec3::new(5, 15, 4)).unwrap();
    assert!(!super::escape::is_island(lattice, room));

    let path = find_path(&grid, start, goal, usize::MAX).expect("the way out of the pocket");
    assert_eq!((path[0], *path.last().unwrap()), (start, goal));
    assert!(path.windows(2).all(|w| grid.line_of_sight(w[0], w[1])));
    // The way passes the lane's corner at (2.55, 3.15, 0.95) and the one at (2.55, 2.75).
    assert!(path.iter().any(|p| p.x < 2.6 && p.y > 3.1), "{path:?}");
    let paths = find_paths(&grid, start, &[goal], usize::MAX);
    assert_eq!(paths[0].as_ref(), Some(&path));
}
