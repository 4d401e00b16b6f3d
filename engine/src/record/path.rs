//! The path each UAV flew, kept in stretches of [`SEGMENT_S`] of simulated time for the
//! recording (plain data, built without the `record` feature).
//!
//! Why stretches: rerun shows the latest value of an entity, so a path logged as one strip
//! would be re-sent whole at every log, quadratic in the mission's length. A stretch is re-sent
//! only while it is being flown, then stays as it was.

use glam::Vec3;

/// A path point every this many metres flown (the map's resolution in the shipped scenes).
pub const PATH_STEP_M: f32 = 0.1;
/// Simulated time covered by one path strip (s).
pub const SEGMENT_S: f64 = 10.0;

/// The path of one UAV, kept in stretches, and which stretches are still to be logged.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FlownPath {
    /// The stretch being flown and its points.
    segment: usize,
    points: Vec<[f32; 3]>,
    /// Stretches ended since the last log: logged once more, complete, then never again.
    ended: Vec<(usize, Vec<[f32; 3]>)>,
    last: Option<Vec3>,
}

impl FlownPath {
    /// The UAV is at `position` at `time_s`: a new point once it moved [`PATH_STEP_M`].
    pub fn note(&mut self, time_s: f64, position: Vec3) {
        let segment = (time_s / SEGMENT_S).floor().max(0.0) as usize;
        if segment != self.segment {
            // The new stretch starts where the old one ends, so the path stays connected.
            let start = self.points.last().copied();
            let ended = std::mem::replace(&mut self.points, start.into_iter().collect());
            if ended.len() > 1 {
                self.ended.push((self.segment, ended));
            }
            self.segment = segment;
        }
        if self
            .last
            .is_none_or(|last| last.distance(position) >= PATH_STEP_M)
        {
            self.points.push(position.to_array());
            self.last = Some(position);
        }
    }

    /// The stretches to log now: those ended since the last call, and the current one.
    pub fn take_for_log(&mut self) -> Vec<(usize, Vec<[f32; 3]>)> {
        let mut stretches = std::mem::take(&mut self.ended);
        if !self.points.is_empty() {
            stretches.push((self.segment, self.points.clone()));
        }
        stretches
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_keep_a_point_per_step_and_connect_their_stretches() {
        let mut path = FlownPath::default();
        path.note(0.0, Vec3::ZERO);
        path.note(1.0, Vec3::new(0.05, 0.0, 0.0)); // under a step: no point
        path.note(2.0, Vec3::new(0.2, 0.0, 0.0));
        assert_eq!(
            path.take_for_log(),
            vec![(0, vec![[0.0; 3], [0.2, 0.0, 0.0]])]
        );
        path.note(10.5, Vec3::new(0.5, 0.0, 0.0));
        path.note(21.0, Vec3::new(1.0, 0.0, 0.0));
        // Stretch 0 ended at 10.5 s, stretch 1 at 21 s: both complete, then the current one.
        assert_eq!(
            path.take_for_log(),
            vec![
                (0, vec![[0.0; 3], [0.2, 0.0, 0.0]]),
                (1, vec![[0.2, 0.0, 0.0], [0.5, 0.0, 0.0]]),
                (2, vec![[0.5, 0.0, 0.0], [1.0, 0.0, 0.0]]),
            ]
        );
        assert_eq!(
            path.take_for_log(),
            vec![(2, vec![[0.5, 0.0, 0.0], [1.0, 0.0, 0.0]])]
        );
    }
}
