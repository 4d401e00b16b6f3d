//! What an exploration run reports: the decision log as CSV (one row per candidate of every
//! decision, deterministic), the decision timings as CSV (wall clock, not deterministic), and
//! the summary keys of the issue (`decisions`, `completion_time_s`, `mean_prediction_error`,
//! `decision_ms_p50`, `decision_ms_p95`).

use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use uavex_components::exploration::{DecisionLog, DecisionTimings, GoalOutcome};

/// The exploration part of a run's summary.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ExplorationSummary {
    /// Decisions that chose a goal.
    pub decisions: u64,
    /// Mean over reached goals of |flown - predicted| / predicted energy of the leg.
    pub mean_prediction_error: Option<f64>,
    /// Median and 95th percentile of the decision time (ms, wall clock).
    pub decision_ms_p50: Option<f64>,
    pub decision_ms_p95: Option<f64>,
}

impl ExplorationSummary {
    pub fn of(log: &DecisionLog, timings: &DecisionTimings) -> Self {
        let errors: Vec<f64> = log
            .decisions
            .iter()
            .filter_map(|d| d.flown)
            .filter(|f| f.outcome == GoalOutcome::Reached && f.prediction_error.is_finite())
            .map(|f| f.prediction_error.abs())
            .collect();
        let mut totals: Vec<f64> = timings.decisions.iter().map(|t| t.total_ms).collect();
        totals.sort_by(f64::total_cmp);
        Self {
            decisions: log.decisions.iter().filter(|d| d.chosen.is_some()).count() as u64,
            mean_prediction_error: (!errors.is_empty())
                .then(|| errors.iter().sum::<f64>() / errors.len() as f64),
            decision_ms_p50: percentile(&totals, 0.50),
            decision_ms_p95: percentile(&totals, 0.95),
        }
    }
}

/// The `q` quantile of sorted `values` by the nearest-rank rule (`None` when empty).
pub fn percentile(sorted: &[f64], q: f64) -> Option<f64> {
    if sorted.is_empty() {
        return None;
    }
    let rank = (q * sorted.len() as f64).ceil().max(1.0) as usize;
    Some(sorted[rank.min(sorted.len()) - 1])
}

fn json<T: Serialize>(value: &T) -> String {
    serde_json::to_value(value)
        .ok()
        .and_then(|v| v.as_str().map(str::to_owned))
        .unwrap_or_default()
}

/// The decision log, one row per candidate (a decision without candidates has one row with
/// empty candidate cells): where and when, every candidate's IG, path length, predicted
/// energy and duration, the choice, and the flown leg of the chosen one.
pub fn decisions_csv(log: &DecisionLog) -> String {
    let mut out = String::from(
        "decision,uav,time_s,x,y,z,clusters,candidate,centroid_x,centroid_y,centroid_z,goal_x,\
         goal_y,goal_z,information_gain,centroid_distance_m,path_length_m,predicted_energy_j,\
         predicted_duration_s,unaffordable,chosen,goal_kind,outcome,flown_energy_j,flown_time_s,\
         prediction_error,flew_candidate\n",
    );
    for (index, d) in log.decisions.iter().enumerate() {
        let head = format!(
            "{index},{},{},{},{},{},{}",
            d.uav, d.time_s, d.position[0], d.position[1], d.position[2], d.clusters
        );
        let kind = d.goal_kind.as_ref().map(json).unwrap_or_default();
        let flown = |chosen: bool| match (&d.flown, chosen) {
            (Some(f), true) => format!(
                "{},{},{},{},{}",
                json(&f.outcome),
                f.energy_j,
                f.time_s,
                f.prediction_error,
                f.flew_candidate
            ),
            _ => ",,,,".to_owned(),
        };
        if d.candidates.is_empty() {
            let _ = writeln!(out, "{head},,,,,,,,,,,,,,,{kind},{}", flown(true));
            continue;
        }
        for (k, c) in d.candidates.iter().enumerate() {
            let chosen = d.chosen == Some(k);
            let _ = writeln!(
                out,
                "{head},{k},{},{},{},{},{},{},{},{},{},{},{},{},{},{kind},{}",
                c.centroid[0],
                c.centroid[1],
                c.centroid[2],
                c.goal[0],
                c.goal[1],
                c.goal[2],
                c.information_gain,
                c.centroid_distance_m,
                c.path_length_m,
                c.predicted_energy_j,
                c.predicted_duration_s,
                c.unaffordable,
                chosen,
                flown(chosen),
            );
        }
    }
    out
}

