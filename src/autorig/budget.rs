//! Keeping a proposal to bones an animator keeps: every piece of the drawing rigged, no bone
//! shorter than a fraction of the character, every bone inside, at most a budget of bones.
//!
//! In: [`ProtoBone`]s (canvas px, parents before children) from the skeleton, template or
//! layer stage, the union [`Shape`] they were proposed on, and the [`SkeletonOptions`]. Out:
//! the same list edited in place:
//!
//! 1. [`rig_free_pieces`]: each outer ring of the shape (a connected piece: a detached head,
//!    a juggling ball) that no bone lies on gets one bone along its principal axis, shortened
//!    to lie inside, parented to the bone nearest to the piece (across the gap).
//! 2. [`keep_inside`]: a bone that leaves the shape is shortened from its tail until it lies
//!    inside, or removed.
//! 3. [`drop_short_bones`]: bones shorter than [`min_bone_length_px`] are removed (shortest
//!    first), their children hung from their parent and, where the child started at the
//!    removed bone's tail, started at its head instead (when that stays inside).
//!
//! The budget itself is [`super::skeleton::limit_bones`] with [`bone_budget`]; a template's
//! proposal with fewer bones than [`bone_minimum`] has its longest bones split
//! ([`reach_minimum`]).

use super::shape::Shape;
use super::skeleton::{ProtoBone, SkeletonOptions};
use super::template::Template;
use crate::geom::{point_in_ring, point_segment_distance, Point};

/// Default bone budget of a humanoid template fit: about what an animator places (spine,
/// neck, head, two bones per limb, hands and feet).
pub const HUMANOID_MAX_BONES: usize = 20;
/// Default bone budget of a quadruped template fit (also ears, a longer tail, wings).
pub const QUADRUPED_MAX_BONES: usize = 25;
/// Default bone budget without a template.
pub const FREE_MAX_BONES: usize = 25;
/// Fewest bones of a humanoid template's proposal: a spine, a neck, a head and two bones per
/// limb, as an animator places them even on a drawing the template does not fit.
pub const HUMANOID_MIN_BONES: usize = 12;
/// Fewest bones of a quadruped template's proposal.
pub const QUADRUPED_MIN_BONES: usize = 15;

/// The fewest bones a proposal should have: the template's minimum, none without a template
/// or with `options.max_bones` given.
pub fn bone_minimum(options: &SkeletonOptions, template: Option<Template>) -> usize {
    match (options.max_bones, template) {
        (Some(_), _) | (None, None) => 1,
        (None, Some(Template::Humanoid)) => HUMANOID_MIN_BONES,
        (None, Some(Template::Quadruped)) => QUADRUPED_MIN_BONES,
    }
}

/// Splits the longest bones in two at their middle until there are `min` bones, never making
/// a bone shorter than `min_px` (so it may stop short of `min`): a limb drawn as one straight
/// piece gets an elbow. The second half is a new, unnamed child of the first; the bone's
/// children that start past its middle hang from it. Halves of a bone inside the shape stay
/// inside.
pub fn reach_minimum(bones: &mut Vec<ProtoBone>, min: usize, min_px: f64) {
    while bones.len() < min {
        let longest = (0..bones.len())
            .filter(|&b| bones[b].length_px() >= 2.0 * min_px)
            .max_by(|&a, &b| {
                bones[a]
                    .length_px()
                    .total_cmp(&bones[b].length_px())
                    .then(b.cmp(&a))
            });
        let Some(b) = longest else { return };
        let (head, tail) = (bones[b].head, bones[b].tail);
        let middle = Point::from((head.coords + tail.coords) / 2.0);
        let second = ProtoBone {
            head: middle,
            tail,
            parent: Some(b),
            name: None,
        };
        bones[b].tail = middle;
        // Where along the bone a child starts: those past the middle hang from the second half.
        let along = |p: Point| (p - head).dot(&(tail - head)) / (tail - head).norm_squared();
        for bone in bones.iter_mut() {
            match bone.parent {
                Some(p) if p == b && along(bone.head) >= 0.5 => bone.parent = Some(b + 1),
                Some(p) if p > b => bone.parent = Some(p + 1),
                _ => {}
            }
        }
        bones.insert(b + 1, second);
    }
}

/// The bone budget: `options.max_bones` when given, else the template's default.
pub fn bone_budget(options: &SkeletonOptions, template: Option<Template>) -> usize {
    options.max_bones.unwrap_or(match template {
        Some(Template::Humanoid) => HUMANOID_MAX_BONES,
        Some(Template::Quadruped) => QUADRUPED_MAX_BONES,
        None => FREE_MAX_BONES,
    })
}

/// The character's size: the larger side of the box of its outlines, px.
pub fn size_px(shape: &Shape) -> f64 {
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for ring in shape.rings() {
        for p in ring {
            lo = [lo[0].min(p.x), lo[1].min(p.y)];
            hi = [hi[0].max(p.x), hi[1].max(p.y)];
        }
    }
    (hi[0] - lo[0]).max(hi[1] - lo[1]).max(0.0)
}

