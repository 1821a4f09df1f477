//! One chart of a picture: the run's curves and reference curves on axes fitted to them, with a
//! legend in the emptiest corner. The history pictures (`legacy`, `declared`) are made of these.

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::font::FAMILY;
use super::history::drawable;

/// A run's results get markers while they are this sparse; denser runs are a plain line.
const MAX_MARKED: usize = 60;

pub(super) const RESULT_U: RGBColor = RGBColor(31, 90, 200);
pub(super) const RESULT_V: RGBColor = RGBColor(200, 40, 40);
pub(super) const REFERENCE_LOW: RGBColor = RGBColor(0, 140, 60);
pub(super) const REFERENCE_HIGH: RGBColor = RGBColor(150, 60, 170);

/// How a curve is drawn.
#[derive(Debug, Clone, Copy)]
pub(super) enum Look {
    /// The run's results: a solid line.
    Result,
    /// A reference curve: a dashed line.
    Reference,
    /// Reference values at some points: crosses.
    Points,
    /// A reference value independent of x: a dashed horizontal line at this y.
    Level(f64),
}

pub(super) struct Curve {
    /// Legend text; `None` for a curve that shares the legend entry of another.
    pub label: Option<String>,
    pub points: Vec<(f64, f64)>,
    pub colour: RGBColor,
    pub look: Look,
}

impl Curve {
    pub fn new(label: &str, points: Vec<(f64, f64)>, colour: RGBColor, look: Look) -> Self {
        Curve {
            label: Some(label.to_string()),
            points,
            colour,
            look,
        }
    }
}

/// One chart of a picture.
pub(super) struct Panel {
    pub caption: String,
    pub x_desc: String,
    pub y_desc: String,
    pub curves: Vec<Curve>,
    /// Whether the y axis starts at zero (loads) or fits the values (a ratio near 1).
    pub y_from_zero: bool,
}

/// Range of the [`drawable`] `values`, widened to hold 0 when `with_zero`, padded by 4 % on a
/// side not at zero, never empty, always finite. Magnitudes below 1e-100 count as 0, so that
/// the tick spacing stays a normal number.
pub(super) fn span(values: impl Iterator<Item = f64>, with_zero: bool) -> (f64, f64) {
    let (mut lo, mut hi) = values
        .filter(|&v| drawable(v))
        .map(|v| if v.abs() < 1e-100 { 0.0 } else { v })
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if with_zero {
        lo = lo.min(0.0);
        hi = hi.max(0.0);
    }
    if lo > hi {
        return (0.0, 1.0);
    }
    if hi - lo <= f64::EPSILON * hi.abs().max(lo.abs()) {
        if lo == 0.0 {
            hi = 1.0;
        } else {
            let half = 0.1 * lo.abs();
            lo -= half;
            hi += half;
        }
    }
    let pad = 0.04 * (hi - lo);
    let lo = if with_zero && lo == 0.0 { lo } else { lo - pad };
    let hi = if with_zero && hi == 0.0 { hi } else { hi + pad };
    (lo, hi)
}

/// The corner of the chart where the legend hides the fewest points of the panel's curves;
/// the lower right on a tie.
fn legend_corner(panel: &Panel, x: (f64, f64), y: (f64, f64)) -> SeriesLabelPosition {
    // Share of the width and height a legend covers, roughly.
    const WIDE: f64 = 0.45;
    const HIGH: f64 = 0.35;
    const SAMPLES: usize = 16;
    let corners = [
        (SeriesLabelPosition::LowerRight, true, false),
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::LowerLeft, false, false),
        (SeriesLabelPosition::UpperLeft, false, true),
    ];
    // Lines are sampled between their points too, so that a long segment counts.
    let mut points: Vec<(f64, f64)> = Vec::new();
    for c in &panel.curves {
        points.extend(&c.points);
        if let Look::Level(level) = c.look {
            points.extend((0..=SAMPLES).map(|k| {
                let t = k as f64 / SAMPLES as f64;
                (x.0 + t * (x.1 - x.0), level)
            }));
        }
        if matches!(c.look, Look::Result | Look::Reference) {
            for w in c.points.windows(2) {
                points.extend((1..SAMPLES).map(|k| {
                    let t = k as f64 / SAMPLES as f64;
                    (
                        w[0].0 + t * (w[1].0 - w[0].0),
                        w[0].1 + t * (w[1].1 - w[0].1),
                    )
                }));
            }
        }
    }
    let hidden = |right: bool, upper: bool| {
        points
            .iter()
            .filter(|p| {
                let tx = (p.0 - x.0) / (x.1 - x.0);
                let ty = (p.1 - y.0) / (y.1 - y.0);
                let in_x = if right { tx >= 1.0 - WIDE } else { tx <= WIDE };
                let in_y = if upper { ty >= 1.0 - HIGH } else { ty <= HIGH };
                in_x && in_y
            })
            .count()
    };
    corners
        .into_iter()
        .min_by_key(|&(_, right, upper)| hidden(right, upper))
        .map_or(SeriesLabelPosition::LowerRight, |c| c.0)
}

