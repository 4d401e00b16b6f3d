//! The time allocation's search for the scale of the segment durations at which the binding
//! limit is just met (Richter, Bry & Roy 2013, §III-C: scale the time until the limits hold).
//!
//! Let `s` scale every duration and `r(s)` be the trajectory's worst excess ratio
//! `max(v/vmax, sqrt(a/amax), yaw rate/max_yaw_rate)` (`super::limits`, `super::yaw_rate`). From rest `r` falls exactly as `1/s`, so the
//! fixed-point step `s <- s r(s)` lands on `r = 1` in one round. From a moving start it does
//! not: the start velocity, acceleration and jerk do not scale with the durations, `r` falls
//! more slowly than `1/s`, and the fixed-point steps creep toward the limit (ratios 1.27,
//! 1.149, 1.085, 1.048, ...: each excess about 0.58 of the last; 13 rounds of a solve and a
//! peak search on average in the Pillars decisions, up to 30, and plans still converging
//! given up after 30 rounds). In
//! `x = ln s`, `g = ln r` is nearly linear over the steps taken, so a secant step lands close
//! to the root in a round or two. The search:
//!
//! 1. the first round as before: accept `r <= 1` (the tightening of `super::planner` then
//!    moves onto the limit), else the fixed-point step;
//! 2. while the limits are exceeded, a secant step through the last two rounds toward the
//!    middle of the window `1 - TOLERANCE <= r <= 1`, at least the fixed-point step and at
//!    most [`MAX_STRETCH`] times it; if the ratio rose although the durations grew, the
//!    fixed-point step, and after [`RISES_TO_GIVE_UP`] such rounds in a row the search gives
//!    up (more time does not lower the peaks: the start's motion, not the durations, sets
//!    them, and the durations would grow until the system is singular);
//! 3. a step that overshoots below the window brackets the root: false position between the
//!    last round above the limit and the first below the window, kept inside the bracket,
//!    until a round lands in the window (after [`BRACKET_ROUNDS`] of them, any `r <= 1`).

/// Ratios are pushed this far below 1 so that rounding never leaves a peak a hair above a limit.
pub const MARGIN: f64 = 1.0 + 1e-6;
/// Width of the window below the limit a re-timed trajectory may end in.
pub const TOLERANCE: f64 = 1e-3;
/// Largest secant step, in multiples of the fixed-point step.
pub const MAX_STRETCH: f64 = 10.0;
/// Rounds in a row whose ratio rose as the durations grew before the search gives up.
pub const RISES_TO_GIVE_UP: u32 = 2;
/// Rounds of false position inside a bracket before any ratio within the limits is accepted.
pub const BRACKET_ROUNDS: u32 = 6;

/// What to do after a round.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step {
    /// The durations just measured meet the limits: keep them.
    Accept,
    /// Multiply every duration by this factor and measure again.
    Scale(f64),
    /// The limits cannot be met by scaling the durations.
    GiveUp,
}

/// A round's point: `x = ln s` and `g = ln r`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Round {
    x: f64,
    g: f64,
}

/// The search's state over the rounds of one time allocation (module doc).
#[derive(Debug, Clone, Default)]
pub struct ScaleSearch {
    /// `ln` of the scale applied to the initial durations so far.
    x: f64,
    /// The last round above the limits.
    above: Option<Round>,
    /// The first round below the window, once a step overshot it.
    below: Option<Round>,
    rises: u32,
    bracket_rounds: u32,
}

impl ScaleSearch {
    pub fn new() -> Self {
        Self::default()
    }

    /// The next step, given the worst ratio `worst` of the durations scaled as told so far.
    pub fn step(&mut self, worst: f64) -> Step {
        if !(worst.is_finite() && worst > 0.0) {
            return Step::GiveUp;
        }
        let here = Round {
            x: self.x,
            g: worst.ln(),
        };
        let settled = self.bracket_rounds >= BRACKET_ROUNDS;
        if worst <= 1.0 {
            if self.above.is_none() || worst >= 1.0 - TOLERANCE || settled {
                return Step::Accept;
            }
            self.below = Some(here);
            return self.bracketed();
        }
        if self.below.is_some() {
            if settled {
                // Back to the round known to hold the limits.
                let below = self.below.expect("checked");
                return self.move_to(below.x);
            }
            self.above = Some(here);
            return self.bracketed();
        }
        let fixed_point = (worst * MARGIN).ln();
        let stride = match self.above.replace(here) {
            None => {
                self.x += fixed_point;
                return Step::Scale(worst * MARGIN);
            }
            Some(previous) if here.g >= previous.g => {
                self.rises += 1;
                if self.rises >= RISES_TO_GIVE_UP {
                    return Step::GiveUp;
                }
                fixed_point
            }
            Some(previous) => {
                self.rises = 0;
                let slope = (here.g - previous.g) / (here.x - previous.x);
                let secant = (here.g - target()) / -slope;
                secant.clamp(fixed_point, MAX_STRETCH * fixed_point)
            }
        };
        self.move_to(self.x + stride)
    }

