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

use super::attach::{continues, part_tree, Overlaps, PartTree};
use super::labels::{End, Label, Part as LabelPart};
use super::medial::{medial_axis, MedialError, MedialOptions};
use super::shape::Shape;
use super::skeleton::{BoneBuilder, NodeTree, ProtoBone, SkeletonOptions};
use super::Template;
use crate::geom::{point_segment_distance, Point, Vec2};
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

/// A part: its name (the layer's path), traced shape and label.
pub struct Part<'a> {
    pub name: &'a str,
    pub shape: &'a Shape,
    pub label: Label,
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

/// A layered skeleton: bones (parents first) and, per bone, the index of its part.
#[derive(Clone, Debug, PartialEq)]
pub struct LayeredSkeleton {
    pub bones: Vec<ProtoBone>,
    pub bone_part: Vec<usize>,
}

/// The layered skeleton of `parts` ([`super::attach::part_tree`] for the hierarchy). Each part
/// gets its bones: a straight bone from its joint through its centroid to its far side, split
/// in two for a whole limb (upper and lower) and for a torso under a template (hip and chest),
/// or the bones of its own medial axis when the part is too curved for a straight bone (a
/// tail). The root part's bone starts at the hips: the end of its axis nearer the legs and
/// tail (or its lower end). A part with a pivot ([`pivot_of`]) starts its bone there. A child
/// hangs from the nearest bone of its parent part, and where it continues its parent's limb
/// ([`super::attach::continues`]) the parent's bone ends at their joint. Bones are named by
/// the template ([`Label::bone_names`]) or after their layer.
pub fn layered_skeleton(
    parts: &[Part],
    pivots: &[Pivot],
    template: Option<Template>,
    medial: &MedialOptions,
    skeleton: &SkeletonOptions,
) -> Result<LayeredSkeleton, MedialError> {
    let shapes: Vec<&Shape> = parts.iter().map(|p| p.shape).collect();
    let labels: Vec<Label> = parts.iter().map(|p| p.label).collect();
    let overlaps = Overlaps::new(&shapes);
    let tree = part_tree(&shapes, &labels, &overlaps);
    let mut bones: Vec<ProtoBone> = Vec::new();
    let mut bone_part = Vec::new();
    let mut names = UniqueNames::default();
    // Per part, its bones' range in `bones`.
    let mut part_bones: Vec<std::ops::Range<usize>> = vec![0..0; parts.len()];
    for &i in &tree.order {
        let part = &parts[i];
        let joint = tree.joints[i];
        let parent_name = joint.map(|j| parts[j.parent].name);
        let pivot = pivot_of(part.name, parent_name, pivots);
        let split = split_names(part, template);
        let grown = match (joint, pivot) {
            (None, _) => {
                let hips = hip_hint(i, parts, &tree);
                root_bones(part.shape, pivot, hips, split.len(), medial, skeleton)?
            }
            (Some(j), _) => child_bones(part.shape, pivot.unwrap_or(j.at_px), split.len(), medial, skeleton)?,
        };
        let first = bones.len();
        let parent_bone = joint.and_then(|j| nearest_bone(&bones, part_bones[j.parent].clone(), j.at_px));
        for (k, mut b) in grown.into_iter().enumerate() {
            b.parent = match b.parent {
                Some(p) => Some(p + first),
                None => parent_bone,
            };
            let base = split.get(k).or(split.last()).cloned().unwrap_or_default();
            let name = if k < split.len() { base } else { format!("{base}_{}", k + 1) };
            b.name = Some(names.take(&name));
            bones.push(b);
            bone_part.push(i);
        }
        part_bones[i] = first..bones.len();
        // A limb continued: the parent's bone ends where this part's first bone starts.
        if let (Some(j), Some(pb)) = (joint, parent_bone) {
            if first < bones.len() && ends_at_joint(&parts[j.parent], part, &tree, j.parent) {
                let seam = bones[first].head;
                let parent_shape = parts[j.parent].shape;
                let b = &bones[pb];
                let along = (seam - b.head).dot(&(b.tail - b.head)) / b.length_px().powi(2).max(1e-12);
                if along > 0.3
                    && (seam - b.head).norm() >= skeleton.min_bone_px
                    && parent_shape.segment_inside(b.head, seam)
                {
                    bones[pb].tail = seam;
                }
            }
        }
        if bones.len() > first {
            // Children of this part's bones placed before (none: parents come first).
        }
    }
    Ok(LayeredSkeleton { bones, bone_part })
}

