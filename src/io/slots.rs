//! Slots, attachments and skins of a rig document.
//!
//! A part without a `slot` field is a slot, and its own (default) attachment: what documents
//! always had. A part whose `slot` names such a part is another attachment of that slot: its
//! own image, traced, meshed and weighted like any part, drawn in the slot's place in the draw
//! order whenever the slot shows it. A slot shows one attachment at a time (or none).
//!
//! What a slot shows, as Spine resolves it: an attachment timeline (or a pose) names an
//! attachment of the slot, or nothing; the slot's own name stands for "the slot's default
//! attachment", which the active skins may replace. Skins map slot → attachment; several
//! combine, a later one overriding an earlier one on the same slot. No skin: every slot shows
//! its own part.
//!
//! In: the document's parts and `skins`. Out: checks (one-line reasons), the slot names in draw
//! order, and for a slot, an attachment name and the active skins, the part that is drawn.

use super::document::RigDocument;
use std::collections::BTreeMap;

/// A skin: slot name → the name of the part (an attachment of that slot) it shows in place of
/// the slot's own part.
pub type Skin = BTreeMap<String, String>;
/// Skins by name.
pub type Skins = BTreeMap<String, Skin>;

/// The name Spine gives the skin of attachments that belong to no skin; a sinew skin may not
/// take it.
pub const DEFAULT_SKIN: &str = "default";

/// What is wrong with a choice of skins.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum SlotError {
    #[error(
        "the rig has no skin '{name}'{} (its skins: {})",
        crate::names::did_you_mean(.suggestion),
        crate::names::listed(.known)
    )]
    UnknownSkin {
        name: String,
        /// The rig's skins, in name order.
        known: Vec<String>,
        /// The one of `known` most like `name` ([`crate::names::closest`]).
        suggestion: Option<String>,
    },
    #[error(
        "the pose shows attachment '{attachment}' in slot '{slot}', which the slot does not \
         have{} (its attachments: {})",
        crate::names::did_you_mean(.suggestion),
        crate::names::listed(.known)
    )]
    UnknownAttachment {
        slot: String,
        attachment: String,
        known: Vec<String>,
        suggestion: Option<String>,
    },
}

impl RigDocument {
    /// The slot part `index` belongs to: its `slot`, or its own name.
    pub fn slot_of(&self, index: usize) -> &str {
        let part = &self.parts[index];
        part.slot.as_deref().unwrap_or(&part.name)
    }

    /// The slots (parts without a `slot` field), in draw order.
    pub fn slot_names(&self) -> Vec<&str> {
        self.parts
            .iter()
            .filter(|p| p.slot.is_none())
            .map(|p| p.name.as_str())
            .collect()
    }

    /// Whether some part is another part's attachment, or the document has skins.
    pub fn has_attachments(&self) -> bool {
        !self.skins.is_empty() || self.parts.iter().any(|p| p.slot.is_some())
    }

    /// The parts `slot` can show (by index): its own part first, then its other attachments in
    /// document order. Empty when `slot` is no slot.
    pub fn attachments_of(&self, slot: &str) -> Vec<usize> {
        let own = self
            .parts
            .iter()
            .position(|p| p.slot.is_none() && p.name == slot);
        own.into_iter()
            .chain(
                self.parts
                    .iter()
                    .enumerate()
                    .filter(|(_, p)| p.slot.as_deref() == Some(slot))
                    .map(|(i, _)| i),
            )
            .collect()
    }

    /// `skins` when the document has every one of them.
    pub fn check_skins(&self, skins: &[String]) -> Result<(), SlotError> {
        match skins.iter().find(|s| !self.skins.contains_key(*s)) {
            None => Ok(()),
            Some(name) => Err(SlotError::UnknownSkin {
                name: name.clone(),
                known: crate::names::owned(self.skins.keys()),
                suggestion: crate::names::closest(name, self.skins.keys()),
            }),
        }
    }

    /// The part slot `slot` draws when it shows `attachment` (`None`: the slot's default, which
    /// the last of `skins` that names the slot replaces). `None` when the slot does not have that
    /// attachment (or `slot` is no slot); unknown skins are skipped (see
    /// [`RigDocument::check_skins`]).
    pub fn shown_part(
        &self,
        slot: &str,
        attachment: Option<&str>,
        skins: &[String],
    ) -> Option<usize> {
        let name = match attachment {
            Some(a) if a != slot => a,
            _ => skins
                .iter()
                .rev()
                .find_map(|s| self.skins.get(s)?.get(slot))
                .map_or(slot, String::as_str),
        };
        self.attachments_of(slot)
            .into_iter()
            .find(|&i| self.parts[i].name == name)
    }