    /// False position between the bracket's ends toward the window's middle, kept off the ends.
    fn bracketed(&mut self) -> Step {
        self.bracket_rounds += 1;
        let (above, below) = (
            self.above.expect("a bracket has an end above"),
            self.below.expect("a bracket has an end below"),
        );
        let fraction = ((above.g - target()) / (above.g - below.g)).clamp(0.1, 0.9);
        self.move_to(above.x + fraction * (below.x - above.x))
    }

    fn move_to(&mut self, x: f64) -> Step {
        let factor = (x - self.x).exp();
        self.x = x;
        Step::Scale(factor)
    }
}

/// `ln r` the secant and false-position steps aim at: the middle of the window.
fn target() -> f64 {
    (1.0 - 0.5 * TOLERANCE).ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs the search on `ratio(s)`, returning the accepted scale and the rounds taken, or
    /// `None` if it gave up or took more than 30 rounds.
    fn search(ratio: impl Fn(f64) -> f64) -> Option<(f64, usize)> {
        let mut search = ScaleSearch::new();
        let mut scale = 1.0;
        for round in 1..=30 {
            match search.step(ratio(scale)) {
                Step::Accept => return Some((scale, round)),
                Step::Scale(factor) => scale *= factor,
                Step::GiveUp => return None,
            }
        }
        None
    }

    #[test]
    fn from_rest_one_fixed_point_step_lands_on_the_limit() {
        // r = 1.8 / s: the fixed-point step s = 1.8 (1 + 1e-6) gives r = 1 / (1 + 1e-6).
        let (scale, rounds) = search(|s| 1.8 / s).expect("accepted");
        assert_eq!(rounds, 2);
        assert!((scale - 1.8 * MARGIN).abs() < 1e-12);
    }

    #[test]
    fn already_within_the_limits_is_accepted_at_once() {
        assert_eq!(search(|s| 0.5 / s), Some((1.0, 1)));
    }

    /// Rounds the fixed-point iteration `s <- s r(s) MARGIN` takes to reach `r <= 1`.
    fn fixed_point_rounds(ratio: impl Fn(f64) -> f64) -> usize {
        let mut scale = 1.0;
        (1..)
            .find(|_| {
                let r = ratio(scale);
                scale *= r * MARGIN;
                r <= 1.0
            })
            .expect("an unbounded range")
    }

    /// A moving start: the velocity's part of the peak does not scale, as in `r(s) = c / s^e`
    /// with `e < 1`, where each fixed-point step leaves `1 - e` of the excess (in logs): 13 to
    /// 50 rounds here, against a few for the secant search.
    #[test]
    fn a_slowly_falling_ratio_is_reached_in_a_few_rounds() {
        for (c, e, fixed_point) in [(1.3, 0.42, 24), (1.05, 0.2, 50), (2.0, 0.7, 13)] {
            let ratio = |s: f64| c / s.powf(e);
            assert_eq!(fixed_point_rounds(ratio), fixed_point, "c {c} e {e}");
            let (scale, rounds) = search(ratio).expect("accepted");
            let r = ratio(scale);
            assert!((1.0 - TOLERANCE..=1.0).contains(&r), "c {c} e {e}: r {r}");
            assert!(rounds <= 5, "c {c} e {e}: {rounds} rounds");
        }
        // Falling faster than 1/s: the fixed-point step overshoots, and is brought back.
        let ratio = |s: f64| 1.5 / s.powf(1.3);
        let (scale, rounds) = search(ratio).expect("accepted");
        assert!(
            ratio(scale) >= 1.0 - TOLERANCE && rounds <= 6,
            "{rounds} rounds"
        );
    }

    /// The peaks of a velocity part that does not scale plus one that does: `r` is not a
    /// power of `s`, and steps past the root are brought back inside the window.
    #[test]
    fn an_overshoot_is_brought_back_into_the_window() {
        let ratio = |s: f64| 0.95 + 0.6 / (s * s * s);
        let (scale, rounds) = search(ratio).expect("accepted");
        let r = ratio(scale);
        assert!(
            (1.0 - TOLERANCE..=1.0).contains(&r),
            "r {r} after {rounds} rounds"
        );
        assert!(rounds <= 10, "{rounds} rounds");
    }

    #[test]
    fn a_ratio_that_rises_with_more_time_is_given_up() {
        // Falls to a minimum of 1.02 at s = 2, then rises: no scale meets the limits.
        let ratio = |s: f64| 1.02 + 0.05 * (s - 2.0).powi(2);
        assert_eq!(search(ratio), None);
        let mut search = ScaleSearch::new();
        let steps: Vec<Step> = [1.2, 1.1, 1.15, 1.3].map(|r| search.step(r)).to_vec();
        assert!(matches!(
            steps[..3],
            [Step::Scale(_), Step::Scale(_), Step::Scale(_)]
        ));
        assert_eq!(steps[3], Step::GiveUp);
    }

    #[test]
    fn non_finite_ratios_are_given_up() {
        assert_eq!(ScaleSearch::new().step(f64::NAN), Step::GiveUp);
        assert_eq!(ScaleSearch::new().step(f64::INFINITY), Step::GiveUp);
    }
}
