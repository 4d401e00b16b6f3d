//! A picture of a coverage plan (PNG or SVG, by the file's extension): the polygon, the footprint
//! of every shot and the path, with the start marked. No text is drawn, so no font is needed on
//! headless machines.

use super::CoverageIoError;
use glam::DVec2;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use uavex_systems::coverage::MissionPlan;

/// Longest side of the picture (px).
const SIZE: f64 = 1200.0;
const MARGIN: f64 = 20.0;

/// Draws `plan` over `polygon` into `file` (`.png` or `.svg`).
pub fn write_picture(
    polygon: &[DVec2],
    plan: &MissionPlan,
    file: &Path,
) -> Result<(), CoverageIoError> {
    let scene = Scene::new(polygon, plan);
    let size = scene.size();
    let extension = file
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let drawn = match extension.as_deref() {
        Some("png") => png_bytes(&scene, size).and_then(|bytes| {
            std::fs::write(file, bytes).map_err(|e| format!("cannot write: {e}"))
        }),
        Some("svg") => scene.draw(&SVGBackend::new(file, size).into_drawing_area()),
        _ => Err("the picture's file name must end in .png or .svg".to_owned()),
    };
    drawn.map_err(|message| CoverageIoError::Picture {
        path: file.to_owned(),
        message,
    })
}

/// The scene rendered into an RGB buffer and encoded with the plots' PNG encoder (plotters'
/// own file encoder would pull in the `image` crate).
fn png_bytes(scene: &Scene, (w, h): (u32, u32)) -> Result<Vec<u8>, String> {
    let mut pixels = vec![0u8; (w as usize) * (h as usize) * 3];
    scene.draw(&BitMapBackend::with_buffer(&mut pixels, (w, h)).into_drawing_area())?;
    crate::plot::draw::encode_png(&pixels, w, h).map_err(|e| e.to_string())
}

/// The plan's geometry and the mapping from metres to pixels (y up in the world, down in the
/// picture).
struct Scene<'a> {
    polygon: &'a [DVec2],
    plan: &'a MissionPlan,
    lo: DVec2,
    hi: DVec2,
    scale: f64,
}

impl<'a> Scene<'a> {
    fn new(polygon: &'a [DVec2], plan: &'a MissionPlan) -> Self {
        let mut lo = DVec2::INFINITY;
        let mut hi = DVec2::NEG_INFINITY;
        let footprints = footprints(plan);
        let points = polygon
            .iter()
            .chain(plan.path.waypoints.iter().map(|w| &w.position))
            .chain(footprints.iter().flatten());
        for &p in points {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let extent = (hi - lo).max(DVec2::splat(1e-6));
        let scale = (SIZE - 2.0 * MARGIN) / extent.max_element();
        Self {
            polygon,
            plan,
            lo,
            hi,
            scale,
        }
    }

    fn size(&self) -> (u32, u32) {
        let extent = (self.hi - self.lo) * self.scale + 2.0 * MARGIN;
        (
            extent.x.ceil().max(64.0) as u32,
            extent.y.ceil().max(64.0) as u32,
        )
    }

    fn px(&self, p: DVec2) -> (i32, i32) {
        let q = (p - self.lo) * self.scale;
        let height = self.size().1 as f64;
        (
            (MARGIN + q.x).round() as i32,
            (height - MARGIN - q.y).round() as i32,
        )
    }

    fn ring(&self, points: &[DVec2]) -> Vec<(i32, i32)> {
        let mut ring: Vec<(i32, i32)> = points.iter().map(|&p| self.px(p)).collect();
        ring.extend(ring.first().copied());
        ring
    }

    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let text = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        area.fill(&WHITE).map_err(text)?;
        let field = self.ring(self.polygon);
        area.draw(&Polygon::new(field.clone(), RGBColor(222, 240, 216)))
            .map_err(text)?;
        let footprint_fill = RGBColor(40, 90, 200).mix(0.07).filled();
        let footprint_edge = RGBColor(40, 90, 200).mix(0.3).stroke_width(1);
        for corners in footprints(self.plan) {
            let ring = self.ring(&corners);
            area.draw(&Polygon::new(ring.clone(), footprint_fill))
                .map_err(text)?;
            area.draw(&PathElement::new(ring, footprint_edge))
                .map_err(text)?;
        }
        area.draw(&PathElement::new(
            field,
            RGBColor(30, 110, 40).stroke_width(3),
        ))
        .map_err(text)?;
        let path: Vec<(i32, i32)> = self
            .plan
            .path
            .waypoints
            .iter()
            .map(|w| self.px(w.position))
            .collect();
        area.draw(&PathElement::new(
            path,
            RGBColor(210, 40, 30).stroke_width(2),
        ))
        .map_err(text)?;
        for (shot, _) in self.plan.path.shots() {
            area.draw(&Circle::new(
                self.px(shot),
                3,
                RGBColor(20, 40, 120).filled(),
            ))
            .map_err(text)?;
        }
        if let Some(start) = self.plan.path.waypoints.first() {
            area.draw(&Circle::new(self.px(start.position), 8, BLACK.filled()))
                .map_err(text)?;
        }
        area.present().map_err(text)
    }
}

/// The four ground corners of each shot's footprint.
fn footprints(plan: &MissionPlan) -> Vec<[DVec2; 4]> {
    let half = DVec2::new(plan.survey.footprint.l_y, plan.survey.footprint.l_x) / 2.0;
    plan.path
        .shots()
        .map(|(p, along)| {
            let across = along.perp();
            [
                p + along * half.x + across * half.y,
                p - along * half.x + across * half.y,
                p - along * half.x - across * half.y,
                p + along * half.x - across * half.y,
            ]
        })
        .collect()
}
