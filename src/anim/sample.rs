//! Sampling an animation at a time.
//!
//! In: an [`Animation`] and a time in seconds, looping or not. Out: the [`Pose`] at that time.
//! Looping wraps the time modulo the animation's duration (its latest key), so the duration itself
//! shows time 0; without looping the time is clamped to [0, duration]. Each timeline holds its first
//! key's value before that key and its last key's value after the last key (Spine instead shows the
//! setup pose before a timeline's first key; author a key at 0 to get the same). Sampled values
//! replace the rest values of the pose's fields; whatever has no timeline stays at rest (is absent
//! from the pose).
//!
//! [`SampleOptions::curves`] chooses between the exact curves and what Spine's runtimes play
//! ([`CurveEvaluation::SpineRuntime`]: f32 key storage, Bézier keys as 10-segment polylines).

use super::curve::{bezier_value, f32_stored, spine_runtime_bezier_value, Curve, CurveEvaluation};
use super::timeline::{Animation, Channels, Key, StepKey};
use crate::rig::pose::{BonePose, CagePose, IkDrag, PartPose, PointPose, Pose};
use serde::{Deserialize, Serialize};

/// Where a time falls among a timeline's keys.
enum Place {
    /// On key i's value (before the first key, on a key, or after the last).
    Hold(usize),
    /// Strictly between key i and key i + 1.
    Between(usize),
}

fn place(times: impl Fn(usize) -> f64, len: usize, t: f64) -> Place {
    let last = len.saturating_sub(1);
    if len == 0 || t <= times(0) {
        return Place::Hold(0);
    }
    if t >= times(last) {
        return Place::Hold(last);
    }
    // times(0) < t < times(last): at least one key is ≤ t and at least one is > t.
    let (mut lo, mut hi) = (0, last);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if times(mid) <= t {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Place::Between(lo)
}

/// How an animation is sampled.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SampleOptions {
    /// Exact curves (default) or the Spine runtime's evaluation.
    pub curves: CurveEvaluation,
}

/// The value of a keyed timeline at time `t`; `None` for a timeline without keys.
pub fn sample_keys<V: Channels>(keys: &[Key<V>], t: f64) -> Option<V> {
    sample_keys_with(keys, t, CurveEvaluation::Exact)
}

/// [`sample_keys`] with a choice of curve evaluation.
pub fn sample_keys_with<V: Channels>(
    keys: &[Key<V>],
    t: f64,
    curves: CurveEvaluation,
) -> Option<V> {
    match curves {
        CurveEvaluation::Exact => sample_keys_exact(keys, t),
        CurveEvaluation::SpineRuntime => sample_keys_spine_runtime(keys, t),
    }
}

