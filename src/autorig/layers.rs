//! Skeletons from layers: one bone per part along its principal axis, parented through the
//! regions where parts overlap.
//!
//! In: the parts (name + traced [`Shape`], all on one canvas, canvas px) and the
//! [`MedialOptions`]/[`SkeletonOptions`] used where an axis bone would leave its part. Out:
//! [`ProtoBone`]s named after their parts, parents first, and for each bone the part it
//! belongs to.
//!
//! After refined principal-axis skeletonization (the "joint boundary centroids" of Lin & al.,
//! "Refined principal-axis skeletonization of layered characters"): a part's axis is the major
//! eigenvector of the covariance of its inside pixels (area-weighted) through their centroid,
//! spanning the part's extent along it. Parts are joined by a maximum spanning tree of their
//! overlap areas, grown from the largest part; the joint between a part and its parent is the
//! centroid of their overlap, and the child's bone runs from that joint's projection on its
//! axis to the far end of the axis. Parts that overlap nothing start their own skeleton. A
//! part too curved for a straight axis bone inside it (a tail) gets the bones of its own
//! medial axis instead, rooted at the axis point nearest to its joint. The largest part's
//! bone runs upward from its lower end, as a hip does. Where the artist marked a group's pivot
//! (a pivot layer, [`Pivot`]), the bone of the group's first part starts at the pivot instead.

use super::medial::{medial_axis, MedialError, MedialOptions};
use super::shape::Shape;
use super::skeleton::{BoneBuilder, NodeTree, ProtoBone, SkeletonOptions};
use crate::geom::{Point, Vec2};
use crate::io::layered::Pivot;

/// One part's principal axis: centroid, unit direction, extent along it (px from the centroid).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrincipalAxis {
    pub centroid: Point,
    pub direction: Vec2,
    pub extent: [f64; 2],
}

impl PrincipalAxis {
    pub fn at(&self, t: f64) -> Point {
        self.centroid + self.direction * t
    }

    pub fn project(&self, p: Point) -> f64 {
        (p - self.centroid).dot(&self.direction)
    }
}

/// The area-weighted principal axis of the inside pixels of `shape` (None when empty).
pub fn principal_axis(shape: &Shape) -> Option<PrincipalAxis> {
    let centers = || shape.inside_centers();
    let n = shape.area_px2;
    if n < 1.0 {
        return None;
    }
    let c = centers().fold(Vec2::zeros(), |s, p| s + p.coords) / n;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in centers() {
        let d = p.coords - c;
        sxx += d.x * d.x;
        sxy += d.x * d.y;
        syy += d.y * d.y;
    }
    // Major eigenvector of [[sxx, sxy], [sxy, syy]].
    let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let direction = Vec2::new(angle.cos(), angle.sin());
    let centroid = Point::from(c);
    let axis = PrincipalAxis {
        centroid,
        direction,
        extent: [0.0, 0.0],
    };
    let (lo, hi) = centers().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
        let t = axis.project(p);
        (lo.min(t), hi.max(t))
    });
    Some(PrincipalAxis {
        extent: [lo, hi],
        ..axis
    })
}

/// The longest piece of the axis line through `from` (at parameter `t_from`) toward `t_to`
/// that stays inside `shape`: the end parameter, found by bisection.
fn inside_reach(shape: &Shape, axis: &PrincipalAxis, t_from: f64, t_to: f64) -> Option<f64> {
    let a = axis.at(t_from);
    if !shape.contains(a) {
        return None;
    }
    if shape.segment_inside(a, axis.at(t_to)) {
        return Some(t_to);
    }
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if shape.segment_inside(a, axis.at(t_from + mid * (t_to - t_from))) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // Back off from the outline, so that rounding the coordinates keeps the end inside.
    let t = t_from + lo * (t_to - t_from);
    Some(t - END_MARGIN_PX.min(0.5 * (t - t_from).abs()) * (t_to - t_from).signum())
}

