//! Gap closing by joining line end points, after Fourey, Tschumperlé & Revoy 2018 ("A Fast and
//! Efficient Semi-guided Algorithm for Flat Coloring Line-arts", G'MIC's Smart Coloring).
//!
//! In: the line mask (true = line pixel: ink ≥ the line threshold), row-major, its size in px,
//! and [`EndPointJoinOptions`] (lengths in px, angles in degrees). Out: [`Joins`]: the pixels of
//! the curves drawn to close the gaps (a mask, true on every pixel a curve passes, from end point
//! to end point or line), the end points and the curves' count per kind.
//!
//! How:
//! 1. the mask is thinned to a one-pixel skeleton (Zhang & Suen 1984);
//! 2. an end point is a skeleton pixel with exactly one skeleton 8-neighbor whose branch runs at
//!    least `branch_min_px` before a junction (shorter branches are thinning spurs); its outward
//!    direction is from the skeleton pixel `direction_px` steps back along the branch to it;
//! 3. pairs of end points at most `spline_max_px` apart that face each other (each direction
//!    within `max_angle_deg` of the line to the other) are joined, best first (quality: nearness
//!    times facing), each end point at most once, by a cubic Hermite curve leaving and entering
//!    along the directions (tangent length `roundness` × the distance), provided the curve
//!    leaves its stroke and meets line pixels again only at its target;
//! 4. every end point still free casts a straight segment along its direction, at most
//!    `segment_max_px` long, kept only if it reaches another line pixel (or, with
//!    `border_is_line`, the canvas edge) after leaving its own stroke.
//!
//! The curves are drawn 8-connected, which stops a 4-connected region flood
//! ([`super::ink_regions`]): a gap closed by a join separates the regions on both sides.

use crate::geom::{Point, Vec2};
use serde::{Deserialize, Serialize};

/// The end-point join's tolerances. Every field has a documented default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EndPointJoinOptions {
    /// Off when false. Default true.
    pub enabled: bool,
    /// Longest curve between two end points, px (straight-line distance). Default 24.
    pub spline_max_px: f64,
    /// Longest straight segment from a free end point to a line, px. Default 12.
    pub segment_max_px: f64,
    /// A join leaves (and enters) an end point at most this far from its direction, degrees.
    /// Default 60.
    pub max_angle_deg: f64,
    /// The end point's direction is taken over this many skeleton steps. Default 6.
    pub direction_px: usize,
    /// Shorter branches (from the end point to a junction, in skeleton steps) are thinning spurs,
    /// not end points. Default 4.
    pub branch_min_px: usize,
    /// A free end point's segment may end on the canvas edge as on a line (a stroke stopping
    /// just short of the edge closes its region there). Default false: on the evaluation's
    /// set 26 it changed nothing, and on set 27 it cut a collar's thin passage along the
    /// canvas edge (docs/colorize-eval.md).
    pub border_is_line: bool,
    /// The curve's tangents are this many times the distance between its ends: 0 is a straight
    /// segment, 1 a round arc. Default 1.
    pub roundness: f64,
}

impl Default for EndPointJoinOptions {
    fn default() -> Self {
        EndPointJoinOptions {
            enabled: true,
            spline_max_px: 24.0,
            segment_max_px: 12.0,
            max_angle_deg: 60.0,
            direction_px: 6,
            branch_min_px: 4,
            roundness: 1.0,
            border_is_line: false,
        }
    }
}

impl EndPointJoinOptions {
    /// Lengths finite and non-negative (at most [`MAX_JOIN_PX`]), the angle in [0, 180]. A
    /// refusal is the field as files name it (`end_point_join.spline_max_px`) and the rule.
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        for (name, v) in [
            ("end_point_join.spline_max_px", self.spline_max_px),
            ("end_point_join.segment_max_px", self.segment_max_px),
            ("end_point_join.roundness", self.roundness),
        ] {
            if !(v.is_finite() && (0.0..=MAX_JOIN_PX).contains(&v)) {
                return Err((name, format!("must lie in [0, {MAX_JOIN_PX}], not {v}")));
            }
        }
        if !(0.0..=180.0).contains(&self.max_angle_deg) {
            return Err((
                "end_point_join.max_angle_deg",
                format!("must lie in [0, 180], not {}", self.max_angle_deg),
            ));
        }
        for (name, v) in [
            ("end_point_join.direction_px", self.direction_px),
            ("end_point_join.branch_min_px", self.branch_min_px),
        ] {
            if v > MAX_JOIN_PX as usize {
                return Err((name, format!("must be at most {MAX_JOIN_PX}, not {v}")));
            }
        }
        Ok(())
    }
}