/// What spine-core 4.2 computes for a timeline at `t` (`CurveTimeline1/2.getCurveValue`, the
/// color timelines alike): times and values as stored in its `Float32Array`s, the Bézier
/// polyline from the keys' unrounded numbers. One-curve timelines (cages) are eased by their
/// 0..1 curve the same way; the exporter's per-channel rewrite of that curve is the same
/// polyline up to f32 rounding.
fn sample_keys_spine_runtime<V: Channels>(keys: &[Key<V>], t: f64) -> Option<V> {
    let stored = |v: &V| {
        let mut out = v.clone();
        for x in out.numbers_mut() {
            *x = f32_stored(*x);
        }
        out
    };
    let i = match place(|i| f32_stored(keys[i].time), keys.len(), t) {
        Place::Hold(i) => return keys.get(i).map(|k| stored(&k.value)),
        Place::Between(i) => i,
    };
    let (a, b) = (&keys[i], &keys[i + 1]);
    let (t0, t1) = (f32_stored(a.time), f32_stored(b.time));
    let mut out = stored(&a.value);
    let pairs = a.value.numbers().iter().zip(b.value.numbers());
    match &a.curve {
        Curve::Stepped => {}
        Curve::Linear => {
            for (o, (va, vb)) in out.numbers_mut().iter_mut().zip(pairs) {
                let (va, vb) = (f32_stored(*va), f32_stored(*vb));
                *o = va + (t - t0) / (t1 - t0) * (vb - va);
            }
        }
        Curve::Bezier(handles) if V::CURVE_PER_CHANNEL => {
            for (c, (o, (va, vb))) in out.numbers_mut().iter_mut().zip(pairs).enumerate() {
                let h = handles.get(4 * c..4 * c + 4).unwrap_or(&[]);
                *o = spine_runtime_bezier_value(
                    ([a.time, *va], [b.time, *vb]),
                    ([t0, f32_stored(*va)], [t1, f32_stored(*vb)]),
                    h,
                    t,
                );
            }
        }
        Curve::Bezier(handles) => {
            let eased = spine_runtime_bezier_value(
                ([a.time, 0.0], [b.time, 1.0]),
                ([t0, 0.0], [t1, 1.0]),
                handles,
                t,
            );
            for (o, (va, vb)) in out.numbers_mut().iter_mut().zip(pairs) {
                let (va, vb) = (f32_stored(*va), f32_stored(*vb));
                *o = va + (vb - va) * eased;
            }
        }
    }
    Some(out)
}

fn sample_keys_exact<V: Channels>(keys: &[Key<V>], t: f64) -> Option<V> {
    let i = match place(|i| keys[i].time, keys.len(), t) {
        Place::Hold(i) => return keys.get(i).map(|k| k.value.clone()),
        Place::Between(i) => i,
    };
    let (a, b) = (&keys[i], &keys[i + 1]);
    let mut out = a.value.clone();
    let fraction = (t - a.time) / (b.time - a.time);
    let pairs = a.value.numbers().iter().zip(b.value.numbers());
    match &a.curve {
        Curve::Stepped => {}
        Curve::Linear => {
            for (o, (va, vb)) in out.numbers_mut().iter_mut().zip(pairs) {
                *o = va + (vb - va) * fraction;
            }
        }
        Curve::Bezier(handles) if V::CURVE_PER_CHANNEL => {
            for (c, (o, (va, vb))) in out.numbers_mut().iter_mut().zip(pairs).enumerate() {
                let h = handles.get(4 * c..4 * c + 4).unwrap_or(&[]);
                *o = bezier_value(a.time, *va, h, b.time, *vb, t);
            }
        }
        Curve::Bezier(handles) => {
            // One curve whose value runs 0 → 1: the fraction of the way for every number.
            let eased = bezier_value(a.time, 0.0, handles, b.time, 1.0, t);
            for (o, (va, vb)) in out.numbers_mut().iter_mut().zip(pairs) {
                *o = va + (vb - va) * eased;
            }
        }
    }
    Some(out)
}

/// The value of a stepped timeline at time `t`; `None` for a timeline without keys.
pub fn sample_steps<V: Clone>(keys: &[StepKey<V>], t: f64) -> Option<V> {
    let i = match place(|i| keys[i].time, keys.len(), t) {
        Place::Hold(i) | Place::Between(i) => i,
    };
    keys.get(i).map(|k| k.value.clone())
}

/// The time within the animation that `time_s` shows: wrapped or clamped into [0, duration].
/// A time that is not a number shows time 0.
pub fn local_time_s(duration_s: f64, time_s: f64, looping: bool) -> f64 {
    if time_s.is_nan() {
        return 0.0;
    }
    if looping {
        if duration_s > 0.0 && time_s.is_finite() {
            // rem_euclid can round up to the modulus itself for tiny negative times.
            let t = time_s.rem_euclid(duration_s);
            if t >= duration_s {
                0.0
            } else {
                t
            }
        } else {
            0.0
        }
    } else {
        time_s.clamp(0.0, duration_s)
    }
}

