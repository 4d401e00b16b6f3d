//! One exploration decision, focused (issue 4: decision p95 <= 20 ms on ONE core).
//!
//! `benches/exploration.rs` times decisions inside whole missions (1-2 min per seed). This bench
//! flies the shipped EAAE Pillars mission once per seed with a snapshot system placed just
//! before the candidates are proposed (`DecideStep::Propose`): at every decision it keeps the
//! refreshed traversability grid, the planning start, the cluster targets, the frontier points
//! and the rollout inputs, and times the clustering in place (`cluster_frontier` on the live
//! map, as `refresh_clusters` runs it). The decisions are then replayed on a one-thread rayon
//! pool, each `REPEATS` times (the fastest kept, the machine is shared):
//!
//! - trajectories: `plan_candidates` with the propose step's fallback to too-close clusters;
//! - energy: `roll_out_candidates` on those candidates;
//! - 2-means: `divisive_two_means` alone on the frontier points.
//!
//! It prints p50 / p95 / max per part and of the sum (clustering + trajectories + energy), how
//! many candidates the time allocation stretched beyond [`STRETCHED`] times the rest-to-rest
//! time of their paths (see the README's design decision on candidates pinned near a moving
//! start), and a digest of every planned candidate (target, viewpoint, trajectory bits), so
//! that a change meant to be a pure speed-up can be checked to plan exactly the same
//! trajectories: set `DECISION_DIGEST=/some/file` to write one line per decision there and diff
//! two runs.
//! `DECISION_SEEDS=1,2` picks the seeds (default 1); `DECISION_TOP=n` lists the n slowest
//! decisions with their parts; `DECISION_EXPLAIN=k` lists every plan decision `k` tries, with
//! its outcome and time; `DECISION_LOOPS=n` replays the planning
//! n more times (for `perf record`); `DECISION_PAUSE_S=s` prints a line and waits `s` seconds
//! between the mission and the replay (to switch a profiler on for the replay alone: under
//! valgrind the mission takes an hour instrumented, a few minutes not).
//!
//! `cargo bench --bench decision` (a plain timed program, `harness = false`).

use bevy_ecs::prelude::*;
use glam::{DVec3, Vec3};
use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::io::Write;
use std::time::Instant;
use uavex_components::airframe::Airframe;
use uavex_components::exploration::{Explorer, NeedsDecision};
use uavex_components::frontier::{
    ClusterSettings, FrontierCluster, FrontierSet, Reachable, Viewpoints,
};
use uavex_components::sim::{RunSeed, SimClock, stream};
use uavex_components::trajectory::{Trajectory, TrajectoryPoint};
use uavex_components::uav::QuadState;
use uavex_engine::exploration::log::percentile;
use uavex_engine::scenario::load;
use uavex_engine::sim::Sim;
use uavex_systems::exploration::DecideStep;
use uavex_systems::exploration::evaluate::{TargetGoal, roll_out_candidates, target_goals};
use uavex_systems::exploration::propose::{
    ClusterTarget, PlannedCandidate, cluster_targets, goal_rollout, plan_decision, planning_start,
    propose_candidates,
};
use uavex_systems::flight::ecs::ReferenceTrajectory;
use uavex_systems::flight::{FlightState, RolloutConfig};
use uavex_systems::frontier::{cluster_frontier, divisive_two_means};
use uavex_systems::mapping::MapReader;
use uavex_systems::planning::{
    BrakingMemo, GlobalPlan, SightMemo, Traversability, TraversableGrid, find_paths,
    plan_along_seen,
};
use uavex_systems::trajectory::DynamicLimits;

/// Replays of each part of each decision, the fastest kept (`DECISION_REPEATS` overrides it:
/// 1 under callgrind, whose counts do not vary).
const REPEATS: usize = 3;

