//! Body-part labels read from layer names: what an artist's layer (`arm_l`, `left arm`,
//! `Arm L`, `L_forearm`, `upperarm.R`, `Head`, `body`, `tail`, `sword`) is.
//!
//! In: a layer's name (its path in the file, `character/arm_l/hand`; only the last segment
//! is read, then the group's names for a side or a limb the last one lacks). Out: a
//! [`Label`]: the body part, its side (the character's own left or right, as `_l` means in
//! sinew's templates) and, for a quadruped's legs, front or back. Names are split into words
//! at separators (`_ - . /` and spaces), at case changes (`upperArm`) and at known words run
//! together (`forearm`, `upperarm`); side words are `l`/`left`/`lt` and `r`/`right`/`rt`.
//!
//! Labels decide a layered rig's hierarchy ([`super::layers`]): what hangs from what, which
//! template the file is drawn for ([`template_from_labels`]) and the bones' names
//! ([`Label::bone_names`]).

use super::Template;

/// The character's own side (its left is on the screen's right when it faces the viewer).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Side {
    Left,
    Right,
}

impl Side {
    /// `l` or `r`, the suffix of sinew's template names.
    pub fn suffix(self) -> &'static str {
        match self {
            Side::Left => "l",
            Side::Right => "r",
        }
    }
}

/// A quadruped's leg: front (at the chest) or back (at the hips).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum End {
    Front,
    Back,
}

/// Which piece of a limb a layer holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Segment {
    /// Upper arm or thigh.
    Upper,
    /// Forearm or shin.
    Lower,
    /// Hand or foot.
    Extremity,
    /// The whole limb in one layer (two bones: upper and lower).
    Whole,
}

/// What a layer is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Part {
    Head,
    Neck,
    /// Chest, belly, trunk, or the whole body.
    Torso,
    /// Hips, pelvis, waist.
    Pelvis,
    Arm(Segment),
    Leg(Segment),
    Tail,
    /// Hair, ears, a hat, an antenna, eyes: hangs from the head.
    HeadAccessory,
    /// Wings, a cape, a backpack: hangs from the torso.
    BodyAccessory,
    /// Something held (a sword, a lantern): hangs from the hand that holds it.
    Prop,
    /// Nothing the name tells.
    Unknown,
}

/// A layer's label: part, side and (legs) end.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Label {
    pub part: Part,
    pub side: Option<Side>,
    pub end: Option<End>,
}

impl Label {
    pub const UNKNOWN: Label = Label {
        part: Part::Unknown,
        side: None,
        end: None,
    };

    /// Whether the name said anything about the body.
    pub fn is_known(&self) -> bool {
        self.part != Part::Unknown
    }

    /// The template's names for this part's bones, in chain order, when the part is a
    /// template part (`arm_upper_l`; a whole arm `[arm_upper_l, arm_lower_l]`; a quadruped's
    /// leg `leg_front_upper_l`). `None` for parts the templates do not name (accessories,
    /// props, unknown parts: they keep their layer's name) and for limbs without a side.
    pub fn bone_names(&self, template: Option<Template>) -> Option<Vec<String>> {
        let limb = |kind: &str, segments: &[&str]| -> Option<Vec<String>> {
            let side = self.side?.suffix();
            let end = match (template, self.end, kind) {
                (Some(Template::Quadruped), Some(End::Front), _) => "front_",
                (Some(Template::Quadruped), Some(End::Back), _) => "back_",
                (Some(Template::Quadruped), None, "leg") => return None,
                _ => "",
            };
            Some(
                segments
                    .iter()
                    .map(|s| format!("{kind}_{end}{s}_{side}"))
                    .collect(),
            )
        };
        let one = |name: &str| Some(vec![name.to_string()]);
        match self.part {
            Part::Head => one("head"),
            Part::Neck => one("neck"),
            Part::Torso => one("chest"),
            Part::Pelvis => one("hip"),
            Part::Tail => one("tail"),
            Part::Arm(Segment::Upper) => limb("arm", &["upper"]),
            Part::Arm(Segment::Lower) => limb("arm", &["lower"]),
            Part::Arm(Segment::Whole) => limb("arm", &["upper", "lower"]),
            Part::Arm(Segment::Extremity) => {
                self.side.map(|s| vec![format!("hand_{}", s.suffix())])
            }
            Part::Leg(Segment::Upper) => limb("leg", &["upper"]),
            Part::Leg(Segment::Lower) => limb("leg", &["lower"]),
            Part::Leg(Segment::Whole) => limb("leg", &["upper", "lower"]),
            Part::Leg(Segment::Extremity) => self.side.map(|s| {
                let end = match self.end {
                    Some(End::Front) => "front_",
                    Some(End::Back) => "back_",
                    None => "",
                };
                vec![format!("foot_{end}{}", s.suffix())]
            }),
            Part::HeadAccessory | Part::BodyAccessory | Part::Prop | Part::Unknown => None,
        }
    }
}

