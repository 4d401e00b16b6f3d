//! Exploration cost (issue 4 benchmarks), on ONE core (a one-thread rayon pool, so candidate
//! planning and rollouts get no second core):
//!
//! 1. decision time in the EAAE Pillars scene with every cluster evaluated (`candidates =
//!    "all"`): p50 / p95 / max over every decision of a whole mission, split as EAAE Table 6.2
//!    (clustering, trajectory generation, energy estimation). Goal: p95 <= 20 ms.
//! 2. whole-mission real-time factor of the shipped `eaae` Pillars run (simulated time / wall
//!    time, everything included: sensing, mapping, frontiers, decisions, planning, physics).
//!    Goal: >= 100x. The wall time is also split by stage of the tick (`StageClock`).
//!
//! Whole missions take tens of seconds, so this is a plain timed program (`harness = false`),
//! not a criterion loop: `cargo bench --bench exploration` (seeds 1 and 2;
//! `EXPLORATION_SEEDS=3,4,5` for others). Each mission is run once per seed; the figures printed
//! are what the README quotes.

use std::time::Instant;
use uavex_components::exploration::{DecisionLog, DecisionTiming, DecisionTimings};
use uavex_engine::exploration::log::percentile;
use uavex_engine::exploration::{AllCandidates, CandidateCount};
use uavex_engine::scenario::{BehaviourSpec, load};
use uavex_engine::sim::Sim;
use uavex_systems::stage_clock::StageClock;
use uavex_systems::stages::Stage;

fn quantile(sorted: &[f64], q: f64) -> f64 {
    percentile(sorted, q).unwrap_or(f64::NAN)
}

fn main() {
    // `cargo bench` passes `--bench`; a filter argument, if any, is ignored.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/eaae_pillars.toml");
    let shipped = load(path).unwrap_or_else(|e| panic!("{e}"));

    println!("exploration bench, one core (EAAE Pillars)");
    // `EXPLORATION_SEEDS=1,2,3` picks the seeds (default 1, 2).
    let seeds: Vec<u64> = std::env::var("EXPLORATION_SEEDS")
        .ok()
        .map(|s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![1, 2]);
    for seed in seeds {
        // 1. Every cluster evaluated.
        let mut all = shipped.clone();
        if let BehaviourSpec::Explore(explore) = &mut all.scenario.uavs[0].behaviour {
            explore.candidates = CandidateCount::Named(AllCandidates::All);
        }
        let mut sim = Sim::build(&all, seed).unwrap_or_else(|e| panic!("{e}"));
        let (outcome, _) = pool.install(|| sim.run_to_end());
        let timings: Vec<DecisionTiming> =
            sim.world.resource::<DecisionTimings>().decisions.clone();
        let log = sim.world.resource::<DecisionLog>();
        let candidates: usize = log.decisions.iter().map(|d| d.candidates.len()).sum();
        let mut totals: Vec<f64> = timings.iter().map(|t| t.total_ms).collect();
        totals.sort_by(f64::total_cmp);
        let mean = |f: fn(&DecisionTiming) -> f64| {
            timings.iter().map(f).sum::<f64>() / timings.len().max(1) as f64
        };
        println!(
            "seed {seed}, candidates = all: {} decisions ({:.1} candidates each), {outcome:?}; \
             decision ms p50 {:.2}, p95 {:.2}, max {:.2}; mean ms clustering {:.2}, \
             trajectories {:.2}, energy {:.2}",
            timings.len(),
            candidates as f64 / log.decisions.len().max(1) as f64,
            quantile(&totals, 0.5),
            quantile(&totals, 0.95),
            totals.last().copied().unwrap_or(0.0),
            mean(|t| t.clustering_ms),
            mean(|t| t.trajectory_ms),
            mean(|t| t.energy_ms),
        );

        // 2. The shipped run, timed whole.
        let mut sim = Sim::build(&shipped, seed).unwrap_or_else(|e| panic!("{e}"));
        let started = Instant::now();
        let (outcome, _) = pool.install(|| sim.run_to_end());
        let wall = started.elapsed().as_secs_f64();
        let simulated = sim.time_s();
        println!(
            "seed {seed}, shipped eaae run: {simulated:.1} s simulated in {wall:.2} s wall, \
             real-time factor {:.1}x, {outcome:?}",
            simulated / wall
        );
        // Where that wall time went, stage by stage (the run's `stage_timings.csv`).
        let clock = sim.world.resource::<StageClock>();
        let stages: Vec<String> = Stage::ORDER
            .into_iter()
            .map(|stage| {
                let spent = clock.spent(stage).as_secs_f64();
                format!("{stage:?} {spent:.2} s ({:.1} %)", 100.0 * spent / wall)
            })
            .collect();
        println!("  stages: {}", stages.join(", "));
    }
}
