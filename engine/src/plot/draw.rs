//! Figures drawn with plotters, each on any backend, saved as PNG and SVG.
//!
//! Text is set in DejaVu Sans, compiled into the binary and registered with plotters'
//! `ab_glyph` font support, so figures render the same on a fresh machine with no system fonts.

use super::PlotError;
use super::series::Band;
use crate::output::write_atomically;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Once;

/// Figure size in pixels (PNG) and user units (SVG).
pub const PANEL_SIZE: (u32, u32) = (640, 420);

/// Tableau's ten categorical colours: distinct, and readable in print.
const COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

pub fn colour(i: usize) -> RGBColor {
    COLOURS[i % COLOURS.len()]
}

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are a valid TrueType font (the dejavu crate ships the release files).
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

fn draw_error(e: impl std::fmt::Display) -> PlotError {
    PlotError::Draw(e.to_string())
}

/// Something that draws itself on one or more panels side by side.
pub trait Figure {
    /// Number of panels, laid out in one row.
    fn panels(&self) -> usize;
    fn draw_panel<DB: DrawingBackend>(
        &self,
        panel: usize,
        area: &DrawingArea<DB, Shift>,
    ) -> Result<(), PlotError>;
}

fn draw_all<DB: DrawingBackend>(
    figure: &impl Figure,
    root: DrawingArea<DB, Shift>,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(draw_error)?;
    let areas = root.split_evenly((1, figure.panels().max(1)));
    for (i, area) in areas.iter().enumerate().take(figure.panels()) {
        figure.draw_panel(i, area)?;
    }
    root.present().map_err(draw_error)
}

/// Saves `figure` as `<stem>.png` and `<stem>.svg`; returns the two paths.
pub fn save(figure: &impl Figure, stem: &Path) -> Result<Vec<PathBuf>, PlotError> {
    register_font();
    let (w, h) = (PANEL_SIZE.0 * figure.panels().max(1) as u32, PANEL_SIZE.1);
    let png_path = stem.with_extension("png");
    let pixels = render_rgb(figure, (w, h))?;
    write_atomically(&png_path, &encode_png(&pixels, w, h)?).map_err(|e| PlotError::Io {
        path: png_path.clone(),
        source: e,
    })?;

    let svg_path = stem.with_extension("svg");
    let mut svg = String::new();
    draw_all(
        figure,
        SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area(),
    )?;
    write_atomically(&svg_path, svg.as_bytes()).map_err(|e| PlotError::Io {
        path: svg_path.clone(),
        source: e,
    })?;
    Ok(vec![png_path, svg_path])
}

/// The figure as RGB pixels, row by row.
pub fn render_rgb(figure: &impl Figure, (w, h): (u32, u32)) -> Result<Vec<u8>, PlotError> {
    register_font();
    let mut pixels = vec![0u8; (w * h * 3) as usize];
    draw_all(
        figure,
        BitMapBackend::with_buffer(&mut pixels, (w, h)).into_drawing_area(),
    )?;
    Ok(pixels)
}

/// 8-bit RGB pixels (row by row) as PNG bytes, with the `png` crate (no `image` crate).
pub fn encode_png(rgb: &[u8], w: u32, h: u32) -> Result<Vec<u8>, PlotError> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(draw_error)?;
    writer.write_image_data(rgb).map_err(draw_error)?;
    writer.finish().map_err(draw_error)?;
    Ok(bytes)
}

/// A value range with a little room around it (a flat range gets a unit height).
fn padded(low: f64, high: f64) -> (f64, f64) {
    if !(low.is_finite() && high.is_finite()) {
        return (0.0, 1.0);
    }
    let span = high - low;
    if span <= f64::EPSILON * high.abs().max(1.0) {
        return (low - 0.5, high + 0.5);
    }
    (low - 0.05 * span, high + 0.05 * span)
}

/// Labels for the ticks of an axis over `low..high`: as many decimals as its ticks (about ten
/// over the span, at 1, 2 or 5 times a power of ten) need, trailing zeros dropped, so that
/// energies read "55000", not "55000.0", and fractions keep the digits that tell ticks apart.
fn tick_labels(low: f64, high: f64) -> impl Fn(&f64) -> String {
    let step = (high - low).abs() / 10.0;
    let decimals = if step.is_finite() && step > 0.0 {
        // One more than the step's first digit needs: ticks at 2.5 times a power of ten.
        (1.0 - step.log10().floor()).clamp(0.0, 12.0) as usize
    } else {
        3
    };
    move |v: &f64| {
        let text = format!("{v:.decimals$}");
        let text = if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.')
        } else {
            &text
        };
        // "-0" reads as zero.
        if text == "-0" { "0" } else { text }.to_owned()
    }
}

