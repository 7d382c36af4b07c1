//! Keys the bundled character's `walk`: a front-view walk cycle of 1 s (contact, down, passing,
//! up; each foot lifts and plants in turn; the body bobs and sways over the standing foot).
//!
//! The legs are keyed by two-bone IK solved here through sinew's own forward kinematics
//! (`rig::handle_transforms`): the middle of the standing foot's sole stays where it rests while the hip
//! bobs; the swinging foot lifts (its thigh foreshortened as it comes towards the viewer) and
//! plants again at the next contact, where `footstep` fires. The arms (separate skeletons) follow
//! the chest and swing against the legs. Keys every 1/24 s, linear; the tail, the antenna
//! point and the events are kept as `animations.json` has them.
//!
//! `cargo run --example walk_cycle` rewrites `assets/character/animations.json`'s `walk`.

use serde_json::{json, Value};
use sinew::geom::Point;
use sinew::rig::pose::BonePose;
use sinew::rig::{handle_transforms, Handles, Pose};
use std::f64::consts::PI;

/// Keys per second (and per cycle).
const KEYS: usize = 24;
/// How high a swinging ankle lifts at its highest (px).
const LIFT_PX: f64 = 24.0;
/// How much the swinging thigh shortens at its highest (foreshortening toward the viewer).
const FORESHORTEN: f64 = 0.1;
/// The middle of each sole at rest (left, right; canvas px): the point a standing foot keeps on
/// the ground.
const SOLE_PX: [[f64; 2]; 2] = [[317.0, 478.0], [194.0, 478.0]];
/// When the back foot leaves the ground after the other foot's contact (s).
const TOE_OFF_S: f64 = 0.06;

/// 0 (planted) .. 1 (highest) for a foot that swings from `start_s` to `start_s + 0.5 - TOE_OFF_S`.
fn swing(t: f64, start_s: f64) -> f64 {
    let u = (t - start_s - TOE_OFF_S) / (0.5 - TOE_OFF_S);
    if (0.0..=1.0).contains(&u) {
        (PI * u).sin().max(0.0).powf(1.3)
    } else {
        0.0
    }
}

fn round(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}

