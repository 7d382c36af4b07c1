//! Events as Spine events: the rig's definitions as the skeleton's `events` (name → default
//! payload) and an animation's keys as its `events` timeline (spine-format.md §7, Events).
//!
//! In: the rig document's event definitions, an animation's event keys. Out: JSON values.
//! Spine reads `volume` and `balance` only for an event with audio, and a key cannot change
//! the audio path; sinew's model is the same ([`crate::anim::event`]), so nothing is lost. One
//! difference: spine-core 4.2's JSON loader gives a key without `volume` (`balance`) volume 1
//! (balance 0), not the definition's (4.2.119 `SkeletonJson.readAnimation`), and 4.3.13's
//! gives a key without `balance` the definition's *volume* (a slip in its `readAnimation`); so
//! every key of an audio event carries its resolved volume and balance (checked in
//! `tests/spine_runtime.rs` on both runtimes).

use super::timelines::num;
use crate::anim::{EventDefs, EventKey};
use serde_json::{json, Map, Value};

/// The skeleton's `events` object: every defined event with its non-default payload.
pub fn event_defs_json(defs: &EventDefs) -> Value {
    let entries = defs.iter().map(|(name, def)| {
        let mut m = Map::new();
        if def.int != 0 {
            m.insert("int".into(), json!(def.int));
        }
        if def.float != 0.0 {
            m.insert("float".into(), num(def.float));
        }
        if !def.string.is_empty() {
            m.insert("string".into(), json!(def.string));
        }
        if let Some(audio) = &def.audio {
            m.insert("audio".into(), json!(audio));
            m.insert("volume".into(), num(def.volume));
            m.insert("balance".into(), num(def.balance));
        }
        (name.clone(), Value::Object(m))
    });
    Value::Object(entries.collect())
}

/// An animation's `events` timeline: one key per event key, its overrides only, and for an
/// event with audio always its resolved volume and balance (see the module doc).
pub fn event_timeline(keys: &[EventKey], defs: &EventDefs) -> Value {
    keys.iter()
        .map(|k| {
            let def = defs.get(&k.name);
            let audio = def.is_some_and(|d| d.audio.is_some());
            let volume = k.volume.or(def.map(|d| d.volume)).filter(|_| audio);
            let balance = k.balance.or(def.map(|d| d.balance)).filter(|_| audio);
            let mut m = Map::new();
            m.insert("time".into(), num(k.time));
            m.insert("name".into(), json!(k.name));
            if let Some(v) = k.int {
                m.insert("int".into(), json!(v));
            }
            if let Some(v) = k.float {
                m.insert("float".into(), num(v));
            }
            if let Some(v) = &k.string {
                m.insert("string".into(), json!(v));
            }
            if let Some(v) = volume {
                m.insert("volume".into(), num(v));
            }
            if let Some(v) = balance {
                m.insert("balance".into(), num(v));
            }
            Value::Object(m)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_left_out_and_keys_keep_only_their_overrides() {
        let defs: EventDefs = serde_json::from_value(json!({
            "hit": {},
            "step": {"int": 2, "string": "l", "audio": "step.wav", "balance": -0.5}
        }))
        .unwrap();
        assert_eq!(
            event_defs_json(&defs),
            json!({"hit": {}, "step": {"int": 2, "string": "l", "audio": "step.wav",
                                        "volume": 1.0, "balance": -0.5}})
        );
        let keys: Vec<EventKey> = serde_json::from_value(json!([
            {"time": 0.25, "name": "step", "float": 1.5},
            {"time": 0.5, "name": "step", "balance": 0},
            {"time": 0.75, "name": "hit", "volume": 0.5}
        ]))
        .unwrap();
        // Each key of an audio event says its volume and balance; a volume of an event without
        // audio is nothing.
        assert_eq!(
            event_timeline(&keys, &defs),
            json!([{"time": 0.25, "name": "step", "float": 1.5, "volume": 1.0, "balance": -0.5},
                   {"time": 0.5, "name": "step", "volume": 1.0, "balance": 0.0},
                   {"time": 0.75, "name": "hit"}])
        );
    }
}
