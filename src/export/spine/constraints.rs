//! Bone IK constraints as Spine IK constraints.
//!
//! In: the rig's [`Handles`] (their `ik` constraints, see [`crate::rig::bone_ik`]) and the
//! export's [`Skeleton`]. Out: which constraints Spine solves itself — every one- and two-bone
//! constraint, written as a Spine 4.2 `ik` entry (`bones`, `target`, `mix`, `softness`,
//! `bendPositive`, `order`; spine-format.md §8), or for 4.3 as an entry of the typed
//! `constraints` array (`"type": "ik"`, the same fields, update order = array order; §11) — and,
//! per animation, which of them must be switched off (an IK timeline keying `mix` to 0, which
//! 4.2 and 4.3 read alike) because their chain is baked.
//!
//! sinew's one- and two-bone solver is spine-core's own (`bone_ik` ports `apply1`/`apply2`), so
//! the fields carry over unchanged: `bend_positive` is `bendPositive`, `softness_px` is
//! `softness`, and `mix` is written clamped to [0, 1] as sinew applies it. The target bone's keys
//! are ordinary bone keys, so the runtime solves the constraint at every frame from them.
//!
//! Chains of three or more bones (FABRIK) have no Spine counterpart: they are not written, so
//! their bones' solved motion differs from forward kinematics of the keys and the bake
//! ([`super::bake`]) samples it into keys. A chain that Spine would solve but whose bones are
//! baked anyway (skinning IK moved them, or `--bake all`) must not be solved a second time on
//! top of its baked keys: [`switch_off_baked`] bakes the whole chain and what hangs from it and
//! names the constraints to key off in that animation.

use super::skeleton::Skeleton;
use super::timelines::num;
use super::SpineVersion;
use crate::rig::Handles;
use serde_json::{json, Value};
use std::collections::BTreeSet;

/// The constraints Spine can solve natively: one or two bones.
pub fn exported(handles: &Handles) -> Vec<usize> {
    (0..handles.ik.len())
        .filter(|&c| matches!(handles.ik[c].bones.len(), 1 | 2))
        .collect()
}

/// `handles` with only the constraints in `keep`: what Spine's runtime applies.
pub fn with_constraints(handles: &Handles, keep: &[usize]) -> Handles {
    Handles {
        ik: keep.iter().map(|&c| handles.ik[c].clone()).collect(),
        ..handles.clone()
    }
}

/// The skeleton index of the sinew bone named `name`.
fn bone_index(skeleton: &Skeleton, name: &str) -> Option<usize> {
    skeleton.bones.iter().position(|b| b.name == name)
}

/// Extends `baked` until no exported constraint has part of its chain baked while Spine would
/// still solve it: such a constraint's whole chain and the bones below its root join `baked`.
/// Returns those constraints (indices into `handles.ik`), to be keyed to mix 0.
pub fn switch_off_baked(
    handles: &Handles,
    skeleton: &Skeleton,
    exported: &[usize],
    baked: &mut BTreeSet<usize>,
) -> Vec<usize> {
    let mut off = BTreeSet::new();
    loop {
        let before = (off.len(), baked.len());
        for &c in exported {
            let chain: Vec<usize> = handles.ik[c]
                .bones
                .iter()
                .filter_map(|b| bone_index(skeleton, b))
                .collect();
            if chain.iter().any(|b| baked.contains(b)) {
                off.insert(c);
                baked.extend(&chain);
                if let Some(&root) = chain.first() {
                    baked.extend(skeleton.descendants(root));
                }
            }
        }
        if (off.len(), baked.len()) == before {
            return off.into_iter().collect();
        }
    }
}

/// The top-level key of the constraint entries: `ik` up to 4.2, `constraints` in 4.3.
pub fn block_key(version: SpineVersion) -> &'static str {
    match version {
        SpineVersion::V4_1 | SpineVersion::V4_2 => "ik",
        SpineVersion::V4_3 => "constraints",
    }
}

/// The entry of constraint `c`, updated `order`-th among the skeleton's constraints (4.3 has no
/// `order`: the entries must be written in that order).
pub fn ik_entry(handles: &Handles, c: usize, order: usize, version: SpineVersion) -> Value {
    let k = &handles.ik[c];
    let mut entry = json!({
        "name": k.name,
        "bones": k.bones,
        "target": k.target,
        "mix": num(k.applied_mix()),
        "softness": num(k.softness_px),
        "bendPositive": k.bend_positive,
    });
    match version {
        SpineVersion::V4_1 | SpineVersion::V4_2 => entry["order"] = json!(order),
        SpineVersion::V4_3 => entry["type"] = json!("ik"),
    }
    entry
}

/// An animation's IK timeline that switches a constraint off for its whole length.
pub fn off_timeline() -> Value {
    json!([{ "time": 0.0, "mix": 0.0 }])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::spine::frame::SpineFrame;
    use crate::export::spine::skeleton::build_skeleton;
    use crate::geom::Point;
    use crate::rig::bone_ik::BoneIk;
    use crate::rig::Bone;

    fn rig() -> Handles {
        let bone = |name: &str, parent: Option<&str>, x: f64| Bone {
            name: name.into(),
            parent: parent.map(Into::into),
            head: Point::new(x, 0.0),
            tail: Point::new(x + 10.0, 0.0),
        };
        let ik = |name: &str, bones: &[&str]| BoneIk {
            name: name.into(),
            bones: bones.iter().map(|b| b.to_string()).collect(),
            target: "goal".into(),
            bend_positive: false,
            mix: 1.5,
            softness_px: 3.0,
        };
        Handles {
            bones: vec![
                bone("a", None, 0.0),
                bone("b", Some("a"), 10.0),
                bone("c", Some("b"), 20.0),
                bone("d", Some("c"), 30.0),
                bone("goal", None, 50.0),
            ],
            ik: vec![ik("long", &["a", "b", "c"]), ik("arm", &["b", "c"])],
            ..Handles::default()
        }
    }

    #[test]
    fn one_and_two_bone_chains_export_with_spine_fields() {
        let h = rig();
        assert_eq!(exported(&h), vec![1]);
        let e = ik_entry(&h, 1, 0, SpineVersion::V4_2);
        assert_eq!(e["order"], json!(0));
        assert!(e.get("type").is_none());
        let e43 = ik_entry(&h, 1, 0, SpineVersion::V4_3);
        assert_eq!(e43["type"], json!("ik"));
        assert!(e43.get("order").is_none());
        assert_eq!(e["bones"], json!(["b", "c"]));
        assert_eq!(e["bendPositive"], json!(false));
        assert_eq!(e["mix"], json!(1.0), "mix is written as applied");
        assert_eq!(e["softness"], json!(3.0));
    }

    #[test]
    fn a_baked_chain_bone_switches_its_constraint_off_and_bakes_what_hangs_below() {
        let h = rig();
        let s = build_skeleton(&h, &SpineFrame::for_canvas([100, 100]), "root").unwrap();
        let index = |n: &str| bone_index(&s, n).unwrap();
        let mut baked = BTreeSet::from([index("c")]);
        let off = switch_off_baked(&h, &s, &[1], &mut baked);
        assert_eq!(off, vec![1]);
        assert_eq!(baked, BTreeSet::from([index("b"), index("c"), index("d")]));
        let mut untouched = BTreeSet::from([index("goal")]);
        assert!(switch_off_baked(&h, &s, &[1], &mut untouched).is_empty());
        assert_eq!(untouched.len(), 1);
    }
}