/// How far a bone end found by bisection stays back from the outline, px.
const END_MARGIN_PX: f64 = 0.5;

/// A straight bone must span at least this fraction of its part's extent along the axis;
/// otherwise the part is too curved for one and gets its medial-axis bones.
const STRAIGHT_SPAN_FRACTION: f64 = 0.8;

/// A part with its overlap relations.
pub struct Part<'a> {
    pub name: &'a str,
    pub shape: &'a Shape,
}

/// Whether the part named by its path (`arm_l/hand`) lies in the group `group` (a path; the
/// empty path is the whole file).
fn in_group(part: &str, group: &str) -> bool {
    group.is_empty()
        || part
            .strip_prefix(group)
            .is_some_and(|rest| rest.starts_with('/'))
}

/// The pivot where part `part`'s bone starts: that of the deepest group holding the part but
/// not its parent part (so a group's pivot starts the bone of the group's first part, the one
/// joined to the rest of the drawing, or a skeleton's root).
fn pivot_of(part: &str, parent: Option<&str>, pivots: &[Pivot]) -> Option<Point> {
    pivots
        .iter()
        .filter(|p| in_group(part, &p.group) && !parent.is_some_and(|q| in_group(q, &p.group)))
        .max_by_key(|p| p.group.len())
        .map(|p| p.at_px)
}