/// Words that name a part (after splitting); compound words are split before this.
const HEAD: &[&str] = &["head", "skull", "face"];
const NECK: &[&str] = &["neck"];
const TORSO: &[&str] = &[
    "torso", "body", "chest", "trunk", "belly", "spine", "shirt", "abdomen", "stomach", "breast",
    "ribcage", "thorax", "bust", "coat", "jacket", "dress", "gown", "robe", "tunic", "frock",
];
const PELVIS: &[&str] = &[
    "pelvis", "hip", "hips", "waist", "shorts", "pants", "skirt", "butt",
];
const ARM: &[&str] = &["arm", "arms"];
const LEG: &[&str] = &["leg", "legs"];
const UPPER: &[&str] = &["upper", "up", "top", "u"];
const LOWER: &[&str] = &["lower", "low", "bottom", "bot"];
const UPPER_ARM: &[&str] = &["bicep", "biceps", "shoulder", "sleeve", "humerus"];
const LOWER_ARM: &[&str] = &["forearm", "elbow", "wrist", "cuff"];
const HAND: &[&str] = &[
    "hand", "hands", "fist", "palm", "glove", "paw", "claw", "fingers",
];
const UPPER_LEG: &[&str] = &["thigh", "femur"];
const LOWER_LEG: &[&str] = &["shin", "calf", "knee", "tibia", "shank"];
const FOOT: &[&str] = &[
    "foot", "feet", "shoe", "boot", "hoof", "toe", "toes", "ankle", "sock",
];
const TAIL: &[&str] = &["tail"];
const HEAD_ACCESSORY: &[&str] = &[
    "hair", "ear", "ears", "hat", "cap", "helmet", "antenna", "horn", "horns", "eye", "eyes",
    "mouth", "nose", "beard", "mustache", "brow", "eyebrow", "crown", "hood", "mane", "jaw",
    "muzzle", "snout", "beak", "ponytail", "bangs", "glasses", "mask",
];
const BODY_ACCESSORY: &[&str] = &[
    "wing", "wings", "cape", "cloak", "backpack", "belt", "scarf", "collar", "saddle", "fin",
];
const PROP: &[&str] = &[
    "sword", "shield", "lantern", "lamp", "bag", "weapon", "staff", "wand", "gun", "bow", "axe",
    "spear", "ball", "book", "umbrella", "flag", "torch", "cup", "basket", "pail", "bucket",
    "knife", "dagger", "hammer", "club", "stick", "pole", "balloon", "sign", "bottle", "rod",
    "prop", "item", "guitar", "broom", "pistol", "rifle", "blade", "mace", "trident", "whip",
    "scythe", "pick", "pickaxe", "shovel", "fork", "key", "flower", "box", "crate",
];
const FRONT: &[&str] = &["front", "fore", "f"];
const BACK: &[&str] = &["back", "hind", "rear", "b"];
const LEFT: &[&str] = &["l", "left", "lt", "lft"];
const RIGHT: &[&str] = &["r", "right", "rt", "rgt"];
/// Compounds written as one word, split into their words.
const COMPOUNDS: &[(&str, &[&str])] = &[
    ("upperarm", &["upper", "arm"]),
    ("lowerarm", &["lower", "arm"]),
    ("upperleg", &["upper", "leg"]),
    ("lowerleg", &["lower", "leg"]),
    ("foreleg", &["front", "leg"]),
    ("forelegs", &["front", "leg"]),
    ("hindleg", &["back", "leg"]),
    ("backleg", &["back", "leg"]),
    ("frontleg", &["front", "leg"]),
    ("forepaw", &["front", "paw"]),
    ("hindpaw", &["back", "paw"]),
    ("armupper", &["arm", "upper"]),
    ("armlower", &["arm", "lower"]),
    ("legupper", &["leg", "upper"]),
    ("leglower", &["leg", "lower"]),
    ("lowerbody", &["pelvis"]),
    ("upperbody", &["torso"]),
];

