//! Nearest-segment queries through a bounding-volume hierarchy. A grid answers "which segments
//! are near here" in O(1), but the distance from a point deep inside a large zone to a finely
//! drawn boundary would make a grid search many empty cells; the hierarchy prunes whole
//! subtrees by their boxes instead, in O(log n) whatever the distance.

use super::segment::{self, Point};

/// Segments per leaf.
const LEAF: usize = 4;

#[derive(Debug, Clone)]
pub struct SegmentTree {
    segs: Vec<[Point; 2]>,
    /// Segment indices, grouped so that each leaf holds a contiguous range.
    order: Vec<u32>,
    nodes: Vec<Node>,
}

#[derive(Debug, Clone)]
struct Node {
    lo: Point,
    hi: Point,
    /// A leaf holds `order[first..first + count]`; an inner node (`count == 0`) has children
    /// `first` and `first + 1`.
    first: u32,
    count: u32,
}

impl SegmentTree {
    pub fn new(segs: Vec<[Point; 2]>) -> SegmentTree {
        let mut tree = SegmentTree {
            order: (0..segs.len() as u32).collect(),
            segs,
            nodes: Vec::new(),
        };
        if !tree.segs.is_empty() {
            tree.nodes.push(Node {
                lo: [0.0; 2],
                hi: [0.0; 2],
                first: 0,
                count: 0,
            });
            tree.build(0, 0, tree.segs.len());
        }
        tree
    }

    /// Makes `nodes[node]` cover `order[start..end]`, splitting at the median of the segment
    /// midpoints along the longer side of their box.
    fn build(&mut self, node: usize, start: usize, end: usize) {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        let mut mlo = [f64::INFINITY; 2];
        let mut mhi = [f64::NEG_INFINITY; 2];
        for &s in &self.order[start..end] {
            let [a, b] = self.segs[s as usize];
            for k in 0..2 {
                lo[k] = lo[k].min(a[k]).min(b[k]);
                hi[k] = hi[k].max(a[k]).max(b[k]);
                let m = 0.5 * (a[k] + b[k]);
                mlo[k] = mlo[k].min(m);
                mhi[k] = mhi[k].max(m);
            }
        }
        self.nodes[node].lo = lo;
        self.nodes[node].hi = hi;
        if end - start <= LEAF {
            self.nodes[node].first = start as u32;
            self.nodes[node].count = (end - start) as u32;
            return;
        }
        let axis = if mhi[0] - mlo[0] >= mhi[1] - mlo[1] {
            0
        } else {
            1
        };
        let mid = start + (end - start) / 2;
        let segs = &self.segs;
        let key = |s: &u32| {
            let [a, b] = segs[*s as usize];
            a[axis] + b[axis]
        };
        self.order[start..end]
            .select_nth_unstable_by(mid - start, |x, y| key(x).total_cmp(&key(y)));
        let left = self.nodes.len();
        self.nodes[node].first = left as u32;
        self.nodes.push(Node {
            lo: [0.0; 2],
            hi: [0.0; 2],
            first: 0,
            count: 0,
        });
        self.nodes.push(Node {
            lo: [0.0; 2],
            hi: [0.0; 2],
            first: 0,
            count: 0,
        });
        self.build(left, start, mid);
        self.build(left + 1, mid, end);
    }

    /// Distance from `p` to the nearest segment and that segment's index (the smallest index
    /// among equally near ones); `None` without segments.
    pub fn nearest(&self, p: Point) -> Option<(f64, usize)> {
        self.nearest_counted(p).0
    }

    /// [`nearest`](Self::nearest) and its work: the segment and box distances it evaluated
    /// (what a test of the query's cost counts, since timings depend on the machine's load).
    pub fn nearest_counted(&self, p: Point) -> (Option<(f64, usize)>, usize) {
        let mut best = None;
        let mut work = 0;
        if !self.nodes.is_empty() {
            self.visit(0, p, &mut best, &mut work);
        }
        (best, work)
    }

    fn visit(&self, node: usize, p: Point, best: &mut Option<(f64, usize)>, work: &mut usize) {
        let n = &self.nodes[node];
        if n.count > 0 {
            *work += n.count as usize;
            for &s in &self.order[n.first as usize..(n.first + n.count) as usize] {
                let [a, b] = self.segs[s as usize];
                let (d, s) = (segment::distance(a, b, p), s as usize);
                if best.is_none_or(|(bd, bs)| d < bd || (d == bd && s < bs)) {
                    *best = Some((d, s));
                }
            }
            return;
        }
        let (l, r) = (n.first as usize, n.first as usize + 1);
        *work += 2;
        let (dl, dr) = (self.box_distance(l, p), self.box_distance(r, p));
        let (near, far, dfar) = if dl <= dr { (l, r, dr) } else { (r, l, dl) };
        let dnear = dl.min(dr);
        // Boxes are pruned only when clearly farther than the best, so rounding in the box
        // distance never loses the nearest segment.
        if best.is_none_or(|(d, _)| dnear * (1.0 - 1e-12) <= d) {
            self.visit(near, p, best, work);
        }
        if best.is_none_or(|(d, _)| dfar * (1.0 - 1e-12) <= d) {
            self.visit(far, p, best, work);
        }
    }

    fn box_distance(&self, node: usize, p: Point) -> f64 {
        let n = &self.nodes[node];
        let dx = (n.lo[0] - p[0]).max(p[0] - n.hi[0]).max(0.0);
        let dy = (n.lo[1] - p[1]).max(p[1] - n.hi[1]).max(0.0);
        dx.hypot(dy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(segs: &[[Point; 2]], p: Point) -> (f64, usize) {
        let mut best = (f64::INFINITY, usize::MAX);
        for (s, &[a, b]) in segs.iter().enumerate() {
            let d = segment::distance(a, b, p);
            if d < best.0 {
                best = (d, s);
            }
        }
        best
    }

    #[test]
    fn nearest_matches_brute_force_near_and_far() {
        let n = 3000;
        let segs: Vec<[Point; 2]> = (0..n)
            .map(|k| {
                let at = |k: usize| {
                    let t = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
                    let r = 1.0 + 0.3 * (7.0 * t).sin();
                    [r * t.cos(), r * t.sin()]
                };
                [at(k), at(k + 1)]
            })
            .collect();
        let tree = SegmentTree::new(segs.clone());
        for k in 0..3000 {
            let t = k as f64 * 0.754_877_666_246_692_7;
            let scale = [0.5, 3.0, 300.0][k % 3];
            let p = [scale * (t.fract() - 0.5), scale * ((t * 1.3).fract() - 0.5)];
            assert_eq!(tree.nearest(p), Some(brute(&segs, p)), "at {p:?}");
        }
        assert_eq!(SegmentTree::new(Vec::new()).nearest([0.0, 0.0]), None);
        let one = SegmentTree::new(vec![[[0.0, 0.0], [2.0, 0.0]]]);
        assert_eq!(one.nearest([1.0, -3.0]), Some((3.0, 0)));
    }
}