fn main() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/character");
    let read = |f: &str| std::fs::read_to_string(format!("{dir}/{f}")).expect(f);
    let handles: Handles = serde_json::from_str(&read("handles.json")).expect("handles");
    let mut animations: Value = serde_json::from_str(&read("animations.json")).expect("json");
    let bone = |name: &str| {
        handles
            .bones
            .iter()
            .position(|b| b.name == name)
            .unwrap_or_else(|| panic!("no bone {name}"))
    };

    let mut keys: std::collections::BTreeMap<(String, &'static str), Vec<Value>> =
        Default::default();
    let mut previous = [(0.0, 0.0), (0.0, 0.0)];
    for k in 0..=KEYS {
        let t = k as f64 / KEYS as f64;
        let w = 2.0 * PI * t;
        let mut pose = Pose::default();
        let set = |pose: &mut Pose, name: &str, f: &dyn Fn(&mut BonePose)| {
            f(pose.bones.entry(name.to_string()).or_default())
        };
        // The body: down after each contact, up before the next; over the standing foot.
        let hip = [3.0 * w.sin(), 3.0 + 3.0 * (4.0 * PI * (t - 0.1)).cos()];
        set(&mut pose, "hip", &|b| b.translate = hip);
        set(&mut pose, "chest", &|b| b.rotate = 2.0 * w.sin());
        set(&mut pose, "head", &|b| b.rotate = -1.2 * w.sin());
        // Legs: left stands in the first half (its contact at 0 s), right in the second.
        let legs = [
            ("leg_upper_l", "leg_lower_l", swing(t, 0.5)),
            ("leg_upper_r", "leg_lower_r", swing(t, 0.0)),
        ];
        for (i, &(upper, lower, lifted)) in legs.iter().enumerate() {
            let rest = Point::new(SOLE_PX[i][0], SOLE_PX[i][1]);
            let target = Point::new(rest.x, rest.y - LIFT_PX * lifted);
            set(&mut pose, upper, &|b| {
                b.scale = [1.0 - FORESHORTEN * lifted, 1.0]
            });
            let ankle = |pose: &mut Pose, a: f64, b: f64| {
                pose.bones.get_mut(upper).expect("thigh").rotate = a;
                pose.bones.entry(lower.to_string()).or_default().rotate = b;
                let transforms = handle_transforms(&handles, pose).expect("poses");
                transforms[bone(lower)].apply(rest)
            };
            // Newton on the two rotations (the sole moves with the shin), from the previous key's.
            let (mut a, mut b) = previous[i];
            for _ in 0..50 {
                let p = ankle(&mut pose, a, b);
                let r = [p.x - target.x, p.y - target.y];
                if r[0].hypot(r[1]) < 1e-9 {
                    break;
                }
                let h = 1e-6;
                let pa = ankle(&mut pose, a + h, b);
                let pb = ankle(&mut pose, a, b + h);
                let j = [
                    [(pa.x - p.x) / h, (pb.x - p.x) / h],
                    [(pa.y - p.y) / h, (pb.y - p.y) / h],
                ];
                let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
                let da = (j[1][1] * r[0] - j[0][1] * r[1]) / det;
                let db = (-j[1][0] * r[0] + j[0][0] * r[1]) / det;
                a -= da.clamp(-5.0, 5.0);
                b -= db.clamp(-5.0, 5.0);
            }
            let reached = ankle(&mut pose, a, b);
            assert!(
                (reached - target).norm() < 1e-6,
                "{lower} at {t} s: cannot reach {target:?}"
            );
            previous[i] = (a, b);
        }
        // Arms swing against the legs, the forearms a little later; the lantern lags more.
        set(&mut pose, "arm_upper_r", &|b| b.rotate = 8.0 * w.cos());
        set(&mut pose, "arm_upper_l", &|b| b.rotate = 6.0 * w.cos());
        set(&mut pose, "arm_lower_r", &|b| {
            b.rotate = 5.0 * (w - 0.5).cos()
        });
        set(&mut pose, "arm_lower_l", &|b| {
            b.rotate = 5.0 * (w - 0.5).cos()
        });
        set(&mut pose, "lantern", &|b| b.rotate = -7.0 * (w - 1.1).cos());
        // The arms are skeletons of their own: their roots follow the chest's shoulders.
        let transforms = handle_transforms(&handles, &pose).expect("poses");
        for arm in ["arm_upper_r", "arm_upper_l"] {
            let head = handles.bones[bone(arm)].head;
            let shoulder = Point::new(head[0], head[1]);
            let moved = transforms[bone("chest")].apply(shoulder);
            let offset = [moved.x - shoulder.x, moved.y - shoulder.y];
            pose.bones.get_mut(arm).expect("arm").translate = offset;
        }
        for (name, b) in &pose.bones {
            let mut push = |timeline: &'static str, value: Value| {
                keys.entry((name.clone(), timeline))
                    .or_default()
                    .push(json!({"time": round(t), "value": value}));
            };
            if name != "hip" {
                push("rotate", json!(round(b.rotate)));
            }
            if name == "hip" || name.starts_with("arm_upper") {
                push(
                    "translate",
                    json!([round(b.translate[0]), round(b.translate[1])]),
                );
            }
            if name.starts_with("leg_upper") {
                push("scale", json!([round(b.scale[0]), 1.0]));
            }
        }
    }
    // The generated bones keep only their generated timelines; the tail's stay.
    let walk = animations["walk"]["bones"]
        .as_object_mut()
        .expect("walk bones");
    for (name, _) in keys.keys() {
        walk.insert(name.clone(), json!({}));
    }
    for ((name, timeline), list) in keys {
        walk[&name][timeline] = Value::Array(list);
    }
    let text = serde_json::to_string_pretty(&animations).expect("json") + "\n";
    std::fs::write(format!("{dir}/animations.json"), text).expect("write animations.json");
}