/// Whether `child`'s joint ends its parent part's bone: the labels say the child continues
/// the parent's limb, or (unlabelled) the child is the parent's only child part.
fn ends_at_joint(parent: &Part, child: &Part, tree: &PartTree, parent_index: usize) -> bool {
    if continues(&parent.label, &child.label) {
        return true;
    }
    let unlabelled = !parent.label.is_known() && !child.label.is_known();
    let children = tree
        .joints
        .iter()
        .filter(|j| j.is_some_and(|j| j.parent == parent_index))
        .count();
    unlabelled && children == 1
}

/// The names of a part's bones in chain order: the template's ([`Label::bone_names`]; a
/// torso under a template is `hip` then `chest`), else the layer's own name (its last path
/// segment).
fn split_names(part: &Part, template: Option<Template>) -> Vec<String> {
    if template.is_some() && part.label.part == LabelPart::Torso {
        return vec!["hip".into(), "chest".into()];
    }
    template
        .and_then(|_| part.label.bone_names(template))
        .unwrap_or_else(|| vec![layer_bone_name(part.name)])
}

/// A bone name from a layer's path: its last segment, trimmed.
fn layer_bone_name(path: &str) -> String {
    let last = path.rsplit('/').next().unwrap_or(path).trim();
    if last.is_empty() {
        "part".into()
    } else {
        last.to_string()
    }
}

/// Bone names made unique by a numeric suffix (`arm`, `arm_2`).
#[derive(Default)]
struct UniqueNames(std::collections::HashSet<String>);

impl UniqueNames {
    fn take(&mut self, name: &str) -> String {
        let mut candidate = name.to_string();
        let mut k = 1;
        while !self.0.insert(candidate.clone()) {
            k += 1;
            candidate = format!("{name}_{k}");
        }
        candidate
    }
}

/// The bone among `range` nearest to `p` (distance to its segment; the first of equals).
fn nearest_bone(bones: &[ProtoBone], range: std::ops::Range<usize>, p: Point) -> Option<usize> {
    range.min_by(|&a, &b| {
        let d = |k: usize| point_segment_distance(p, bones[k].head, bones[k].tail);
        d(a).total_cmp(&d(b)).then(a.cmp(&b))
    })
}

/// Where the root part's bone should start: the mean joint of its children that hang at the
/// hips (legs, a tail), if any.
fn hip_hint(root: usize, parts: &[Part], tree: &PartTree) -> Option<Point> {
    let at_hips: Vec<Point> = tree
        .joints
        .iter()
        .enumerate()
        .filter_map(|(c, j)| j.filter(|j| j.parent == root).map(|j| (c, j.at_px)))
        .filter(|(c, _)| {
            matches!(parts[*c].label.part, LabelPart::Leg(_) | LabelPart::Tail)
                && parts[*c].label.end != Some(End::Front)
        })
        .map(|(_, p)| p)
        .collect();
    (!at_hips.is_empty()).then(|| {
        Point::from(at_hips.iter().fold(Vec2::zeros(), |s, p| s + p.coords) / at_hips.len() as f64)
    })
}

