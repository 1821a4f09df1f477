//! Contour pictures of a per-particle field on the deformed mesh of a frame, like the seed
//! paper's Figs 12, 17 and 20: every triangle filled with the field interpolated linearly
//! between its vertices (each pixel centre coloured from its barycentric coordinates), the
//! body's outline, the mesh when its triangles are large enough to see, the rigid bodies (grey,
//! outlined), axes in metres at equal scale over the window (`super::window`), and a colour bar
//! with the field's minimum and maximum: viridis, or blue–white–red about zero for a field of
//! both signs.

use std::collections::BTreeMap;
use std::path::Path;

use plotters::prelude::*;

use super::colour_map::{colour_map, diverging_colour_map};
use super::font::FAMILY;
use super::frame::Frame;
use super::numbers::short;
use super::picture::{save, Area, Drawn};
use super::window::{clip_polygon, clip_segment, Window};
use super::PlotError;

/// Width and height in pixels of a contour picture.
pub const CONTOUR_SIZE: (u32, u32) = (1100, 800);
/// Width in pixels of the colour bar strip at the right edge of a contour picture; the mesh is
/// drawn left of it.
pub const COLOUR_BAR_WIDTH: u32 = 180;

const MARGIN: u32 = 20;
const X_LABELS: u32 = 50;
const Y_LABELS: u32 = 85;
/// Interior mesh lines are drawn when the mean edge is at least this long on screen.
const MESH_LINES_FROM_PX: f64 = 10.0;
/// Colour steps of the colour bar.
const BAR_STEPS: usize = 256;

/// A field to draw and the words to call it by.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Spec {
    /// Name of the field in the frame file (`/point_data/NAME`) and of the picture.
    pub field: &'static str,
    /// Title text, with the unit.
    pub label: &'static str,
    /// Whether a frame without this field is an error rather than a picture fewer.
    pub required: bool,
}

/// The contour pictures of a run, in drawing order.
pub(crate) const CONTOURS: [Spec; 4] = [
    Spec {
        field: "incremental_displacement",
        label: "|Δu|, incremental displacement (m)",
        required: false,
    },
    Spec {
        field: "eps_q",
        label: "εq, accumulated plastic strain",
        required: true,
    },
    Spec {
        field: "sigma_yy",
        label: "σyy, vertical stress (Pa)",
        required: true,
    },
    Spec {
        field: "tau_xy",
        label: "τxy, shear stress (Pa)",
        required: true,
    },
];

