//! The part tree of a layered character: which part hangs from which, and where they join.
//!
//! In: the parts (traced [`Shape`]s on one canvas, canvas px) with their [`Label`]s. Out: a
//! [`PartTree`]: per part its parent part and joint (canvas px), and an order that lists
//! parents first.
//!
//! The root is the pelvis, else the torso, else the largest part: the hips, where animators
//! root a character. A part whose label names what it attaches to ([`parent_rank`]: a
//! forearm to the upper arm of its side, a hand to its forearm, a tail to the hips, a hat to
//! the head, a held sword to the hand it overlaps) hangs from the best such part present; any
//! other part hangs from the part it overlaps most, grown as a maximum spanning tree of the
//! overlap areas (after Lin et al., "Refined principal-axis skeletonization of layered
//! characters"); a part that overlaps nothing hangs from the nearest part, so pieces drawn
//! apart (a floating hand) still move with the body. The joint of two overlapping parts is the
//! centroid of their overlap; of two apart, the middle of their closest points.

use super::labels::{End, Label, Part, Segment, Side};
use super::shape::Shape;
use crate::geom::{Point, Vec2};

/// The overlap of every pair of parts: area (px²) and centroid (canvas px).
pub struct Overlaps {
    area_px2: Vec<Vec<f64>>,
    centroid: Vec<Vec<Point>>,
}

impl Overlaps {
    /// Counts the pixels inside both shapes of each pair, within their boxes' intersection.
    pub fn new(shapes: &[&Shape]) -> Overlaps {
        let n = shapes.len();
        let mut area_px2 = vec![vec![0.0; n]; n];
        let mut centroid = vec![vec![Point::origin(); n]; n];
        let boxes: Vec<[usize; 4]> = shapes.iter().map(|s| s.cell_box()).collect();
        for i in 0..n {
            for j in (i + 1)..n {
                let (a, b) = (&shapes[i].inside, &shapes[j].inside);
                let w = shapes[i].width as usize;
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
                let c = Point::from(if count > 0.0 { sum / count } else { sum });
                area_px2[i][j] = count;
                area_px2[j][i] = count;
                centroid[i][j] = c;
                centroid[j][i] = c;
            }
        }
        Overlaps { area_px2, centroid }
    }

    pub fn area_px2(&self, i: usize, j: usize) -> f64 {
        self.area_px2[i][j]
    }

    pub fn centroid(&self, i: usize, j: usize) -> Point {
        self.centroid[i][j]
    }
}

/// Outline points compared per part when ranking parts apart by closeness.
const RANK_SAMPLES: usize = 64;
/// ... and when placing the joint of two parts apart.
const JOINT_SAMPLES: usize = 400;

/// The closest pair of outline points of two shapes, each outline sampled at most `samples`
/// times, and their distance, px.
pub fn closest_points(a: &Shape, b: &Shape, samples: usize) -> (Point, Point, f64) {
    let sample = |s: &Shape| -> Vec<Point> {
        let all: Vec<Point> = s.rings().flatten().copied().collect();
        let step = all.len().div_ceil(samples.max(1)).max(1);
        all.into_iter().step_by(step).collect()
    };
    let (pa, pb) = (sample(a), sample(b));
    let mut best = (Point::origin(), Point::origin(), f64::INFINITY);
    for &p in &pa {
        for &q in &pb {
            let d = (p - q).norm();
            if d < best.2 {
                best = (p, q, d);
            }
        }
    }
    best
}

