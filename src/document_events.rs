//! The document's events: their definitions (name → default payload) and the event keys of an
//! animation, edited one [`EventEdit`] at a time (see [`super::Command::Events`]).
//!
//! In: the state's event definitions and animations. Out: the state after the edit, or why it
//! is refused: a key naming an event that is not defined, a definition whose numbers are not
//! finite or out of range ([`EventDef::check`]), a name already defined, no event at the time
//! named. Moving, copying and deleting event keys are the dopesheet's key edits
//! ([`crate::anim::edit`], timeline [`crate::anim::edit::TimelineId::Events`]).

use super::{animation_named, store_animation, DocumentError, State};
use crate::anim::edit::KEY_TIME_TOLERANCE_S;
use crate::anim::{EventDef, EventKey};

/// One edit of the events (see [`super::Command::Events`]).
#[derive(Clone, Debug, PartialEq)]
pub enum EventEdit {
    /// Adds `key` to `animation` (made when missing), after the events already at its time.
    Add { animation: String, key: EventKey },
    /// Replaces the `index`-th event (0: the first) at `time_s` of `animation` by `key`.
    Set {
        animation: String,
        time_s: f64,
        index: usize,
        key: EventKey,
    },
    /// Defines a new event `name` with its default payload.
    Define { name: String, def: EventDef },
    /// Changes the default payload (and audio path) of the defined event `name`.
    Redefine { name: String, def: EventDef },
}

/// The events at `time_s` of `keys`, by index into `keys`.
pub fn events_at(keys: &[EventKey], time_s: f64) -> Vec<usize> {
    (0..keys.len())
        .filter(|&i| (keys[i].time - time_s).abs() <= KEY_TIME_TOLERANCE_S)
        .collect()
}

/// Refuses a key naming an event `state` does not define.
fn check_defined(state: &State, key: &EventKey) -> Result<(), DocumentError> {
    if state.events.contains_key(&key.name) {
        return Ok(());
    }
    let known: Vec<&str> = state.events.keys().map(String::as_str).collect();
    Err(DocumentError::UnknownEvent {
        name: key.name.clone(),
        known: if known.is_empty() {
            "none yet".into()
        } else {
            known.join(", ")
        },
    })
}

/// Applies `edit` to `next` (a copy of the state).
pub(super) fn apply(next: &mut State, edit: EventEdit) -> Result<(), DocumentError> {
    match edit {
        EventEdit::Add { animation, key } => {
            check_defined(next, &key)?;
            let mut anim = animation_named(next, &animation);
            let at = anim
                .events
                .partition_point(|k| k.time <= key.time + KEY_TIME_TOLERANCE_S);
            anim.events.insert(at, key);
            store_animation(next, &animation, anim)?;
        }
        EventEdit::Set {
            animation,
            time_s,
            index,
            key,
        } => {
            check_defined(next, &key)?;
            let mut anim = animation_named(next, &animation);
            let at =
                *events_at(&anim.events, time_s)
                    .get(index)
                    .ok_or(DocumentError::NoEventAt {
                        animation: animation.clone(),
                        time_s,
                    })?;
            if (key.time - time_s).abs() > KEY_TIME_TOLERANCE_S {
                // Retiming is the dopesheet's (a move keeps the order of the other events).
                return Err(DocumentError::NoEventAt {
                    animation,
                    time_s: key.time,
                });
            }
            anim.events[at] = key;
            store_animation(next, &animation, anim)?;
        }
        EventEdit::Define { name, def } => {
            if next.events.contains_key(&name) {
                return Err(DocumentError::EventExists(name));
            }
            def.check(&name)?;
            next.events.insert(name, def);
        }
        EventEdit::Redefine { name, def } => {
            if !next.events.contains_key(&name) {
                return Err(DocumentError::UnknownEvent {
                    known: next.events.keys().cloned().collect::<Vec<_>>().join(", "),
                    name,
                });
            }
            def.check(&name)?;
            next.events.insert(name, def);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::{Command, Document};
    use super::*;

    fn key(time: f64, name: &str) -> EventKey {
        EventKey {
            time,
            name: name.into(),
            int: None,
            float: None,
            string: None,
            volume: None,
            balance: None,
        }
    }

    #[test]
    fn events_are_defined_added_and_set_and_bad_ones_refused() {
        let mut doc = Document::new();
        let events = |e| Command::Events(e);
        let add = |time, name: &str| {
            events(EventEdit::Add {
                animation: "walk".into(),
                key: key(time, name),
            })
        };
        let e = doc.apply(add(0.5, "step")).unwrap_err().to_string();
        assert_eq!(e, "there is no event named 'step' (defined: none yet)");
        let step = EventDef {
            int: 1,
            audio: Some("sfx/step.wav".into()),
            ..Default::default()
        };
        doc.apply(events(EventEdit::Define {
            name: "step".into(),
            def: step.clone(),
        }))
        .expect("defined");
        let e = doc.apply(events(EventEdit::Define {
            name: "step".into(),
            def: step,
        }));
        assert!(matches!(e, Err(DocumentError::EventExists(_))), "{e:?}");
        let nan = EventDef {
            float: f64::NAN,
            ..Default::default()
        };
        let e = doc
            .apply(events(EventEdit::Define {
                name: "cue".into(),
                def: nan,
            }))
            .unwrap_err()
            .to_string();
        assert!(e.contains("float must be a finite number"), "{e}");
        doc.apply(add(0.5, "step")).expect("added");
        doc.apply(add(0.0, "step")).expect("added before");
        doc.apply(add(0.5, "step")).expect("added at the same time");
        let times: Vec<f64> = doc.state().animations["walk"]
            .events
            .iter()
            .map(|k| k.time)
            .collect();
        assert_eq!(times, [0.0, 0.5, 0.5]);

        // The second event at 0.5 s gets an int; a float beyond the limit is refused.
        let mut second = key(0.5, "step");
        second.int = Some(7);
        let set = |index, key: EventKey| {
            events(EventEdit::Set {
                animation: "walk".into(),
                time_s: 0.5,
                index,
                key,
            })
        };
        doc.apply(set(1, second.clone())).expect("set");
        let ints: Vec<Option<i32>> = doc.state().animations["walk"]
            .events
            .iter()
            .map(|k| k.int)
            .collect();
        assert_eq!(ints, [None, None, Some(7)]);
        second.float = Some(1e300);
        let e = doc.apply(set(1, second)).unwrap_err().to_string();
        assert!(e.contains("float must be a finite number"), "{e}");
        assert!(doc.apply(set(2, key(0.5, "step"))).is_err());

        // Redefining changes the audio path every key plays.
        doc.apply(events(EventEdit::Redefine {
            name: "step".into(),
            def: EventDef {
                audio: Some("sfx/thud.wav".into()),
                ..Default::default()
            },
        }))
        .expect("redefined");
        assert_eq!(
            doc.state().events["step"].audio.as_deref(),
            Some("sfx/thud.wav")
        );
        assert!(doc.undo());
        assert_eq!(doc.state().events["step"].int, 1);
    }
}