/// Smallest and largest finite value; `None` when there is none.
fn finite_range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.filter(|v| v.is_finite()).fold(None, |r, v| match r {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// Axis ranges of a plot `width` x `height` pixels showing `window` (with 3 % to spare) at
/// equal scale in x and y, centred.
fn equal_scale_ranges(window: &Window, width: f64, height: f64) -> ((f64, f64), (f64, f64)) {
    let (x, y) = ((window.x0, window.x1), (window.y0, window.y1));
    let size = (x.1 - x.0).max(y.1 - y.0);
    let size = if size > 0.0 { size } else { 1.0 };
    let pad = 0.03 * size;
    let metres_per_px = ((x.1 - x.0 + 2.0 * pad) / width).max((y.1 - y.0 + 2.0 * pad) / height);
    let centred = |(lo, hi): (f64, f64), px: f64| {
        let mid = 0.5 * (lo + hi);
        let half = 0.5 * px * metres_per_px;
        (mid - half, mid + half)
    };
    (centred(x, width), centred(y, height))
}

/// How the values map to colours: viridis over [lo, hi], or for a field of both signs the
/// diverging scale over [-m, m], m the larger magnitude, so that white is zero.
#[derive(Debug, Clone, Copy)]
struct Scale {
    lo: f64,
    hi: f64,
    diverging: bool,
}

impl Scale {
    fn of(lo: f64, hi: f64) -> Scale {
        if lo < 0.0 && hi > 0.0 {
            let m = hi.max(-lo);
            Scale {
                lo: -m,
                hi: m,
                diverging: true,
            }
        } else {
            Scale {
                lo,
                hi,
                diverging: false,
            }
        }
    }

    fn colour(&self, v: f64) -> RGBColor {
        let t = if self.hi > self.lo {
            (v - self.lo) / (self.hi - self.lo)
        } else {
            0.5
        };
        let [r, g, b] = if self.diverging {
            diverging_colour_map(t)
        } else {
            colour_map(t)
        };
        RGBColor(r, g, b)
    }
}

/// What a contour picture shows besides the field: the part of the plane, and the rigid
/// bodies' outlines there.
pub(crate) struct View<'a> {
    pub window: Window,
    pub bodies: &'a [Vec<[f64; 2]>],
}

/// Fill and outline of the rigid bodies.
const BODY_FILL: RGBColor = RGBColor(200, 200, 200);
pub(crate) const BODY_LINE: RGBColor = RGBColor(60, 60, 60);

/// Maps metres to continuous pixel coordinates the way plotters places points: pixel `i`
/// holds the points that map into [i, i + 1).
struct ToPixels {
    x: (f64, f64),
    y: (f64, f64),
    px: (f64, f64),
    py: (f64, f64),
}

impl ToPixels {
    fn new(
        x: (f64, f64),
        y: (f64, f64),
        cols: std::ops::Range<i32>,
        rows: std::ops::Range<i32>,
    ) -> Self {
        ToPixels {
            x,
            y,
            px: (f64::from(cols.start), f64::from(cols.end - 1)),
            py: (f64::from(rows.end - 1), f64::from(rows.start)),
        }
    }

    fn map(&self, p: [f64; 2]) -> [f64; 2] {
        let tx = (p[0] - self.x.0) / (self.x.1 - self.x.0);
        let ty = (p[1] - self.y.0) / (self.y.1 - self.y.0);
        [
            self.px.0 + (self.px.1 - self.px.0) * tx,
            self.py.0 + (self.py.1 - self.py.0) * ty,
        ]
    }
}

/// Twice the signed area of (a, b, c).
fn cross(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Calls `put(column, row, value)` for every pixel of `clip` whose centre lies in the
/// triangle `p` (pixel coordinates) or less than half a pixel outside it, with the value
/// interpolated (or extrapolated by that half pixel) linearly from `v`.
fn fill_triangle(
    p: [[f64; 2]; 3],
    v: [f64; 3],
    clip: (&std::ops::Range<i32>, &std::ops::Range<i32>),
    mut put: impl FnMut(i32, i32, f64),
) {
    let area = cross(p[0], p[1], p[2]);
    if !area.is_normal() {
        return;
    }
    // Each triangle is grown by half a pixel, so that the pixels the body's outline is drawn
    // on are filled too and rounding leaves no holes along shared edges. Weight k is the
    // signed distance from edge k times its length over twice the area.
    let length = |a: [f64; 2], b: [f64; 2]| (b[0] - a[0]).hypot(b[1] - a[1]);
    let tolerance = [
        -0.5 * length(p[1], p[2]) / area.abs(),
        -0.5 * length(p[2], p[0]) / area.abs(),
        -0.5 * length(p[0], p[1]) / area.abs(),
    ];
    let lo = |k: usize| p.iter().map(|q| q[k]).fold(f64::INFINITY, f64::min);
    let hi = |k: usize| p.iter().map(|q| q[k]).fold(f64::NEG_INFINITY, f64::max);
    // Bounds are clamped to the clip range before the casts, so they cannot overflow.
    let c0 = ((lo(0) - 1.0).floor().max(f64::from(clip.0.start))) as i32;
    let c1 = ((hi(0) + 1.0).ceil().min(f64::from(clip.0.end - 1))) as i32;
    let r0 = ((lo(1) - 1.0).floor().max(f64::from(clip.1.start))) as i32;
    let r1 = ((hi(1) + 1.0).ceil().min(f64::from(clip.1.end - 1))) as i32;
    for row in r0..=r1 {
        for col in c0..=c1 {
            let c = [f64::from(col) + 0.5, f64::from(row) + 0.5];
            let w = [
                cross(p[1], p[2], c) / area,
                cross(p[2], p[0], c) / area,
                cross(p[0], p[1], c) / area,
            ];
            if w.iter().zip(&tolerance).all(|(wi, t)| wi >= t) {
                put(col, row, w[0] * v[0] + w[1] * v[1] + w[2] * v[2]);
            }
        }
    }
}

/// Edges of the triangles with the number of triangles sharing each: 1 on the boundary.
/// Ordered, so that a frame always draws to the same picture.
fn edges(triangles: &[[usize; 3]]) -> BTreeMap<(usize, usize), u32> {
    let mut count = BTreeMap::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    count
}

/// Draws `values` (one per particle of `frame`) as a contour picture of `view` titled `title`
/// to `path`.
pub(crate) fn draw(
    frame: &Frame,
    values: &[f64],
    view: &View,
    title: &str,
    path: &Path,
) -> Result<(), PlotError> {
    if values.len() != frame.position.len() {
        return Err(PlotError::new(
            &frame.path,
            format!(
                "{} values for {} particles",
                values.len(),
                frame.position.len()
            ),
        ));
    }
    save(path, CONTOUR_SIZE, |root: &Area<'_>| {
        draw_on(root, frame, values, view, title)
    })
}

fn draw_on<'a>(
    root: &Area<'a>,
    frame: &Frame,
    values: &[f64],
    view: &View,
    title: &str,
) -> Drawn<'a> {
    let body = root.titled(title, (FAMILY, 26))?;
    let (mesh_area, bar_area) = body.split_horizontally(CONTOUR_SIZE.0 - COLOUR_BAR_WIDTH);

    // The plot's pixel size follows from the fixed margins and label areas.
    let (w, h) = mesh_area.dim_in_pixel();
    let plot_w = f64::from(w.saturating_sub(2 * MARGIN + Y_LABELS).max(2) - 1);
    let plot_h = f64::from(h.saturating_sub(2 * MARGIN + X_LABELS).max(2) - 1);
    let (xr, yr) = equal_scale_ranges(&view.window, plot_w, plot_h);
    // Everything is clipped to the plotting area, which the equal scale may make wider or
    // taller than the window.
    let shown = Window {
        x0: xr.0,
        y0: yr.0,
        x1: xr.1,
        y1: yr.1,
    };
    let mut chart = ChartBuilder::on(&mesh_area)
        .margin(MARGIN)
        .x_label_area_size(X_LABELS)
        .y_label_area_size(Y_LABELS)
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .axis_desc_style((FAMILY, 20))
        .label_style((FAMILY, 16))
        .draw()?;

    let (lo, hi) = finite_range(values.iter().copied()).unwrap_or((0.0, 1.0));
    let scale = Scale::of(lo, hi);
    let (cols, rows) = chart.plotting_area().get_pixel_range();
    let to_px = ToPixels::new(xr, yr, cols.clone(), rows.clone());
    let mut failed = Ok(());
    for t in &frame.triangles {
        let p = t.map(|i| to_px.map(frame.position[i]));
        if p.iter().flatten().any(|c| !c.is_finite()) {
            continue;
        }
        fill_triangle(p, t.map(|i| values[i]), (&cols, &rows), |c, r, v| {
            if failed.is_ok() {
                failed = root.draw_pixel((c, r), &scale.colour(v));
            }
        });
        std::mem::replace(&mut failed, Ok(()))?;
    }

    let edges = edges(&frame.triangles);
    let clipped = |&(a, b): &(usize, usize)| {
        let (p, q) = clip_segment(frame.position[a], frame.position[b], &shown)?;
        Some(((p[0], p[1]), (q[0], q[1])))
    };
    let on_screen = |&(a, b): &(usize, usize)| {
        let (pa, pb) = (to_px.map(frame.position[a]), to_px.map(frame.position[b]));
        (pa[0] - pb[0]).hypot(pa[1] - pb[1])
    };
    let visible: Vec<f64> = edges
        .keys()
        .filter(|e| clipped(e).is_some())
        .map(on_screen)
        .filter(|l| l.is_finite())
        .collect();
    let mean_px = visible.iter().sum::<f64>() / visible.len().max(1) as f64;
    if mean_px >= MESH_LINES_FROM_PX {
        chart.draw_series(
            edges
                .iter()
                .filter(|(_, &n)| n > 1)
                .filter_map(|(e, _)| clipped(e))
                .map(|(p, q)| PathElement::new(vec![p, q], BLACK.mix(0.3))),
        )?;
    }
    chart.draw_series(
        edges
            .iter()
            .filter(|(_, &n)| n == 1)
            .filter_map(|(e, _)| clipped(e))
            .map(|(p, q)| PathElement::new(vec![p, q], BLACK.stroke_width(1))),
    )?;
    for body in view.bodies {
        let inside: Vec<(f64, f64)> = clip_polygon(body, &shown)
            .iter()
            .map(|p| (p[0], p[1]))
            .collect();
        if inside.len() >= 3 {
            chart.draw_series(std::iter::once(Polygon::new(inside, BODY_FILL.filled())))?;
        }
        chart.draw_series(
            body.iter()
                .zip(body.iter().cycle().skip(1))
                .filter_map(|(&p, &q)| clip_segment(p, q, &shown))
                .map(|(p, q)| {
                    PathElement::new(vec![(p[0], p[1]), (q[0], q[1])], BODY_LINE.stroke_width(2))
                }),
        )?;
    }

    draw_colour_bar(&bar_area, lo, hi, scale)
}

