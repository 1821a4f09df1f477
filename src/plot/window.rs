//! Which part of the body a contour picture shows: the region where the field varies (a
//! T-bar's 0.4 × 0.8 m box with the action in a 0.1 m spot is drawn as the spot), or the
//! window `pfem-mpi plot DIR --window x0,y0,x1,y1` asks for. Also the clipping of lines and
//! polygons to it, so that nothing is drawn over the axes.

/// A rectangle of the plane, in metres: `x0 < x1`, `y0 < y1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    pub x0: f64,
    pub y0: f64,
    pub x1: f64,
    pub y1: f64,
}

/// A vertex differs noticeably from the far field by more than this share of the field's range.
const NOTICEABLE: f64 = 0.05;
/// Each side of the varying region is padded by this share of its larger side...
const PAD: f64 = 0.25;
/// ...and by at least this many mean edge lengths, so a one-triangle spot shows its neighbours.
const PAD_EDGES: f64 = 3.0;

impl Window {
    /// Parses `x0,y0,x1,y1` (metres) as `--window` takes it; the error names `--window`.
    pub fn parse(text: &str) -> Result<Window, String> {
        let bad = |why: &str| format!("--window {text}: {why}; give x0,y0,x1,y1 in metres");
        let v: Vec<f64> = text
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad("not four numbers"))?;
        let [x0, y0, x1, y1] = v[..] else {
            return Err(bad(&format!("{} numbers, not four", v.len())));
        };
        if v.iter().any(|c| !c.is_finite()) {
            return Err(bad("a coordinate is not finite"));
        }
        if !(x0 < x1 && y0 < y1) {
            return Err(bad("needs x0 < x1 and y0 < y1"));
        }
        Ok(Window { x0, y0, x1, y1 })
    }

    /// The smallest window holding `points` (None without a finite point).
    pub fn around(points: impl Iterator<Item = [f64; 2]>) -> Option<Window> {
        points
            .filter(|p| p[0].is_finite() && p[1].is_finite())
            .fold(None, |w: Option<Window>, p| {
                Some(match w {
                    None => Window {
                        x0: p[0],
                        y0: p[1],
                        x1: p[0],
                        y1: p[1],
                    },
                    Some(w) => Window {
                        x0: w.x0.min(p[0]),
                        y0: w.y0.min(p[1]),
                        x1: w.x1.max(p[0]),
                        y1: w.y1.max(p[1]),
                    },
                })
            })
    }

    fn union(self, o: Window) -> Window {
        Window {
            x0: self.x0.min(o.x0),
            y0: self.y0.min(o.y0),
            x1: self.x1.max(o.x1),
            y1: self.y1.max(o.y1),
        }
    }

    /// The overlap, or None when there is none.
    pub fn intersect(self, o: Window) -> Option<Window> {
        let w = Window {
            x0: self.x0.max(o.x0),
            y0: self.y0.max(o.y0),
            x1: self.x1.min(o.x1),
            y1: self.y1.min(o.y1),
        };
        (w.x0 < w.x1 && w.y0 < w.y1).then_some(w)
    }

    fn padded(self, by: f64) -> Window {
        Window {
            x0: self.x0 - by,
            y0: self.y0 - by,
            x1: self.x1 + by,
            y1: self.y1 + by,
        }
    }

    pub fn contains(&self, p: [f64; 2]) -> bool {
        (self.x0..=self.x1).contains(&p[0]) && (self.y0..=self.y1).contains(&p[1])
    }
}