/// Longest join, px: end points farther apart are separate strokes, not a gap (and the pair
/// search grows with the square of the length).
pub const MAX_JOIN_PX: f64 = 256.0;

/// An end point of the skeleton: its pixel and its outward unit direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EndPoint {
    pub x_px: usize,
    pub y_px: usize,
    pub direction: Vec2,
}

impl EndPoint {
    /// The end point's pixel as a position, px.
    pub fn at_px(&self) -> Point {
        Point::new(self.x_px as f64, self.y_px as f64)
    }
}

/// The joins drawn.
#[derive(Clone, Debug, PartialEq)]
pub struct Joins {
    /// Per pixel: whether a join passes there, line pixels included (the end of a stroke is
    /// often a faint antialiased pixel: the join gives it full ink).
    pub mask: Vec<bool>,
    /// The end points found.
    pub end_points: Vec<EndPoint>,
    /// Curves drawn between two end points.
    pub splines: usize,
    /// Segments drawn from an end point to a line.
    pub segments: usize,
}

/// Closes the gaps of `line` (`width`×`height`, row-major) by joining its end points.
pub fn join_end_points(
    line: &[bool],
    width: u32,
    height: u32,
    options: &EndPointJoinOptions,
) -> Joins {
    let (w, h) = (width as usize, height as usize);
    let mut joins = Joins {
        mask: vec![false; w * h],
        end_points: Vec::new(),
        splines: 0,
        segments: 0,
    };
    if !options.enabled || w < 3 || h < 3 {
        return joins;
    }
    let skeleton = thin(line, w, h);
    joins.end_points = end_points(&skeleton, w, h, options);
    let ends = &joins.end_points;
    let cos_max = options.max_angle_deg.to_radians().cos();
    // Candidate pairs, best first.
    let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
    for a in 0..ends.len() {
        for b in a + 1..ends.len() {
            let (s, t) = (ends[a], ends[b]);
            let d = t.at_px() - s.at_px();
            let dist = d.norm();
            if dist == 0.0 || dist > options.spline_max_px {
                continue;
            }
            let u = d / dist;
            let leave = s.direction.dot(&u);
            let enter = -t.direction.dot(&u);
            if leave < cos_max || enter < cos_max {
                continue;
            }
            let quality = (1.0 - dist / (options.spline_max_px + 1.0)) * (leave + enter) / 2.0;
            pairs.push((quality, a, b));
        }
    }
    // Ties broken by index, so the result does not depend on the sort's stability.
    pairs.sort_by(|p, q| q.0.total_cmp(&p.0).then((p.1, p.2).cmp(&(q.1, q.2))));
    let mut joined = vec![false; ends.len()];
    let blocked = |i: usize, joins: &Joins| line[i] || joins.mask[i];
    for &(_, a, b) in &pairs {
        if joined[a] || joined[b] {
            continue;
        }
        let path = hermite(&ends[a], &ends[b], options.roundness, w, h);
        // Leaves its stroke, crosses paper, meets a line (or a join) only at the end.
        if !crosses_once(&path, |i| blocked(i, &joins)) {
            continue;
        }
        for &i in &path {
            joins.mask[i] = true;
        }
        joined[a] = true;
        joined[b] = true;
        joins.splines += 1;
    }
    for (k, e) in ends.iter().enumerate() {
        if joined[k] {
            continue;
        }
        let reach = options.segment_max_px.max(0.0);
        let path = raster_line(e.at_px(), e.at_px() + e.direction * reach, w, h);
        // Walk: on the own stroke, then paper, then the first line pixel ends the segment.
        let mut left_stroke = false;
        let mut end = None;
        for (n, &i) in path.iter().enumerate() {
            if blocked(i, &joins) {
                if left_stroke {
                    end = Some(n);
                    break;
                }
            } else {
                left_stroke = true;
                // The canvas edge closes like a line: the segment takes its last pixel.
                let (x, y) = (i % w, i / w);
                if options.border_is_line && (x == 0 || y == 0 || x + 1 == w || y + 1 == h) {
                    end = Some(n + 1);
                    break;
                }
            }
        }
        if let Some(n) = end {
            for &i in &path[..n] {
                joins.mask[i] = true;
            }
            joins.segments += 1;
        }
    }
    joins
}

