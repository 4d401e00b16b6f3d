//! The stages of one tick (DESIGN.md "One tick"). Each is a `SystemSet`; behaviours, strategies
//! and adapters are systems added to their stage, so a new behaviour is a new system, not an
//! edit of a match statement.

use bevy_ecs::prelude::*;
use bevy_ecs::schedule::ScheduleLabel;

/// The schedule run once per fixed physics step.
#[derive(ScheduleLabel, Debug, Clone, PartialEq, Eq, Hash)]
pub struct Tick;

/// Pipeline stages, run in this order every tick.
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Rate-limited raycast sensing into each sensor's `Scan`.
    Sense,
    /// Scans integrated into the voxel chunks.
    Map,
    /// Frontier bookkeeping on changed chunks.
    Frontier,
    /// Goal selection, when a UAV needs a goal.
    Decide,
    /// Environment-adaptive parameters.
    Adapt,
    /// Local replanning toward the goal.
    Plan,
    /// Behaviour and controller: commands (or kinematic poses) for this step.
    Control,
    /// Rigid-body step, contacts.
    Physics,
    /// Energy, metrics, termination.
    Account,
}

impl Stage {
    /// All stages in tick order.
    pub const ORDER: [Stage; 9] = [
        Stage::Sense,
        Stage::Map,
        Stage::Frontier,
        Stage::Decide,
        Stage::Adapt,
        Stage::Plan,
        Stage::Control,
        Stage::Physics,
        Stage::Account,
    ];

    /// This stage's place in [`Stage::ORDER`].
    pub const fn index(self) -> usize {
        self as usize
    }
}

/// A schedule with the stages chained in tick order and no systems yet.
pub fn tick_schedule() -> Schedule {
    let mut schedule = Schedule::new(Tick);
    for pair in Stage::ORDER.windows(2) {
        schedule.configure_sets(pair[0].before(pair[1]));
    }
    schedule
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stage_index_is_its_place_in_the_order() {
        for (i, stage) in Stage::ORDER.into_iter().enumerate() {
            assert_eq!(stage.index(), i, "{stage:?}");
        }
    }
}
