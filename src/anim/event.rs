//! Events: named moments of an animation (a footstep, a hit frame) with a payload a game reads.
//!
//! In: the rig document's `events` (name → [`EventDef`], the default payload) and an
//! animation's `events` timeline ([`EventKey`]s: a time, a name and payload values that override
//! the defaults). Out: the [`FiredEvent`]s (resolved payloads) an animation fires as its time
//! moves from one moment to another ([`Animation::events_between`]), and which frame of a
//! rendered loop fires which ([`frame_events`]). Units: seconds; `volume` 0..1 and `balance`
//! −1 (left) .. 1 (right) as Spine's audio events.
//!
//! Firing follows Spine's event timeline (spine-format.md §7, `EventTimeline.apply` of
//! spine-core 4.2): moving from `after_s` to `up_to_s` fires the keys with
//! `after_s < time ≤ up_to_s`, in key order; a negative `after_s` stands for "before the
//! start" and so includes keys at 0. Events change no pose: they are not part of
//! [`Animation::sample`].

use super::curve::f32_stored;
use super::timeline::{Animation, TimelineError};
use super::CurveEvaluation;
use serde::{Deserialize, Serialize};

/// An event's default payload (the rig document's `events`, by name). Spine's event data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct EventDef {
    /// Default 0.
    #[serde(skip_serializing_if = "is_zero_i32")]
    pub int: i32,
    /// Default 0.
    #[serde(skip_serializing_if = "is_zero_f64")]
    pub float: f64,
    /// Default empty.
    #[serde(skip_serializing_if = "String::is_empty")]
    pub string: String,
    /// A sound to play when the event fires: a path as the game resolves it (Spine resolves it
    /// against the skeleton's audio folder). Default none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub audio: Option<String>,
    /// Audio volume, 0..1. Default 1.
    #[serde(skip_serializing_if = "is_one")]
    pub volume: f64,
    /// Audio balance, −1 (left) .. 1 (right). Default 0.
    #[serde(skip_serializing_if = "is_zero_f64")]
    pub balance: f64,
}

impl Default for EventDef {
    fn default() -> Self {
        EventDef {
            int: 0,
            float: 0.0,
            string: String::new(),
            audio: None,
            volume: 1.0,
            balance: 0.0,
        }
    }
}

fn is_zero_i32(v: &i32) -> bool {
    *v == 0
}
fn is_zero_f64(v: &f64) -> bool {
    *v == 0.0
}
fn is_one(v: &f64) -> bool {
    *v == 1.0
}

/// A key of an animation's events timeline: the event `name` fires at `time`; each payload
/// value given overrides the definition's (as a Spine event key; the audio path itself is the
/// definition's).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EventKey {
    /// Seconds from the start of the animation.
    pub time: f64,
    /// An event of the rig document's `events`.
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub int: Option<i32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub float: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub string: Option<String>,
    /// Only for an event with audio.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub volume: Option<f64>,
    /// Only for an event with audio.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub balance: Option<f64>,
}

/// An event as it fires: its key's time and the resolved payload.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FiredEvent {
    pub name: String,
    /// The key's time, s.
    pub time: f64,
    pub int: i32,
    pub float: f64,
    pub string: String,
    /// The sound to play, for an event with audio.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub audio: Option<FiredAudio>,
}

/// The sound a fired event plays.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FiredAudio {
    pub path: String,
    /// 0..1.
    pub volume: f64,
    /// −1 (left) .. 1 (right).
    pub balance: f64,
}

/// What is wrong with an event definition (the rig document names it).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EventDefError {
    #[error("events: {0}")]
    Json(String),
    #[error("event '{name}': {field} must be a finite number{range} (got {})", crate::shown::Shown(*.value))]
    Value {
        name: String,
        field: &'static str,
        value: f64,
        range: &'static str,
    },
    #[error("event '{0}': volume and balance are for an event with audio")]
    NoAudio(String),
    #[error("event name {0:?} is empty or has control characters")]
    BadName(String),
}

/// `value` is finite and, when `range` is given, inside it.
fn check_number(
    name: &str,
    field: &'static str,
    value: f64,
    range: Option<(f64, f64, &'static str)>,
) -> Result<(), EventDefError> {
    let inside = range.is_none_or(|(lo, hi, _)| (lo..=hi).contains(&value));
    if value.is_finite() && inside && value.abs() <= super::timeline::MAX_KEY_VALUE {
        return Ok(());
    }
    Err(EventDefError::Value {
        name: name.into(),
        field,
        value,
        range: range.map_or(WITHIN_LIMIT, |(_, _, text)| text),
    })
}

const WITHIN_LIMIT: &str = " within ±1e6";

/// How a payload field's allowed range reads in messages.
pub(super) fn range_text(field: &str) -> &'static str {
    match field {
        "volume" => " in [0, 1]",
        "balance" => " in [-1, 1]",
        _ => WITHIN_LIMIT,
    }
}

const VOLUME: Option<(f64, f64, &str)> = Some((0.0, 1.0, " in [0, 1]"));
const BALANCE: Option<(f64, f64, &str)> = Some((-1.0, 1.0, " in [-1, 1]"));

