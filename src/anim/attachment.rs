//! Attachment timelines checked against the rig's slots.
//!
//! In: an [`Animation`] (checked on its own and by [`Animation::check_rig`], so its `parts` keys
//! are slots) and the rig document. Out: `Ok` when every attachment key names an attachment of
//! its slot (or is `null`: hidden), and no slot is keyed by both `visible` and `attachment` (in
//! Spine both are the one attachment timeline of the slot).

use super::timeline::Animation;
use super::AnimError;
use crate::io::RigDocument;

impl Animation {
    /// Fails on the first attachment key the slot cannot show.
    pub fn check_attachments(&self, name: &str, doc: &RigDocument) -> Result<(), AnimError> {
        for (slot, timelines) in &self.parts {
            let Some(keys) = &timelines.attachment else {
                continue;
            };
            if timelines.visible.is_some() {
                return Err(AnimError::VisibleAndAttachment {
                    animation: name.into(),
                    slot: slot.clone(),
                });
            }
            for (key, k) in keys.iter().enumerate() {
                let Some(attachment) = &k.value else { continue };
                if doc.shown_part(slot, Some(attachment), &[]).is_none() {
                    return Err(AnimError::UnknownAttachment {
                        animation: name.into(),
                        place: format!(
                            "parts.{slot}.attachment: key {key} shows '{attachment}', which \
                             slot '{slot}' does not have (its attachments: {})",
                            doc.attachment_names(slot).join(", ")
                        ),
                    });
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::io::slots::tests::part;
    use crate::io::RigDocument;
    use serde_json::json;

    fn doc(animation: serde_json::Value) -> RigDocument {
        let mut doc = RigDocument::new([4, 4]);
        for (name, slot) in [("body", None), ("hand", None), ("fist", Some("hand"))] {
            doc.parts.push(part(name, slot));
        }
        doc.animations = crate::anim::animations_from_json(&json!({ "grab": animation })).unwrap();
        doc
    }

    #[test]
    fn keys_swap_hide_and_are_checked_against_the_slot() {
        let keys = json!({"parts": {"hand": {"attachment": [
            {"time": 0, "value": "hand"}, {"time": 0.5, "value": "fist"},
            {"time": 1, "value": null}]}}});
        let d = doc(keys);
        d.check_animations().unwrap();
        let anim = &d.animations["grab"];
        let at = |t: f64| anim.sample(t, false).parts["hand"].clone();
        assert_eq!(at(0.2).attachment.as_deref(), Some("hand"));
        assert_eq!(
            d.shown_part("hand", at(0.2).attachment.as_deref(), &[]),
            Some(1)
        );
        assert_eq!(at(0.5).attachment.as_deref(), Some("fist"));
        assert_eq!(
            d.shown_part("hand", at(0.7).attachment.as_deref(), &[]),
            Some(2)
        );
        assert!(at(0.7).visible && !at(1.0).visible);
        // Written back, the same keys.
        let back = serde_json::to_value(anim).unwrap();
        assert_eq!(back["parts"]["hand"]["attachment"][2]["value"], json!(null));

        let e = doc(json!({"parts": {"hand": {"attachment": [{"time": 0, "value": "body"}]}}}))
            .check_animations()
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "animation 'grab', parts.hand.attachment: key 0 shows 'body', which slot 'hand' \
             does not have (its attachments: hand, fist)"
        );
        let e = doc(json!({"parts": {"fist": {"attachment": [{"time": 0, "value": "fist"}]}}}))
            .check_animations()
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "animation 'grab' names part 'fist', which the rig does not have"
        );
        let e = doc(json!({"parts": {"hand": {
            "attachment": [{"time": 0, "value": "fist"}],
            "visible": [{"time": 0, "value": true}]}}}))
        .check_animations()
        .unwrap_err()
        .to_string();
        assert!(e.contains("keys both 'visible' and 'attachment'"), "{e}");
    }
}