/// Everything one decision's planning needs, as the propose step sees it.
struct Snapshot {
    grid: TraversableGrid,
    start: TrajectoryPoint,
    flight: FlightState,
    airframe: Airframe,
    limits: DynamicLimits,
    config: RolloutConfig,
    position: Vec3,
    min_goal_distance_m: f32,
    min_travel_m: f64,
    clusters: Vec<ClusterTarget>,
    points: Vec<Vec3>,
    r_max_m: f32,
    clustering_ms: f64,
}

#[derive(Resource, Default)]
struct Snapshots(Vec<Snapshot>);

#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn snapshot(
    clock: Res<SimClock>,
    map: MapReader,
    mut grid: ResMut<Traversability>,
    set: Res<FrontierSet>,
    settings: Res<ClusterSettings>,
    seed: Res<RunSeed>,
    uavs: Query<
        (
            &Explorer,
            &Airframe,
            &QuadState,
            Option<&ReferenceTrajectory>,
        ),
        With<NeedsDecision>,
    >,
    clusters: Query<(Entity, &FrontierCluster, &Viewpoints), With<Reachable>>,
    mut snapshots: ResMut<Snapshots>,
) {
    if uavs.is_empty() {
        return;
    }
    grid.0.refresh(&map);
    // The clustering of this decision, timed on the live map (any stream: the cost is alike).
    let mut rng = seed.stream(stream::CLUSTERING, snapshots.0.len() as u64);
    let clustering = Instant::now();
    let found = cluster_frontier(&set, &map, &settings, &mut rng);
    let clustering_ms = clustering.elapsed().as_secs_f64() * 1e3;
    std::hint::black_box(found);
    let config = map.config.clone();
    let points: Vec<Vec3> = set.iter().map(|k| config.center_of(k)).collect();
    let all = cluster_targets(&clusters);
    for (explorer, airframe, state, reference) in &uavs {
        let s = &explorer.settings;
        snapshots.0.push(Snapshot {
            grid: grid.0.clone(),
            start: planning_start(reference, state, clock.time_s()),
            flight: FlightState::from(state),
            airframe: airframe.clone(),
            limits: DynamicLimits::of(airframe),
            config: goal_rollout(s),
            position: state.position,
            min_goal_distance_m: s.min_goal_distance_m,
            min_travel_m: s.goal_tolerance_m,
            clusters: all.clone(),
            points: points.clone(),
            r_max_m: settings.r_max_m,
            clustering_ms,
        });
    }
}

/// The propose step's planning ([`plan_decision`]).
fn plan(s: &Snapshot) -> Vec<PlannedCandidate> {
    plan_decision(
        &s.grid,
        &s.start,
        &s.clusters,
        s.position,
        s.min_goal_distance_m,
        &s.limits,
        s.min_travel_m,
    )
    .1
}

/// A candidate whose trajectory lasts more than this many times the rest-to-rest time of its
/// path's legs counts as stretched ([`stretch`]). Half the allocations of a Pillars mission
/// end within 1.1 times that time, nine in ten within 2.3 (docs/performance.md, fifty-first
/// session).
const STRETCHED: f64 = 3.0;

/// How far the time allocation stretched a candidate: its duration over the fastest
/// rest-to-rest time of its path's legs ([`DynamicLimits::rest_to_rest_time`]).
fn stretch(plan: &GlobalPlan, limits: &DynamicLimits) -> f64 {
    let needed: f64 = plan
        .path
        .windows(2)
        .map(|leg| limits.rest_to_rest_time(leg[0].distance(leg[1])))
        .sum();
    plan.trajectory.duration() / needed
}

fn digest(planned: &[PlannedCandidate]) -> u64 {
    let mut h = DefaultHasher::new();
    for c in planned {
        c.target.hash(&mut h);
        c.viewpoint.hash(&mut h);
        c.goal.to_array().map(f64::to_bits).hash(&mut h);
        c.plan.path_length_m.to_bits().hash(&mut h);
        c.plan.trajectory.duration().to_bits().hash(&mut h);
        for segment in c.plan.trajectory.segments() {
            segment.duration.to_bits().hash(&mut h);
            for output in &segment.coefficients {
                output.map(f64::to_bits).hash(&mut h);
            }
        }
    }
    h.finish()
}