/// The words of a name: split at separators and case changes, lower case, compounds split.
pub fn words(name: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut word = String::new();
    let mut prev: Option<char> = None;
    let flush = |word: &mut String, out: &mut Vec<String>| {
        if !word.is_empty() {
            let w = word.to_lowercase();
            match COMPOUNDS.iter().find(|(c, _)| *c == w) {
                Some((_, parts)) => out.extend(parts.iter().map(|p| p.to_string())),
                None => out.push(w),
            }
            word.clear();
        }
    };
    for c in name.chars() {
        if !c.is_alphanumeric() {
            flush(&mut word, &mut out);
            prev = None;
            continue;
        }
        let case_break = prev.is_some_and(|p| p.is_lowercase() && c.is_uppercase());
        let digit_break = prev.is_some_and(|p| p.is_ascii_digit() != c.is_ascii_digit());
        if case_break || digit_break {
            flush(&mut word, &mut out);
        }
        word.push(c);
        prev = Some(c);
    }
    flush(&mut word, &mut out);
    out
}

/// The label of a layer named `path` (`group/sub/layer`): the last segment's words, with a
/// side, an end or a limb taken from the groups above when the last segment lacks them
/// (`arm_l/hand` is the left hand).
pub fn label(path: &str) -> Label {
    let mut segments = path.rsplit('/');
    let last_words = words(segments.next().unwrap_or(""));
    let mut found = label_of_words(&last_words);
    let has = |set: &[&str]| last_words.iter().any(|w| set.contains(&w.as_str()));
    // "upper" or "lower" alone names a piece of the limb its group is.
    let piece = if has(UPPER) {
        Some(Segment::Upper)
    } else if has(LOWER) {
        Some(Segment::Lower)
    } else {
        None
    };
    for group in segments {
        let g = label_of_words(&words(group));
        if found.side.is_none() {
            found.side = g.side;
        }
        if found.end.is_none() {
            found.end = g.end;
        }
        // A "hand" in a group "leg_front" is a foot (a paw); "upper" in "arm_l" an upper arm.
        if let (Part::Arm(s), Part::Leg(_)) = (found.part, g.part) {
            found.part = Part::Leg(s);
        }
        if found.part == Part::Unknown {
            found.part = match (g.part, piece) {
                (Part::Arm(_), Some(s)) => Part::Arm(s),
                (Part::Leg(_), Some(s)) => Part::Leg(s),
                (Part::Arm(_) | Part::Leg(_), None) => Part::Unknown,
                (p, _) => p,
            };
        }
    }
    found
}

/// Two-letter leg codes: end then side (`HL`: hind left).
const LEG_CODES: &[(&str, End, Side)] = &[
    ("fl", End::Front, Side::Left),
    ("fr", End::Front, Side::Right),
    ("hl", End::Back, Side::Left),
    ("hr", End::Back, Side::Right),
    ("bl", End::Back, Side::Left),
    ("br", End::Back, Side::Right),
    ("rl", End::Back, Side::Left),
    ("rr", End::Back, Side::Right),
];