impl Animation {
    /// The pose at `time_s` seconds.
    pub fn sample(&self, time_s: f64, looping: bool) -> Pose {
        self.sample_with(time_s, looping, &SampleOptions::default())
    }

    /// [`Animation::sample`] with a choice of curve evaluation.
    pub fn sample_with(&self, time_s: f64, looping: bool, options: &SampleOptions) -> Pose {
        let curves = options.curves;
        let t = local_time_s(self.duration_s(), time_s, looping);
        let mut pose = Pose::default();
        for (name, timelines) in &self.bones {
            let mut bone = BonePose::default();
            let mut keyed = false;
            if let Some(v) = timelines
                .rotate
                .as_deref()
                .and_then(|k| sample_keys_with(k, t, curves))
            {
                bone.rotate = v;
                keyed = true;
            }
            for (field, keys) in [
                (&mut bone.translate, &timelines.translate),
                (&mut bone.scale, &timelines.scale),
                (&mut bone.shear, &timelines.shear),
            ] {
                if let Some(v) = keys.as_deref().and_then(|k| sample_keys_with(k, t, curves)) {
                    *field = v;
                    keyed = true;
                }
            }
            if keyed {
                pose.bones.insert(name.clone(), bone);
            }
        }
        for (name, timelines) in &self.points {
            let mut point = PointPose::default();
            let mut keyed = false;
            if let Some(v) = timelines
                .rotate
                .as_deref()
                .and_then(|k| sample_keys_with(k, t, curves))
            {
                point.rotate = v;
                keyed = true;
            }
            for (field, keys) in [
                (&mut point.translate, &timelines.translate),
                (&mut point.scale, &timelines.scale),
                (&mut point.shear, &timelines.shear),
            ] {
                if let Some(v) = keys.as_deref().and_then(|k| sample_keys_with(k, t, curves)) {
                    *field = v;
                    keyed = true;
                }
            }
            if keyed {
                pose.points.insert(name.clone(), point);
            }
        }
        for (name, keys) in &self.cages {
            if let Some(polygon) = sample_keys_with(keys, t, curves) {
                pose.cages.insert(name.clone(), CagePose { polygon });
            }
        }
        for (name, keys) in &self.deform {
            if let Some(offsets) = sample_keys_with(keys, t, curves) {
                pose.deform.insert(name.clone(), offsets);
            }
        }
        for (name, timelines) in &self.parts {
            let mut part = PartPose::default();
            let mut keyed = false;
            if let Some(c) = timelines
                .color
                .as_deref()
                .and_then(|k| sample_keys_with(k, t, curves))
            {
                part.color = c.0;
                keyed = true;
            }
            if let Some(v) = timelines
                .visible
                .as_deref()
                .and_then(|k| sample_steps(k, t))
            {
                part.visible = v;
                keyed = true;
            }
            if let Some(shown) = timelines
                .attachment
                .as_deref()
                .and_then(|k| sample_steps(k, t))
            {
                match shown {
                    Some(name) => part.attachment = Some(name),
                    None => part.visible = false,
                }
                keyed = true;
            }
            if keyed {
                pose.parts.insert(name.clone(), part);
            }
        }
        pose.draw_order = self.draw_order.as_deref().and_then(|k| sample_steps(k, t));
        pose.ik = self
            .ik
            .iter()
            .filter_map(|drag| {
                sample_keys_with(&drag.to, t, curves).map(|to| IkDrag {
                    at: drag.at,
                    to,
                    weight: drag.weight,
                })
            })
            .collect();
        pose
    }
}

#[cfg(test)]
mod tests {
    use super::super::timeline::{BoneTimelines, IkTimeline, PartTimelines, Rgba};
    use super::*;
    use crate::geom::Point;