/// The root part's bones: along its principal axis from the end nearer `hips` (else the lower
/// end; a `pivot` is the head itself) to the other, split into `count` equal bones; or its
/// medial-axis bones when the axis leaves the part.
fn root_bones(
    shape: &Shape,
    pivot: Option<Point>,
    hips: Option<Point>,
    count: usize,
    medial: &MedialOptions,
    skeleton: &SkeletonOptions,
) -> Result<Vec<ProtoBone>, MedialError> {
    let Some(axis) = principal_axis(shape) else {
        return Ok(Vec::new());
    };
    let [t0, t1] = axis.extent;
    let span = inside_reach(shape, &axis, 0.0, t0)
        .zip(inside_reach(shape, &axis, 0.0, t1))
        .filter(|&(lo, hi)| hi - lo >= STRAIGHT_SPAN_FRACTION * (t1 - t0))
        .filter(|&(lo, hi)| hi - lo >= skeleton.min_bone_px);
    match span {
        Some((lo, hi)) => {
            let lo_first = match hips.or(pivot) {
                Some(h) => (axis.at(lo) - h).norm() <= (axis.at(hi) - h).norm(),
                None => axis.at(lo).y >= axis.at(hi).y,
            };
            let (a, b) = if lo_first { (axis.at(lo), axis.at(hi)) } else { (axis.at(hi), axis.at(lo)) };
            Ok(chain(pivot.unwrap_or(a), b, count, shape, skeleton))
        }
        None => medial_bones(shape, hips.or(pivot).unwrap_or(axis.centroid), medial, skeleton),
    }
}

/// A child part's bones from its joint `joint` (canvas px): a straight bone from the joint
/// through the part's centroid to its far side, split into `count`; or the part's medial-axis
/// bones rooted nearest the joint when that line leaves the part early (a curved part).
fn child_bones(
    shape: &Shape,
    joint: Point,
    count: usize,
    medial: &MedialOptions,
    skeleton: &SkeletonOptions,
) -> Result<Vec<ProtoBone>, MedialError> {
    let Some(axis) = principal_axis(shape) else {
        return Ok(Vec::new());
    };
    // Start inside the part: at the joint, or at the inside pixel nearest to it.
    let start = if shape.contains(joint) {
        joint
    } else {
        shape
            .inside_centers()
            .min_by(|a, b| (a - joint).norm().total_cmp(&(b - joint).norm()))
            .unwrap_or(axis.centroid)
    };
    let to_centroid = axis.centroid - start;
    let extent = axis.extent[1] - axis.extent[0];
    // The direction: through the centroid, or along the axis away from the start when the
    // start lies near the centroid (a part overlapping its parent mostly).
    let direction = if to_centroid.norm() > 0.15 * extent {
        to_centroid / to_centroid.norm()
    } else if axis.project(start) <= 0.0 {
        axis.direction
    } else {
        -axis.direction
    };
    let line = PrincipalAxis {
        centroid: start,
        direction,
        extent: [0.0, 0.0],
    };
    let far = shape
        .inside_centers()
        .map(|p| line.project(p))
        .fold(0.0f64, f64::max);
    let reach = inside_reach(shape, &line, 0.0, far);
    match reach {
        Some(t) if t >= STRAIGHT_SPAN_FRACTION * far && t >= skeleton.min_bone_px.min(far) && t > 0.0 => {
            Ok(chain(start, line.at(t), count, shape, skeleton))
        }
        _ => {
            let grown = medial_bones(shape, start, medial, skeleton)?;
            if grown.is_empty() && far > 0.0 {
                // Too small for an axis: one bone as far as it stays inside.
                let t = reach.unwrap_or(0.0).max(far.min(1.0));
                return Ok(vec![ProtoBone {
                    head: start,
                    tail: line.at(t),
                    parent: None,
                    name: None,
                }]);
            }
            Ok(grown)
        }
    }
}

/// `count` bones in a chain from `a` to `b` (equal lengths; one bone when shorter pieces
/// would fall under the minimum bone length).
fn chain(a: Point, b: Point, count: usize, _shape: &Shape, skeleton: &SkeletonOptions) -> Vec<ProtoBone> {
    let length = (b - a).norm();
    let count = if count > 1 && length / count as f64 >= skeleton.min_bone_px { count } else { 1 };
    (0..count)
        .map(|k| ProtoBone {
            head: a + (b - a) * (k as f64 / count as f64),
            tail: a + (b - a) * ((k + 1) as f64 / count as f64),
            parent: k.checked_sub(1),
            name: None,
        })
        .collect()
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
