//! Sampling animations into poses (`sinew::anim`).
//!
//! - `anim/sample/50_timelines`: a 2 s animation over 20 bones and 5 points with 50 timelines
//!   (20 bone rotates, 10 translates, 10 scales, 3 shears, 5 point translates, 2 point rotates),
//!   9 keys each, curves cycling through Bézier, linear and stepped; sampled looping at a time
//!   that advances by 1/60 s per call, so every segment and curve kind is visited.
//! - `anim/sample/walk`: the bundled character's walk (`assets/character/animations.json`).
//! - `anim/mix/walk_to_wave`: the crossfade from the walk into the wave half way through a 0.3 s
//!   mix (samples both, blends).
//!
//! Target (on the two-core reference machine): one 50-timeline sample < 20 µs.
//!
//! `cargo bench --bench anim`

use criterion::{criterion_group, criterion_main, Criterion};
use sinew::anim::{parse_animations, sample_mix, Animation, BoneTimelines, Curve, Key};
use sinew::anim::{Playhead, PointTimelines};
use sinew::geom::Point;
use sinew::rig::{Bone, Handles, PointHandle};
use std::collections::BTreeMap;
use std::hint::black_box;

const BONES: usize = 20;
const POINTS: usize = 5;
const KEYS: usize = 9;
const DURATION_S: f64 = 2.0;
const FRAME_S: f64 = 1.0 / 60.0;

/// Key k of a timeline: a wavy value, with the curve kind cycling by key and timeline.
fn keys<V: Clone>(timeline: usize, value: impl Fn(f64) -> V, channels: usize) -> Vec<Key<V>> {
    (0..KEYS)
        .map(|k| {
            let time = DURATION_S * k as f64 / (KEYS - 1) as f64;
            let next = DURATION_S * (k + 1) as f64 / (KEYS - 1) as f64;
            let curve = match (k + timeline) % 3 {
                0 => Curve::Bezier(
                    (0..channels)
                        .flat_map(|c| {
                            let c = c as f64;
                            [
                                time + 0.3 * (next - time),
                                c - 5.0,
                                time + 0.6 * (next - time),
                                c + 5.0,
                            ]
                        })
                        .collect(),
                ),
                1 => Curve::Linear,
                _ => Curve::Stepped,
            };
            Key {
                time,
                value: value((k * 7 + timeline) as f64),
                curve,
            }
        })
        .collect()
}

fn synthetic() -> (Animation, Handles) {
    let handles = Handles {
        bones: (0..BONES)
            .map(|i| Bone {
                name: format!("bone_{i:02}"),
                parent: (i % 4 != 0).then(|| format!("bone_{:02}", i - 1)),
                head: Point::new(10.0 * i as f64, 0.0),
                tail: Point::new(10.0 * i as f64 + 8.0, 0.0),
            })
            .collect(),
        points: (0..POINTS)
            .map(|i| PointHandle {
                name: format!("point_{i}"),
                at: Point::new(5.0 * i as f64, 40.0),
                parent: None,
            })
            .collect(),
        ..Default::default()
    };
    let mut bones = BTreeMap::new();
    let mut timeline = 0;
    let mut next = || {
        timeline += 1;
        timeline
    };
    for (i, bone) in handles.bones.iter().enumerate() {
        let t = BoneTimelines {
            rotate: Some(keys(next(), |x| (x * 37.0) % 90.0 - 45.0, 1)),
            translate: (i < 10).then(|| keys(next(), |x| [x % 5.0, -(x % 3.0)], 2)),
            scale: (i >= 10).then(|| keys(next(), |x| [1.0 + (x % 4.0) * 0.05, 1.0], 2)),
            shear: (i < 3).then(|| keys(next(), |x| [x % 7.0, 0.0], 2)),
        };
        bones.insert(bone.name.clone(), t);
    }
    let mut points = BTreeMap::new();
    for (i, point) in handles.points.iter().enumerate() {
        let t = PointTimelines {
            translate: Some(keys(next(), |x| [x % 6.0, x % 2.0], 2)),
            rotate: (i < 2).then(|| keys(next(), |x| x * 10.0, 1)),
            scale: None,
            shear: None,
        };
        points.insert(point.name.clone(), t);
    }
    assert_eq!(timeline, 50, "the benchmark promises 50 timelines");
    let animation = Animation {
        bones,
        points,
        ..Default::default()
    };
    if let Err(e) = animation.validate("synthetic") {
        panic!("{e}");
    }
    (animation, handles)
}

fn bundled() -> BTreeMap<String, Animation> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/character/animations.json"
    );
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let raw: BTreeMap<String, serde_json::Value> =
        serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"));
    parse_animations(&raw).unwrap_or_else(|e| panic!("{path}: {e}"))
}

fn bench(c: &mut Criterion) {
    let (animation, _handles) = synthetic();
    let mut group = c.benchmark_group("anim");
    let mut t = 0.0;
    group.bench_function("sample/50_timelines", |b| {
        b.iter(|| {
            t += FRAME_S;
            black_box(animation.sample(black_box(t), true))
        })
    });
    let bundled = bundled();
    let walk = &bundled["walk"];
    let wave = &bundled["wave"];
    let mut t = 0.0;
    group.bench_function("sample/walk", |b| {
        b.iter(|| {
            t += FRAME_S;
            black_box(walk.sample(black_box(t), true))
        })
    });
    let rest = Handles::default();
    group.bench_function("mix/walk_to_wave", |b| {
        b.iter(|| {
            let from = Playhead {
                animation: walk,
                time_s: black_box(0.4),
                looping: true,
            };
            let to = Playhead {
                animation: wave,
                time_s: black_box(0.15),
                looping: true,
            };
            black_box(sample_mix(from, to, 0.15, 0.3, &rest))
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
