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
//! bone runs upward from its lower end, as a hip does. A pelvis part (shorts, a skirt) roots
//! at the waist; a quadruped's spine bends at the chest over its front legs; a bust (a torso
//! with a head and no limbs) gets a bone to each shoulder; a layer holding a pair of legs
//! gets its medial-axis bones, a chain per leg. Where the artist marked a group's pivot
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
    /// The shape's [`principal_axis`] (`None`: nothing inside), computed once per part.
    pub axis: Option<PrincipalAxis>,
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
        let max = max_part_bones(&part.label).max(split.len());
        let grown = match joint {
            None => {
                let hints = RootHints::of(i, parts, &tree, template);
                root_bones(part, pivot, &hints, split.len(), max, medial, skeleton)?
            }
            Some(j) => {
                let from = pivot.unwrap_or(j.at_px);
                let pair = if holds_a_pair(part.name, &part.label) {
                    let mut grown = medial_bones(part.shape, from, medial, skeleton)?;
                    super::skeleton::limit_bones(&mut grown, Some(2 * max), part.shape);
                    grown
                } else {
                    Vec::new()
                };
                if pair.len() > 1 {
                    pair
                } else {
                    let mut grown =
                        ray_bones(part, from, None, split.len(), max, medial, skeleton)?;
                    if template == Some(Template::Quadruped) && part.label.part == LabelPart::Head {
                        to_middle(&mut grown, part, skeleton);
                    }
                    grown
                }
            }
        };
        let first = bones.len();
        let parent_bone =
            joint.and_then(|j| nearest_bone(&bones, part_bones[j.parent].clone(), j.at_px));
        for (k, mut b) in grown.into_iter().enumerate() {
            // A part's further root bones (branches at its start) hang from its first bone.
            b.parent = match b.parent {
                Some(p) => Some(p + first),
                None if k > 0 => Some(first),
                None => parent_bone,
            };
            let base = split.get(k).or(split.last()).cloned().unwrap_or_default();
            let name = if k < split.len() {
                base
            } else {
                format!("{base}_{}", k + 1)
            };
            let name = b.name.take().unwrap_or(name);
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
                let along =
                    (seam - b.head).dot(&(b.tail - b.head)) / b.length_px().powi(2).max(1e-12);
                if along > 0.3
                    && (seam - b.head).norm() >= skeleton.min_bone_px
                    && parent_shape.segment_inside(b.head, seam)
                {
                    bones[pb].tail = seam;
                }
            }
        }
    }
    Ok(LayeredSkeleton { bones, bone_part })
}

/// A quadruped's head, carried forward on its neck, turns at the neck and its bone points to
/// the middle of the head (the skull), not to the muzzle's tip: a one-bone part's bone ends
/// at its centroid's projection on the bone (kept at least `min_bone_px` long).
fn to_middle(bones: &mut [ProtoBone], part: &Part, skeleton: &SkeletonOptions) {
    let ([b], Some(axis)) = (bones, part.axis) else {
        return;
    };
    let d = b.tail - b.head;
    let length = d.norm();
    if length < 1e-9 {
        return;
    }
    let t = (axis.centroid - b.head).dot(&d) / length;
    if t >= skeleton.min_bone_px && t < length {
        b.tail = b.head + d * (t / length);
    }
}