    fn key<V>(time: f64, value: V, curve: Curve) -> Key<V> {
        Key { time, value, curve }
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn linear_stepped_and_clamped() {
        let keys = vec![
            key(0.5, 10.0, Curve::Linear),
            key(1.5, 20.0, Curve::Stepped),
            key(2.0, 40.0, Curve::Linear),
        ];
        assert_eq!(sample_keys(&keys, 0.0), Some(10.0)); // before the first key
        assert!(close(sample_keys(&keys, 0.75).unwrap(), 12.5));
        assert_eq!(sample_keys(&keys, 1.5), Some(20.0));
        assert_eq!(sample_keys(&keys, 1.99), Some(20.0)); // stepped holds
        assert_eq!(sample_keys(&keys, 2.0), Some(40.0));
        assert_eq!(sample_keys(&keys, 9.0), Some(40.0));
        assert_eq!(sample_keys::<f64>(&[], 1.0), None);
    }

    #[test]
    fn rotation_beyond_180_is_interpolated_as_authored() {
        // 0 → 360 is a full turn, not a standstill; −170 → 190 passes through 10.
        let turn = vec![key(0.0, 0.0, Curve::Linear), key(1.0, 360.0, Curve::Linear)];
        assert!(close(sample_keys(&turn, 0.5).unwrap(), 180.0));
        assert!(close(sample_keys(&turn, 0.25).unwrap(), 90.0));
        let wide = vec![
            key(0.0, -170.0, Curve::Linear),
            key(1.0, 190.0, Curve::Linear),
        ];
        assert!(close(sample_keys(&wide, 0.5).unwrap(), 10.0));
        let anim = Animation {
            bones: [(
                "b".to_string(),
                BoneTimelines {
                    rotate: Some(vec![
                        key(0.0, 0.0, Curve::Linear),
                        key(2.0, 720.0, Curve::Linear),
                    ]),
                    ..Default::default()
                },
            )]
            .into(),
            ..Default::default()
        };
        assert!(close(anim.sample(1.5, false).bones["b"].rotate, 540.0));
    }

    #[test]
    fn bezier_key_halfway_per_channel() {
        // x channel eases (handles at mid-time: value 5 halfway), y channel has handles at
        // thirds with cy at thirds too, i.e. it is linear.
        let keys = vec![
            key(
                0.0,
                [0.0, 0.0],
                Curve::Bezier(vec![1.0, 0.0, 1.0, 10.0, 2.0 / 3.0, 2.0, 4.0 / 3.0, 4.0]),
            ),
            key(2.0, [10.0, 6.0], Curve::Linear),
        ];
        let v = sample_keys(&keys, 1.0).unwrap();
        assert!(close(v[0], 5.0) && close(v[1], 3.0), "{v:?}");
        let v = sample_keys(&keys, 0.5).unwrap();
        assert!(v[0] < 1.25 && close(v[1], 1.5), "{v:?}");
    }

    #[test]
    fn spine_runtime_sampling_stores_f32_and_walks_the_polyline() {
        let rt = CurveEvaluation::SpineRuntime;
        // Linear and stepped keys: the same as exact, up to f32 storage of times and values.
        let keys = vec![
            key(0.1, 10.3, Curve::Linear),
            key(0.7, -4.9, Curve::Stepped),
            key(1.0, 2.0, Curve::Linear),
        ];
        for t in [0.0, 0.25, 0.5, 0.8, 1.5] {
            let (a, b) = (
                sample_keys(&keys, t).unwrap(),
                sample_keys_with(&keys, t, rt).unwrap(),
            );
            assert!((a - b).abs() < 1e-5, "{t}: {a} {b}");
        }
        assert_eq!(sample_keys_with(&keys, 0.0, rt), Some(f32_stored(10.3)));
        // A Bézier key: exact at the keys, off the exact cubic in between (the runtime's
        // polyline), and on the polyline's straight segment between two of its points.
        let eased = vec![
            key(0.0, 0.0, Curve::Bezier(vec![0.5, 0.0, 0.5, 90.0])),
            key(1.0, 90.0, Curve::Linear),
        ];
        let exact = sample_keys(&eased, 0.3).unwrap();
        let runtime = sample_keys_with(&eased, 0.3, rt).unwrap();
        assert!((exact - runtime).abs() > 1e-3 && (exact - runtime).abs() < 2.0);
        assert_eq!(sample_keys_with(&eased, 1.0, rt), Some(90.0));
    }

    #[test]
    fn cage_bezier_is_one_fraction_for_every_vertex() {
        let keys = vec![
            key(
                0.0,
                vec![Point::new(0.0, 0.0), Point::new(10.0, 0.0)],
                Curve::Bezier(vec![0.5, 0.0, 0.5, 1.0]),
            ),
            key(
                1.0,
                vec![Point::new(4.0, 8.0), Point::new(10.0, 20.0)],
                Curve::Linear,
            ),
        ];
        let v = sample_keys(&keys, 0.5).unwrap();
        assert!(close(v[0][0], 2.0) && close(v[0][1], 4.0) && close(v[1][1], 10.0));
        let early = sample_keys(&keys, 0.2).unwrap();
        assert!(early[1][1] < 0.2 * 20.0);
    }

    fn walkish() -> Animation {
        Animation {
            bones: [(
                "leg".to_string(),
                BoneTimelines {
                    rotate: Some(vec![
                        key(0.0, 20.0, Curve::Linear),
                        key(0.5, -20.0, Curve::Linear),
                        key(1.0, 20.0, Curve::Linear),
                    ]),
                    ..Default::default()
                },
            )]
            .into(),
            parts: [(
                "hat".to_string(),
                PartTimelines {
                    color: Some(vec![key(0.0, Rgba([1.0, 0.5, 0.5, 1.0]), Curve::Linear)]),
                    visible: Some(vec![
                        StepKey {
                            time: 0.0,
                            value: true,
                        },
                        StepKey {
                            time: 0.8,
                            value: false,
                        },
                    ]),
                    attachment: None,
                },
            )]
            .into(),
            draw_order: Some(vec![StepKey {
                time: 0.25,
                value: vec!["b".into(), "a".into()],
            }]),
            ik: vec![IkTimeline {
                at: Point::new(1.0, 2.0),
                to: vec![
                    key(0.0, Point::new(1.0, 2.0), Curve::Linear),
                    key(1.0, Point::new(3.0, 2.0), Curve::Linear),
                ],
                weight: None,
            }],
            ..Default::default()
        }
    }

    #[test]
    fn looping_wraps_and_clamping_holds() {
        let anim = walkish();
        assert_eq!(anim.duration_s(), 1.0);
        let at = |t: f64, looping: bool| anim.sample(t, looping).bones["leg"].rotate;
        assert!(close(at(0.25, true), 0.0));
        assert!(close(at(1.25, true), 0.0));
        assert!(close(at(-0.75, true), 0.0));
        assert!(close(at(1.0, true), 20.0)); // the duration shows time 0
        assert!(close(at(1.75, true), at(0.75, false)));
        assert!(close(at(1.75, false), 20.0));
        assert!(close(at(-1.0, false), 20.0));
        assert!(close(at(f64::NAN, true), 20.0));
        let pose = anim.sample(0.9, false);
        assert!(!pose.parts["hat"].visible);
        assert_eq!(pose.parts["hat"].color, [1.0, 0.5, 0.5, 1.0]);
        assert_eq!(
            pose.draw_order,
            Some(vec!["b".to_string(), "a".to_string()])
        );
        assert!(close(pose.ik[0].to[0], 2.8) && pose.ik[0].to[1] == 2.0);
        // Nothing untimed appears in the pose.
        assert!(pose.points.is_empty() && pose.cages.is_empty());
        // Before the draw order's first key, its first key holds.
        assert!(anim.sample(0.1, false).draw_order.is_some());
    }
}