/// One panel of curves: each group's mean line and its band.
pub struct BandPanel {
    pub title: String,
    pub groups: Vec<(String, Band)>,
}

/// Curves over time, one panel per scene.
pub struct BandFigure {
    pub y_label: String,
    pub panels: Vec<BandPanel>,
}

impl Figure for BandFigure {
    fn panels(&self) -> usize {
        self.panels.len()
    }

    fn draw_panel<DB: DrawingBackend>(
        &self,
        panel: usize,
        area: &DrawingArea<DB, Shift>,
    ) -> Result<(), PlotError> {
        let p = &self.panels[panel];
        let bands = p.groups.iter().map(|(_, b)| b);
        let t_end = bands
            .clone()
            .filter_map(|b| b.times.last().copied())
            .fold(0.0, f64::max);
        let low = bands
            .clone()
            .flat_map(|b| b.low.iter().copied())
            .fold(f64::INFINITY, f64::min);
        let high = bands
            .flat_map(|b| b.high.iter().copied())
            .fold(f64::NEG_INFINITY, f64::max);
        let (y0, y1) = padded(low, high);
        let mut chart = ChartBuilder::on(area)
            .caption(&p.title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d(0.0..t_end.max(1e-9), y0..y1)
            .map_err(draw_error)?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc(self.y_label.as_str())
            .x_label_formatter(&tick_labels(0.0, t_end))
            .y_label_formatter(&tick_labels(y0, y1))
            .label_style(("sans-serif", 12))
            .draw()
            .map_err(draw_error)?;
        for (i, (label, band)) in p.groups.iter().enumerate() {
            let c = colour(i);
            let outline: Vec<(f64, f64)> = band
                .times
                .iter()
                .zip(&band.high)
                .map(|(t, v)| (*t, *v))
                .chain(
                    band.times
                        .iter()
                        .zip(&band.low)
                        .rev()
                        .map(|(t, v)| (*t, *v)),
                )
                .collect();
            chart
                .draw_series(std::iter::once(Polygon::new(outline, c.mix(0.18).filled())))
                .map_err(draw_error)?;
            let mean = band.times.iter().copied().zip(band.mean.iter().copied());
            chart
                .draw_series(LineSeries::new(mean, c.stroke_width(2)))
                .map_err(draw_error)?
                .label(label.as_str())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2))
                });
        }
        // The legend goes in the right-hand corner the curves end away from.
        let ends: Vec<f64> = p
            .groups
            .iter()
            .filter_map(|(_, b)| b.mean.last().copied())
            .collect();
        let end_mean = ends.iter().sum::<f64>() / ends.len().max(1) as f64;
        let corner = if end_mean < (y0 + y1) / 2.0 {
            SeriesLabelPosition::UpperRight
        } else {
            SeriesLabelPosition::LowerRight
        };
        chart
            .configure_series_labels()
            .position(corner)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.4))
            .label_font(("sans-serif", 12))
            .draw()
            .map_err(draw_error)
    }
}

/// One panel of per-run values: a column of points per group, with its mean as a bar.
pub struct StripPanel {
    pub title: String,
    pub groups: Vec<(String, Vec<f64>)>,
}

/// Per-run values of one metric, one panel per scene.
pub struct StripFigure {
    /// What the groups differ by (empty: no axis title).
    pub x_label: String,
    pub y_label: String,
    pub panels: Vec<StripPanel>,
}

/// Horizontal offset of point `k` of `n` in a strip: spread evenly, deterministic.
pub fn strip_offset(k: usize, n: usize) -> f64 {
    if n <= 1 {
        return 0.0;
    }
    -0.15 + 0.3 * k as f64 / (n - 1) as f64
}

impl Figure for StripFigure {
    fn panels(&self) -> usize {
        self.panels.len()
    }

