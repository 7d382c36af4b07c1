//! Joint maps: which segment of a capture skeleton drives which bone of a sinew rig.
//!
//! In: a [`Clip`]'s joint names and a rig's bone names. Out: a [`JointMap`], per driven bone
//! the source segment (`from` joint → `to` joint, or `from`'s end site) whose direction the
//! bone takes.
//!
//! Capture files name joints in a few schemes; [`SourceJoint::resolve`] knows CMU's
//! (`LeftUpLeg`, `LeftLeg`, `LeftFoot`, `LeftArm`, `LeftForeArm`, `Spine1`…), Mixamo's (the same
//! names behind a `mixamorig:` prefix), the Biovision-style names of older files (`LeftHip`,
//! `LeftKnee`, `LeftAnkle`, `LeftShoulder`, `LeftElbow`, `LeftWrist`, `Chest`…) and short
//! ones (`l_hip`, `lknee`, `L_Elbow`…). The rig side is the humanoid template's bone names
//! ([`crate::autorig::Template::Humanoid`]: `hip`, `chest`, `neck`, `head`, `arm_upper_l`,
//! `arm_lower_l`, `hand_l`, `leg_upper_l`, `leg_lower_l`, `foot_l`, and `_r`). Any other rig
//! gets a user map file ([`MapFile`]): bone name → source joint names. A quadruped rig
//! (`leg_front_upper_l`, `leg_back_lower_r`…) has its legs driven by the performer's, in
//! diagonal pairs ([`JointMap::quadruped`]).

use super::bvh::{Clip, JointId};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// What is wrong with a joint map.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MapError {
    #[error("the map names bone '{0}', which the rig does not have")]
    UnknownBone(String),
    #[error("the map names joint '{joint}' for bone '{bone}', which the capture does not have")]
    UnknownJoint { bone: String, joint: String },
    #[error(
        "no bone of the rig is driven by the capture (no bone with a humanoid template name, \
         hip, chest, head, arm_upper_l, leg_upper_l..., has both its joints in the capture): \
         rename the bones or give a map file (--map)"
    )]
    Empty,
}

/// A joint every human capture skeleton has, whatever its naming scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum SourceJoint {
    Hips,
    /// The lowest spine joint above the hips.
    Spine,
    /// The highest spine joint below the neck.
    Chest,
    Neck,
    Head,
    UpperArm(Side),
    Forearm(Side),
    Hand(Side),
    Thigh(Side),
    Shin(Side),
    Foot(Side),
    Toe(Side),
}

/// The performer's own side.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Side {
    Left,
    Right,
}

/// A joint name reduced for matching: lower case, without a `prefix:` and without `_ . - `
/// and spaces.
fn squash(name: &str) -> String {
    let name = name.rsplit(':').next().unwrap_or(name);
    name.chars()
        .filter(|c| !matches!(c, '_' | '.' | '-' | ' '))
        .flat_map(char::to_lowercase)
        .collect()
}

/// The side a squashed name starts or ends with, and the rest.
fn split_side(name: &str) -> Option<(Side, &str)> {
    for (prefix, side) in [("left", Side::Left), ("right", Side::Right)] {
        if let Some(rest) = name.strip_prefix(prefix) {
            return Some((side, rest));
        }
        if let Some(rest) = name.strip_suffix(prefix) {
            return Some((side, rest));
        }
    }
    for (letter, side) in [('l', Side::Left), ('r', Side::Right)] {
        if let Some(rest) = name.strip_prefix(letter) {
            return Some((side, rest));
        }
        if let Some(rest) = name.strip_suffix(letter) {
            return Some((side, rest));
        }
    }
    None
}

impl SourceJoint {
    /// Every joint the maps use.
    pub fn all() -> Vec<SourceJoint> {
        let mut all = vec![
            SourceJoint::Hips,
            SourceJoint::Spine,
            SourceJoint::Chest,
            SourceJoint::Neck,
            SourceJoint::Head,
        ];
        for side in [Side::Left, Side::Right] {
            all.extend([
                SourceJoint::UpperArm(side),
                SourceJoint::Forearm(side),
                SourceJoint::Hand(side),
                SourceJoint::Thigh(side),
                SourceJoint::Shin(side),
                SourceJoint::Foot(side),
                SourceJoint::Toe(side),
            ]);
        }
        all
    }