/// Per-decision timings (ms) split as EAAE Table 6.2: clustering, trajectory generation,
/// energy estimation, and the total.
pub fn decision_timings_csv(timings: &DecisionTimings) -> String {
    let mut out = String::from("decision,clustering_ms,trajectory_ms,energy_ms,total_ms\n");
    for (i, t) in timings.decisions.iter().enumerate() {
        let _ = writeln!(
            out,
            "{i},{},{},{},{}",
            t.clustering_ms, t.trajectory_ms, t.energy_ms, t.total_ms
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use uavex_components::exploration::{
        CandidateRecord, DecisionRecord, DecisionTiming, FlownLeg, GoalKind,
    };

    #[test]
    fn percentiles_by_nearest_rank() {
        let v: Vec<f64> = (1..=20).map(f64::from).collect();
        assert_eq!(percentile(&v, 0.5), Some(10.0));
        assert_eq!(percentile(&v, 0.95), Some(19.0));
        assert_eq!(percentile(&[7.0], 0.95), Some(7.0));
        assert_eq!(percentile(&[], 0.5), None);
    }

    fn candidate(gain: u32, energy: f64) -> CandidateRecord {
        CandidateRecord {
            centroid: [1.0, 2.0, 1.0],
            goal: [1.0, 2.0, 1.0],
            information_gain: gain,
            centroid_distance_m: 2.5,
            path_length_m: 3.0,
            predicted_energy_j: energy,
            predicted_duration_s: 4.0,
            unaffordable: false,
        }
    }

    #[test]
    fn summary_and_csv_of_a_small_log() {
        let log = DecisionLog {
            decisions: vec![
                DecisionRecord {
                    uav: 0,
                    time_s: 0.0,
                    position: [0.0, 0.0, 1.0],
                    clusters: 2,
                    candidates: vec![candidate(100, 500.0), candidate(50, 400.0)],
                    chosen: Some(1),
                    goal_kind: Some(GoalKind::Frontier),
                    flown: Some(FlownLeg {
                        outcome: GoalOutcome::Reached,
                        energy_j: 440.0,
                        time_s: 4.5,
                        prediction_error: 0.1,
                        flew_candidate: false,
                    }),
                },
                DecisionRecord {
                    uav: 0,
                    time_s: 5.0,
                    position: [1.0, 2.0, 1.0],
                    clusters: 1,
                    candidates: vec![candidate(70, 300.0)],
                    chosen: Some(0),
                    goal_kind: Some(GoalKind::Frontier),
                    flown: Some(FlownLeg {
                        outcome: GoalOutcome::Reached,
                        energy_j: 270.0,
                        time_s: 3.0,
                        prediction_error: -0.1,
                        flew_candidate: false,
                    }),
                },
                DecisionRecord {
                    uav: 0,
                    time_s: 8.0,
                    position: [1.0, 2.0, 1.0],
                    clusters: 0,
                    candidates: vec![],
                    chosen: None,
                    goal_kind: None,
                    flown: None,
                },
            ],
        };
        let timings = DecisionTimings {
            decisions: [3.0, 1.0, 2.0]
                .map(|total_ms| DecisionTiming {
                    total_ms,
                    ..Default::default()
                })
                .to_vec(),
            pending_clustering_ms: 0.0,
        };
        let summary = ExplorationSummary::of(&log, &timings);
        assert_eq!(summary.decisions, 2);
        // |0.1| and |-0.1|: mean 0.1.
        assert!((summary.mean_prediction_error.unwrap() - 0.1).abs() < 1e-12);
        assert_eq!(summary.decision_ms_p50, Some(2.0));
        assert_eq!(summary.decision_ms_p95, Some(3.0));

        let csv = decisions_csv(&log);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 1 + 2 + 1 + 1);
        assert_eq!(
            lines[2],
            "0,0,0,0,0,1,2,1,1,2,1,1,2,1,50,2.5,3,400,4,false,true,frontier,reached,440,4.5,0.1,false"
        );
        assert!(
            lines[1].ends_with(",false,false,frontier,,,,,"),
            "{}",
            lines[1]
        );
        assert_eq!(lines[4], format!("2,0,8,1,2,1,0{}", ",".repeat(20)));
        let columns = lines[0].split(',').count();
        assert!(lines.iter().all(|l| l.split(',').count() == columns));
    }
}