/// The colour bar: the colour scale from `lo` (bottom) to `hi` (top) with ticks, and the two
/// values written out above and below it.
fn draw_colour_bar<'a>(
    area: &DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>,
    lo: f64,
    hi: f64,
    scale: Scale,
) -> Drawn<'a> {
    const TOP: u32 = 50;
    const BOTTOM: u32 = MARGIN + X_LABELS + 10;
    // A constant field still needs an axis of some length.
    let (a0, a1) = if scale.hi > scale.lo {
        (scale.lo, scale.hi)
    } else {
        let d = (lo.abs() * 0.1).max(1e-12);
        (lo - d, hi + d)
    };
    let mut bar = ChartBuilder::on(area)
        .margin_top(TOP)
        .margin_bottom(BOTTOM)
        .margin_left(15)
        .margin_right(5)
        .right_y_label_area_size(110)
        .build_cartesian_2d(0.0..1.0, a0..a1)?;
    let formatter = |v: &f64| short(*v);
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(9)
        .y_label_formatter(&formatter)
        .label_style((FAMILY, 16))
        .draw()?;
    let step = (a1 - a0) / BAR_STEPS as f64;
    bar.draw_series((0..BAR_STEPS).map(|k| {
        let v0 = a0 + step * k as f64;
        Rectangle::new(
            [(0.0, v0), (1.0, v0 + step)],
            scale.colour(v0 + 0.5 * step).filled(),
        )
    }))?;
    bar.draw_series(std::iter::once(Rectangle::new(
        [(0.0, a0), (1.0, a1)],
        BLACK.stroke_width(1),
    )))?;

    let text = TextStyle::from((FAMILY, 18).into_font()).color(&BLACK);
    let (_, h) = area.dim_in_pixel();
    let left = 15;
    area.draw_text(
        &format!("max {}", short(hi)),
        &text,
        (left, TOP as i32 - 30),
    )?;
    area.draw_text(
        &format!("min {}", short(lo)),
        &text,
        (left, h as i32 - BOTTOM as i32 + 10),
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_are_filled_once_with_interpolated_values() {
        // Two triangles tiling the square [0, 10]²: every pixel centre inside is reached, and
        // the value, x, is interpolated exactly.
        let sq = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];
        let value = |p: [f64; 2]| p[0];
        let mut hits = vec![0; 100];
        let clip = (&(0..10), &(0..10));
        for t in [[0, 1, 2], [0, 2, 3]] {
            let p = [sq[t[0]], sq[t[1]], sq[t[2]]];
            fill_triangle(p, p.map(value), clip, |c, r, v| {
                assert!((v - (f64::from(c) + 0.5)).abs() < 1e-9);
                hits[(r * 10 + c) as usize] += 1;
            });
        }
        assert!(hits.iter().all(|&h| h >= 1));
        // Only pixels centred on the diagonal are within half a pixel of both triangles.
        for (k, &h) in hits.iter().enumerate() {
            let (c, r) = (k % 10, k / 10);
            assert_eq!(h > 1, c == r, "pixel {c}, {r}: {h} hits");
        }
    }

    #[test]
    fn edges_count_their_triangles() {
        let e = edges(&[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(e.len(), 5);
        assert_eq!(e[&(0, 2)], 2);
        assert_eq!(e.values().filter(|&&n| n == 1).count(), 4);
    }
}
