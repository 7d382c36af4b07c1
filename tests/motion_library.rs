//! The bundled motion library (`assets/motions/`, sources in `assets/motions/SOURCES.md`):
//! every clip parses with the default limits, has the joints the library promises, finite
//! positions in every frame, a sensible size and frame rate; and the clips converted from
//! DeepMimic put their joints where DeepMimic's own skeleton does.

use sinew::motion::{self, fk, BvhLimits, Clip};
use std::path::Path;

/// The DeepMimic humanoid3d skeleton as `tools/motions/deepmimic_to_bvh.py` names it.
const DEEPMIMIC_JOINTS: [&str; 16] = [
    "Hips",
    "Spine",
    "Neck",
    "Head",
    "RightArm",
    "RightForeArm",
    "RightHand",
    "LeftArm",
    "LeftForeArm",
    "LeftHand",
    "RightUpLeg",
    "RightLeg",
    "RightFoot",
    "LeftUpLeg",
    "LeftLeg",
    "LeftFoot",
];

/// The CMU skeleton (cgspeed's BVH conversion), in file order.
const CMU_JOINTS: [&str; 31] = [
    "Hips",
    "LHipJoint",
    "LeftUpLeg",
    "LeftLeg",
    "LeftFoot",
    "LeftToeBase",
    "RHipJoint",
    "RightUpLeg",
    "RightLeg",
    "RightFoot",
    "RightToeBase",
    "LowerBack",
    "Spine",
    "Spine1",
    "Neck",
    "Neck1",
    "Head",
    "LeftShoulder",
    "LeftArm",
    "LeftForeArm",
    "LeftHand",
    "LeftFingerBase",
    "LFingers",
    "LThumb",
    "RightShoulder",
    "RightArm",
    "RightForeArm",
    "RightHand",
    "RightFingerBase",
    "RFingers",
    "RThumb",
];

/// (file, joints, frame time s, frames, metres per file unit).
const CLIPS: [(&str, &[&str], f64, usize, f64); 6] = [
    ("idle", &CMU_JOINTS, 1.0 / 120.0, 144, CMU_UNIT_M),
    ("jump_forward", &CMU_JOINTS, 1.0 / 120.0, 192, CMU_UNIT_M),
    ("walk", &DEEPMIMIC_JOINTS, 1.0 / 30.0, 39, 1.0),
    ("run", &DEEPMIMIC_JOINTS, 1.0 / 30.0, 25, 1.0),
    ("jump", &DEEPMIMIC_JOINTS, 1.0 / 60.0, 107, 1.0),
    ("wave", &DEEPMIMIC_JOINTS, 1.0 / 30.0, 61, 1.0),
];

/// The CMU database's length unit: 1/0.45 inch.
const CMU_UNIT_M: f64 = 0.0254 / 0.45;