/// How well `parent` suits `child` as the part it attaches to, from their labels: 0 best,
/// larger worse, `None` when the labels say nothing of the pair. `overlapping`: whether the
/// two parts overlap (a prop hangs only from a hand or arm that holds it).
pub fn parent_rank(child: &Label, parent: &Label, overlapping: bool) -> Option<u8> {
    use Part::*;
    use Segment::*;
    let side = child.side.is_none() || parent.side.is_none() || child.side == parent.side;
    let end = child.end.is_none() || parent.end.is_none() || child.end == parent.end;
    let chain = side && end;
    let front = child.end == Some(End::Front);
    match (child.part, parent.part) {
        (Head, Neck) => Some(0),
        (Head, Torso) => Some(1),
        (Head, Pelvis) => Some(2),
        (Neck, Torso) => Some(0),
        (Neck, Pelvis) => Some(1),
        (Torso, Pelvis) | (Pelvis, Torso) => Some(0),
        (Arm(Upper | Whole), Torso) => Some(0),
        (Arm(Upper | Whole), Neck) => Some(1),
        (Arm(Upper | Whole), Pelvis) => Some(2),
        (Arm(Lower), Arm(Upper)) if chain => Some(0),
        (Arm(Lower), Arm(Whole)) if chain => Some(1),
        (Arm(Lower), Torso) => Some(2),
        (Arm(Extremity), Arm(Lower)) if chain => Some(0),
        (Arm(Extremity), Arm(Whole)) if chain => Some(1),
        (Arm(Extremity), Arm(Upper)) if chain => Some(2),
        (Arm(Extremity), Torso) => Some(3),
        (Leg(Upper | Whole), Torso) if front => Some(0),
        (Leg(Upper | Whole), Pelvis) if front => Some(1),
        (Leg(Upper | Whole), Pelvis) => Some(0),
        (Leg(Upper | Whole), Torso) => Some(1),
        (Leg(Lower), Leg(Upper)) if chain => Some(0),
        (Leg(Lower), Leg(Whole)) if chain => Some(1),
        (Leg(Lower), Pelvis) => Some(2),
        (Leg(Lower), Torso) => Some(3),
        (Leg(Extremity), Leg(Lower)) if chain => Some(0),
        (Leg(Extremity), Leg(Whole)) if chain => Some(1),
        (Leg(Extremity), Leg(Upper)) if chain => Some(2),
        (Leg(Extremity), Pelvis) => Some(3),
        (Leg(Extremity), Torso) => Some(4),
        (Tail, Pelvis) => Some(0),
        (Tail, Torso) => Some(1),
        (HeadAccessory, Head) => Some(0),
        (HeadAccessory, Neck) => Some(1),
        (BodyAccessory, Torso) => Some(0),
        (BodyAccessory, Pelvis) => Some(1),
        (Prop, Arm(Extremity)) if overlapping => Some(0),
        (Prop, Arm(Lower)) if overlapping => Some(1),
        (Prop, Arm(Whole)) if overlapping => Some(2),
        (Prop, Arm(Upper)) if overlapping => Some(3),
        _ => None,
    }
}

/// Whether `child` continues `parent`'s limb (an upper arm then its forearm, a neck then the
/// head): the parent's bone then ends where the child's starts.
pub fn continues(parent: &Label, child: &Label) -> bool {
    use Part::*;
    use Segment::*;
    matches!(
        (parent.part, child.part),
        (Arm(Upper), Arm(Lower))
            | (Arm(Lower), Arm(Extremity))
            | (Arm(Whole), Arm(Extremity))
            | (Leg(Upper), Leg(Lower))
            | (Leg(Lower), Leg(Extremity))
            | (Leg(Whole), Leg(Extremity))
            | (Neck, Head)
    )
}

/// Where a part joins its parent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Joint {
    pub parent: usize,
    /// Canvas px: the overlap's centroid, or the middle of the closest points.
    pub at_px: Point,
}

/// The part tree.
#[derive(Clone, Debug, PartialEq)]
pub struct PartTree {
    /// Per part, where it joins its parent (`None` for the root).
    pub joints: Vec<Option<Joint>>,
    /// Every part, parents before children, the root first.
    pub order: Vec<usize>,
}

/// Builds the part tree of `shapes` with their `labels` (same length; at least one part).
pub fn part_tree(shapes: &[&Shape], labels: &[Label], overlaps: &Overlaps) -> PartTree {
    let n = shapes.len();
    let area = |i: usize| shapes[i].area_px2;
    let largest = |keep: &dyn Fn(usize) -> bool| {
        (0..n)
            .filter(|&i| keep(i))
            .max_by(|&a, &b| area(a).total_cmp(&area(b)).then(b.cmp(&a)))
    };
    let root = largest(&|i| labels[i].part == Part::Pelvis)
        .or_else(|| largest(&|i| labels[i].part == Part::Torso))
        .or_else(|| largest(&|_| true))
        .unwrap_or(0);
    let rank =
        |c: usize, p: usize| parent_rank(&labels[c], &labels[p], overlaps.area_px2(c, p) > 0.0);
    // Each part's best rank among the parts present: it hangs only from a part of that rank.
    let best_rank: Vec<Option<u8>> = (0..n)
        .map(|c| (0..n).filter(|&p| p != c).filter_map(|p| rank(c, p)).min())
        .collect();
    let mut distance = vec![vec![None::<f64>; n]; n];
    let mut apart = |c: usize, p: usize| -> f64 {
        *distance[c][p].get_or_insert_with(|| closest_points(shapes[c], shapes[p], RANK_SAMPLES).2)
    };
    let mut joints: Vec<Option<Joint>> = vec![None; n];
    let mut attached = vec![false; n];
    attached[root] = true;
    let mut order = vec![root];
    while order.len() < n {
        // The best pair (child outside, parent inside): labelled pairs first, then by overlap
        // area, then by closeness. A part with labelled parents present waits for one of them,
        // unless nothing else can join (then labels are set aside for this step).
        let mut best: Option<((bool, f64, f64), usize, usize)> = None;
        for strict in [true, false] {
            for c in (0..n).filter(|&c| !attached[c]) {
                for &p in &order {
                    let ruled = best_rank[c].is_some() && rank(c, p) == best_rank[c];
                    if strict && best_rank[c].is_some() && !ruled {
                        continue;
                    }
                    let overlap = overlaps.area_px2(c, p);
                    let d = if overlap > 0.0 { 0.0 } else { apart(c, p) };
                    let key = (ruled, overlap, -d);
                    let better = best
                        .as_ref()
                        .is_none_or(|(k, _, _)| key.partial_cmp(k).is_some_and(|o| o.is_gt()));
                    if better {
                        best = Some((key, c, p));
                    }
                }
            }
            if best.is_some() {
                break;
            }
        }
        let Some((_, c, p)) = best else { break };
        let at_px = if overlaps.area_px2(c, p) > 0.0 {
            overlaps.centroid(c, p)
        } else {
            let (a, b, _) = closest_points(shapes[c], shapes[p], JOINT_SAMPLES);
            Point::from((a.coords + b.coords) * 0.5)
        };
        joints[c] = Some(Joint { parent: p, at_px });
        attached[c] = true;
        order.push(c);
    }
    PartTree { joints, order }
}