fn fastest_ms<T>(mut f: impl FnMut() -> T) -> (f64, T) {
    let repeats = env_number("DECISION_REPEATS").unwrap_or(REPEATS).max(1);
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..repeats {
        let started = Instant::now();
        let value = f();
        best = best.min(started.elapsed().as_secs_f64() * 1e3);
        out = Some(value);
    }
    (best, out.expect("at least one repeat"))
}

fn quantiles(mut v: Vec<f64>) -> (f64, f64, f64) {
    v.sort_by(f64::total_cmp);
    let q = |q: f64| percentile(&v, q).unwrap_or(f64::NAN);
    (q(0.5), q(0.95), v.last().copied().unwrap_or(0.0))
}

/// Every plan decision `k` tries (each target's centroid, then its viewpoints, as
/// [`plan_decision`] tries them, though here every option is tried), with its outcome and time.
fn explain(k: usize, s: &Snapshot) {
    let start = &s.start;
    println!(
        "decision {k}: start {:.2?} v {:.2?} a {:.2?} j {:.2?}",
        start.position.to_array(),
        start.velocity.to_array(),
        start.acceleration.to_array(),
        start.jerk.to_array()
    );
    let options: Vec<(usize, TargetGoal)> = (s.clusters.iter().enumerate())
        .flat_map(|(i, target)| target_goals(target).map(move |goal| (i, goal)))
        .collect();
    let goals: Vec<DVec3> = options.iter().map(|(_, goal)| goal.position).collect();
    let paths = find_paths(&s.grid, start.position, &goals, usize::MAX);
    // As `plan_targets` plans them: one line-of-sight memo and one braking leg for all.
    let (mut sight, braking) = (SightMemo::new(&s.grid), BrakingMemo::new());
    for ((target, goal), path) in options.into_iter().zip(paths) {
        let viewpoint = goal.viewpoint;
        let Some(path) = path else {
            println!("  target {target:2} {viewpoint:?}: no path");
            continue;
        };
        let started = Instant::now();
        let result = plan_along_seen(&mut sight, &braking, start, &path, goal.yaw, &s.limits);
        let ms = started.elapsed().as_secs_f64() * 1e3;
        let outcome = match result {
            Ok(plan) => format!(
                "ok, {:.2} s ({:.1}x rest to rest)",
                plan.trajectory.duration(),
                stretch(&plan, &s.limits)
            ),
            Err(e) => e.to_string(),
        };
        println!(
            "  target {target:2} {viewpoint:?}: {ms:6.2} ms, {} path points: {outcome}",
            path.len()
        );
    }
}

/// The number in environment variable `name`, if set and well formed.
fn env_number<T: std::str::FromStr>(name: &str) -> Option<T> {
    std::env::var(name).ok().and_then(|s| s.parse().ok())
}