/// The window of a contour picture of `values` (one per vertex of `position`) on `triangles`:
/// the triangles with a vertex that differs from the far-field value (the median, which most of
/// a large body keeps) by more than [`NOTICEABLE`] of the range, with the rigid bodies'
/// `bodies` boxes, padded, within the whole drawing (mesh and bodies). A field that varies
/// everywhere, or not at all, shows the whole drawing.
pub fn focus(
    position: &[[f64; 2]],
    triangles: &[[usize; 3]],
    values: &[f64],
    bodies: &[Window],
) -> Option<Window> {
    let used = || triangles.iter().flatten().map(|&i| position[i]);
    let all = bodies.iter().fold(Window::around(used()), |w, b| {
        Some(w.map_or(*b, |w| w.union(*b)))
    })?;
    let mut finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    finite.sort_unstable_by(f64::total_cmp);
    let (Some(&lo), Some(&hi)) = (finite.first(), finite.last()) else {
        return Some(all);
    };
    if hi <= lo {
        return Some(all);
    }
    let far = finite[finite.len() / 2];
    let differs = |i: usize| (values[i] - far).abs() > NOTICEABLE * (hi - lo);
    let varying = triangles
        .iter()
        .filter(|t| t.iter().any(|&i| differs(i)))
        .flatten()
        .map(|&i| position[i]);
    let Some(region) = Window::around(varying) else {
        return Some(all);
    };
    let region = bodies.iter().fold(region, |w, b| w.union(*b));
    let edges = triangles.len().max(1) as f64;
    let mean_edge = triangles
        .iter()
        .map(|t| {
            let d = |a: usize, b: usize| {
                (position[a][0] - position[b][0]).hypot(position[a][1] - position[b][1])
            };
            (d(t[0], t[1]) + d(t[1], t[2]) + d(t[2], t[0])) / 3.0
        })
        .filter(|l| l.is_finite())
        .sum::<f64>()
        / edges;
    let side = (region.x1 - region.x0).max(region.y1 - region.y0);
    let pad = (PAD * side).max(PAD_EDGES * mean_edge);
    Some(region.padded(pad).intersect(all).unwrap_or(all))
}

/// The part of segment `a`–`b` inside `w` (Liang–Barsky), or None.
pub fn clip_segment(a: [f64; 2], b: [f64; 2], w: &Window) -> Option<([f64; 2], [f64; 2])> {
    let d = [b[0] - a[0], b[1] - a[1]];
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-d[0], a[0] - w.x0),
        (d[0], w.x1 - a[0]),
        (-d[1], a[1] - w.y0),
        (d[1], w.y1 - a[1]),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    // An end inside stays exactly where it was.
    let at = |t: f64| match t {
        0.0 => a,
        1.0 => b,
        _ => [a[0] + t * d[0], a[1] + t * d[1]],
    };
    (t0 <= t1).then(|| (at(t0), at(t1)))
}