    /// The parts `slot` can show, by name, for messages.
    pub fn attachment_names(&self, slot: &str) -> Vec<&str> {
        self.attachments_of(slot)
            .into_iter()
            .map(|i| self.parts[i].name.as_str())
            .collect()
    }

    /// Makes each part named in `attachments` (part → slot) an attachment of that slot, sets
    /// `skins`, and checks the result ([`RigDocument::validate`]'s reasons).
    pub fn set_slots(
        &mut self,
        attachments: &BTreeMap<String, String>,
        skins: Skins,
    ) -> Result<(), String> {
        if let Some(name) = attachments
            .keys()
            .find(|n| !self.parts.iter().any(|p| &p.name == *n))
        {
            return Err(format!("attachment '{name}' is not a part of the rig"));
        }
        for part in &mut self.parts {
            if let Some(slot) = attachments.get(&part.name) {
                part.slot = Some(slot.clone());
            }
        }
        self.skins = skins;
        validate_slots(self)
    }

    /// Checks a pose's attachments: each names an attachment of its slot.
    pub fn check_pose_attachments(&self, pose: &crate::rig::Pose) -> Result<(), SlotError> {
        for (slot, state) in &pose.parts {
            let Some(attachment) = &state.attachment else {
                continue;
            };
            if self.shown_part(slot, Some(attachment), &[]).is_none() {
                let known = self.attachment_names(slot);
                return Err(SlotError::UnknownAttachment {
                    slot: slot.clone(),
                    attachment: attachment.clone(),
                    suggestion: crate::names::closest(attachment, &known),
                    known: crate::names::owned(known),
                });
            }
        }
        Ok(())
    }
}

