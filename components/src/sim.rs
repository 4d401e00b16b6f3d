//! Run-wide resources: clock, random numbers, outcome.

use bevy_ecs::prelude::*;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;

/// Simulation time, advanced by one fixed physics step per tick.
#[derive(Resource, Debug, Clone, Copy, PartialEq)]
pub struct SimClock {
    /// Ticks since the start of the run.
    pub tick: u64,
    /// Fixed step (s), 1 / physics rate.
    pub dt: f64,
}

impl SimClock {
    pub fn new(rate_hz: f64) -> Self {
        Self {
            tick: 0,
            dt: 1.0 / rate_hz,
        }
    }

    /// Simulation time of the current tick (s). Computed from the tick count so that it never
    /// drifts by accumulated rounding.
    pub fn time_s(&self) -> f64 {
        self.tick as f64 * self.dt
    }
}

/// The run's seed. Every consumer of randomness derives its own stream from it with
/// [`RunSeed::stream`], so that adding a consumer never shifts the numbers another one draws.
#[derive(Resource, Debug, Clone, Copy, PartialEq, Eq)]
pub struct RunSeed(pub u64);

impl RunSeed {
    /// A deterministic random stream for one consumer, named by a purpose and an index.
    pub fn stream(&self, purpose: u64, index: u64) -> ChaCha8Rng {
        let mut rng = ChaCha8Rng::seed_from_u64(self.0);
        rng.set_stream(purpose.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ index);
        rng
    }
}

/// Stream purposes for [`RunSeed::stream`].
pub mod stream {
    pub const SENSOR_NOISE: u64 = 1;
    pub const WORLD_GENERATOR: u64 = 2;
    pub const CLUSTERING: u64 = 3;
}

/// How a run ended (the `outcome` of `summary.json`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    Complete,
    TimeLimit,
    Crashed,
    BatteryEmpty,
    ReturnedHome,
    Failed,
}

/// Set once, by whichever system ends the run; the run loop stops after the tick that set it.
#[derive(Resource, Debug, Default, Clone, PartialEq)]
pub struct RunEnd(pub Option<(Outcome, String)>);
