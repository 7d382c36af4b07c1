//! Crossfading one animation into another (a walk into a run).
//!
//! In: two poses (or two animations with their own playheads) and the mix's progress; the rig's
//! handles supply the rest polygon of a cage only one side animates. Out: the blended [`Pose`].
//!
//! The mix weight alpha = elapsed / duration, clamped to [0, 1], runs linearly as in Spine. A
//! field one side leaves at rest blends with its rest value. Bone and point rotations blend along
//! the shortest arc (Spine's rule: the difference is wrapped into (−180°, 180°]); translations,
//! scales, shears, colors, cage vertices, deform offsets (none on one side: zero) and IK targets
//! blend linearly. Values that cannot blend — visibility, draw order, IK drags or cages present
//! on one side only, cages whose vertex counts differ — switch from the old animation's to the new one's when alpha reaches
//! [`STEPPED_MIX_THRESHOLD`]. (Spine's default thresholds are 0: the new animation's attachments
//! and draw order apply at once. Half way keeps a short mix from popping at its very start.) At
//! alpha 0 the result is exactly the old pose and at alpha 1 exactly the new one.

use super::timeline::Animation;
use crate::geom::{Point, Vec2};
use crate::rig::pose::{BonePose, CagePose, IkDrag, PartPose, PointPose, Pose};
use crate::rig::Handles;
use std::collections::BTreeSet;

/// Stepped values show the new animation's once the mix weight is at least this.
pub const STEPPED_MIX_THRESHOLD: f64 = 0.5;

/// An animation being played: which, at what time (s), and whether it loops.
#[derive(Clone, Copy, Debug)]
pub struct Playhead<'a> {
    pub animation: &'a Animation,
    pub time_s: f64,
    pub looping: bool,
}

impl Playhead<'_> {
    pub fn sample(&self) -> Pose {
        self.animation.sample(self.time_s, self.looping)
    }
}

/// The mix weight of the new animation: elapsed / duration in [0, 1]; a mix without duration is
/// complete at once, and an elapsed time that is not a number counts as the mix's start.
pub fn mix_alpha(mix_elapsed_s: f64, mix_duration_s: f64) -> f64 {
    // Also catches a duration that is not a number.
    if mix_duration_s.is_nan() || mix_duration_s <= 0.0 {
        return 1.0;
    }
    let alpha = mix_elapsed_s / mix_duration_s;
    if alpha.is_nan() {
        0.0
    } else {
        alpha.clamp(0.0, 1.0)
    }
}

/// From `from_deg` towards `to_deg` along the shorter way round, by `alpha`.
pub fn shortest_arc_deg(from_deg: f64, to_deg: f64, alpha: f64) -> f64 {
    let mut diff = to_deg - from_deg;
    diff -= (diff / 360.0 - 0.5).ceil() * 360.0;
    from_deg + diff * alpha
}

fn lerp(a: f64, b: f64, alpha: f64) -> f64 {
    a + (b - a) * alpha
}

fn lerp2(a: [f64; 2], b: [f64; 2], alpha: f64) -> [f64; 2] {
    [lerp(a[0], b[0], alpha), lerp(a[1], b[1], alpha)]
}

fn lerp_point(a: Point, b: Point, alpha: f64) -> Point {
    a + (b - a) * alpha
}

