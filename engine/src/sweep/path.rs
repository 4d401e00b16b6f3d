//! Override paths: a place in a scenario file named the way a plan writes it,
//! `uav.0.behaviour.strategy` (list elements by their index, as a dotted segment) or, as the
//! scenario diagnostics print it, `uav[0].behaviour.strategy`. Both spell the same path.

use std::fmt;
use thiserror::Error;

/// One step of an [`OverridePath`]: a table key or a list index.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Step {
    Key(String),
    Index(usize),
}

/// A path from the top of a scenario file to the value an override replaces.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct OverridePath {
    steps: Vec<Step>,
}

/// A path that cannot name a place in a file.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("`{text}` is not a field path: {why}")]
pub struct PathError {
    pub text: String,
    pub why: &'static str,
}

impl OverridePath {
    /// Reads `uav.0.behaviour.speed` or `uav[0].behaviour.speed`. A segment of digits only is
    /// a list index (no scenario key is a number).
    pub fn parse(text: &str) -> Result<Self, PathError> {
        let error = |why| PathError {
            text: text.to_owned(),
            why,
        };
        let mut steps = Vec::new();
        for part in text.split('.') {
            let (key, mut rest) = match part.find('[') {
                Some(at) => part.split_at(at),
                None => (part, ""),
            };
            if key.is_empty() && rest.is_empty() {
                return Err(error("it has an empty segment"));
            }
            if !key.is_empty() {
                steps.push(match key.parse::<usize>() {
                    Ok(index) if key.bytes().all(|b| b.is_ascii_digit()) => Step::Index(index),
                    _ if key.contains(']') => return Err(error("it has a `]` without `[`")),
                    _ => Step::Key(key.to_owned()),
                });
            }
            while !rest.is_empty() {
                let close = rest.find(']').ok_or_else(|| error("a `[` is not closed"))?;
                let index = rest[1..close]
                    .parse::<usize>()
                    .map_err(|_| error("a list index is not a whole number"))?;
                steps.push(Step::Index(index));
                rest = &rest[close + 1..];
                if !rest.is_empty() && !rest.starts_with('[') {
                    return Err(error("text follows a `]` without a `.`"));
                }
            }
        }
        Ok(Self { steps })
    }

    /// The path made of these steps (empty: the whole file).
    pub fn from_steps(steps: &[Step]) -> Self {
        Self {
            steps: steps.to_vec(),
        }
    }

    /// This path followed by the steps of `tail`.
    pub fn join(&self, tail: &OverridePath) -> Self {
        let mut steps = self.steps.clone();
        steps.extend(tail.steps.iter().cloned());
        Self { steps }
    }

    pub fn steps(&self) -> &[Step] {
        &self.steps
    }

    /// The last key of the path (`speed` for `uav.0.behaviour.speed`), used to name runs.
    pub fn last_key(&self) -> Option<&str> {
        self.steps.iter().rev().find_map(|step| match step {
            Step::Key(key) => Some(key.as_str()),
            Step::Index(_) => None,
        })
    }
}

/// The plan's spelling: `uav.0.behaviour.speed`.
impl fmt::Display for OverridePath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, step) in self.steps.iter().enumerate() {
            if i > 0 {
                f.write_str(".")?;
            }
            match step {
                Step::Key(key) => f.write_str(key)?,
                Step::Index(index) => write!(f, "{index}")?,
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(k: &str) -> Step {
        Step::Key(k.to_owned())
    }

    #[test]
    fn dotted_and_bracketed_indices_are_the_same_path() {
        let dotted = OverridePath::parse("uav.0.behaviour.speed").unwrap();
        let bracketed = OverridePath::parse("uav[0].behaviour.speed").unwrap();
        assert_eq!(dotted, bracketed);
        assert_eq!(
            dotted.steps(),
            [key("uav"), Step::Index(0), key("behaviour"), key("speed")]
        );
        assert_eq!(dotted.to_string(), "uav.0.behaviour.speed");
        assert_eq!(dotted.last_key(), Some("speed"));
    }

    #[test]
    fn nested_list_indices() {
        let path = OverridePath::parse("uav[1].behaviour.waypoints[2][0]").unwrap();
        assert_eq!(path.to_string(), "uav.1.behaviour.waypoints.2.0");
        assert_eq!(path.last_key(), Some("waypoints"));
    }

    #[test]
    fn malformed_paths_are_refused() {
        for text in ["", "a..b", "uav[0", "uav[x].b", "uav[0]b", "a]"] {
            assert!(OverridePath::parse(text).is_err(), "{text:?} was accepted");
        }
    }

    #[test]
    fn join_appends() {
        let a = OverridePath::parse("world").unwrap();
        let b = OverridePath::parse("obstacle.3.center").unwrap();
        assert_eq!(a.join(&b).to_string(), "world.obstacle.3.center");
    }
}