    fn draw_panel<DB: DrawingBackend>(
        &self,
        panel: usize,
        area: &DrawingArea<DB, Shift>,
    ) -> Result<(), PlotError> {
        let p = &self.panels[panel];
        let all = p.groups.iter().flat_map(|(_, v)| v.iter().copied());
        let low = all.clone().fold(f64::INFINITY, f64::min);
        let high = all.fold(f64::NEG_INFINITY, f64::max);
        let (y0, y1) = padded(low, high);
        let n = p.groups.len();
        let labels: Vec<String> = p.groups.iter().map(|(l, _)| l.clone()).collect();
        let name_of = move |x: &f64| {
            let i = x.round();
            if (x - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < labels.len() {
                labels[i as usize].clone()
            } else {
                String::new()
            }
        };
        let mut chart = ChartBuilder::on(area)
            .caption(&p.title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d(-0.5..(n as f64 - 0.5), y0..y1)
            .map_err(draw_error)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(n.max(1))
            .x_label_formatter(&name_of)
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .y_label_formatter(&tick_labels(y0, y1))
            .label_style(("sans-serif", 12))
            .draw()
            .map_err(draw_error)?;
        for (i, (_, values)) in p.groups.iter().enumerate() {
            let c = colour(i);
            let x = i as f64;
            chart
                .draw_series(values.iter().enumerate().map(|(k, v)| {
                    Circle::new((x + strip_offset(k, values.len()), *v), 4, c.filled())
                }))
                .map_err(draw_error)?;
            if !values.is_empty() {
                let mean = values.iter().sum::<f64>() / values.len() as f64;
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(x - 0.25, mean), (x + 0.25, mean)],
                        BLACK.stroke_width(2),
                    )))
                    .map_err(draw_error)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::plot::series::Band;

    #[test]
    fn tick_labels_keep_the_digits_their_ticks_need() {
        let energy = tick_labels(27_000.0, 50_000.0);
        assert_eq!(
            [energy(&30_000.0), energy(&45_000.0), energy(&27_500.0)],
            ["30000", "45000", "27500"]
        );
        let fraction = tick_labels(0.9960, 0.9976);
        assert_eq!(
            [fraction(&0.9965), fraction(&0.997), fraction(&0.99725)],
            ["0.9965", "0.997", "0.99725"]
        );
        let percent = tick_labels(0.0, 100.0);
        assert_eq!(
            [percent(&0.0), percent(&25.0), percent(&-0.0)],
            ["0", "25", "0"]
        );
        let small = tick_labels(0.0, 1.0);
        assert_eq!([small(&0.25), small(&0.5)], ["0.25", "0.5"]);
    }

    #[test]
    fn text_is_drawn_with_the_bundled_font() {
        let band = Band {
            times: vec![0.0, 1.0, 2.0],
            mean: vec![1.0, 2.0, 3.0],
            low: vec![0.5, 1.5, 2.5],
            high: vec![1.5, 2.5, 3.5],
        };
        let figure = BandFigure {
            y_label: "value".to_owned(),
            panels: vec![BandPanel {
                title: "A title".to_owned(),
                groups: vec![("group".to_owned(), band)],
            }],
        };
        let (w, h) = PANEL_SIZE;
        let pixels = render_rgb(&figure, (w, h)).unwrap();
        let dark = |rows: std::ops::Range<u32>, cols: std::ops::Range<u32>| {
            rows.flat_map(|y| cols.clone().map(move |x| (x, y)))
                .filter(|&(x, y)| {
                    let at = ((y * w + x) * 3) as usize;
                    pixels[at..at + 3].iter().all(|&c| c < 100)
                })
                .count()
        };
        // The caption is centred at the top; nothing else is drawn in that strip.
        let title = dark(4..30, w / 2 - 60..w / 2 + 60);
        assert!(title > 40, "{title} dark pixels where the title should be");
        assert_eq!(dark(4..30, 0..60), 0, "the top-left corner is blank");
        // The mean line is drawn in the first colour.
        let c = colour(0);
        let blue = pixels
            .chunks(3)
            .filter(|p| p[0] == c.0 && p[1] == c.1 && p[2] == c.2)
            .count();
        assert!(blue > 100, "{blue} pixels of the mean line");
    }

    #[test]
    fn padding_and_offsets() {
        assert_eq!(padded(0.0, 10.0), (-0.5, 10.5));
        assert_eq!(padded(3.0, 3.0), (2.5, 3.5));
        assert_eq!(padded(f64::INFINITY, f64::NEG_INFINITY), (0.0, 1.0));
        assert_eq!(strip_offset(0, 1), 0.0);
        assert_eq!(strip_offset(0, 3), -0.15);
        assert!((strip_offset(2, 3) - 0.15).abs() < 1e-12);
    }
}