/// The layered skeleton: bones (parents first) and, per bone, the index of its part. A part
/// with a pivot ([`pivot_of`]) starts its bone there (its joint with its parent is the pivot).
pub fn layered_skeleton(
    parts: &[Part],
    pivots: &[Pivot],
    medial: &MedialOptions,
    skeleton: &SkeletonOptions,
) -> Result<(Vec<ProtoBone>, Vec<usize>), MedialError> {
    let n = parts.len();
    let axes: Vec<Option<PrincipalAxis>> = parts.iter().map(|p| principal_axis(p.shape)).collect();
    // Overlap area and centroid per pair.
    let mut overlap = vec![vec![(0.0f64, Vec2::zeros()); n]; n];
    let boxes: Vec<[usize; 4]> = parts.iter().map(|p| p.shape.cell_box()).collect();
    for i in 0..n {
        for j in (i + 1)..n {
            let (a, b) = (&parts[i].shape.inside, &parts[j].shape.inside);
            let w = parts[i].shape.width as usize;
            // Only where both boxes meet, row by row (the order of the sums over the whole
            // canvas).
            let [x0, y0] = [0, 1].map(|k| boxes[i][k].max(boxes[j][k]));
            let [x1, y1] = [2, 3].map(|k| boxes[i][k].min(boxes[j][k]));
            let (mut count, mut sum) = (0.0, Vec2::zeros());
            for y in y0..y1.max(y0) {
                for x in x0..x1.max(x0) {
                    let k = y * w + x;
                    if a[k] && b[k] {
                        count += 1.0;
                        sum += Vec2::new(x as f64 + 0.5, y as f64 + 0.5);
                    }
                }
            }
            let c = if count > 0.0 { sum / count } else { sum };
            overlap[i][j] = (count, c);
            overlap[j][i] = (count, c);
        }
    }
    // Prim's maximum spanning forest, each tree grown from its largest part.
    let mut parent: Vec<Option<usize>> = vec![None; n];
    let mut order = Vec::new();
    let mut joined = vec![false; n];
    while order.len() < n {
        let root = (0..n)
            .filter(|&i| !joined[i])
            .max_by(|&a, &b| {
                parts[a]
                    .shape
                    .area_px2
                    .total_cmp(&parts[b].shape.area_px2)
                    .then(b.cmp(&a))
            })
            .unwrap_or(0);
        joined[root] = true;
        order.push(root);
        loop {
            let best = order
                .iter()
                .flat_map(|&i| (0..n).filter(|&j| !joined[j]).map(move |j| (i, j)))
                .filter(|&(i, j)| overlap[i][j].0 > 0.0)
                .max_by(|a, b| {
                    overlap[a.0][a.1]
                        .0
                        .total_cmp(&overlap[b.0][b.1].0)
                        .then(b.1.cmp(&a.1))
                });
            let Some((i, j)) = best else { break };
            joined[j] = true;
            parent[j] = Some(i);
            order.push(j);
        }
    }
    let mut bones: Vec<ProtoBone> = Vec::new();
    let mut bone_part = Vec::new();
    // The last bone of each part (what its children hang from).
    let mut part_bone: Vec<Option<usize>> = vec![None; n];
    for &i in &order {
        let Some(axis) = axes[i] else { continue };
        let parent_bone = parent[i].and_then(|p| part_bone[p]);
        let pivot = pivot_of(parts[i].name, parent[i].map(|p| parts[p].name), pivots);
        let joint = pivot.or(parent[i].map(|p| Point::from(overlap[i][p].1)));
        // The axis line clipped to the part around the centroid: a straight bone needs it to
        // span most of the part's extent.
        let shape = parts[i].shape;
        let [t0, t1] = axis.extent;
        let span = inside_reach(shape, &axis, 0.0, t0)
            .zip(inside_reach(shape, &axis, 0.0, t1))
            .filter(|&(lo, hi)| hi - lo >= STRAIGHT_SPAN_FRACTION * (t1 - t0))
            .filter(|&(lo, hi)| hi - lo >= skeleton.min_bone_px);
        // Head: the joint's projection (children) or the lower end (roots); tail: the far end.
        let straight = span.map(|(lo, hi)| {
            let t_head = match joint {
                Some(j) => axis.project(j).clamp(lo, hi),
                None if axis.at(lo).y >= axis.at(hi).y => lo,
                None => hi,
            };
            let t_tail = if t_head - lo > hi - t_head { lo } else { hi };
            (t_head, t_tail)
        });
        let first = bones.len();
        match straight {
            Some((t_head, t_tail)) => bones.push(ProtoBone {
                // A marked pivot is the bone's origin itself, not its projection on the axis.
                head: pivot.unwrap_or(axis.at(t_head)),
                tail: axis.at(t_tail),
                parent: parent_bone,
                name: None,
            }),
            None => {
                let anchor = joint.unwrap_or(axis.centroid);
                let mut grown = medial_bones(shape, anchor, medial, skeleton)?;
                for b in &mut grown {
                    b.parent = match b.parent {
                        Some(p) => Some(p + first),
                        None => parent_bone,
                    };
                }
                bones.extend(grown);
            }
        }
        if bones.len() > first {
            part_bone[i] = Some(first);
        }
        for (k, bone) in bones.iter_mut().enumerate().skip(first) {
            let name = if k == first {
                parts[i].name.to_string()
            } else {
                format!("{}_{}", parts[i].name, k - first + 1)
            };
            bone.name = Some(name);
            bone_part.push(i);
        }
    }
    Ok((bones, bone_part))
}

/// The medial-axis bones of one part, rooted at the axis node nearest to `anchor`; parents
/// are indices into the returned list (the first bones have none).
fn medial_bones(
    shape: &Shape,
    anchor: Point,
    medial: &MedialOptions,
    skeleton: &SkeletonOptions,
) -> Result<Vec<ProtoBone>, MedialError> {
    let axis = medial_axis(shape, medial)?;
    let Some(root) = axis.live_nodes().min_by(|&a, &b| {
        (axis.nodes[a].pos - anchor)
            .norm()
            .total_cmp(&(axis.nodes[b].pos - anchor).norm())
    }) else {
        return Ok(Vec::new());
    };
    let tree = NodeTree::new(&axis, root);
    let mut builder = BoneBuilder::new(&axis, shape, skeleton);
    builder.grow(&tree, root, &tree.children[root], None);
    Ok(builder.bones)
}