/// `from` blended into `to` by `alpha` ∈ [0, 1].
pub fn mix_poses(from: &Pose, to: &Pose, alpha: f64, rest: &Handles) -> Pose {
    if alpha.is_nan() || alpha <= 0.0 {
        return from.clone();
    }
    if alpha >= 1.0 {
        return to.clone();
    }
    let stepped_to_new = alpha >= STEPPED_MIX_THRESHOLD;
    let mut out = Pose::default();

    let bone_names: BTreeSet<&String> = from.bones.keys().chain(to.bones.keys()).collect();
    for name in bone_names {
        let a = from.bones.get(name).cloned().unwrap_or_default();
        let b = to.bones.get(name).cloned().unwrap_or_default();
        let bone = BonePose {
            rotate: shortest_arc_deg(a.rotate, b.rotate, alpha),
            translate: lerp2(a.translate, b.translate, alpha),
            scale: lerp2(a.scale, b.scale, alpha),
            shear: lerp2(a.shear, b.shear, alpha),
        };
        out.bones.insert(name.clone(), bone);
    }

    let point_names: BTreeSet<&String> = from.points.keys().chain(to.points.keys()).collect();
    for name in point_names {
        let a = from.points.get(name).cloned().unwrap_or_default();
        let b = to.points.get(name).cloned().unwrap_or_default();
        let point = PointPose {
            translate: lerp2(a.translate, b.translate, alpha),
            rotate: shortest_arc_deg(a.rotate, b.rotate, alpha),
            scale: lerp2(a.scale, b.scale, alpha),
            shear: lerp2(a.shear, b.shear, alpha),
        };
        out.points.insert(name.clone(), point);
    }

    let cage_names: BTreeSet<&String> = from.cages.keys().chain(to.cages.keys()).collect();
    for name in cage_names {
        let rest_polygon = rest
            .cages
            .iter()
            .find(|c| &c.name == name)
            .map(|c| &c.polygon);
        let a = from.cages.get(name).map(|c| &c.polygon).or(rest_polygon);
        let b = to.cages.get(name).map(|c| &c.polygon).or(rest_polygon);
        let polygon = match (a, b) {
            (Some(a), Some(b)) if a.len() == b.len() => Some(
                a.iter()
                    .zip(b)
                    .map(|(&p, &q)| lerp_point(p, q, alpha))
                    .collect(),
            ),
            _ if stepped_to_new => to.cages.get(name).map(|c| c.polygon.clone()),
            _ => from.cages.get(name).map(|c| c.polygon.clone()),
        };
        if let Some(polygon) = polygon {
            out.cages.insert(name.clone(), CagePose { polygon });
        }
    }

    // Deform offsets fade from and to none (zero offsets) on the side without them.
    let deform_names: BTreeSet<&String> = from.deform.keys().chain(to.deform.keys()).collect();
    for name in deform_names {
        let (a, b) = (from.deform.get(name), to.deform.get(name));
        let n = a.or(b).map_or(0, Vec::len);
        let none = vec![Vec2::zeros(); n];
        let (a, b) = (a.unwrap_or(&none), b.unwrap_or(&none));
        let offsets = if a.len() == b.len() {
            a.iter()
                .zip(b)
                .map(|(&p, &q)| p + (q - p) * alpha)
                .collect()
        } else if stepped_to_new {
            b.clone()
        } else {
            a.clone()
        };
        out.deform.insert(name.clone(), offsets);
    }

    let part_names: BTreeSet<&String> = from.parts.keys().chain(to.parts.keys()).collect();
    for name in part_names {
        let a = from.parts.get(name).cloned().unwrap_or_default();
        let b = to.parts.get(name).cloned().unwrap_or_default();
        let mut color = a.color;
        for (c, target) in color.iter_mut().zip(b.color) {
            *c = lerp(*c, target, alpha);
        }
        let part = PartPose {
            color,
            visible: if stepped_to_new { b.visible } else { a.visible },
            attachment: if stepped_to_new {
                b.attachment
            } else {
                a.attachment
            },
        };
        out.parts.insert(name.clone(), part);
    }

    out.draw_order = if stepped_to_new {
        to.draw_order.clone()
    } else {
        from.draw_order.clone()
    };

    // Drags pair up by their rest point; unpaired ones come and go at the threshold.
    let bits = |p: Point| [p.x.to_bits(), p.y.to_bits()];
    let same_at = |d: &IkDrag, e: &IkDrag| bits(d.at) == bits(e.at);
    for drag in &from.ik {
        match to.ik.iter().find(|e| same_at(drag, e)) {
            Some(target) => out.ik.push(IkDrag {
                at: drag.at,
                to: lerp_point(drag.to, target.to, alpha),
                weight: target.weight,
            }),
            None if !stepped_to_new => out.ik.push(drag.clone()),
            None => {}
        }
    }
    if stepped_to_new {
        for drag in &to.ik {
            if !from.ik.iter().any(|d| same_at(d, drag)) {
                out.ik.push(drag.clone());
            }
        }
    }
    out
}

/// The crossfade from `from` into `to`, `mix_elapsed_s` into a mix of `mix_duration_s`.
pub fn sample_mix(
    from: Playhead,
    to: Playhead,
    mix_elapsed_s: f64,
    mix_duration_s: f64,
    rest: &Handles,
) -> Pose {
    let alpha = mix_alpha(mix_elapsed_s, mix_duration_s);
    if alpha >= 1.0 {
        return to.sample();
    }
    mix_poses(&from.sample(), &to.sample(), alpha, rest)
}

#[cfg(test)]
mod tests {
    use super::super::curve::Curve;
    use super::super::timeline::{BoneTimelines, Key};
    use super::*;
    use crate::rig::Cage;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    fn rotating(name: &str, from_deg: f64, to_deg: f64) -> Animation {
        let key = |time, value| Key {
            time,
            value,
            curve: Curve::Linear,
        };
        Animation {
            bones: [(
                name.to_string(),
                BoneTimelines {
                    rotate: Some(vec![key(0.0, from_deg), key(1.0, to_deg)]),
                    ..Default::default()
                },
            )]
            .into(),
            ..Default::default()
        }
    }

