//! Colour scales of the recording: candidate trajectories by predicted energy, occupied voxels
//! by height. Plain functions of numbers to sRGB, so they are tested (and compiled) without the
//! `record` feature.

/// An sRGB colour with alpha.
pub type Rgba = [u8; 4];

/// A colour scale: sRGB stops spaced evenly over [0, 1], linearly interpolated between them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Palette(&'static [[u8; 3]]);

impl Palette {
    /// Predicted energy, cheap to costly: ColorBrewer's RdYlGn reversed (green, yellow, red),
    /// the reading of a cost every viewer already knows.
    pub const ENERGY: Palette = Palette(&[
        [26, 150, 65],
        [166, 217, 106],
        [255, 255, 191],
        [253, 174, 97],
        [215, 25, 28],
    ]);

    /// Height of occupied voxels, floor to ceiling: viridis (as octovis colours its maps by
    /// height), distinct from the energy scale so voxels are never read as costs.
    pub const HEIGHT: Palette = Palette(&[
        [68, 1, 84],
        [59, 82, 139],
        [33, 145, 140],
        [94, 201, 98],
        [253, 231, 37],
    ]);

    /// The colour at `fraction` of the scale, clamped to [0, 1]; NaN takes the low end.
    pub fn at(&self, fraction: f64) -> Rgba {
        let stops = self.0;
        let Some(last) = stops.len().checked_sub(1) else {
            return [0, 0, 0, 255];
        };
        let x = if fraction.is_nan() {
            0.0
        } else {
            fraction.clamp(0.0, 1.0) * last as f64
        };
        let i = (x.floor() as usize).min(last.saturating_sub(1));
        let t = x - i as f64;
        let (a, b) = (stops[i], stops[(i + 1).min(last)]);
        let mix = |k: usize| (f64::from(a[k]) + t * (f64::from(b[k]) - f64::from(a[k]))).round();
        [mix(0) as u8, mix(1) as u8, mix(2) as u8, 255]
    }
}

/// Maps values onto [0, 1] between the least and the largest of a set: each decision's
/// candidates span the whole energy scale, so the cheapest is always green and the costliest
/// red, whatever the magnitudes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span {
    pub low: f64,
    pub high: f64,
}

impl Span {
    /// The span of the finite values of `values`; `None` if there is none.
    pub fn of(values: impl IntoIterator<Item = f64>) -> Option<Span> {
        values
            .into_iter()
            .filter(|v| v.is_finite())
            .fold(None, |span: Option<Span>, v| {
                Some(span.map_or(Span { low: v, high: v }, |s| Span {
                    low: s.low.min(v),
                    high: s.high.max(v),
                }))
            })
    }

    /// Where `value` lies in the span (clamped); 0 when the span is a single value.
    pub fn fraction(&self, value: f64) -> f64 {
        let width = self.high - self.low;
        if width > 0.0 {
            ((value - self.low) / width).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Red minus green: rises from the cheap (green) to the costly (red) end of the scale.
    fn redness(c: Rgba) -> i32 {
        i32::from(c[0]) - i32::from(c[1])
    }

    #[test]
    fn energy_scale_runs_from_green_to_red() {
        let scale = Palette::ENERGY;
        assert_eq!(scale.at(0.0), [26, 150, 65, 255]);
        assert_eq!(scale.at(0.5), [255, 255, 191, 255]);
        assert_eq!(scale.at(1.0), [215, 25, 28, 255]);
        // Halfway between the first two stops.
        assert_eq!(scale.at(0.125), [96, 184, 86, 255]);
        let reds: Vec<i32> = (0..=100)
            .map(|i| redness(scale.at(f64::from(i) / 100.0)))
            .collect();
        assert!(reds.windows(2).all(|w| w[0] < w[1]), "{reds:?}");
    }

    #[test]
    fn out_of_range_fractions_clamp() {
        let scale = Palette::ENERGY;
        assert_eq!(scale.at(-3.0), scale.at(0.0));
        assert_eq!(scale.at(7.0), scale.at(1.0));
        assert_eq!(scale.at(f64::NAN), scale.at(0.0));
        assert_eq!(Palette::HEIGHT.at(1.0), [253, 231, 37, 255]);
    }

    #[test]
    fn spans_map_the_cheapest_to_zero_and_the_costliest_to_one() {
        let span = Span::of([900.0, 300.0, f64::NAN, 600.0]).unwrap();
        assert_eq!(
            span,
            Span {
                low: 300.0,
                high: 900.0
            }
        );
        assert_eq!(span.fraction(300.0), 0.0);
        assert_eq!(span.fraction(600.0), 0.5);
        assert_eq!(span.fraction(900.0), 1.0);
        assert_eq!(span.fraction(1200.0), 1.0);
        // One candidate (or all equal): the cheap end.
        assert_eq!(Span::of([42.0]).unwrap().fraction(42.0), 0.0);
        assert_eq!(Span::of([f64::INFINITY]), None);
    }
}