pub(super) fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let xs = panel
        .curves
        .iter()
        .flat_map(|c| c.points.iter().map(|p| p.0));
    let (x0, x1) = span(xs, true);
    let ys = panel.curves.iter().flat_map(|c| match c.look {
        Look::Level(y) => vec![y],
        _ => c.points.iter().map(|p| p.1).collect(),
    });
    let (y0, y1) = span(ys, panel.y_from_zero);

    let mut chart = ChartBuilder::on(area)
        .caption(&panel.caption, (FAMILY, 26))
        .margin(20)
        .x_label_area_size(55)
        .y_label_area_size(75)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .x_desc(panel.x_desc.as_str())
        .y_desc(panel.y_desc.as_str())
        .axis_desc_style((FAMILY, 20))
        .label_style((FAMILY, 16))
        .light_line_style(RGBColor(235, 235, 235))
        .max_light_lines(4)
        .draw()?;

    for curve in &panel.curves {
        let colour = curve.colour;
        let solid = colour.stroke_width(2);
        let label = curve.label.as_deref();
        match curve.look {
            Look::Result => {
                if curve.points.len() <= MAX_MARKED {
                    chart.draw_series(
                        curve
                            .points
                            .iter()
                            .map(|&p| Circle::new(p, 3, colour.filled())),
                    )?;
                }
                let series =
                    chart.draw_series(LineSeries::new(curve.points.iter().copied(), solid))?;
                if let Some(label) = label {
                    series
                        .label(label)
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], solid));
                }
            }
            Look::Reference | Look::Level(_) => {
                let points = match curve.look {
                    Look::Level(y) => vec![(x0, y), (x1, y)],
                    _ => curve.points.clone(),
                };
                let series = chart.draw_series(DashedLineSeries::new(points, 9, 6, solid))?;
                if let Some(label) = label {
                    series.label(label).legend(move |(x, y)| {
                        DashedPathElement::new(vec![(x, y), (x + 24, y)], 9, 6, solid)
                    });
                }
            }
            Look::Points => {
                let cross = |p| Cross::new(p, 6, colour.stroke_width(2));
                let series = chart.draw_series(curve.points.iter().map(|&p| cross(p)))?;
                if let Some(label) = label {
                    series
                        .label(label)
                        .legend(move |(x, y)| Cross::new((x + 12, y), 6, colour.stroke_width(2)));
                }
            }
        }
    }
    if panel.curves.iter().any(|c| c.label.is_some()) {
        chart
            .configure_series_labels()
            .position(legend_corner(panel, (x0, x1), (y0, y1)))
            .margin(12)
            .label_font((FAMILY, 17))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.5))
            .draw()?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::span;

    #[test]
    fn spans_hold_zero_and_pad() {
        assert_eq!(span([1.0, 2.0].into_iter(), true), (0.0, 2.08));
        let (lo, hi) = span([0.9, 1.1].into_iter(), false);
        assert!((lo - 0.892).abs() < 1e-12 && (hi - 1.108).abs() < 1e-12);
        let (lo, hi) = span([1.0, 1.0].into_iter(), false);
        assert!(lo < 0.91 && hi > 1.09);
        assert_eq!(span(std::iter::empty(), false), (0.0, 1.0));
        assert_eq!(span([f64::NAN].into_iter(), true), (0.0, 1.04));
        let (lo, hi) = span([1.0, 1e308, -1e308, 2.0].into_iter(), false);
        assert!((lo - 0.96).abs() < 1e-12 && (hi - 2.04).abs() < 1e-12);
        let (lo, hi) = span([1e-310, 2e-310].into_iter(), false);
        assert_eq!((lo, hi), (-0.04, 1.04));
    }
}