    /// The names this joint goes by, squashed ([`squash`]), best first; sided joints without
    /// their side.
    fn names(self) -> &'static [&'static str] {
        match self {
            SourceJoint::Hips => &["hips", "hip", "pelvis", "root"],
            SourceJoint::Spine => &["spine", "lowerback", "abdomen", "spine1", "chest"],
            SourceJoint::Chest => &["spine2", "spine1", "chest", "upperchest", "spine", "thorax"],
            SourceJoint::Neck => &["neck", "neck1"],
            SourceJoint::Head => &["head"],
            SourceJoint::UpperArm(_) => &["arm", "uparm", "upperarm", "shoulder", "humerus"],
            SourceJoint::Forearm(_) => &["forearm", "lowarm", "lowerarm", "elbow"],
            SourceJoint::Hand(_) => &["hand", "wrist"],
            SourceJoint::Thigh(_) => &["upleg", "upperleg", "thigh", "hip", "femur"],
            SourceJoint::Shin(_) => &["leg", "lowleg", "lowerleg", "shin", "knee", "calf", "tibia"],
            SourceJoint::Foot(_) => &["foot", "ankle"],
            SourceJoint::Toe(_) => &["toebase", "toe", "toes", "ball"],
        }
    }

    fn side(self) -> Option<Side> {
        match self {
            SourceJoint::UpperArm(s)
            | SourceJoint::Forearm(s)
            | SourceJoint::Hand(s)
            | SourceJoint::Thigh(s)
            | SourceJoint::Shin(s)
            | SourceJoint::Foot(s)
            | SourceJoint::Toe(s) => Some(s),
            _ => None,
        }
    }

    /// This joint in `clip`: the first of its names that a joint of the clip goes by. Where a
    /// scheme names a shoulder blade `LeftShoulder` and the upper arm `LeftArm` (CMU, Mixamo),
    /// `arm` comes first; a hip's `hip` is tried only for sided names, so `LHipJoint` (CMU's
    /// pelvis side bone) is no thigh while `LeftUpLeg` exists.
    pub fn resolve(self, clip: &Clip) -> Option<JointId> {
        let squashed: Vec<(JointId, String)> = clip
            .ids()
            .map(|id| (id, squash(&clip.joints[id.index()].name)))
            .collect();
        for want in self.names() {
            for (id, name) in &squashed {
                let hit = match self.side() {
                    None => name == want,
                    Some(side) => {
                        split_side(name).is_some_and(|(s, rest)| s == side && rest == *want)
                    }
                };
                if hit {
                    return Some(*id);
                }
            }
        }
        None
    }
}

/// The end of a source segment: a joint, or a joint's end site (the head's top, a toe tip).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SegmentEnd {
    Joint(JointId),
    EndSite(JointId),
}

/// A source segment: the direction from `from` to `to` is the bone's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segment {
    pub from: JointId,
    pub to: SegmentEnd,
}

/// Driven bones (names of the rig) and their source segments.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointMap {
    pub bones: BTreeMap<String, Segment>,
}

/// A user map file: bone name → `[from, to]` joint names of the capture (`to` may be
/// `"FROM/end"` for `from`'s end site).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MapFile {
    pub bones: BTreeMap<String, [String; 2]>,
}

/// The humanoid template's bones and the source joints that span them (`None`: the `from`
/// joint's end site, else its first child).
fn humanoid_pairs() -> Vec<(String, SourceJoint, Option<SourceJoint>)> {
    use SourceJoint as J;
    let mut pairs = vec![
        ("hip".to_string(), J::Hips, Some(J::Chest)),
        ("chest".to_string(), J::Spine, Some(J::Neck)),
        ("neck".to_string(), J::Neck, Some(J::Head)),
        ("head".to_string(), J::Head, None),
    ];
    for (side, s) in [(Side::Left, "l"), (Side::Right, "r")] {
        pairs.extend([
            (
                format!("arm_upper_{s}"),
                J::UpperArm(side),
                Some(J::Forearm(side)),
            ),
            (
                format!("arm_lower_{s}"),
                J::Forearm(side),
                Some(J::Hand(side)),
            ),
            (format!("hand_{s}"), J::Hand(side), None),
            (
                format!("leg_upper_{s}"),
                J::Thigh(side),
                Some(J::Shin(side)),
            ),
            (format!("leg_lower_{s}"), J::Shin(side), Some(J::Foot(side))),
            (format!("foot_{s}"), J::Foot(side), Some(J::Toe(side))),
        ]);
    }
    pairs
}