/// Whether a limb part holds both limbs of a pair in one layer (`front legs`, `hind legs`:
/// a plural limb word and no side): it gets the bones of its medial axis, a chain per limb.
fn holds_a_pair(name: &str, label: &Label) -> bool {
    let limb = matches!(label.part, LabelPart::Leg(_) | LabelPart::Arm(_));
    let last = name.rsplit('/').next().unwrap_or(name);
    limb && label.side.is_none()
        && super::labels::words(last)
            .iter()
            .any(|w| matches!(w.as_str(), "legs" | "arms" | "feet" | "hands" | "paws"))
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

/// The mean joint of the root's children whose labels `keep` accepts, if any.
fn mean_joint(
    root: usize,
    parts: &[Part],
    tree: &PartTree,
    keep: impl Fn(&Label) -> bool,
) -> Option<Point> {
    let at: Vec<Point> = tree
        .joints
        .iter()
        .enumerate()
        .filter_map(|(c, j)| j.filter(|j| j.parent == root).map(|j| (c, j.at_px)))
        .filter(|(c, _)| keep(&parts[*c].label))
        .map(|(_, p)| p)
        .collect();
    (!at.is_empty())
        .then(|| Point::from(at.iter().fold(Vec2::zeros(), |s, p| s + p.coords) / at.len() as f64))
}

/// Where the root part's children join it, which places its bones.
struct RootHints {
    /// Where the legs and tail join (a quadruped's back legs and tail).
    hips: Option<Point>,
    /// Where the top of the spine's children join (a torso over a pelvis, the neck, the head,
    /// the upper or whole arms; a quadruped's front legs).
    up: Option<Point>,
    /// Where a torso joins a pelvis part.
    waist: Option<Point>,
    /// A quadruped's front legs' joint (the shoulders).
    front: Option<Point>,
    /// Where the head or neck joins.
    neck: Option<Point>,
    /// Whether any arm or leg part hangs from the root.
    limbs: bool,
    template: Option<Template>,
}

impl RootHints {
    fn of(root: usize, parts: &[Part], tree: &PartTree, template: Option<Template>) -> RootHints {
        use super::labels::Segment;
        let quadruped = template == Some(Template::Quadruped);
        let front_leg =
            |l: &Label| matches!(l.part, LabelPart::Leg(_)) && l.end == Some(End::Front);
        let joint = |keep: &dyn Fn(&Label) -> bool| mean_joint(root, parts, tree, keep);
        RootHints {
            hips: joint(&|l| {
                matches!(l.part, LabelPart::Leg(_) | LabelPart::Tail)
                    && !(quadruped && front_leg(l))
            }),
            up: joint(&|l| {
                let arm = matches!(l.part, LabelPart::Arm(Segment::Upper | Segment::Whole));
                matches!(l.part, LabelPart::Torso | LabelPart::Neck | LabelPart::Head)
                    || arm
                    || (quadruped && front_leg(l))
            }),
            waist: joint(&|l| l.part == LabelPart::Torso),
            front: joint(&|l| quadruped && front_leg(l)),
            neck: joint(&|l| matches!(l.part, LabelPart::Neck | LabelPart::Head)),
            limbs: joint(&|l| matches!(l.part, LabelPart::Arm(_) | LabelPart::Leg(_))).is_some(),
            template,
        }
    }
}

/// The share of a quadruped's trunk depth, from its back, at which the chest joint (the
/// shoulders, over the front legs) sits: below the middle.
const CHEST_DEPTH: f64 = 0.6;

/// The cross-section of `shape` through `p` across `along` (a unit direction): the point at
/// `fraction` of the way from the side away from `belly` to the side toward it (None when `p`
/// is outside).
fn across_at(shape: &Shape, p: Point, along: Vec2, belly: Point, fraction: f64) -> Option<Point> {
    if !shape.contains(p) {
        return None;
    }
    let mut n = Vec2::new(-along.y, along.x);
    if (belly - p).dot(&n) < 0.0 {
        n = -n;
    }
    let reach = |dir: Vec2| {
        let (mut lo, mut hi) = (0.0, 1.0);
        while shape.contains(p + dir * hi) && hi < 1e5 {
            hi *= 2.0;
        }
        for _ in 0..30 {
            let mid = 0.5 * (lo + hi);
            if shape.contains(p + dir * mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    };
    let (back, front) = (reach(-n), reach(n));
    Some(p + n * (-back + fraction * (back + front)))
}

/// A quadruped's spine on its trunk: the hip bone from the hips (`start`) to the chest joint
/// over the front legs ([`CHEST_DEPTH`] down the trunk, level with the front legs' joint),
/// the chest bone from there to where the neck or head joins. None when a bone would leave
/// the part or be too short.
fn quadruped_spine(
    part: &Part,
    start: Point,
    hints: &RootHints,
    skeleton: &SkeletonOptions,
) -> Option<Vec<ProtoBone>> {
    let (front, neck) = (hints.front?, hints.neck?);
    let shape = part.shape;
    let d = neck - start;
    let along = d / d.norm().max(1e-9);
    // Level with the front legs along the spine, on the line from the hips to the neck.
    let on_line = start + along * (front - start).dot(&along);
    let chest = across_at(shape, on_line, along, front, CHEST_DEPTH).unwrap_or(on_line);
    let ok =
        |a: Point, b: Point| (b - a).norm() >= skeleton.min_bone_px && shape.segment_inside(a, b);
    (ok(start, chest) && ok(chest, neck)).then(|| {
        vec![
            ProtoBone {
                head: start,
                tail: chest,
                parent: None,
                name: None,
            },
            ProtoBone {
                head: chest,
                tail: neck,
                parent: Some(0),
                name: None,
            },
        ]
    })
}

/// A bust's bones (a torso with a head and no arm or leg parts, under the humanoid
/// template): rooted at the body's centroid, a spine of two bones up to where the head joins
/// (`neck`), and a bone from there to each shoulder: 80 % of the way to the torso's farthest
/// pixel on that side in the band below the neck (the top quarter of the torso below it).
fn bust_bones(part: &Part, neck: Point, skeleton: &SkeletonOptions) -> Option<Vec<ProtoBone>> {
    let shape = part.shape;
    let c = part.axis?.centroid;
    let up = neck - c;
    if up.norm() < 2.0 * skeleton.min_bone_px.max(1.0) {
        return None;
    }
    let u = up / up.norm();
    let side = Vec2::new(-u.y, u.x);
    let bottom = shape
        .inside_centers()
        .map(|p| (p - neck).dot(&u))
        .fold(0.0, f64::min);
    let band = 0.25 * -bottom;
    let mut far = [None::<(f64, Point)>; 2];
    for p in shape.inside_centers() {
        let down = -(p - neck).dot(&u);
        if !(0.0..=band).contains(&down) {
            continue;
        }
        let x = (p - neck).dot(&side);
        let k = usize::from(x < 0.0);
        if far[k].is_none_or(|(best, _)| x.abs() > best) {
            far[k] = Some((x.abs(), p));
        }
    }
    let mid = Point::from((c.coords + neck.coords) * 0.5);
    let bone = |head: Point, tail: Point, parent: Option<usize>| ProtoBone {
        head,
        tail,
        parent,
        name: None,
    };
    let mut bones = vec![bone(c, mid, None), bone(mid, neck, Some(0))];
    if !(shape.segment_inside(c, mid) || shape.contains(c)) {
        return None;
    }
    for (k, found) in far.into_iter().enumerate() {
        let Some((_, p)) = found else { continue };
        let tail = neck + (p - neck) * 0.8;
        if (tail - neck).norm() >= skeleton.min_bone_px {
            let mut b = bone(neck, tail, Some(1));
            b.name = Some(if k == 0 { "shoulder_l" } else { "shoulder_r" }.into());
            bones.push(b);
        }
    }
    Some(bones)
}

/// The root part's bones, `count` in a chain (at most `max` medial bones when the part is
/// too curved for a straight spine). The spine starts at the hips: a marked `pivot`, else for
/// a pelvis part (shorts, a skirt) the waist where a torso joins it (running down toward the
/// legs), else its centroid, else where the legs and tail join (`hips`); it runs toward
/// where the torso, head and arms join (`up`). A quadruped's spine bends at the chest over
/// its front legs ([`quadruped_spine`]); a bust gets shoulders ([`bust_bones`]). Without
/// hints, it runs along the principal axis from its lower end.
fn root_bones(
    part: &Part,
    pivot: Option<Point>,
    hints: &RootHints,
    count: usize,
    max: usize,
    medial: &MedialOptions,
    skeleton: &SkeletonOptions,
) -> Result<Vec<ProtoBone>, MedialError> {
    let shape = part.shape;
    let Some(axis) = part.axis else {
        return Ok(Vec::new());
    };
    let (hips, up) = (hints.hips, hints.up);
    if let Some(start) = pivot {
        return ray_bones(part, start, up, count, max, medial, skeleton);
    }
    if part.label.part == LabelPart::Pelvis {
        // Shorts or a skirt: the pelvis is at the waist, where the torso joins it (the part's
        // centroid sits at the thighs), and the hip bone runs down toward the legs.
        return match hints.waist {
            Some(w) => ray_bones(part, w, hips, count, max, medial, skeleton),
            None => ray_bones(part, axis.centroid, up, count, max, medial, skeleton),
        };
    }
    if hints.template == Some(Template::Humanoid) && !hints.limbs {
        if let Some(bones) = hints.neck.and_then(|n| bust_bones(part, n, skeleton)) {
            return Ok(bones);
        }
    }
    if let Some(hips) = hips {
        // The spine runs through the part's middle, parallel to hips → top, from the hips'
        // level: a quadruped's hips sit on its spine, not at its belly where the legs join.
        let (start, toward) = match up.filter(|u| (u - hips).norm() > 1e-9) {
            Some(u) => {
                let d = (u - hips) / (u - hips).norm();
                let c = axis.centroid;
                (c + d * (hips - c).dot(&d), Some(c + d * (u - c).dot(&d)))
            }
            // Legs drawn apart (a tee's feet): the spine starts inside, nearest the hips,
            // and runs through the part's centroid.
            None => (hips, Some(axis.centroid)),
        };
        if hints.template == Some(Template::Quadruped) && count == 2 {
            if let Some(bones) = quadruped_spine(part, start, hints, skeleton) {
                return Ok(bones);
            }
        }
        return ray_bones(part, start, toward, count, max, medial, skeleton);
    }
    let [t0, t1] = axis.extent;
    let span = inside_reach(shape, &axis, 0.0, t0)
        .zip(inside_reach(shape, &axis, 0.0, t1))
        .filter(|&(lo, hi)| hi - lo >= STRAIGHT_SPAN_FRACTION * (t1 - t0))
        .filter(|&(lo, hi)| hi - lo >= skeleton.min_bone_px);
    match span {
        Some((lo, hi)) => {
            // The end farther from the top's joints, else the lower end.
            let lo_first = match up {
                Some(u) => (axis.at(lo) - u).norm() >= (axis.at(hi) - u).norm(),
                None => axis.at(lo).y >= axis.at(hi).y,
            };
            let (a, b) = if lo_first {
                (axis.at(lo), axis.at(hi))
            } else {
                (axis.at(hi), axis.at(lo))
            };
            Ok(chain(a, b, count, skeleton))
        }
        None => {
            let mut grown = medial_bones(shape, axis.centroid, medial, skeleton)?;
            super::skeleton::limit_bones(&mut grown, Some(max), shape);
            Ok(grown)
        }
    }
}

/// The most bones a part of this label gets: one for rigid pieces (a head, a hand, a held
/// prop), two for a whole limb or a torso, a chain for a tail.
pub fn max_part_bones(label: &Label) -> usize {
    use super::labels::Segment;
    match label.part {
        LabelPart::Tail => 10,
        LabelPart::Unknown | LabelPart::BodyAccessory => 4,
        LabelPart::Torso | LabelPart::HeadAccessory => 2,
        LabelPart::Arm(Segment::Whole) | LabelPart::Leg(Segment::Whole) => 2,
        _ => 1,
    }
}

/// The share of a part's area a straight bone's far end may leave beyond it (thin tips: an
/// antenna, fingertips): the far end is this upper quantile of the inside pixels' projections.
const FAR_QUANTILE: f64 = 0.97;

/// Directions tried for a one-bone part, each side of the one through its centroid, degrees.
const ONE_BONE_SWEEP_DEG: f64 = 60.0;
const ONE_BONE_STEP_DEG: f64 = 5.0;

/// A part's bones from its joint `joint` (canvas px), at most `max` of them: a straight bone
/// from the joint toward `toward` (default: through the part's centroid) to its far side (the
/// [`FAR_QUANTILE`] of its pixels along that line), split into `count`; when that line leaves
/// the part early (a curved part), the part's medial-axis bones rooted nearest the joint (at
/// most `max`), or for a one-bone part the longest straight bone inside among directions near
/// the first.
fn ray_bones(
    part: &Part,
    joint: Point,
    toward: Option<Point>,
    count: usize,
    max: usize,
    medial: &MedialOptions,
    skeleton: &SkeletonOptions,
) -> Result<Vec<ProtoBone>, MedialError> {
    let shape = part.shape;
    let Some(axis) = part.axis else {
        return Ok(Vec::new());
    };
    // Start inside the part, clear of its outline: at the joint, or at the nearest inside
    // pixel that is.
    let clear = |p: Point| shape.segment_inside(p, p);
    // A part drawn apart from its parent (the joint outside it) starts at the end of its own
    // axis nearer the joint, and runs along that axis: a floating hand along the hand.
    let apart = toward.is_none() && !shape.contains(joint);
    let axis_end = {
        let toward_joint = if axis.project(joint) >= 0.0 {
            axis.extent[1]
        } else {
            axis.extent[0]
        };
        inside_reach(shape, &axis, 0.0, toward_joint).map(|t| axis.at(t))
    };
    let anchor = match axis_end {
        Some(end) if apart => end,
        _ => joint,
    };
    let start = if clear(anchor) {
        anchor
    } else {
        shape
            .inside_centers()
            .filter(|&p| clear(p))
            .min_by(|a, b| (a - anchor).norm().total_cmp(&(b - anchor).norm()))
            .unwrap_or(axis.centroid)
    };
    let to_centroid = toward.unwrap_or(axis.centroid) - start;
    let extent = axis.extent[1] - axis.extent[0];
    // The direction: toward `toward` or the centroid, or along the axis away from the start
    // when the start lies near it (a part overlapping its parent mostly) or the part is apart.
    let direction = if apart && axis_end.is_some() {
        if axis.project(start) <= 0.0 {
            axis.direction
        } else {
            -axis.direction
        }
    } else if to_centroid.norm() > 0.15 * extent {
        to_centroid / to_centroid.norm()
    } else if axis.project(start) <= 0.0 {
        axis.direction
    } else {
        -axis.direction
    };
    let ray = |d: Vec2| PrincipalAxis {
        centroid: start,
        direction: d,
        extent: [0.0, 0.0],
    };
    let far_along = |d: Vec2| -> f64 {
        let line = ray(d);
        let mut t: Vec<f64> = shape.inside_centers().map(|p| line.project(p)).collect();
        if t.is_empty() {
            return 0.0;
        }
        let k = ((t.len() as f64 - 1.0) * FAR_QUANTILE).round() as usize;
        // The quantile by selection: no full sort (this runs once per direction tried).
        let (_, far, _) = t.select_nth_unstable_by(k, f64::total_cmp);
        far.max(0.0)
    };
    let far = far_along(direction);
    let reach = inside_reach(shape, &ray(direction), 0.0, far);

    if let Some(t) = reach.filter(|&t| t >= STRAIGHT_SPAN_FRACTION * far && t > 0.0) {
        if t >= skeleton.min_bone_px.min(far) {
            return Ok(chain(start, ray(direction).at(t), count.min(max), skeleton));
        }
    }
    if max > 1 {
        let mut grown = medial_bones(shape, start, medial, skeleton)?;
        if !grown.is_empty() {
            super::skeleton::limit_bones(&mut grown, Some(max), shape);
            return Ok(grown);
        }
    }
    // One straight bone: the longest inside among directions near the centroid's.
    let steps = (ONE_BONE_SWEEP_DEG / ONE_BONE_STEP_DEG) as i32;
    let mut best: Option<(f64, Point)> = None;
    for k in -steps..=steps {
        let angle = (k as f64 * ONE_BONE_STEP_DEG).to_radians();
        let (sin, cos) = angle.sin_cos();
        let d = Vec2::new(
            direction.x * cos - direction.y * sin,
            direction.x * sin + direction.y * cos,
        );
        let far = far_along(d);
        if far <= 0.0 {
            continue;
        }
        let Some(t) = inside_reach(shape, &ray(d), 0.0, far) else {
            continue;
        };
        // Longer is better; straying from the centroid's direction costs.
        let score = t * cos;
        if best.is_none_or(|b| score > b.0) {
            best = Some((score, ray(d).at(t)));
        }
    }
    Ok(match best {
        Some((_, tail)) if (tail - start).norm() > 1e-6 => vec![ProtoBone {
            head: start,
            tail,
            parent: None,
            name: None,
        }],
        _ => Vec::new(),
    })
}

/// `count` bones in a chain from `a` to `b` (equal lengths; one bone when shorter pieces
/// would fall under the minimum bone length).
fn chain(a: Point, b: Point, count: usize, skeleton: &SkeletonOptions) -> Vec<ProtoBone> {
    let length = (b - a).norm();
    let count = if count > 1 && length / count as f64 >= skeleton.min_bone_px {
        count
    } else {
        1
    };
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

#[cfg(test)]
mod tests {
    use super::super::labels::label;
    use super::*;

    #[test]
    fn a_layer_of_both_legs_is_a_pair() {
        let pair = |name: &str| holds_a_pair(name, &label(name));
        assert!(pair("front legs"));
        assert!(pair("cat/Hind Legs"));
        assert!(!pair("FrontLeg"));
        assert!(!pair("legs_l"));
        assert!(!pair("tail"));
    }
}