/// Whether `path` starts on blocked pixels, then leaves them, and meets blocked pixels again
/// only in one final run (the target stroke) that lasts to its end.
fn crosses_once(path: &[usize], blocked: impl Fn(usize) -> bool) -> bool {
    let mut switches = 0;
    let mut on = true;
    for &i in path {
        let b = blocked(i);
        if b != on {
            switches += 1;
            on = b;
        }
    }
    // off once and on once again (the end point lies on the target's skeleton, so it is blocked).
    switches == 2 && on
}

/// The pixels of the cubic Hermite curve from `s` to `t` (tangents `roundness`·distance along
/// `s`'s direction and against `t`'s), 8-connected, without repeats.
fn hermite(s: &EndPoint, t: &EndPoint, roundness: f64, w: usize, h: usize) -> Vec<usize> {
    let (p0, p1) = (s.at_px(), t.at_px());
    let dist = (p1 - p0).norm();
    let m0 = s.direction * roundness * dist;
    let m1 = -t.direction * roundness * dist;
    let at = |u: f64| {
        let (u2, u3) = (u * u, u * u * u);
        let (h00, h10, h01, h11) = (
            2.0 * u3 - 3.0 * u2 + 1.0,
            u3 - 2.0 * u2 + u,
            -2.0 * u3 + 3.0 * u2,
            u3 - u2,
        );
        Point::from(p0.coords * h00 + m0 * h10 + p1.coords * h01 + m1 * h11)
    };
    // Samples close enough that consecutive ones are at most a pixel apart, joined by lines.
    let steps = (4.0 * dist * (1.0 + roundness)).ceil().max(1.0) as usize;
    let mut path: Vec<usize> = Vec::new();
    let mut prev = p0;
    for k in 1..=steps {
        let q = at(k as f64 / steps as f64);
        for i in raster_line(prev, q, w, h) {
            if path.last() != Some(&i) {
                path.push(i);
            }
        }
        prev = q;
    }
    path
}

/// The pixels of the segment from `a` to `b` (px, rounded), 8-connected (one per step along the
/// longer axis), clipped to the image.
fn raster_line(a: Point, b: Point, w: usize, h: usize) -> Vec<usize> {
    let n = (b.x - a.x).abs().max((b.y - a.y).abs()).round().max(0.0) as usize;
    let mut out = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let u = if n == 0 { 0.0 } else { k as f64 / n as f64 };
        let x = (a.x + u * (b.x - a.x)).round();
        let y = (a.y + u * (b.y - a.y)).round();
        if x < 0.0 || y < 0.0 || x >= w as f64 || y >= h as f64 {
            break;
        }
        out.push(y as usize * w + x as usize);
    }
    out
}

/// The 8 neighbors of (x, y), clockwise from north, as (dx, dy).
const RING: [(isize, isize); 8] = [
    (0, -1),
    (1, -1),
    (1, 0),
    (1, 1),
    (0, 1),
    (-1, 1),
    (-1, 0),
    (-1, -1),
];