/// The quadruped template's legs and the performer's legs that drive them: back legs from the
/// legs of their side, front legs from the legs of the other side, so that diagonal pairs
/// step together as in a trot (a person's arms swing with the opposite leg for the same
/// reason). The spine, neck, head and tail keep their pose: a person's upright spine is no
/// model for a level one.
fn quadruped_pairs() -> Vec<(String, SourceJoint, Option<SourceJoint>)> {
    use SourceJoint as J;
    let mut pairs = Vec::new();
    for (end, s, side) in [
        ("back", "l", Side::Left),
        ("back", "r", Side::Right),
        ("front", "l", Side::Right),
        ("front", "r", Side::Left),
    ] {
        pairs.extend([
            (
                format!("leg_{end}_upper_{s}"),
                J::Thigh(side),
                Some(J::Shin(side)),
            ),
            (
                format!("leg_{end}_lower_{s}"),
                J::Shin(side),
                Some(J::Foot(side)),
            ),
        ]);
    }
    pairs
}

/// The end of a segment leaving `from` when no joint names it: its end site, else its only
/// child.
fn default_end(clip: &Clip, from: JointId) -> Option<SegmentEnd> {
    if clip.joints[from.index()].end_site.is_some() {
        return Some(SegmentEnd::EndSite(from));
    }
    let mut children = clip.children(from);
    match (children.next(), children.next()) {
        (Some(c), None) => Some(SegmentEnd::Joint(c)),
        _ => None,
    }
}

impl JointMap {
    /// The humanoid template's map onto `clip`, for the bones `rig_bones` has: every bone of
    /// the template whose two joints the capture has (by any known naming scheme).
    pub fn humanoid(clip: &Clip, rig_bones: &[&str]) -> Result<JointMap, MapError> {
        Self::from_pairs(clip, rig_bones, humanoid_pairs())
    }

    /// The quadruped template's legs driven by a person's legs ([`quadruped_pairs`]).
    pub fn quadruped(clip: &Clip, rig_bones: &[&str]) -> Result<JointMap, MapError> {
        Self::from_pairs(clip, rig_bones, quadruped_pairs())
    }

    /// The map for a rig named by a template: the quadruped's when the rig has a front or a
    /// back leg (`leg_front_*`, `leg_back_*`), else the humanoid's.
    pub fn for_rig(clip: &Clip, rig_bones: &[&str]) -> Result<JointMap, MapError> {
        let four_legged = rig_bones
            .iter()
            .any(|b| b.starts_with("leg_front_") || b.starts_with("leg_back_"));
        if four_legged {
            Self::quadruped(clip, rig_bones)
        } else {
            Self::humanoid(clip, rig_bones)
        }
    }

    fn from_pairs(
        clip: &Clip,
        rig_bones: &[&str],
        pairs: Vec<(String, SourceJoint, Option<SourceJoint>)>,
    ) -> Result<JointMap, MapError> {
        let mut bones = BTreeMap::new();
        for (bone, from, to) in pairs {
            if !rig_bones.contains(&bone.as_str()) {
                continue;
            }
            let Some(from_id) = from.resolve(clip) else {
                continue;
            };
            let end = match to {
                Some(to) => to.resolve(clip).map(SegmentEnd::Joint),
                None => default_end(clip, from_id),
            };
            // A chest and a hips resolving to one joint (a two-joint spine) spans nothing.
            if let Some(end) = end.filter(|&e| e != SegmentEnd::Joint(from_id)) {
                bones.insert(
                    bone,
                    Segment {
                        from: from_id,
                        to: end,
                    },
                );
            }
        }
        if bones.is_empty() {
            return Err(MapError::Empty);
        }
        Ok(JointMap { bones })
    }