/// The shortest bone kept: `min_bone_px`, or `min_bone_fraction` of the character's size if
/// that is longer, px.
pub fn min_bone_length_px(options: &SkeletonOptions, shape: &Shape) -> f64 {
    options
        .min_bone_px
        .max(options.min_bone_fraction * size_px(shape))
}

/// Which outer ring (piece) of `shape` holds `p`: the smallest one containing it.
fn piece_of(shape: &Shape, p: Point) -> Option<usize> {
    shape
        .outlines
        .iter()
        .enumerate()
        .filter(|(_, o)| point_in_ring(p, &o.outer))
        .min_by(|a, b| ring_area(&a.1.outer).total_cmp(&ring_area(&b.1.outer)))
        .map(|(k, _)| k)
}

fn ring_area(ring: &[Point]) -> f64 {
    let n = ring.len();
    0.5 * (0..n)
        .map(|i| {
            let (a, b) = (ring[i], ring[(i + 1) % n]);
            a.x * b.y - b.x * a.y
        })
        .sum::<f64>()
        .abs()
}

/// Gives each piece of `shape` with no bone on it a bone along its principal axis (inside,
/// at least `min_px` long), named `piece_N`, parented to the nearest bone. Returns how many
/// pieces got one; pieces too small for such a bone get none (the rig binds them to the
/// nearest handle).
pub fn rig_free_pieces(bones: &mut Vec<ProtoBone>, shape: &Shape, min_px: f64) -> usize {
    let mut rigged = vec![false; shape.outlines.len()];
    for b in bones.iter() {
        let middle = b.head + (b.tail - b.head) * 0.5;
        for p in [b.head, middle, b.tail] {
            if let Some(k) = piece_of(shape, p) {
                rigged[k] = true;
            }
        }
    }
    let mut added = 0;
    for (k, outline) in shape.outlines.iter().enumerate() {
        if rigged[k] {
            continue;
        }
        let piece = Shape::from_outlines(vec![outline.clone()], shape.width, shape.height);
        let Some(mut bone) = super::principal_bone(&piece) else {
            continue;
        };
        if bone.length_px() < min_px {
            continue;
        }
        let middle = bone.head + (bone.tail - bone.head) * 0.5;
        bone.parent = nearest_bone(bones, middle);
        added += 1;
        bone.name = Some(format!("piece_{added}"));
        bones.push(bone);
    }
    added
}

/// The bone nearest to `p` (distance to its segment), if any.
fn nearest_bone(bones: &[ProtoBone], p: Point) -> Option<usize> {
    (0..bones.len()).min_by(|&a, &b| {
        let d = |i: usize| point_segment_distance(p, bones[i].head, bones[i].tail);
        d(a).total_cmp(&d(b)).then(a.cmp(&b))
    })
}

/// Shortens every bone that leaves `shape` from its tail (by halving the excess) until it
/// lies inside; removes those that cannot keep `min_px` inside.
pub fn keep_inside(bones: &mut Vec<ProtoBone>, shape: &Shape, min_px: f64) {
    let mut k = 0;
    while k < bones.len() {
        let b = &bones[k];
        if shape.segment_inside(b.head, b.tail) {
            k += 1;
            continue;
        }
        // Largest t with head..head + t (tail - head) inside, by bisection.
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..24 {
            let t = 0.5 * (lo + hi);
            if shape.segment_inside(b.head, b.head + (b.tail - b.head) * t) {
                lo = t;
            } else {
                hi = t;
            }
        }
        let tail = b.head + (b.tail - b.head) * lo;
        if lo > 0.0 && (tail - b.head).norm() >= min_px && bones.len() > 1 {
            bones[k].tail = tail;
            k += 1;
        } else if bones.len() > 1 {
            remove_bone(bones, k, shape);
        } else {
            k += 1;
        }
    }
}

/// Removes bones shorter than `min_px`, shortest first, never the last one.
pub fn drop_short_bones(bones: &mut Vec<ProtoBone>, shape: &Shape, min_px: f64) {
    while bones.len() > 1 {
        let shortest = (0..bones.len())
            .filter(|&b| bones[b].length_px() < min_px)
            .min_by(|&a, &b| {
                bones[a]
                    .length_px()
                    .total_cmp(&bones[b].length_px())
                    .then(a.cmp(&b))
            });
        match shortest {
            Some(b) => remove_bone(bones, b, shape),
            None => break,
        }
    }
}

