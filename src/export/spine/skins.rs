//! Slots and skins of the skeleton JSON (spine-format.md §5, §6).
//!
//! In: the document (its slots, attachments and skins, [`crate::io::slots`]) and the exported
//! meshes (one per part, in part order). Out: the `slots` array (one per sinew slot, in draw
//! order, its setup attachment named after the slot) and the `skins` array: `default` holds every
//! part's mesh under its own name in its slot; each sinew skin holds, for each slot it names, a
//! linked mesh under the slot's name (`type: linkedmesh`, `name` = the part, which is also its
//! atlas region, its mesh the default skin's attachment of that name in the same slot, §6): no
//! copy of the geometry per skin (1,000 skins of 12 slots made a 1.5 GB file), and the part's
//! deform keys, written for its default-skin mesh, apply to it (`timelines` defaults to true).
//! The runtime looks an attachment name up in the active skin first, then in `default`, so a key
//! or setup attachment naming the slot shows the skin's choice and any other name shows that part:
//! sinew's [`crate::io::RigDocument::shown_part`].

use super::ExportedPart;
use crate::io::RigDocument;
use serde_json::{json, Map, Value};

/// `slots` and `skins` for `parts` (the exported meshes, in part order), each mesh attachment
/// written by `mesh_json`; skins' linked meshes name their mesh by `source` (`true`: 4.3) or
/// `parent` (4.1, 4.2).
pub fn slots_and_skins(
    doc: &RigDocument,
    parts: &[ExportedPart],
    root_bone: &str,
    mesh_json: &dyn Fn(&ExportedPart) -> Value,
    linked_by_source: bool,
) -> (Vec<Value>, Vec<Value>) {
    let slots: Vec<Value> = doc
        .slot_names()
        .into_iter()
        .map(|slot| json!({"name": slot, "bone": root_bone, "attachment": slot}))
        .collect();
    let mut default = Map::new();
    for (i, part) in parts.iter().enumerate() {
        let slot = default
            .entry(doc.slot_of(i).to_string())
            .or_insert_with(|| Value::Object(Map::new()));
        slot[part.name.as_str()] = mesh_json(part);
    }
    let mut skins = vec![json!({"name": crate::io::slots::DEFAULT_SKIN, "attachments": default})];
    for (name, skin) in &doc.skins {
        let mut attachments = Map::new();
        for (slot, attachment) in skin {
            if !parts.iter().any(|p| &p.name == attachment) {
                continue;
            }
            // The skin's choice is a part of this slot (the document's check), so its mesh is
            // in the default skin under its own name in this very slot.
            let source_key = if linked_by_source { "source" } else { "parent" };
            let linked = json!({
                "type": "linkedmesh",
                "name": attachment,
                source_key: attachment,
                "skin": crate::io::slots::DEFAULT_SKIN,
            });
            attachments.insert(slot.clone(), json!({ slot.clone(): linked }));
        }
        skins.push(json!({"name": name, "attachments": attachments}));
    }
    (slots, skins)
}