fn load(name: &str) -> Clip {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets/motions")
        .join(format!("{name}.bvh"));
    motion::read(&path, &BvhLimits::default()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn every_clip_parses_with_its_joints_and_finite_positions() {
    for (name, joints, frame_time, frames, unit_m) in CLIPS {
        let clip = load(name);
        let names: Vec<&str> = clip.joints.iter().map(|j| j.name.as_str()).collect();
        assert_eq!(names, joints, "{name}");
        assert!(
            (clip.frame_time_s - frame_time).abs() < 1e-4,
            "{name}: {}",
            clip.frame_time_s
        );
        assert_eq!(clip.frame_count(), frames, "{name}");
        assert!(clip.duration_s() < 3.0, "{name}: keep clips short");
        let hips = clip.find("Hips").unwrap();
        let head = clip.find("Head").unwrap();
        for f in 0..clip.frame_count() {
            let p = fk::frame_positions(&clip, f).unwrap();
            for q in p.joints.iter().chain(p.end_sites.iter().flatten()) {
                assert!(q.iter().all(|c| c.is_finite()), "{name} frame {f}");
            }
            // A standing, walking or jumping person: the head 0.3 to 0.9 m above the hips
            // (y-up), both within a few metres of the origin.
            let rise = (p.joint(head).unwrap().y - p.joint(hips).unwrap().y) * unit_m;
            assert!(
                (0.3..0.9).contains(&rise),
                "{name} frame {f}: head {rise} m over the hips"
            );
            assert!(
                p.joint(hips).unwrap().coords.norm() * unit_m < 5.0,
                "{name} frame {f}"
            );
        }
    }
}

#[test]
fn clips_face_plus_z_with_their_left_at_plus_x() {
    for (name, ..) in CLIPS {
        let clip = load(name);
        let p = fk::frame_positions(&clip, 0).unwrap();
        let left = p.joint(clip.find("LeftUpLeg").unwrap()).unwrap();
        let right = p.joint(clip.find("RightUpLeg").unwrap()).unwrap();
        assert!(
            left.x > right.x,
            "{name}: left hip at x {} ≤ right {}",
            left.x,
            right.x
        );
    }
    // Walking and running go forward along +z.
    for name in ["walk", "run", "jump_forward"] {
        let clip = load(name);
        let hips = clip.find("Hips").unwrap();
        let first = fk::frame_positions(&clip, 0).unwrap().joint(hips).unwrap();
        let last = fk::frame_positions(&clip, clip.frame_count() - 1)
            .unwrap()
            .joint(hips)
            .unwrap();
        assert!(
            last.z - first.z > (last.x - first.x).abs(),
            "{name}: {first} → {last}"
        );
    }
}

/// The hand-keyed wave: at rest at its ends, the right hand above the head and out to the
/// character's right (−x) while it waves, the forearm swinging from side to side.
#[test]
fn the_wave_raises_the_right_hand_and_waves() {
    let clip = load("wave");
    let at = |f: usize, joint: &str| {
        let p = fk::frame_positions(&clip, f).unwrap();
        let id = clip.find(joint).unwrap();
        p.end_site(id).unwrap_or_else(|| p.joint(id).unwrap())
    };
    let rest = fk::frame_positions(&clip, 0).unwrap();
    assert_eq!(
        rest,
        fk::frame_positions(&clip, clip.frame_count() - 1).unwrap()
    );
    assert!(at(0, "RightHand").y < at(0, "Hips").y);
    let mut xs = Vec::new();
    for f in 15..=45 {
        let (hand, head) = (at(f, "RightHand"), at(f, "Head"));
        assert!(hand.y > head.y - 0.1, "frame {f}: hand {hand}, head {head}");
        assert!(hand.x < at(f, "RightArm").x - 0.1, "frame {f}: hand {hand}");
        xs.push(hand.x);
    }
    let (lo, hi) = xs
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    assert!(hi - lo > 0.15, "the hand sweeps {} m", hi - lo);
}

/// The converted clips' joints, through the BVH reader and its Euler forward kinematics, lie
/// where DeepMimic's quaternion skeleton puts them (to 0.1 mm: the BVH keeps 5 decimals of a
/// degree and 6 of a metre).
#[test]
fn deepmimic_conversions_match_the_source_skeleton() {
    for &(clip_name, frame, joint, expected) in DEEPMIMIC_POSITIONS {
        let clip = load(clip_name);
        let p = fk::frame_positions(&clip, frame).unwrap();
        let (joint, end) = match joint.strip_suffix("/end") {
            Some(j) => (j, true),
            None => (joint, false),
        };
        let id = clip.find(joint).unwrap();
        let got = if end {
            p.end_site(id).unwrap()
        } else {
            p.joint(id).unwrap()
        };
        let error = (got.coords - nalgebra::Vector3::from(expected)).norm();
        assert!(
            error < 1e-4,
            "{clip_name} frame {frame} {joint}{}: {got} vs {expected:?} ({error} m)",
            if end { " end site" } else { "" }
        );
    }
}

/// (clip, frame, joint or JOINT/end, position in metres): `tools/motions/deepmimic_to_bvh.py
/// assets-source.txt --positions FRAME` (quaternion forward kinematics on the DeepMimic data).
const DEEPMIMIC_POSITIONS: &[(&str, usize, &str, [f64; 3])] = &[
    ("walk", 0, "Hips", [0.000000, 0.847532, 0.000000]),
    ("walk", 0, "Spine", [-0.006669, 1.082435, 0.023307]),
    ("walk", 0, "Neck", [-0.017326, 1.304798, 0.047178]),
    ("walk", 0, "Head", [-0.025656, 1.478601, 0.065836]),
    ("walk", 0, "Head/end", [-0.030535, 1.580400, 0.076765]),
    ("walk", 0, "RightArm", [-0.198064, 1.320157, 0.007305]),
    ("walk", 0, "RightForeArm", [-0.220474, 1.063899, -0.089327]),
    ("walk", 0, "RightHand", [-0.237371, 0.810171, -0.138216]),
    ("walk", 0, "RightHand/end", [-0.239981, 0.770977, -0.145768]),
    ("walk", 0, "LeftArm", [0.166096, 1.333709, 0.043645]),
    ("walk", 0, "LeftForeArm", [0.262498, 1.081844, 0.096362]),
    ("walk", 0, "LeftHand", [0.280290, 0.888384, 0.267564]),
    ("walk", 0, "LeftHand/end", [0.283039, 0.858500, 0.294010]),
    ("walk", 0, "RightUpLeg", [-0.084853, 0.845147, -0.000237]),
    ("walk", 0, "RightLeg", [-0.067058, 0.460441, 0.171187]),
    ("walk", 0, "RightFoot", [-0.036419, 0.057733, 0.241051]),
    ("walk", 0, "RightFoot/end", [-0.039729, 0.033817, 0.381547]),
    ("walk", 0, "LeftUpLeg", [0.084853, 0.849917, 0.000237]),
    ("walk", 0, "LeftLeg", [0.073263, 0.441740, -0.104445]),
    ("walk", 0, "LeftFoot", [0.035082, 0.113879, -0.347432]),
    ("walk", 0, "LeftFoot/end", [0.046830, 0.020054, -0.240750]),
    ("walk", 19, "Hips", [0.000000, 0.847532, 0.619295]),
    ("walk", 19, "Spine", [0.006669, 1.082435, 0.642602]),
    ("walk", 19, "Neck", [0.017326, 1.304798, 0.666473]),
    ("walk", 19, "Head", [0.025656, 1.478601, 0.685131]),
    ("walk", 19, "Head/end", [0.030535, 1.580400, 0.696060]),
    ("walk", 19, "RightArm", [-0.166096, 1.333709, 0.662940]),
    ("walk", 19, "RightForeArm", [-0.262498, 1.081844, 0.715657]),
    ("walk", 19, "RightHand", [-0.280290, 0.888384, 0.886859]),
    ("walk", 19, "RightHand/end", [-0.283039, 0.858500, 0.913305]),
    ("walk", 19, "LeftArm", [0.198064, 1.320157, 0.626600]),
    ("walk", 19, "LeftForeArm", [0.220474, 1.063899, 0.529968]),
    ("walk", 19, "LeftHand", [0.237371, 0.810171, 0.481079]),
    ("walk", 19, "LeftHand/end", [0.239981, 0.770977, 0.473527]),
    ("walk", 19, "RightUpLeg", [-0.084853, 0.849917, 0.619532]),
    ("walk", 19, "RightLeg", [-0.073263, 0.441740, 0.514850]),
    ("walk", 19, "RightFoot", [-0.035082, 0.113879, 0.271863]),
    ("walk", 19, "RightFoot/end", [-0.046830, 0.020054, 0.378545]),
    ("walk", 19, "LeftUpLeg", [0.084853, 0.845147, 0.619058]),
    ("walk", 19, "LeftLeg", [0.067058, 0.460441, 0.790482]),
    ("walk", 19, "LeftFoot", [0.036419, 0.057733, 0.860346]),
    ("walk", 19, "LeftFoot/end", [0.039729, 0.033817, 1.000842]),
    ("run", 12, "Hips", [0.000000, 0.780608, 1.422720]),
    ("run", 12, "Spine", [-0.029644, 0.997094, 1.512287]),
    ("run", 12, "Neck", [-0.017507, 1.195564, 1.615199]),
    ("run", 12, "Head", [-0.008021, 1.350692, 1.695637]),
    ("run", 12, "Head/end", [-0.002465, 1.441553, 1.742751]),
    ("run", 12, "RightArm", [-0.200235, 1.228768, 1.615369]),
    ("run", 12, "RightForeArm", [-0.358361, 1.012319, 1.554915]),
    ("run", 12, "RightHand", [-0.286655, 0.845170, 1.739233]),
    ("run", 12, "RightHand/end", [-0.275579, 0.819350, 1.767705]),
    ("run", 12, "LeftArm", [0.165015, 1.219348, 1.590461]),
    ("run", 12, "LeftForeArm", [0.287294, 1.034058, 1.428521]),
    ("run", 12, "LeftHand", [0.273073, 0.817937, 1.570447]),
    ("run", 12, "LeftHand/end", [0.270876, 0.784552, 1.592370]),
    ("run", 12, "RightUpLeg", [-0.084216, 0.770762, 1.418646]),
    ("run", 12, "RightLeg", [-0.100714, 0.361240, 1.320050]),
    ("run", 12, "RightFoot", [-0.052990, 0.392456, 0.914167]),
    ("run", 12, "RightFoot/end", [-0.044765, 0.268886, 0.843562]),
    ("run", 12, "LeftUpLeg", [0.084216, 0.790454, 1.426794]),
    ("run", 12, "LeftLeg", [0.062726, 0.433406, 1.649853]),
    ("run", 12, "LeftFoot", [0.067001, 0.036693, 1.546926]),
    ("run", 12, "LeftFoot/end", [0.055333, 0.004328, 1.685269]),
    ("jump", 60, "Hips", [-0.058597, 1.127976, 0.594207]),
    ("jump", 60, "Spine", [-0.062537, 1.364072, 0.597453]),
    ("jump", 60, "Neck", [-0.053945, 1.581656, 0.649528]),
    ("jump", 60, "Head", [-0.027601, 1.745848, 0.704044]),
    ("jump", 60, "Head/end", [-0.012172, 1.842018, 0.735975]),
    ("jump", 60, "RightArm", [-0.229934, 1.619680, 0.603987]),
    ("jump", 60, "RightForeArm", [-0.340432, 1.368695, 0.621448]),
    ("jump", 60, "RightHand", [-0.331983, 1.171184, 0.788695]),
    ("jump", 60, "RightHand/end", [-0.330677, 1.140674, 0.814530]),
    ("jump", 60, "LeftArm", [0.131268, 1.592501, 0.657949]),
    ("jump", 60, "LeftForeArm", [0.194162, 1.340355, 0.747252]),
    ("jump", 60, "LeftHand", [0.111416, 1.182095, 0.934763]),
    ("jump", 60, "LeftHand/end", [0.098634, 1.157648, 0.963728]),
    ("jump", 60, "RightUpLeg", [-0.142337, 1.126769, 0.580350]),
    ("jump", 60, "RightLeg", [-0.142843, 0.705919, 0.556144]),
    ("jump", 60, "RightFoot", [-0.090533, 0.333300, 0.393627]),
    ("jump", 60, "RightFoot/end", [-0.124180, 0.232725, 0.488889]),
    ("jump", 60, "LeftUpLeg", [0.025142, 1.129183, 0.608064]),
    ("jump", 60, "LeftLeg", [0.042629, 0.708109, 0.617636]),
    ("jump", 60, "LeftFoot", [0.092831, 0.354003, 0.417429]),
    ("jump", 60, "LeftFoot/end", [0.074161, 0.232657, 0.489878]),
];