/// Zhang–Suen thinning of `mask` to a one-pixel-wide 8-connected skeleton.
pub fn thin(mask: &[bool], w: usize, h: usize) -> Vec<bool> {
    let mut skel = mask.to_vec();
    // Image borders count as background.
    for x in 0..w {
        skel[x] = false;
        skel[(h - 1) * w + x] = false;
    }
    for y in 0..h {
        skel[y * w] = false;
        skel[y * w + w - 1] = false;
    }
    let mut candidates: Vec<usize> = (0..w * h).filter(|&i| skel[i]).collect();
    let mut remove = Vec::new();
    loop {
        let mut changed = false;
        for pass in 0..2 {
            remove.clear();
            for &i in &candidates {
                if !skel[i] {
                    continue;
                }
                let (x, y) = (i % w, i / w);
                let p = RING.map(|(dx, dy)| {
                    skel[(y as isize + dy) as usize * w + (x as isize + dx) as usize]
                });
                let b = p.iter().filter(|&&v| v).count();
                if !(2..=6).contains(&b) {
                    continue;
                }
                let a = (0..8).filter(|&k| !p[k] && p[(k + 1) % 8]).count();
                if a != 1 {
                    continue;
                }
                // p[0] = N, p[2] = E, p[4] = S, p[6] = W.
                // Pass 0: not (N and E and S), not (E and S and W); pass 1: not (N and E and W),
                // not (N and S and W).
                let ok = if pass == 0 {
                    !(p[2] && p[4] && (p[0] || p[6]))
                } else {
                    !(p[0] && p[6] && (p[2] || p[4]))
                };
                if ok {
                    remove.push(i);
                }
            }
            for &i in &remove {
                skel[i] = false;
            }
            changed |= !remove.is_empty();
        }
        candidates.retain(|&i| skel[i]);
        if !changed {
            break;
        }
    }
    skel
}

/// The skeleton's 8-neighbors of pixel `i` (interior pixels only: the skeleton avoids borders).
fn skeleton_neighbors(skel: &[bool], i: usize, w: usize) -> impl Iterator<Item = usize> + '_ {
    let (x, y) = ((i % w) as isize, (i / w) as isize);
    RING.iter().filter_map(move |&(dx, dy)| {
        let j = (y + dy) as usize * w + (x + dx) as usize;
        skel[j].then_some(j)
    })
}

/// The skeleton's end points that start a branch at least `branch_min_px` long, with their
/// outward directions. A tip is a skeleton pixel whose skeleton neighbors are one, or two side
/// by side.
fn end_points(skel: &[bool], w: usize, h: usize, options: &EndPointJoinOptions) -> Vec<EndPoint> {
    let mut out = Vec::new();
    let steps = options.direction_px.max(options.branch_min_px).max(1);
    for i in 0..w * h {
        if !skel[i] {
            continue;
        }
        let first = next_along(skel, i, &[i], w);
        let Step::One(_) = first else { continue };
        // Walk back along the branch; `seen` holds the pixels passed and the ones skipped
        // beside them.
        let mut seen = vec![i];
        let (mut cur, mut walked, mut back) = (i, 0, i);
        let mut spur = false;
        while walked < steps {
            match next_along(skel, cur, &seen, w) {
                Step::One(next) => {
                    seen.extend(skeleton_neighbors(skel, cur, w));
                    cur = next;
                    walked += 1;
                    if walked <= options.direction_px {
                        back = cur;
                    }
                }
                Step::Junction => {
                    spur = walked < options.branch_min_px;
                    break;
                }
                Step::None => break,
            }
        }
        if spur || walked < options.branch_min_px || back == i {
            continue;
        }
        let d = Vec2::new(
            (i % w) as f64 - (back % w) as f64,
            (i / w) as f64 - (back / w) as f64,
        );
        out.push(EndPoint {
            x_px: i % w,
            y_px: i / w,
            direction: d / d.norm(),
        });
    }
    out
}

/// Where a walk along the skeleton goes from a pixel.
enum Step {
    /// Nowhere: the branch ends.
    None,
    /// On to this pixel.
    One(usize),
    /// Several ways: a junction.
    Junction,
}