/// Gives sides to limb parts whose names did not: of two parts with the same limb label and
/// no side, the one farther right on screen is the character's left (it faces the viewer);
/// one alone takes the side its partner of the other side lacks. `centroids`: per part,
/// canvas px.
pub fn complete_sides(labels: &mut [Label], centroids: &[Point]) {
    let n = labels.len();
    let limb = |l: &Label| matches!(l.part, Part::Arm(_) | Part::Leg(_));
    for i in 0..n {
        if !limb(&labels[i]) || labels[i].side.is_some() {
            continue;
        }
        let same = |l: &Label| l.part == labels[i].part && l.end == labels[i].end;
        let unsided: Vec<usize> = (0..n)
            .filter(|&j| same(&labels[j]) && labels[j].side.is_none())
            .collect();
        if unsided.len() == 2 {
            let (a, b) = (unsided[0], unsided[1]);
            let (left, right) = if centroids[a].x >= centroids[b].x {
                (a, b)
            } else {
                (b, a)
            };
            labels[left].side = Some(Side::Left);
            labels[right].side = Some(Side::Right);
        } else if unsided.len() == 1 {
            let taken: Vec<Side> = (0..n)
                .filter(|&j| same(&labels[j]))
                .filter_map(|j| labels[j].side)
                .collect();
            labels[i].side = match taken.as_slice() {
                [Side::Left] => Some(Side::Right),
                [Side::Right] => Some(Side::Left),
                _ => None,
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::labels::label;
    use super::*;

    #[test]
    fn limbs_hang_from_their_own_side_and_props_from_the_holding_hand() {
        let r = |c: &str, p: &str, o: bool| parent_rank(&label(c), &label(p), o);
        assert_eq!(r("arm_lower_l", "arm_upper_l", true), Some(0));
        assert_eq!(r("arm_lower_l", "arm_upper_r", true), None);
        assert_eq!(r("hand_l", "forearm_l", false), Some(0));
        assert_eq!(r("tail", "pelvis", true), Some(0));
        assert_eq!(r("tail", "leg_upper_l", true), None);
        assert_eq!(r("lantern", "hand_r", true), Some(0));
        assert_eq!(r("lantern", "hand_r", false), None);
        assert_eq!(r("hat", "head", false), Some(0));
        assert_eq!(r("front leg l", "body", true), Some(0));
        assert_eq!(r("hind leg l", "hips", true), Some(0));
    }

    #[test]
    fn unsided_pairs_take_sides_from_the_screen() {
        let mut labels = vec![label("arm"), label("arm"), label("leg_l"), label("leg")];
        let centroids = [
            Point::new(10.0, 0.0),
            Point::new(90.0, 0.0),
            Point::new(60.0, 50.0),
            Point::new(40.0, 50.0),
        ];
        complete_sides(&mut labels, &centroids);
        let sides: Vec<Option<Side>> = labels.iter().map(|l| l.side).collect();
        assert_eq!(
            sides,
            [
                Some(Side::Right),
                Some(Side::Left),
                Some(Side::Left),
                Some(Side::Right)
            ]
        );
    }
}