    /// A user's map onto `clip`, checked against the rig's bones and the clip's joints.
    pub fn from_file(
        file: &MapFile,
        clip: &Clip,
        rig_bones: &[&str],
    ) -> Result<JointMap, MapError> {
        let mut bones = BTreeMap::new();
        for (bone, [from, to]) in &file.bones {
            if !rig_bones.contains(&bone.as_str()) {
                return Err(MapError::UnknownBone(bone.clone()));
            }
            let joint = |name: &str| {
                clip.find(name).ok_or_else(|| MapError::UnknownJoint {
                    bone: bone.clone(),
                    joint: name.to_string(),
                })
            };
            let from_id = joint(from)?;
            let end = match to.strip_suffix("/end") {
                Some(site) => SegmentEnd::EndSite(joint(site)?),
                None => SegmentEnd::Joint(joint(to)?),
            };
            bones.insert(
                bone.clone(),
                Segment {
                    from: from_id,
                    to: end,
                },
            );
        }
        if bones.is_empty() {
            return Err(MapError::Empty);
        }
        Ok(JointMap { bones })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::bvh::{parse, BvhLimits};

    fn clip_with(names: &[&str]) -> Clip {
        // A chain of joints, each one unit above its parent; the last has an end site.
        let mut text = String::from("HIERARCHY\n");
        for (k, name) in names.iter().enumerate() {
            let kind = if k == 0 { "ROOT" } else { "JOINT" };
            text += &format!(
                "{kind} {name}\n{{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
            );
        }
        text += "End Site\n{\nOFFSET 0 1 0\n}\n";
        text += &"}\n".repeat(names.len());
        text += &format!(
            "MOTION\nFrames: 1\nFrame Time: 0.033\n{}\n",
            vec!["0"; 3 * names.len()].join(" ")
        );
        parse(text.as_bytes(), &BvhLimits::default()).expect("parses")
    }

    #[test]
    fn names_of_every_scheme_resolve() {
        for (names, joint, want) in [
            (
                vec!["Hips", "LeftUpLeg", "LeftLeg"],
                SourceJoint::Thigh(Side::Left),
                "LeftUpLeg",
            ),
            (
                vec!["Hips", "LHipJoint", "LeftUpLeg"],
                SourceJoint::Thigh(Side::Left),
                "LeftUpLeg",
            ),
            (
                vec!["mixamorig:Hips", "mixamorig:RightForeArm"],
                SourceJoint::Forearm(Side::Right),
                "mixamorig:RightForeArm",
            ),
            (
                vec!["Hips", "LeftHip", "LeftKnee"],
                SourceJoint::Shin(Side::Left),
                "LeftKnee",
            ),
            (
                vec!["pelvis", "l_hip", "l_knee"],
                SourceJoint::Thigh(Side::Left),
                "l_hip",
            ),
            (
                vec!["Hips", "LeftShoulder", "LeftArm"],
                SourceJoint::UpperArm(Side::Left),
                "LeftArm",
            ),
            (
                vec!["Hips", "LeftShoulder", "LeftElbow"],
                SourceJoint::UpperArm(Side::Left),
                "LeftShoulder",
            ),
            (
                vec!["Hips", "Spine", "Spine1", "Neck"],
                SourceJoint::Chest,
                "Spine1",
            ),
        ] {
            let clip = clip_with(&names);
            let id = joint
                .resolve(&clip)
                .unwrap_or_else(|| panic!("{joint:?} in {names:?}"));
            assert_eq!(clip.joints[id.index()].name, want, "{joint:?} in {names:?}");
        }
        // The right side is never taken for the left.
        let clip = clip_with(&["Hips", "RightUpLeg"]);
        assert_eq!(SourceJoint::Thigh(Side::Left).resolve(&clip), None);
    }

    #[test]
    fn the_humanoid_map_drives_only_bones_the_rig_has_and_the_head_to_its_end_site() {
        let clip = clip_with(&["Hips", "Spine", "Neck", "Head"]);
        let map = JointMap::humanoid(&clip, &["hip", "head", "tail_1"]).expect("a map");
        assert_eq!(map.bones.keys().collect::<Vec<_>>(), ["head", "hip"]);
        let head = clip.find("Head").expect("Head");
        assert_eq!(map.bones["head"].to, SegmentEnd::EndSite(head));
        assert_eq!(JointMap::humanoid(&clip, &["tail_1"]), Err(MapError::Empty));
    }

    #[test]
    fn a_map_file_is_checked_against_rig_and_capture() {
        let clip = clip_with(&["Hips", "Spine", "Head"]);
        let file: MapFile =
            serde_json::from_str(r#"{"bones": {"body": ["Hips", "Head/end"]}}"#).expect("json");
        let map = JointMap::from_file(&file, &clip, &["body"]).expect("a map");
        assert_eq!(
            map.bones["body"].to,
            SegmentEnd::EndSite(clip.find("Head").expect("Head"))
        );
        assert_eq!(
            JointMap::from_file(&file, &clip, &["torso"]),
            Err(MapError::UnknownBone("body".into()))
        );
        let file: MapFile =
            serde_json::from_str(r#"{"bones": {"body": ["Pelvis", "Head"]}}"#).expect("json");
        assert!(matches!(
            JointMap::from_file(&file, &clip, &["body"]),
            Err(MapError::UnknownJoint { .. })
        ));
    }
}