/// The skeleton pixel after `cur`, avoiding `seen`: the unseen neighbors must be one, or two
/// side by side (a staircase step: the 4-neighbor of `cur` is taken).
fn next_along(skel: &[bool], cur: usize, seen: &[usize], w: usize) -> Step {
    let fresh: Vec<usize> = skeleton_neighbors(skel, cur, w)
        .filter(|j| !seen.contains(j))
        .collect();
    match fresh.as_slice() {
        [] => Step::None,
        [j] => Step::One(*j),
        [a, b] if a.abs_diff(*b) == 1 || a.abs_diff(*b) == w => {
            let four = |j: usize| j.abs_diff(cur) == 1 || j.abs_diff(cur) == w;
            Step::One(if four(*a) { *a } else { *b })
        }
        _ => Step::Junction,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `w`×`h` mask with 3-px-thick horizontal bars at rows y−1..=y+1 over the x ranges.
    fn bars(w: usize, h: usize, y: usize, xs: &[(usize, usize)]) -> Vec<bool> {
        let mut m = vec![false; w * h];
        for &(x0, x1) in xs {
            for x in x0..x1 {
                for yy in y - 1..=y + 1 {
                    m[yy * w + x] = true;
                }
            }
        }
        m
    }

    #[test]
    fn thinning_leaves_a_one_pixel_line() {
        let (w, h) = (30, 9);
        let m = bars(w, h, 4, &[(3, 27)]);
        let s = thin(&m, w, h);
        for x in 5..25 {
            let column: usize = (0..h).filter(|&y| s[y * w + x]).count();
            assert_eq!(column, 1, "column {x}");
        }
    }

    #[test]
    fn two_facing_ends_are_joined_across_the_gap() {
        // Two collinear bars with a 6-px gap between x = 17 and 23.
        let (w, h) = (40, 11);
        let m = bars(w, h, 5, &[(2, 17), (23, 38)]);
        let j = join_end_points(&m, w as u32, h as u32, &EndPointJoinOptions::default());
        assert_eq!(j.splines, 1, "{:?}", j.end_points);
        for x in 17..23 {
            assert!((3..=7).any(|y| j.mask[y * w + x]), "column {x} open");
        }
    }

    #[test]
    fn an_end_facing_a_line_casts_a_segment() {
        // A vertical wall at x = 30..33 and a bar ending 8 px before it.
        let (w, h) = (40, 21);
        let mut m = bars(w, h, 10, &[(2, 22)]);
        for y in 1..20 {
            for x in 30..33 {
                m[y * w + x] = true;
            }
        }
        let j = join_end_points(&m, w as u32, h as u32, &EndPointJoinOptions::default());
        assert_eq!((j.splines, j.segments), (0, 1));
        for x in 22..30 {
            assert!(j.mask[10 * w + x], "x {x}");
        }
        let off = EndPointJoinOptions {
            enabled: false,
            ..Default::default()
        };
        assert!(!join_end_points(&m, w as u32, h as u32, &off)
            .mask
            .contains(&true));
    }

    #[test]
    fn the_canvas_edge_closes_only_when_asked() {
        // A bar stopping 2 px short of the left edge and 6 px short of the right one.
        let (w, h) = (40, 11);
        let m = bars(w, h, 5, &[(2, 34)]);
        let j = join_end_points(&m, w as u32, h as u32, &EndPointJoinOptions::default());
        assert_eq!(j.segments, 0);
        let border = EndPointJoinOptions {
            border_is_line: true,
            ..Default::default()
        };
        let j = join_end_points(&m, w as u32, h as u32, &border);
        assert_eq!(j.segments, 2, "{:?}", j.end_points);
        assert!((0..2).chain(34..40).all(|x| j.mask[5 * w + x]));
    }

    #[test]
    fn a_closed_outline_has_no_end_points() {
        let (w, h) = (30, 30);
        let mut m = vec![false; w * h];
        for y in 5..25 {
            for x in 5..25 {
                let ring = !(8..22).contains(&x) || !(8..22).contains(&y);
                m[y * w + x] = ring;
            }
        }
        let j = join_end_points(&m, w as u32, h as u32, &EndPointJoinOptions::default());
        assert!(j.end_points.is_empty(), "{:?}", j.end_points);
        assert!(!j.mask.contains(&true));
    }
}