fn label_of_words(words: &[String]) -> Label {
    let has = |set: &[&str]| words.iter().any(|w| set.contains(&w.as_str()));
    let code = LEG_CODES
        .iter()
        .find(|(c, _, _)| words.iter().any(|w| w == c) && has(LEG))
        .map(|&(_, e, s)| (e, s));
    let side = if has(LEFT) {
        Some(Side::Left)
    } else if has(RIGHT) {
        Some(Side::Right)
    } else {
        code.map(|c| c.1)
    };
    let end = if has(FRONT) {
        Some(End::Front)
    } else if has(BACK) && !has(TORSO) {
        Some(End::Back)
    } else {
        code.map(|c| c.0)
    };
    let segment = if has(UPPER) {
        Segment::Upper
    } else if has(LOWER) {
        Segment::Lower
    } else {
        Segment::Whole
    };
    // The most specific word wins: a "hand" layer in an "arm" group is a hand.
    let part = if has(HAND) {
        // A paw on a leg (or at an end) is a foot.
        if has(LEG) || end.is_some() {
            Part::Leg(Segment::Extremity)
        } else {
            Part::Arm(Segment::Extremity)
        }
    } else if has(FOOT) {
        Part::Leg(Segment::Extremity)
    } else if has(LOWER_ARM) {
        Part::Arm(Segment::Lower)
    } else if has(UPPER_ARM) {
        Part::Arm(Segment::Upper)
    } else if has(LOWER_LEG) {
        Part::Leg(Segment::Lower)
    } else if has(UPPER_LEG) {
        Part::Leg(Segment::Upper)
    } else if has(ARM) {
        Part::Arm(segment)
    } else if has(LEG) {
        Part::Leg(segment)
    } else if has(TAIL) {
        Part::Tail
    } else if has(NECK) {
        Part::Neck
    } else if has(HEAD) {
        Part::Head
    } else if has(HEAD_ACCESSORY) {
        Part::HeadAccessory
    } else if has(PELVIS) {
        Part::Pelvis
    } else if has(TORSO) {
        Part::Torso
    } else if has(BODY_ACCESSORY) {
        Part::BodyAccessory
    } else if has(PROP) {
        Part::Prop
    } else {
        Part::Unknown
    };
    let limb = matches!(part, Part::Arm(_) | Part::Leg(_));
    Label {
        part,
        side: if limb || part == Part::Unknown {
            side
        } else {
            None
        },
        end: if matches!(part, Part::Leg(_) | Part::Arm(_)) {
            end
        } else {
            None
        },
    }
}