impl EventDef {
    /// Checks the definition of the event `name`: a usable name, finite numbers, volume in
    /// [0, 1], balance in [−1, 1], volume and balance only with audio.
    pub fn check(&self, name: &str) -> Result<(), EventDefError> {
        if name.is_empty() || name.chars().any(char::is_control) {
            return Err(EventDefError::BadName(name.into()));
        }
        check_number(name, "float", self.float, None)?;
        check_number(name, "volume", self.volume, VOLUME)?;
        check_number(name, "balance", self.balance, BALANCE)?;
        if self.audio.is_none() && (self.volume != 1.0 || self.balance != 0.0) {
            return Err(EventDefError::NoAudio(name.into()));
        }
        Ok(())
    }
}

/// Times finite, ≥ 0 and non-decreasing (several events may fire at one time); payload numbers
/// finite, volume and balance in range.
pub(super) fn check_event_keys(keys: &[EventKey]) -> Result<(), TimelineError> {
    let mut previous: Option<f64> = None;
    for (key, k) in keys.iter().enumerate() {
        if !(k.time.is_finite() && k.time >= 0.0) {
            return Err(TimelineError::BadTime { key, time: k.time });
        }
        if let Some(previous) = previous.filter(|&p| k.time < p) {
            return Err(TimelineError::TimeNotIncreasing {
                key,
                time: k.time,
                previous,
            });
        }
        previous = Some(k.time);
        let numbers = [
            ("float", k.float, None),
            ("volume", k.volume, VOLUME),
            ("balance", k.balance, BALANCE),
        ];
        for (field, value, range) in numbers {
            if let Some(value) = value {
                check_number(&k.name, field, value, range).map_err(|_| TimelineError::Payload {
                    key,
                    field,
                    value,
                })?;
            }
        }
    }
    Ok(())
}

impl EventKey {
    /// The event as it fires with the definition `def`; its time as the curves' evaluation
    /// stores it (Spine's runtimes keep key times as 32-bit floats).
    pub fn fired(&self, def: &EventDef, curves: CurveEvaluation) -> FiredEvent {
        FiredEvent {
            name: self.name.clone(),
            time: key_time(self.time, curves),
            int: self.int.unwrap_or(def.int),
            float: self.float.unwrap_or(def.float),
            string: self.string.clone().unwrap_or_else(|| def.string.clone()),
            audio: def.audio.as_ref().map(|path| FiredAudio {
                path: path.clone(),
                volume: self.volume.unwrap_or(def.volume),
                balance: self.balance.unwrap_or(def.balance),
            }),
        }
    }
}

/// A key time as `curves` evaluates it: exact, or rounded to f32 as Spine's runtimes store it.
fn key_time(time_s: f64, curves: CurveEvaluation) -> f64 {
    match curves {
        CurveEvaluation::Exact => time_s,
        CurveEvaluation::SpineRuntime => f32_stored(time_s),
    }
}

/// The definitions events are resolved with: name → default payload.
pub type EventDefs = std::collections::BTreeMap<String, EventDef>;

/// Reads and checks event definitions (an events file, or a rig document's `events`): a JSON
/// object of name → [`EventDef`].
pub fn events_from_json(value: &serde_json::Value) -> Result<EventDefs, EventDefError> {
    if !value.is_object() {
        return Err(EventDefError::Json(
            "expected an object: name → event".into(),
        ));
    }
    let defs = EventDefs::deserialize(value).map_err(|e| EventDefError::Json(e.to_string()))?;
    for (name, def) in &defs {
        def.check(name)?;
    }
    Ok(defs)
}

impl Animation {
    /// The events fired while the animation's time moves from `after_s` (exclusive; negative:
    /// before the start) to `up_to_s` (inclusive), in key order, with payloads resolved from
    /// `defs` (a key whose name `defs` lacks fires with the default payload; the rig check
    /// refuses such keys first). No wrapping: see [`frame_events`] for a loop.
    pub fn events_between(
        &self,
        after_s: f64,
        up_to_s: f64,
        defs: &EventDefs,
        curves: CurveEvaluation,
    ) -> Vec<FiredEvent> {
        let fallback = EventDef::default();
        self.events
            .iter()
            .filter(|k| {
                let t = key_time(k.time, curves);
                after_s < t && t <= up_to_s
            })
            .map(|k| k.fired(defs.get(&k.name).unwrap_or(&fallback), curves))
            .collect()
    }
}