/// Removes bone `r`: its children hang from its parent; a child that started at `r`'s tail
/// starts at `r`'s head instead when it stays inside `shape`.
fn remove_bone(bones: &mut Vec<ProtoBone>, r: usize, shape: &Shape) {
    let removed = bones.remove(r);
    for b in bones.iter_mut() {
        match b.parent {
            Some(p) if p == r => {
                b.parent = removed.parent;
                let joined = (b.head - removed.tail).norm() < 1e-9;
                if joined && shape.segment_inside(removed.head, b.tail) {
                    b.head = removed.head;
                }
            }
            Some(p) if p > r => b.parent = Some(p - 1),
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reaching_the_minimum_splits_the_longest_bones_and_keeps_the_hierarchy() {
        let bone = |head: [f64; 2], tail: [f64; 2], parent| ProtoBone {
            head: Point::new(head[0], head[1]),
            tail: Point::new(tail[0], tail[1]),
            parent,
            name: None,
        };
        // A 100 px trunk with a 30 px branch from its tail.
        let mut bones = vec![
            bone([0.0, 0.0], [0.0, 100.0], None),
            bone([0.0, 100.0], [30.0, 100.0], Some(0)),
        ];
        reach_minimum(&mut bones, 4, 20.0);
        // The trunk splits (100 → 50 + 50), then a half (50 → 25 + 25); the branch (30 px)
        // could not split without a bone under 20 px.
        assert_eq!(bones.len(), 4);
        for (k, b) in bones.iter().enumerate() {
            assert!(b.parent.is_none_or(|p| p < k), "bone {k} before its parent");
            if let Some(p) = b.parent {
                assert!(
                    (bones[p].tail - b.head).norm() < 1e-12,
                    "bone {k} is not joined"
                );
            }
        }
        let lengths: Vec<f64> = bones.iter().map(ProtoBone::length_px).collect();
        assert_eq!(lengths, [25.0, 25.0, 50.0, 30.0]);
        // The branch still hangs from the trunk's tail.
        assert_eq!(bones[3].head, Point::new(0.0, 100.0));
        // Only the 50 px bone can still split into halves of at least 20 px: it stops short.
        reach_minimum(&mut bones, 10, 20.0);
        let lengths: Vec<f64> = bones.iter().map(ProtoBone::length_px).collect();
        assert_eq!(lengths, [25.0, 25.0, 25.0, 25.0, 30.0]);
    }
    use crate::autorig::shape::tests::square;
    use crate::trace::Outline;

    fn bone(head: (f64, f64), tail: (f64, f64), parent: Option<usize>) -> ProtoBone {
        ProtoBone {
            head: Point::new(head.0, head.1),
            tail: Point::new(tail.0, tail.1),
            parent,
            name: None,
        }
    }

    /// A long bar and a separate square: the square gets a bone parented to the bar's.
    #[test]
    fn a_free_piece_gets_a_bone_parented_across_the_gap() {
        let outlines = vec![
            Outline {
                outer: square(10.0, 10.0, 90.0, 20.0),
                holes: vec![],
            },
            Outline {
                outer: square(40.0, 40.0, 70.0, 52.0),
                holes: vec![],
            },
        ];
        let shape = Shape::from_outlines(outlines, 100, 60);
        let mut bones = vec![bone((15.0, 15.0), (85.0, 15.0), None)];
        assert_eq!(rig_free_pieces(&mut bones, &shape, 5.0), 1);
        assert_eq!(bones.len(), 2);
        let b = &bones[1];
        assert_eq!(b.parent, Some(0));
        assert_eq!(b.name.as_deref(), Some("piece_1"));
        assert!(shape.segment_inside(b.head, b.tail));
        assert!(b.head.y > 40.0 && b.tail.y > 40.0, "{b:?}");
        // Rigged pieces get nothing more.
        assert_eq!(rig_free_pieces(&mut bones, &shape, 5.0), 0);
    }

    #[test]
    fn short_bones_go_and_their_children_start_at_their_heads() {
        let shape = Shape::from_outlines(
            vec![Outline {
                outer: square(0.0, 0.0, 100.0, 20.0),
                holes: vec![],
            }],
            100,
            20,
        );
        let mut bones = vec![
            bone((5.0, 10.0), (40.0, 10.0), None),
            bone((40.0, 10.0), (43.0, 10.0), Some(0)),
            bone((43.0, 10.0), (90.0, 10.0), Some(1)),
            bone((90.0, 10.0), (92.0, 10.0), Some(2)),
        ];
        drop_short_bones(&mut bones, &shape, 10.0);
        assert_eq!(bones.len(), 2);
        assert_eq!(bones[1].parent, Some(0));
        assert_eq!(bones[1].head, Point::new(40.0, 10.0));
        assert!(bones.iter().all(|b| b.length_px() >= 10.0));
    }

    #[test]
    fn a_bone_leaving_the_shape_is_shortened_to_lie_inside() {
        let shape = Shape::from_outlines(
            vec![Outline {
                outer: square(0.0, 0.0, 50.0, 20.0),
                holes: vec![],
            }],
            100,
            20,
        );
        let mut bones = vec![
            bone((5.0, 10.0), (30.0, 10.0), None),
            bone((30.0, 10.0), (80.0, 10.0), Some(0)),
        ];
        keep_inside(&mut bones, &shape, 5.0);
        assert_eq!(bones.len(), 2);
        assert!(shape.segment_inside(bones[1].head, bones[1].tail));
        assert!(bones[1].tail.x > 45.0 && bones[1].tail.x < 50.0);
    }
}
