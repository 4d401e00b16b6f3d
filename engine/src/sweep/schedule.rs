//! The order in which a sweep's workers take its runs: longest expected first.
//!
//! A sweep ends when its last run does. Taken in plan order (or split in halves, as rayon
//! splits a list), the runs of a plan's last group start last: scenario-major order puts,
//! say, the slowest strategy of the largest scene there, and one worker runs the longest
//! missions alone while the others wait. Longest processing time first (LPT, Graham 1969)
//! makes the last runs to start the short ones, so the workers finish together. The EAAE
//! protocol (30 runs, 2 jobs, 2026-12-02): 128.1 s for 229.7 s of runs split by rayon, one
//! core idle for the last 13 s; 113.2 s for 225.2 s of runs with this queue.
//!
//! How long a run will take is not known before it ran, but runs that differ only in their
//! seed (a *group*: the same scenario and grid values) take about as long as each other. So
//! the queue first starts one run of every group, in plan order, and then, whenever a worker
//! is free, the next run of the group whose finished runs took longest on average; a group
//! none of whose runs has finished yet counts as the longest (its probe is still running, and
//! starting its runs early is the safe side). Ties go to plan order.
//!
//! The order changes only when runs finish, never what a run computes: each run is a pure
//! function of its scenario and seed.

use std::time::Duration;

/// Runs (by position in the list given to [`RunQueue::new`]) in the order workers take them.
#[derive(Debug, Clone)]
pub struct RunQueue {
    /// Group of each run.
    group_of: Vec<usize>,
    /// The runs not yet taken, per group, in plan order (front first).
    waiting: Vec<std::collections::VecDeque<usize>>,
    /// Groups whose first run has not been taken yet, in plan order.
    probes: std::collections::VecDeque<usize>,
    /// Wall time of each group's finished runs: (sum, count).
    finished: Vec<(Duration, u32)>,
}

impl RunQueue {
    /// A queue over runs whose groups are `groups[i]` (any labels that can be ordered), in
    /// plan order.
    pub fn new<G: Ord>(groups: &[G]) -> Self {
        // Groups are numbered in order of first appearance; a map, not a search of the groups
        // seen, so that a plan of a million single-seed groups is not 10^12 comparisons.
        let mut number: std::collections::BTreeMap<&G, usize> = Default::default();
        let group_of: Vec<usize> = groups
            .iter()
            .map(|g| {
                let next = number.len();
                *number.entry(g).or_insert(next)
            })
            .collect();
        let labels = number.len();
        let mut waiting = vec![std::collections::VecDeque::new(); labels];
        for (run, &group) in group_of.iter().enumerate() {
            waiting[group].push_back(run);
        }
        Self {
            group_of,
            probes: (0..labels).collect(),
            finished: vec![(Duration::ZERO, 0); labels],
            waiting,
        }
    }

    /// The next run to start, or `None` when every run was taken.
    pub fn take(&mut self) -> Option<usize> {
        if let Some(group) = self.probes.pop_front() {
            return self.waiting[group].pop_front();
        }
        // Longest expected first; groups are numbered in plan order, and `max_by` keeps the
        // last of equal elements, so the comparison is reversed on the group number.
        let group = (0..self.waiting.len())
            .filter(|&g| !self.waiting[g].is_empty())
            .max_by(|&a, &b| self.expected(a).cmp(&self.expected(b)).then(b.cmp(&a)))?;
        self.waiting[group].pop_front()
    }

    /// Records that `run` (as [`Self::take`] gave it) finished after `wall`, whatever its
    /// outcome.
    pub fn finished(&mut self, run: usize, wall: Duration) {
        let (sum, count) = &mut self.finished[self.group_of[run]];
        *sum += wall;
        *count += 1;
    }

    /// A group's mean wall time so far; `Duration::MAX` before any of its runs finished.
    fn expected(&self, group: usize) -> Duration {
        match self.finished[group] {
            (_, 0) => Duration::MAX,
            (sum, count) => sum / count,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn secs(s: u64) -> Duration {
        Duration::from_secs(s)
    }

    #[test]
    fn one_run_of_each_group_first_then_the_longest_group() {
        // Groups a, a, b, b, c, c in plan order.
        let mut queue = RunQueue::new(&["a", "a", "b", "b", "c", "c"]);
        assert_eq!(
            (queue.take(), queue.take(), queue.take()),
            (Some(0), Some(2), Some(4)),
            "a probe of each group, in plan order"
        );
        queue.finished(0, secs(3));
        queue.finished(2, secs(9));
        // c's probe is still running: its group counts as the longest.
        assert_eq!(queue.take(), Some(5));
        queue.finished(4, secs(1));
        assert_eq!(
            (queue.take(), queue.take()),
            (Some(3), Some(1)),
            "b (9 s), a (3 s)"
        );
        assert_eq!(queue.take(), None);
    }

    #[test]
    fn ties_go_to_plan_order_and_every_run_is_taken_once() {
        let groups: Vec<u32> = (0..40).map(|i| i % 4).collect();
        let mut queue = RunQueue::new(&groups);
        let mut taken = Vec::new();
        while let Some(run) = queue.take() {
            // Every group takes as long: plan order decides.
            queue.finished(run, secs(5));
            taken.push(run);
        }
        let mut sorted = taken.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..40).collect::<Vec<_>>());
        // Probes 0..4, then group 0's runs (4, 8, ...), as the lowest-numbered equal group.
        assert_eq!(&taken[..6], &[0, 1, 2, 3, 4, 8]);
    }

    #[test]
    fn a_groups_mean_moves_with_its_runs() {
        let mut queue = RunQueue::new(&[1, 1, 1, 2, 2, 2]);
        let (a, b) = (queue.take().unwrap(), queue.take().unwrap());
        queue.finished(a, secs(10));
        queue.finished(b, secs(6));
        assert_eq!(queue.take(), Some(1), "group 1: 10 s against 6 s");
        queue.finished(1, secs(0));
        // Group 1 now averages 5 s, group 2 still 6 s.
        assert_eq!(queue.take(), Some(4));
    }

    #[test]
    fn a_million_groups_are_queued_in_order_of_first_appearance() {
        // A search of the groups seen so far took hours here (10^12 comparisons); the numbering
        // is by first appearance whatever order the labels sort in.
        let groups: Vec<usize> = (0..1_000_000).rev().collect();
        let queue = RunQueue::new(&groups);
        assert_eq!(queue.waiting.len(), 1_000_000);
        assert_eq!(queue.group_of[..3], [0, 1, 2]);
        assert_eq!(queue.waiting[999_999], [999_999]);
    }

    #[test]
    fn an_empty_plan_has_nothing_to_run() {
        let mut queue = RunQueue::new::<u8>(&[]);
        assert_eq!(queue.take(), None);
    }
}