/// The document's slots and skins as a one-line reason: every `slot` field names a part that is
/// a slot (has no `slot` itself); every skin has a name other than [`DEFAULT_SKIN`] and maps
/// slots to attachments of that slot.
pub(super) fn validate_slots(doc: &RigDocument) -> Result<(), String> {
    for part in &doc.parts {
        let Some(slot) = &part.slot else { continue };
        if slot == &part.name {
            return Err(format!(
                "part '{slot}' names itself as its slot (leave 'slot' out: a part is its own slot)"
            ));
        }
        match doc.parts.iter().find(|p| &p.name == slot) {
            None => {
                return Err(format!(
                    "part '{}' is an attachment of slot '{slot}', which is no part",
                    part.name
                ))
            }
            Some(owner) if owner.slot.is_some() => {
                return Err(format!(
                    "part '{}' is an attachment of '{slot}', which is itself an attachment of \
                     slot '{}' (name the slot)",
                    part.name,
                    owner.slot.as_deref().unwrap_or_default()
                ))
            }
            Some(_) => {}
        }
    }
    for (name, skin) in &doc.skins {
        if name.is_empty() || name == DEFAULT_SKIN {
            return Err(format!(
                "skin name '{name}' is reserved (Spine's skin of every attachment)"
            ));
        }
        for (slot, attachment) in skin {
            if !doc
                .parts
                .iter()
                .any(|p| p.slot.is_none() && &p.name == slot)
            {
                return Err(format!(
                    "skin '{name}' names slot '{slot}', which the rig does not have"
                ));
            }
            if doc.shown_part(slot, Some(attachment), &[]).is_none() {
                return Err(format!(
                    "skin '{name}' shows '{attachment}' in slot '{slot}', which is not one of \
                     its attachments ({})",
                    doc.attachment_names(slot).join(", ")
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::geom::Point;
    use crate::io::{MeshDoc, PartDoc};
    use std::path::Path;

    /// A one-triangle part named `name` (image `NAME.png`), another attachment of `slot` if
    /// given; no weights. Shared by the crate's slot and attachment tests.
    pub(crate) fn part(name: &str, slot: Option<&str>) -> PartDoc {
        PartDoc {
            name: name.into(),
            slot: slot.map(Into::into),
            image: format!("{name}.png"),
            offset_px: [0, 0],
            mesh: MeshDoc {
                vertices: vec![
                    Point::new(0.0, 0.0),
                    Point::new(1.0, 0.0),
                    Point::new(0.0, 1.0),
                ],
                triangles: vec![[0, 1, 2]],
            },
            weights: None,
            stale_weights: None,
        }
    }

    fn doc() -> RigDocument {
        let mut doc = RigDocument::new([4, 4]);
        doc.parts = vec![
            part("body", None),
            part("hand", None),
            part("fist", Some("hand")),
            part("glove", Some("hand")),
        ];
        doc.skins = [
            (
                "gloves".to_string(),
                [("hand".into(), "glove".into())].into(),
            ),
            ("fists".to_string(), [("hand".into(), "fist".into())].into()),
        ]
        .into();
        doc
    }

    #[test]
    fn skins_and_keys_resolve_as_spine_resolves_them() {
        let doc = doc();
        doc.validate().unwrap();
        assert_eq!(doc.slot_names(), ["body", "hand"]);
        assert_eq!(doc.attachments_of("hand"), [1, 2, 3]);
        assert_eq!(doc.slot_of(2), "hand");
        let s = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        // No skin: the slot's own part; a skin replaces it; a later skin wins.
        assert_eq!(doc.shown_part("hand", None, &[]), Some(1));
        assert_eq!(doc.shown_part("hand", None, &s(&["gloves"])), Some(3));
        assert_eq!(
            doc.shown_part("hand", None, &s(&["gloves", "fists"])),
            Some(2)
        );
        // A key naming the slot itself stands for the skin's choice; other names are as named.
        assert_eq!(
            doc.shown_part("hand", Some("hand"), &s(&["gloves"])),
            Some(3)
        );
        assert_eq!(
            doc.shown_part("hand", Some("fist"), &s(&["gloves"])),
            Some(2)
        );
        assert_eq!(doc.shown_part("hand", Some("body"), &[]), None);
        assert_eq!(doc.shown_part("body", None, &s(&["gloves"])), Some(0));
        assert!(doc.check_skins(&s(&["gloves", "fists"])).is_ok());
        assert_eq!(
            doc.check_skins(&s(&["hats"])).unwrap_err().to_string(),
            "the rig has no skin 'hats' (its skins: fists, gloves)"
        );
        assert_eq!(
            doc.check_skins(&s(&["glove"])).unwrap_err().to_string(),
            "the rig has no skin 'glove'; did you mean 'gloves'? (its skins: fists, gloves)"
        );
    }

    #[test]
    fn slots_and_skins_round_trip_and_bad_ones_fail_in_one_line() {
        let good = doc();
        let text = serde_json::to_string(&good).unwrap();
        let p = Path::new("r.json");
        assert_eq!(RigDocument::from_json(&text, p).unwrap(), good);
        let reason = |edit: &dyn Fn(&mut RigDocument)| {
            let mut d = good.clone();
            edit(&mut d);
            let text = serde_json::to_string(&d).unwrap();
            RigDocument::from_json(&text, p).unwrap_err().to_string()
        };
        assert_eq!(
            reason(&|d| d.parts[2].slot = Some("hat".into())),
            "r.json: part 'fist' is an attachment of slot 'hat', which is no part"
        );
        assert_eq!(
            reason(&|d| d.parts[3].slot = Some("fist".into())),
            "r.json: part 'glove' is an attachment of 'fist', which is itself an attachment of \
             slot 'hand' (name the slot)"
        );
        assert_eq!(
            reason(&|d| {
                d.skins
                    .get_mut("gloves")
                    .unwrap()
                    .insert("tail".into(), "glove".into());
            }),
            "r.json: skin 'gloves' names slot 'tail', which the rig does not have"
        );
        assert_eq!(
            reason(&|d| {
                d.skins
                    .get_mut("gloves")
                    .unwrap()
                    .insert("body".into(), "glove".into());
            }),
            "r.json: skin 'gloves' shows 'glove' in slot 'body', which is not one of its \
             attachments (body)"
        );
        assert!(reason(&|d| {
            d.skins.insert(DEFAULT_SKIN.into(), Skin::new());
        })
        .contains("reserved"));
        // A document without slots or skins writes neither field.
        let mut plain = RigDocument::new([4, 4]);
        plain.parts = vec![part("body", None)];
        let v = serde_json::to_value(&plain).unwrap();
        assert!(v.get("skins").is_none() && v["parts"][0].get("slot").is_none());
    }
}