/// The template a set of labels is drawn for, and why (for the person): a quadruped when
/// more than two legs are named (or legs at a front and a back); none for a tail without
/// arms or four legs (a bird, a fish, a kite); a humanoid when arms or legs are named, or a
/// head on a body (a bust); `None` when the names tell nothing of the body.
pub fn template_from_labels(labels: &[Label]) -> Option<(Option<Template>, String)> {
    let arms = labels
        .iter()
        .filter(|l| matches!(l.part, Part::Arm(_)))
        .count();
    let legs: Vec<&Label> = labels
        .iter()
        .filter(|l| matches!(l.part, Part::Leg(_)))
        .collect();
    // Whole legs or thighs: one per leg.
    let limbs = legs
        .iter()
        .filter(|l| matches!(l.part, Part::Leg(Segment::Upper | Segment::Whole)))
        .count();
    // Legs (thighs or whole legs, not feet: a side view's near and far foot are "front" and
    // "back" too) at both a front and a back.
    let both_ends = [End::Front, End::Back].iter().all(|e| {
        legs.iter().any(|l| {
            l.end == Some(*e) && matches!(l.part, Part::Leg(Segment::Upper | Segment::Whole))
        })
    });
    if both_ends || (arms == 0 && limbs > 2) {
        return Some((
            Some(Template::Quadruped),
            format!(
                "the layer names give {} leg parts at a front and a back",
                legs.len()
            ),
        ));
    }
    let has = |p: Part| labels.iter().any(|l| l.part == p);
    if has(Part::Tail) && arms == 0 {
        return Some((
            None,
            "the layer names give a tail and neither arms nor four legs".into(),
        ));
    }
    if arms > 0 || !legs.is_empty() {
        return Some((
            Some(Template::Humanoid),
            format!(
                "the layer names give {arms} arm and {} leg parts",
                legs.len()
            ),
        ));
    }
    if has(Part::Head) && (has(Part::Torso) || has(Part::Neck)) {
        return Some((
            Some(Template::Humanoid),
            "the layer names give a head on a body and no limbs: a bust".into(),
        ));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn l(part: Part, side: Option<Side>) -> Label {
        Label {
            part,
            side,
            end: None,
        }
    }

    #[test]
    fn names_split_at_separators_case_and_compounds() {
        assert_eq!(words("upperArm.R"), ["upper", "arm", "r"]);
        assert_eq!(words("L_forearm"), ["l", "forearm"]);
        assert_eq!(words("Arm L"), ["arm", "l"]);
        assert_eq!(words("leg2"), ["leg", "2"]);
        assert_eq!(words("UpperLeg-left"), ["upper", "leg", "left"]);
    }

    #[test]
    fn artists_names_give_the_part_and_side() {
        use Segment::*;
        let (left, right) = (Some(Side::Left), Some(Side::Right));
        assert_eq!(label("arm_l"), l(Part::Arm(Whole), left));
        assert_eq!(label("left arm"), l(Part::Arm(Whole), left));
        assert_eq!(label("Arm L"), l(Part::Arm(Whole), left));
        assert_eq!(label("L_forearm"), l(Part::Arm(Lower), left));
        // A dress or a robe is the torso (the root), not an unknown layer.
        assert_eq!(label("Dress").part, Part::Torso);
        assert_eq!(label("robe").part, Part::Torso);
        assert_eq!(label("upperarm.R"), l(Part::Arm(Upper), right));
        assert_eq!(label("arm_upper_r"), l(Part::Arm(Upper), right));
        assert_eq!(label("leg_lower_l"), l(Part::Leg(Lower), left));
        assert_eq!(label("Right Thigh"), l(Part::Leg(Upper), right));
        assert_eq!(label("Head"), l(Part::Head, None));
        assert_eq!(label("body"), l(Part::Torso, None));
        assert_eq!(label("tail"), l(Part::Tail, None));
        assert_eq!(label("sword"), l(Part::Prop, None));
        assert_eq!(label("bag"), l(Part::Prop, None));
        assert_eq!(label("hair front"), l(Part::HeadAccessory, None));
        assert_eq!(label("Layer 3"), Label::UNKNOWN);
        // The group gives the side and the limb.
        assert_eq!(label("arm_l/hand"), l(Part::Arm(Extremity), left));
        assert_eq!(label("leg right/upper"), l(Part::Leg(Upper), right));
        // A quadruped's legs.
        let hind = label("hind leg L");
        assert_eq!((hind.part, hind.end), (Part::Leg(Whole), Some(End::Back)));
        assert_eq!(label("foreleg_r").end, Some(End::Front));
        let code = label("Leg.HL");
        assert_eq!((code.end, code.side), (Some(End::Back), Some(Side::Left)));
        // "back" on a torso is the back, not a hind part.
        assert_eq!(label("back").part, Part::Unknown);
    }

    #[test]
    fn template_names_for_bones() {
        let arm = label("left arm");
        assert_eq!(
            arm.bone_names(Some(Template::Humanoid)).unwrap(),
            ["arm_upper_l", "arm_lower_l"]
        );
        let leg = label("hind leg upper R");
        assert_eq!(
            leg.bone_names(Some(Template::Quadruped)).unwrap(),
            ["leg_back_upper_r"]
        );
        assert_eq!(label("sword").bone_names(Some(Template::Humanoid)), None);
        // A limb without a side keeps its layer's name.
        assert_eq!(label("arm").bone_names(Some(Template::Humanoid)), None);
    }

    #[test]
    fn the_template_follows_the_limbs_named() {
        let names = |ns: &[&str]| ns.iter().map(|n| label(n)).collect::<Vec<_>>();
        let t = |ns: &[&str]| template_from_labels(&names(ns)).and_then(|t| t.0);
        assert_eq!(
            t(&["head", "body", "arm_l", "arm_r", "leg_l", "leg_r"]),
            Some(Template::Humanoid)
        );
        assert_eq!(
            t(&["head", "torso", "left arm", "right arm"]),
            Some(Template::Humanoid)
        );
        assert_eq!(
            t(&[
                "head",
                "body",
                "front leg l",
                "front leg r",
                "hind leg l",
                "hind leg r",
                "tail"
            ]),
            Some(Template::Quadruped)
        );
        assert_eq!(
            t(&["head", "body", "leg 1", "leg 2", "leg 3", "leg 4"]),
            Some(Template::Quadruped)
        );
        assert_eq!(t(&["blade", "hilt"]), None);
        assert_eq!(
            t(&["head", "front legs", "body", "tail", "hind legs"]),
            Some(Template::Quadruped)
        );
        assert_eq!(
            t(&["Flipper_Front", "Foot_Front", "Head", "Body", "Foot_Back"]),
            Some(Template::Humanoid)
        );
        assert_eq!(t(&["head", "body"]), Some(Template::Humanoid));
        assert_eq!(
            t(&["hand", "foot_front", "body", "foot_back"]),
            Some(Template::Humanoid)
        );
        let said = |ns: &[&str]| template_from_labels(&names(ns)).map(|t| t.0);
        assert_eq!(said(&["feet", "head", "body", "tail"]), Some(None));
        assert_eq!(said(&["blade", "hilt"]), None);
    }
}