fn main() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/eaae_pillars.toml");
    let shipped = load(path).unwrap_or_else(|e| panic!("{e}"));
    let seeds: Vec<u64> = std::env::var("DECISION_SEEDS")
        .ok()
        .map(|s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![1]);
    let loops: usize = env_number("DECISION_LOOPS").unwrap_or(0);
    let top: usize = env_number("DECISION_TOP").unwrap_or(0);
    let pause = env_number("DECISION_PAUSE_S").map(std::time::Duration::from_secs_f64);
    let mut digest_file = std::env::var("DECISION_DIGEST")
        .ok()
        .map(|p| std::fs::File::create(p).expect("a writable digest file"));

    println!("decision bench, one core (EAAE Pillars, decisions replayed from the mission)");
    for seed in seeds {
        let mut sim = Sim::build(&shipped, seed).unwrap_or_else(|e| panic!("{e}"));
        sim.world.init_resource::<Snapshots>();
        sim.add_systems(
            snapshot
                .in_set(DecideStep::Propose)
                .before(propose_candidates),
        );
        let (outcome, _) = pool.install(|| sim.run_to_end());
        let snapshots = std::mem::take(&mut sim.world.resource_mut::<Snapshots>().0);
        drop(sim);
        if let Some(pause) = pause {
            // A profiler attached to the replay only (e.g. valgrind --instr-atstart=no, then
            // `callgrind_control -i on` on this line) starts at the same point every run.
            println!("seed {seed}: mission flown, replay in {pause:?}");
            std::io::stdout().flush().expect("stdout flushed");
            std::thread::sleep(pause);
        }

        let (mut clustering, mut trajectories, mut energy, mut means, mut totals) =
            (vec![], vec![], vec![], vec![], vec![]);
        let mut candidates = 0usize;
        let mut targets = 0usize;
        let (mut stretched, mut most_stretched) = (0usize, 0.0f64);
        let mut rows = Vec::new();
        for (k, s) in snapshots.iter().enumerate() {
            let (t_ms, planned) = pool.install(|| fastest_ms(|| plan(s)));
            let (e_ms, _) = pool.install(|| {
                fastest_ms(|| roll_out_candidates(&s.airframe, &s.flight, &planned, &s.config))
            });
            let (m_ms, _) = fastest_ms(|| {
                let mut rng = RunSeed(seed).stream(stream::CLUSTERING, k as u64);
                divisive_two_means(&s.points, s.r_max_m, &mut rng).len()
            });
            candidates += planned.len();
            targets += s.clusters.len();
            for candidate in &planned {
                let stretch = stretch(&candidate.plan, &s.limits);
                stretched += usize::from(stretch > STRETCHED);
                most_stretched = most_stretched.max(stretch);
            }
            if let Some(file) = &mut digest_file {
                writeln!(
                    file,
                    "seed {seed} decision {k}: {} clusters, {} planned {:?}, digest {:016x}",
                    s.clusters.len(),
                    planned.len(),
                    planned
                        .iter()
                        .map(|c| (c.target, c.viewpoint))
                        .collect::<Vec<_>>(),
                    digest(&planned)
                )
                .expect("digest written");
            }
            rows.push((
                s.clustering_ms + t_ms + e_ms,
                k,
                s.clusters.len(),
                planned.len(),
                s.clustering_ms,
                t_ms,
                e_ms,
            ));
            clustering.push(s.clustering_ms);
            trajectories.push(t_ms);
            energy.push(e_ms);
            means.push(m_ms);
            totals.push(s.clustering_ms + t_ms + e_ms);
        }
        if let Some(k) = env_number::<usize>("DECISION_EXPLAIN")
            && let Some(s) = snapshots.get(k)
        {
            explain(k, s);
        }
        for _ in 0..loops {
            for s in &snapshots {
                std::hint::black_box(pool.install(|| plan(s)));
            }
        }
        let n = snapshots.len().max(1) as f64;
        println!(
            "seed {seed}: {} decisions ({:.1} clusters, {:.1} candidates each), {outcome:?}",
            snapshots.len(),
            targets as f64 / n,
            candidates as f64 / n
        );
        println!(
            "  candidates stretched beyond {STRETCHED}x the rest-to-rest time of their paths: \
             {stretched} of {candidates} (at most {most_stretched:.1}x)"
        );
        rows.sort_by(|a, b| b.0.total_cmp(&a.0));
        for (total, k, clusters, planned, c, t, e) in rows.iter().take(top) {
            println!(
                "  decision {k:3}: {total:7.2} ms ({clusters} clusters, {planned} planned): \
                 clustering {c:.2}, trajectories {t:.2}, energy {e:.2}"
            );
        }
        for (name, v) in [
            ("total", totals),
            ("clustering (in place)", clustering),
            ("  of it 2-means", means),
            ("trajectories", trajectories),
            ("energy", energy),
        ] {
            let mean = v.iter().sum::<f64>() / n;
            let (p50, p95, max) = quantiles(v);
            println!(
                "  {name:<22} ms: p50 {p50:7.2}  p95 {p95:7.2}  max {max:7.2}  mean {mean:7.2}"
            );
        }
    }
}