/// Which events each frame of a looping render fires, for frames at `times_s` (increasing,
/// the first at 0, all before the duration; [`crate::playback::frame_times`]): frame k > 0
/// fires those after frame k − 1's time up to its own, as the runtime does stepping from one
/// frame to the next; frame 0 fires those after the last frame's time up to the end, then
/// those at time 0, in that order, as the runtime does when a loop wraps to frame 0. Every key
/// lands on exactly one frame.
pub fn frame_events(
    animation: &Animation,
    times_s: &[f64],
    defs: &EventDefs,
    curves: CurveEvaluation,
) -> Vec<Vec<FiredEvent>> {
    let mut out: Vec<Vec<FiredEvent>> = Vec::with_capacity(times_s.len());
    for (k, &t) in times_s.iter().enumerate() {
        out.push(match k {
            0 => {
                let last = times_s[times_s.len() - 1];
                let mut wrap = animation.events_between(last, f64::INFINITY, defs, curves);
                wrap.extend(animation.events_between(-1.0, t, defs, curves));
                wrap
            }
            _ => animation.events_between(times_s[k - 1], t, defs, curves),
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn walk() -> Animation {
        Animation::from_json(
            "walk",
            &json!({"events": [
                {"time": 0, "name": "step", "string": "left"},
                {"time": 0.5, "name": "step", "string": "right", "int": 2},
                {"time": 0.5, "name": "cue"},
                {"time": 0.95, "name": "cue", "float": 0.25}
            ]}),
        )
        .unwrap()
    }

    fn defs() -> EventDefs {
        serde_json::from_value(json!({
            "step": {"int": 1, "audio": "sfx/step.wav", "volume": 0.8},
            "cue": {"float": 1.5, "string": "go"}
        }))
        .unwrap()
    }

    #[test]
    fn keys_fire_after_the_last_time_up_to_the_next_with_their_payloads() {
        let (anim, defs) = (walk(), defs());
        let exact = CurveEvaluation::Exact;
        assert_eq!(anim.duration_s(), 0.95);
        let names = |a: f64, b: f64| -> Vec<(String, f64)> {
            anim.events_between(a, b, &defs, exact)
                .into_iter()
                .map(|e| (e.string, e.time))
                .collect()
        };
        assert_eq!(names(-1.0, 0.0), [("left".to_string(), 0.0)]);
        assert!(
            names(0.0, 0.4).is_empty(),
            "a key at the start time is past"
        );
        assert_eq!(
            names(0.4, 0.5),
            [("right".to_string(), 0.5), ("go".to_string(), 0.5)]
        );
        let fired = anim.events_between(0.9, 1.0, &defs, exact);
        assert_eq!(fired.len(), 1);
        let cue = &fired[0];
        assert_eq!((cue.int, cue.float, cue.string.as_str()), (0, 0.25, "go"));
        assert_eq!(cue.audio, None);
        let step = &anim.events_between(0.4, 0.5, &defs, exact)[0];
        let audio = step.audio.as_ref().unwrap();
        assert_eq!(
            (step.int, audio.path.as_str(), audio.volume, audio.balance),
            (2, "sfx/step.wav", 0.8, 0.0)
        );
    }

    #[test]
    fn each_key_lands_on_one_frame_of_a_loop() {
        let (anim, defs) = (walk(), defs());
        // Frames at 0, 0.3, 0.6: the key at 0.95 fires as the loop wraps to frame 0.
        let frames = frame_events(&anim, &[0.0, 0.3, 0.6], &defs, CurveEvaluation::Exact);
        let counts: Vec<usize> = frames.iter().map(Vec::len).collect();
        assert_eq!(counts, [2, 0, 2]);
        // The loop's end fires first as it wraps, then its start.
        assert_eq!((frames[0][0].time, frames[0][1].time), (0.95, 0.0));
        // The runtime's 32-bit key times: 0.95 is stored as 0.949999988….
        let after = 0.949_999_999;
        assert_eq!(
            anim.events_between(after, 1.0, &defs, CurveEvaluation::Exact)
                .len(),
            1
        );
        let runtime = anim.events_between(after, 1.0, &defs, CurveEvaluation::SpineRuntime);
        assert!(runtime.is_empty());
    }

    #[test]
    fn bad_definitions_and_keys_are_refused() {
        let def = |v: serde_json::Value| serde_json::from_value::<EventDef>(v).unwrap();
        assert_eq!(
            def(json!({"float": 1e300}))
                .check("hit")
                .unwrap_err()
                .to_string(),
            "event 'hit': float must be a finite number within ±1e6 (got 1e300)"
        );
        assert_eq!(
            def(json!({"audio": "a.wav", "volume": 2}))
                .check("hit")
                .unwrap_err()
                .to_string(),
            "event 'hit': volume must be a finite number in [0, 1] (got 2)"
        );
        assert_eq!(
            def(json!({"balance": 0.5}))
                .check("hit")
                .unwrap_err()
                .to_string(),
            "event 'hit': volume and balance are for an event with audio"
        );
        assert!(def(json!({})).check("").is_err());
        let message = |v: serde_json::Value| {
            Animation::from_json("walk", &json!({ "events": v }))
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            message(json!([{"time": 1, "name": "a"}, {"time": 0.5, "name": "a"}])),
            "animation 'walk', events: key 1 at 0.5 s does not come after the previous key at 1 s"
        );
        assert_eq!(
            message(json!([{"time": 0, "name": "a", "volume": -1}])),
            "animation 'walk', events: key 0: volume must be a finite number in [0, 1] (got -1)"
        );
        assert!(message(json!([{"time": 0, "name": "a", "value": 1}]))
            .starts_with("animation 'walk', events key 0: unknown field `value`"),);
    }
}