/// The part of polygon `points` inside `w` (Sutherland–Hodgman); empty when none.
pub fn clip_polygon(points: &[[f64; 2]], w: &Window) -> Vec<[f64; 2]> {
    // Each side keeps the points with inside(p) >= 0.
    let sides: [&dyn Fn([f64; 2]) -> f64; 4] =
        [&|p| p[0] - w.x0, &|p| w.x1 - p[0], &|p| p[1] - w.y0, &|p| {
            w.y1 - p[1]
        }];
    let mut out = points.to_vec();
    for inside in sides {
        let input = std::mem::take(&mut out);
        for (k, &p) in input.iter().enumerate() {
            let q = input[(k + 1) % input.len()];
            let (fp, fq) = (inside(p), inside(q));
            if fp >= 0.0 {
                out.push(p);
            }
            if (fp >= 0.0) != (fq >= 0.0) {
                let t = fp / (fp - fq);
                out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An n x n grid of the unit square scaled to `size`, two triangles a cell.
    fn grid(n: usize, size: [f64; 2]) -> (Vec<[f64; 2]>, Vec<[usize; 3]>) {
        let mut p = Vec::new();
        for j in 0..n {
            for i in 0..n {
                p.push([
                    size[0] * i as f64 / (n - 1) as f64,
                    size[1] * j as f64 / (n - 1) as f64,
                ]);
            }
        }
        let mut t = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = j * n + i;
                t.push([a, a + 1, a + 1 + n]);
                t.push([a, a + 1 + n, a + n]);
            }
        }
        (p, t)
    }

    #[test]
    fn a_spot_of_action_is_framed_with_its_surroundings() {
        // A T-bar's box, 0.4 x 0.8 m, with the field non-zero within 0.05 m of (0, 0.44).
        let (p, t) = grid(81, [0.4, 0.8]);
        let v: Vec<f64> = p
            .iter()
            .map(|q| (0.05 - q[0].hypot(q[1] - 0.44)).max(0.0))
            .collect();
        let w = focus(&p, &t, &v, &[]).unwrap();
        assert!(w.x0 == 0.0 && w.x1 < 0.15, "{w:?}");
        assert!(w.y0 > 0.3 && w.y1 < 0.58 && w.y1 - w.y0 < 0.25, "{w:?}");
        assert!(w.contains([0.0, 0.44]) && w.contains([0.05, 0.44]), "{w:?}");
        // The bar itself (a box around its circle) is framed too.
        let bar = Window {
            x0: -0.02,
            y0: 0.62,
            x1: 0.02,
            y1: 0.66,
        };
        let w = focus(&p, &t, &v, &[bar]).unwrap();
        assert!(w.contains([0.0, 0.66]) && w.contains([0.0, 0.40]), "{w:?}");
        assert!(
            w.x0 == -0.02,
            "the body's box is part of the drawing: {w:?}"
        );
    }

    #[test]
    fn a_field_varying_everywhere_or_nowhere_shows_the_whole_body() {
        let (p, t) = grid(11, [2.0, 1.0]);
        let whole = Window {
            x0: 0.0,
            y0: 0.0,
            x1: 2.0,
            y1: 1.0,
        };
        let linear: Vec<f64> = p.iter().map(|q| -1000.0 * (1.0 - q[1])).collect();
        assert_eq!(focus(&p, &t, &linear, &[]), Some(whole));
        assert_eq!(focus(&p, &t, &vec![3.0; p.len()], &[]), Some(whole));
        assert_eq!(focus(&p, &t, &vec![f64::NAN; p.len()], &[]), Some(whole));
    }

    #[test]
    fn windows_parse_or_name_the_option() {
        assert_eq!(
            Window::parse("0,0.3,0.2,0.6"),
            Ok(Window {
                x0: 0.0,
                y0: 0.3,
                x1: 0.2,
                y1: 0.6
            })
        );
        for bad in [
            "0,0,1",
            "0,0,1,1,2",
            "a,0,1,1",
            "1,0,0,1",
            "0,1,1,1",
            "0,0,inf,1",
            "",
        ] {
            let e = Window::parse(bad).unwrap_err();
            assert!(
                e.starts_with("--window") && e.contains("x0,y0,x1,y1"),
                "{bad}: {e}"
            );
        }
    }

    #[test]
    fn segments_and_polygons_are_clipped_to_the_window() {
        let w = Window {
            x0: 0.0,
            y0: 0.0,
            x1: 1.0,
            y1: 1.0,
        };
        assert_eq!(
            clip_segment([-1.0, 0.5], [2.0, 0.5], &w),
            Some(([0.0, 0.5], [1.0, 0.5]))
        );
        assert_eq!(clip_segment([2.0, 2.0], [3.0, 0.5], &w), None);
        let inside = ([0.2, 0.2], [0.8, 0.9]);
        assert_eq!(clip_segment(inside.0, inside.1, &w), Some(inside));
        // A square straddling the corner (1, 1) keeps its quarter inside.
        let square = [[0.5, 0.5], [1.5, 0.5], [1.5, 1.5], [0.5, 1.5]];
        let clipped = clip_polygon(&square, &w);
        let area = clipped
            .iter()
            .zip(clipped.iter().cycle().skip(1))
            .map(|(a, b)| a[0] * b[1] - b[0] * a[1])
            .sum::<f64>()
            / 2.0;
        assert!((area - 0.25).abs() < 1e-12, "{clipped:?}");
        assert!(clip_polygon(&square.map(|p| [p[0] + 5.0, p[1]]), &w).is_empty());
    }
}
