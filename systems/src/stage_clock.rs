//! Wall-clock time spent in each stage of the tick (the "computation time per module" EAAE
//! reports, and the mapping time EANS compares), measured in every run.
//!
//! [`time_stages`] puts one small marker system between every two consecutive stages (and one
//! before the first): each reads the clock once and charges the time since the previous marker
//! to the stage that just ran. A stage's systems, its command flushes and any system a user
//! adds to it are timed with it; nothing is charged for the time between ticks. A stage with no
//! systems shows the markers' own cost (about 40 ns per tick on the project's machine; the ten
//! of them add about 1 % to a Pillars mission).
//!
//! The figures measure the host, not the run: like the decision timings they differ from one
//! machine (and one moment) to the next, and nothing in a run reads them back.

use crate::stages::Stage;
use bevy_ecs::prelude::*;
use std::time::{Duration, Instant};

/// Time spent in each stage so far, indexed by [`Stage::index`].
#[derive(Resource, Debug, Default, Clone)]
pub struct StageClock {
    spent: [Duration; Stage::ORDER.len()],
    /// When the current lap began (the last marker's reading), during a tick.
    lap_start: Option<Instant>,
    /// Ticks begun.
    ticks: u64,
}

impl StageClock {
    /// A tick begins: the first stage's lap starts now.
    pub fn begin_tick(&mut self, now: Instant) {
        self.lap_start = Some(now);
        self.ticks += 1;
    }

    /// `stage` ended at `now`: the time since the last marker is its.
    pub fn end_stage(&mut self, stage: Stage, now: Instant) {
        if let Some(start) = self.lap_start.replace(now) {
            self.spent[stage.index()] += now.saturating_duration_since(start);
        }
    }

    /// Time spent in `stage`.
    pub fn spent(&self, stage: Stage) -> Duration {
        self.spent[stage.index()]
    }

    /// Time spent in all stages.
    pub fn total(&self) -> Duration {
        self.spent.iter().sum()
    }

    /// Ticks begun.
    pub fn ticks(&self) -> u64 {
        self.ticks
    }
}

/// Adds the markers that keep [`StageClock`] (which the world must hold) to a tick schedule
/// made by [`crate::stages::tick_schedule`].
pub fn time_stages(schedule: &mut Schedule) {
    schedule.add_systems(
        (|mut clock: ResMut<StageClock>| clock.begin_tick(Instant::now())).before(Stage::ORDER[0]),
    );
    for (i, &stage) in Stage::ORDER.iter().enumerate() {
        let marker = (move |mut clock: ResMut<StageClock>| clock.end_stage(stage, Instant::now()))
            .after(stage);
        match Stage::ORDER.get(i + 1) {
            Some(&next) => schedule.add_systems(marker.before(next)),
            None => schedule.add_systems(marker),
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stages::tick_schedule;
    use std::thread::sleep;

    /// Each lap goes to the stage that ended it; nothing before a tick begins is charged.
    #[test]
    fn laps_are_charged_to_the_stage_that_ended_them() {
        let t0 = Instant::now();
        let at = |ms: u64| t0 + Duration::from_millis(ms);
        let mut clock = StageClock::default();
        clock.end_stage(Stage::Sense, at(5));
        assert_eq!(clock.total(), Duration::ZERO);
        clock.begin_tick(at(10));
        clock.end_stage(Stage::Sense, at(13));
        clock.end_stage(Stage::Map, at(20));
        clock.begin_tick(at(100));
        clock.end_stage(Stage::Sense, at(101));
        clock.end_stage(Stage::Map, at(111));
        assert_eq!(clock.spent(Stage::Sense), Duration::from_millis(4));
        assert_eq!(clock.spent(Stage::Map), Duration::from_millis(17));
        assert_eq!(clock.spent(Stage::Physics), Duration::ZERO);
        assert_eq!(clock.total(), Duration::from_millis(21));
        assert_eq!(clock.ticks(), 2);
    }

    /// In a schedule, a stage's systems are timed with that stage and no other: the map stage
    /// sleeps, and only its time holds the sleep. (The bound checked on the other stages,
    /// which run nothing, is the sleep itself: only a host stall that long could break it.)
    #[test]
    fn a_slow_system_is_timed_with_its_stage() {
        const NAP: Duration = Duration::from_millis(40);
        let mut world = World::new();
        world.insert_resource(StageClock::default());
        let mut schedule = tick_schedule();
        schedule.add_systems((|| sleep(NAP)).in_set(Stage::Map));
        time_stages(&mut schedule);
        for _ in 0..2 {
            schedule.run(&mut world);
        }
        let clock = world.resource::<StageClock>();
        assert_eq!(clock.ticks(), 2);
        assert!(clock.spent(Stage::Map) >= 2 * NAP, "{clock:?}");
        for stage in Stage::ORDER.into_iter().filter(|&s| s != Stage::Map) {
            assert!(clock.spent(stage) < NAP, "{stage:?} in {clock:?}");
        }
    }
}