    #[test]
    fn shortest_arc_wraps_like_spine() {
        assert!(close(shortest_arc_deg(170.0, -170.0, 0.5), 180.0));
        assert!(close(shortest_arc_deg(-170.0, 170.0, 0.5), -180.0));
        assert!(close(shortest_arc_deg(0.0, 350.0, 0.5), -5.0));
        assert!(close(shortest_arc_deg(720.0, 10.0, 1.0), 730.0));
        // Exactly opposite: Spine turns the positive way.
        assert!(close(shortest_arc_deg(0.0, 180.0, 0.5), 90.0));
        assert!(close(shortest_arc_deg(0.0, -180.0, 0.5), 90.0));
    }

    #[test]
    fn crossfade_blends_and_ends_exactly_on_the_new_pose() {
        let walk = rotating("leg", 0.0, 40.0);
        let run = rotating("leg", 350.0, 350.0);
        let wave = rotating("arm", 90.0, 90.0);
        let rest = Handles::default();
        let at = |from: &Animation, to: &Animation, elapsed: f64| {
            sample_mix(
                Playhead {
                    animation: from,
                    time_s: 0.5,
                    looping: false,
                },
                Playhead {
                    animation: to,
                    time_s: 0.0,
                    looping: false,
                },
                elapsed,
                0.2,
                &rest,
            )
        };
        // From 20° at 0.5 s to 350°: the short way is −30°.
        assert!(close(at(&walk, &run, 0.0).bones["leg"].rotate, 20.0));
        assert!(close(at(&walk, &run, 0.1).bones["leg"].rotate, 5.0));
        assert_eq!(at(&walk, &run, 0.2), run.sample(0.0, false));
        assert_eq!(at(&walk, &run, 5.0), run.sample(0.0, false));
        // What only one side animates blends with rest.
        let half = at(&walk, &wave, 0.05);
        assert!(close(half.bones["leg"].rotate, 15.0));
        assert!(close(half.bones["arm"].rotate, 22.5));
        // A mix of no duration is a cut.
        assert_eq!(mix_alpha(0.0, 0.0), 1.0);
        assert_eq!(mix_alpha(f64::NAN, 1.0), 0.0);
    }

    #[test]
    fn stepped_values_switch_at_the_threshold_and_cages_fade_from_rest() {
        let mut from = Pose {
            draw_order: Some(vec!["a".into(), "b".into()]),
            ..Default::default()
        };
        from.parts.insert(
            "a".into(),
            PartPose {
                visible: false,
                color: [0.0, 0.0, 0.0, 1.0],
                attachment: None,
            },
        );
        from.ik.push(IkDrag {
            at: Point::new(0.0, 0.0),
            to: Point::new(10.0, 0.0),
            weight: None,
        });
        let mut to = Pose::default();
        to.ik.push(IkDrag {
            at: Point::new(0.0, 0.0),
            to: Point::new(20.0, 0.0),
            weight: None,
        });
        to.ik.push(IkDrag {
            at: Point::new(5.0, 5.0),
            to: Point::new(6.0, 6.0),
            weight: None,
        });
        to.cages.insert(
            "c".into(),
            CagePose {
                polygon: vec![
                    Point::new(10.0, 0.0),
                    Point::new(20.0, 0.0),
                    Point::new(20.0, 10.0),
                ],
            },
        );
        let rest = Handles {
            cages: vec![Cage {
                name: "c".into(),
                polygon: vec![
                    Point::new(0.0, 0.0),
                    Point::new(10.0, 0.0),
                    Point::new(10.0, 10.0),
                ],
            }],
            ..Default::default()
        };
        let early = mix_poses(&from, &to, 0.25, &rest);
        assert_eq!(early.draw_order, from.draw_order);
        assert!(!early.parts["a"].visible);
        assert!(close(early.parts["a"].color[0], 0.25));
        assert_eq!(early.ik.len(), 1);
        assert!(close(early.ik[0].to[0], 12.5));
        assert!(close(early.cages["c"].polygon[0][0], 2.5));
        let late = mix_poses(&from, &to, STEPPED_MIX_THRESHOLD, &rest);
        assert_eq!(late.draw_order, None);
        assert!(late.parts["a"].visible);
        assert_eq!(late.ik.len(), 2);
        assert!(close(late.ik[0].to[0], 15.0));
    }
}
