//! Interpolation between two keys: linear, stepped, or a cubic Bézier in (time, value) units.
//!
//! In: a segment from key (t0, v0) to key (t1, v1) — seconds and the timeline's value units —,
//! the curve stored on the segment's first key, and a time t in [t0, t1]. Out: the value at t.
//!
//! A Bézier curve is Spine 4.x's: per value channel four numbers `cx1, cy1, cx2, cy2`, the two
//! inner control points in absolute units (seconds, value units); the outer control points are
//! the keys themselves. Its time coordinate x(s) is inverted exactly (Newton safeguarded by
//! bisection, to machine precision), where Spine's runtimes walk a 10-segment polyline instead
//! (differences of ~0.1° on a typical rotate key; see /work/shared/spine-format.md §7).
//!
//! [`CurveEvaluation::SpineRuntime`] reproduces the runtime instead, for previews that must show
//! what a game shows: [`spine_runtime_bezier_value`] is spine-core 4.2's
//! `CurveTimeline.setBezier` (forward differences at s = 0.1 … 0.9, stored as 32-bit floats) and
//! `getBezierValue` (linear in time between those points and the keys).

use serde::de::{self, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;

/// How a key's value travels to the next key's.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Curve {
    /// Straight in time (`"linear"`, or no `curve` field).
    #[default]
    Linear,
    /// Hold the value until the next key (`"stepped"`).
    Stepped,
    /// Cubic Bézier: `cx1, cy1, cx2, cy2` per value channel, flat (Spine's layout: for a 2-value
    /// timeline, the x channel's four numbers then the y channel's).
    Bezier(Vec<f64>),
}

/// Numbers per Bézier channel: `cx1, cy1, cx2, cy2`.
pub const BEZIER_NUMBERS_PER_CHANNEL: usize = 4;

/// The solver stops when a Newton step moves the curve parameter by at most this many ulps of 1,
/// or when bisection has shrunk the bracket to this width.
pub const BEZIER_PARAMETER_TOLERANCE: f64 = 2.0 * f64::EPSILON;

/// Iteration cap of the solver; bisection alone reaches machine precision in 53 steps.
pub const BEZIER_MAX_ITERATIONS: usize = 100;

/// How Bézier keys (and key storage) are evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveEvaluation {
    /// The exact cubic, in f64: what the animator drew.
    #[default]
    Exact,
    /// What Spine's official runtimes play: key times, values and the curve's sample points
    /// stored as 32-bit floats, each Bézier walked as a 10-segment polyline.
    SpineRuntime,
}

/// Rounds to the nearest 32-bit float, as the runtime's `Float32Array` storage does.
pub fn f32_stored(x: f64) -> f64 {
    x as f32 as f64
}

/// Points of the polyline the runtime walks per Bézier: parameters 0.1 … 0.9.
pub const SPINE_BEZIER_POINTS: usize = 9;

/// The runtime's polyline of one Bézier channel from key (t0, v0) to key (t1, v1) with
/// `[cx1, cy1, cx2, cy2]`: the curve at s = 0.1 … 0.9 as (time, value) pairs, by spine-core's
/// forward differences (its constants 0.03, 0.006, 0.16666667 included), stored as f32.
pub fn spine_bezier_polyline(
    t0: f64,
    v0: f64,
    [cx1, cy1, cx2, cy2]: [f64; 4],
    t1: f64,
    v1: f64,
) -> [[f64; 2]; SPINE_BEZIER_POINTS] {
    let tmpx = (t0 - cx1 * 2.0 + cx2) * 0.03;
    let tmpy = (v0 - cy1 * 2.0 + cy2) * 0.03;
    let dddx = ((cx1 - cx2) * 3.0 - t0 + t1) * 0.006;
    let dddy = ((cy1 - cy2) * 3.0 - v0 + v1) * 0.006;
    let (mut ddx, mut ddy) = (tmpx * 2.0 + dddx, tmpy * 2.0 + dddy);
    let mut dx = (cx1 - t0) * 0.3 + tmpx + dddx * 0.16666667;
    let mut dy = (cy1 - v0) * 0.3 + tmpy + dddy * 0.16666667;
    let (mut x, mut y) = (t0 + dx, v0 + dy);
    let mut out = [[0.0; 2]; SPINE_BEZIER_POINTS];
    for point in &mut out {
        *point = [f32_stored(x), f32_stored(y)];
        dx += ddx;
        dy += ddy;
        ddx += dddx;
        ddy += dddy;
        x += dx;
        y += dy;
    }
    out
}

/// The value of one Bézier channel at time t as the runtime computes it: (t0, v0) and
/// (t1, v1) are the keys as stored (f32), `handles` and the unrounded key values `exact_v0`,
/// `exact_v1` and times feed the polyline as the JSON loader does (it passes the parsed f64
/// numbers to `setBezier`).
pub fn spine_runtime_bezier_value(
    exact: ([f64; 2], [f64; 2]),
    stored: ([f64; 2], [f64; 2]),
    handles: &[f64],
    t: f64,
) -> f64 {
    let ([et0, ev0], [et1, ev1]) = exact;
    let ([t0, v0], [t1, v1]) = stored;
    let h = match handles {
        &[a, b, c, d] => [a, b, c, d],
        _ => return v0 + (t - t0) / (t1 - t0) * (v1 - v0),
    };
    let points = spine_bezier_polyline(et0, ev0, h, et1, ev1);
    if points[0][0] > t {
        return v0 + (t - t0) / (points[0][0] - t0) * (points[0][1] - v0);
    }
    for pair in points.windows(2) {
        if pair[1][0] >= t {
            let [x, y] = pair[0];
            return y + (t - x) / (pair[1][0] - x) * (pair[1][1] - y);
        }
    }
    let [x, y] = points[SPINE_BEZIER_POINTS - 1];
    y + (t - x) / (t1 - x) * (v1 - y)
}

impl Curve {
    pub fn is_linear(&self) -> bool {
        matches!(self, Curve::Linear)
    }
}

impl Serialize for Curve {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            Curve::Linear => serializer.serialize_str("linear"),
            Curve::Stepped => serializer.serialize_str("stepped"),
            Curve::Bezier(numbers) => numbers.serialize(serializer),
        }
    }
}

impl<'de> Deserialize<'de> for Curve {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct CurveVisitor;
        impl<'de> Visitor<'de> for CurveVisitor {
            type Value = Curve;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("\"linear\", \"stepped\" or an array of Bézier numbers")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Curve, E> {
                match v {
                    "linear" => Ok(Curve::Linear),
                    "stepped" => Ok(Curve::Stepped),
                    other => Err(E::custom(format!(
                        "unknown curve \"{other}\" (expected \"linear\", \"stepped\" or an array \
                         of Bézier numbers)"
                    ))),
                }
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Curve, A::Error> {
                let mut numbers = Vec::with_capacity(seq.size_hint().unwrap_or(4));
                while let Some(x) = seq.next_element::<f64>()? {
                    numbers.push(x);
                }
                Ok(Curve::Bezier(numbers))
            }
        }
        deserializer.deserialize_any(CurveVisitor)
    }
}

/// One coordinate of a cubic Bézier with control values p0..p3 at parameter s ∈ [0, 1].
pub fn cubic(p: [f64; 4], s: f64) -> f64 {
    let u = 1.0 - s;
    u * u * u * p[0] + 3.0 * u * u * s * p[1] + 3.0 * u * s * s * p[2] + s * s * s * p[3]
}

/// d/ds of [`cubic`].
pub fn cubic_derivative(p: [f64; 4], s: f64) -> f64 {
    let u = 1.0 - s;
    3.0 * (u * u * (p[1] - p[0]) + 2.0 * u * s * (p[2] - p[1]) + s * s * (p[3] - p[2]))
}

/// The parameter s ∈ [0, 1] where the time coordinate x(s) with control times `x` equals `t`.
///
/// x must be non-decreasing (inner control times within [x0, x3], which validation enforces),
/// so the root is unique. Newton steps are taken while they stay inside the bracket that the
/// signs of x(s) − t maintain; otherwise the bracket is bisected, so the solve always converges.
pub fn solve_bezier_parameter(x: [f64; 4], t: f64) -> f64 {
    if t <= x[0] {
        return 0.0;
    }
    if t >= x[3] {
        return 1.0;
    }
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    // The linear guess is exact when the handles sit at thirds, as a linear-looking curve does.
    let mut s = (t - x[0]) / (x[3] - x[0]);
    for _ in 0..BEZIER_MAX_ITERATIONS {
        let f = cubic(x, s) - t;
        if f == 0.0 {
            return s;
        }
        if f < 0.0 {
            lo = s;
        } else {
            hi = s;
        }
        if hi - lo <= BEZIER_PARAMETER_TOLERANCE {
            break;
        }
        let slope = cubic_derivative(x, s);
        let newton = s - f / slope;
        if slope > 0.0 && newton > lo && newton < hi {
            let step = (newton - s).abs();
            s = newton;
            if step <= BEZIER_PARAMETER_TOLERANCE {
                break;
            }
        } else {
            s = 0.5 * (lo + hi);
        }
    }
    s
}

/// The value of one Bézier channel at time t: the curve through (t0, v0), (cx1, cy1),
/// (cx2, cy2), (t1, v1), with `handles = [cx1, cy1, cx2, cy2]`.
pub fn bezier_value(t0: f64, v0: f64, handles: &[f64], t1: f64, v1: f64, t: f64) -> f64 {
    let [cx1, cy1, cx2, cy2] = match handles {
        &[a, b, c, d] => [a, b, c, d],
        // Validation rejects other lengths; without handles the segment is linear.
        _ => return v0 + (v1 - v0) * ((t - t0) / (t1 - t0)),
    };
    let s = solve_bezier_parameter([t0, cx1, cx2, t1], t);
    cubic([v0, cy1, cy2, v1], s)
}

/// Splits the cubic with control values `p` at parameter `s` (de Casteljau): the control
/// values of its part over [0, s] and of its part over [s, 1], which together trace the same
/// curve.
pub fn split_cubic(p: [f64; 4], s: f64) -> ([f64; 4], [f64; 4]) {
    let lerp = |a: f64, b: f64| a + (b - a) * s;
    let (a, b, c) = (lerp(p[0], p[1]), lerp(p[1], p[2]), lerp(p[2], p[3]));
    let (d, e) = (lerp(a, b), lerp(b, c));
    let f = lerp(d, e);
    ([p[0], a, d, f], [f, e, c, p[3]])
}

/// A segment's curve split by a key inserted at time `t` strictly between its keys (t0, `v0`)
/// and (t1, `v1`), so that the two new segments play what the one did.
#[derive(Clone, Debug, PartialEq)]
pub struct SplitCurve {
    /// The curve from the first key to the inserted one.
    pub before: Curve,
    /// The curve from the inserted key to the second one.
    pub after: Curve,
    /// The segment's value at `t`, per number (what the inserted key must hold for the motion
    /// to be unchanged).
    pub value: Vec<f64>,
}

/// Splits the segment from (t0, `v0`) to (t1, `v1`) with `curve` at `t` ∈ (t0, t1): linear
/// and stepped segments stay what they are; a Bézier is split by de Casteljau at the parameter
/// where its time is `t`, channel by channel, so the sampled motion is unchanged. `per_channel`
/// is [`super::timeline::Channels::CURVE_PER_CHANNEL`]: false when one curve gives a 0..1
/// fraction of the way for all numbers (cage polygons); its two parts are then rescaled to
/// their own segments. A Bézier of the wrong length is split as the linear segment it samples
/// as.
pub fn split_curve(
    curve: &Curve,
    (t0, v0): (f64, &[f64]),
    (t1, v1): (f64, &[f64]),
    t: f64,
    per_channel: bool,
) -> SplitCurve {
    let f = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
    let lerp = |fraction: f64| -> Vec<f64> {
        v0.iter()
            .zip(v1)
            .map(|(a, b)| a + (b - a) * fraction)
            .collect()
    };
    let linear = |fraction: f64| SplitCurve {
        before: Curve::Linear,
        after: Curve::Linear,
        value: lerp(fraction),
    };
    let numbers = match curve {
        Curve::Linear => return linear(f),
        Curve::Stepped => {
            return SplitCurve {
                before: Curve::Stepped,
                after: Curve::Stepped,
                value: v0.to_vec(),
            }
        }
        Curve::Bezier(numbers) => numbers,
    };
    let channels = if per_channel { v0.len() } else { 1 };
    if numbers.len() != channels * BEZIER_NUMBERS_PER_CHANNEL || v1.len() != v0.len() {
        return linear(f);
    }
    // Control times stay inside their new segments (rounding could push one a hair out).
    let (mut before, mut after, mut value) = (Vec::new(), Vec::new(), Vec::new());
    let inside = |x: f64, lo: f64, hi: f64| x.clamp(lo, hi);
    for (c, h) in numbers.chunks_exact(BEZIER_NUMBERS_PER_CHANNEL).enumerate() {
        let x = [t0, h[0], h[2], t1];
        let s = solve_bezier_parameter(x, t);
        let (xl, xr) = split_cubic(x, s);
        let y = if per_channel {
            [v0[c], h[1], h[3], v1[c]]
        } else {
            [0.0, h[1], h[3], 1.0]
        };
        let (yl, yr) = split_cubic(y, s);
        if per_channel {
            before.extend([inside(xl[1], t0, t), yl[1], inside(xl[2], t0, t), yl[2]]);
            after.extend([inside(xr[1], t, t1), yr[1], inside(xr[2], t, t1), yr[2]]);
            value.push(yl[3]);
            continue;
        }
        // One fraction curve: each part's fractions rescaled to run 0..1 over its own segment
        // (where the split point is at an end of the value range, that part does not move and
        // is linear).
        let fraction = yl[3];
        let scale = |y: f64, from: f64, span: f64| (y - from) / span;
        before = if fraction.abs() > f64::EPSILON {
            vec![
                inside(xl[1], t0, t),
                scale(yl[1], 0.0, fraction),
                inside(xl[2], t0, t),
                scale(yl[2], 0.0, fraction),
            ]
        } else {
            Vec::new()
        };
        after = if (1.0 - fraction).abs() > f64::EPSILON {
            vec![
                inside(xr[1], t, t1),
                scale(yr[1], fraction, 1.0 - fraction),
                inside(xr[2], t, t1),
                scale(yr[2], fraction, 1.0 - fraction),
            ]
        } else {
            Vec::new()
        };
        value = lerp(fraction);
    }
    let curve_of = |numbers: Vec<f64>| {
        if numbers.is_empty() {
            Curve::Linear
        } else {
            Curve::Bezier(numbers)
        }
    };
    SplitCurve {
        before: curve_of(before),
        after: curve_of(after),
        value,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn handles_at_thirds_are_a_cubic_in_time() {
        // x(s) = s exactly, so y is the cubic itself: y(0.25) = 3·0.75·0.0625 + 0.015625.
        let h = [1.0 / 3.0, 0.0, 2.0 / 3.0, 1.0];
        assert!((bezier_value(0.0, 0.0, &h, 1.0, 1.0, 0.25) - 0.15625).abs() < 1e-15);
        assert!((bezier_value(0.0, 0.0, &h, 1.0, 1.0, 0.5) - 0.5).abs() < 1e-15);
    }

    #[test]
    fn asymmetric_handles_hit_the_hand_computed_point() {
        // x(0.5) = 0.375·0.2 + 0.375·0.9 + 0.125·1 = 0.5375; y(0.5) = 0.375·3 − 0.375 + 0.125·2 = 1.
        let h = [0.2, 3.0, 0.9, -1.0];
        let v = bezier_value(0.0, 0.0, &h, 1.0, 2.0, 0.5375);
        assert!((v - 1.0).abs() < 1e-14, "{v}");
    }

    #[test]
    fn ease_in_out_halfway_is_the_middle_value() {
        // Both handles at mid-time: x(0.5) = 0.375 + 0.375 + 0.25 = 1; y(0.5) = 3.75 + 1.25.
        let h = [1.0, 0.0, 1.0, 10.0];
        assert!((bezier_value(0.0, 0.0, &h, 2.0, 10.0, 1.0) - 5.0).abs() < 1e-13);
        // Eased: a quarter of the way in time is under half of a quarter of the way in value
        // (x(s) = 3s − 3s² + 2s³ = 0.5 at s ≈ 0.201964, y = 10·s²·(3 − 2s) ≈ 1.058925).
        let v = bezier_value(0.0, 0.0, &h, 2.0, 10.0, 0.5);
        assert!((v - 1.058925).abs() < 1e-6, "{v}");
    }

    #[test]
    fn solver_reaches_machine_precision_even_with_flat_ends() {
        // Handles on the keys' times: x'(0) = x'(1) = 0, where plain Newton stalls.
        for x in [
            [0.0, 0.0, 1.0, 1.0],
            [2.0, 2.9, 3.0, 3.0],
            [0.0, 0.5, 0.5, 1.0],
        ] {
            for k in 0..=1000 {
                let t = x[0] + (x[3] - x[0]) * (k as f64 / 1000.0);
                let s = solve_bezier_parameter(x, t);
                assert!((0.0..=1.0).contains(&s));
                let err = (cubic(x, s) - t).abs();
                assert!(
                    err <= 8.0 * f64::EPSILON * x[3].abs().max(1.0),
                    "{x:?} {t} {err}"
                );
            }
            // Near the flat ends too.
            for t in [x[0] + 1e-12, x[3] - 1e-12] {
                let s = solve_bezier_parameter(x, t);
                assert!((cubic(x, s) - t).abs() <= 8.0 * f64::EPSILON * x[3].abs().max(1.0));
            }
        }
    }

    #[test]
    fn spine_runtime_polyline_lies_on_the_curve_and_is_straight_between() {
        // The polyline's defining property: its points lie on the exact curve at s = 0.1 … 0.9
        // (forward differences accumulate only rounding). The end-to-end check against the
        // runtime itself is tests/spine_runtime.rs.
        let h = [0.3, -20.0, 0.5, 130.0];
        let points = spine_bezier_polyline(0.0, 0.0, h, 1.0, 90.0);
        for (k, p) in points.iter().enumerate() {
            let s = (k + 1) as f64 / 10.0;
            let x = cubic([0.0, 0.3, 0.5, 1.0], s);
            let y = cubic([0.0, -20.0, 130.0, 90.0], s);
            assert!(
                (p[0] - x).abs() < 1e-6 && (p[1] - y).abs() < 1e-4,
                "{k} {p:?} {x} {y}"
            );
        }
        // Between the points the runtime is linear, so it differs from the exact curve.
        let ends = (([0.0, 0.0], [1.0, 90.0]), ([0.0, 0.0], [1.0, 90.0]));
        let t = 0.55;
        let runtime = spine_runtime_bezier_value(ends.0, ends.1, &h, t);
        let exact = bezier_value(0.0, 0.0, &h, 1.0, 90.0, t);
        assert!((runtime - exact).abs() > 1e-3, "{runtime} {exact}");
        assert!((runtime - exact).abs() < 1.0, "{runtime} {exact}");
        // On a sample point it agrees with the exact curve up to f32 storage.
        let on = spine_runtime_bezier_value(ends.0, ends.1, &h, points[4][0]);
        assert!((on - points[4][1]).abs() < 1e-9);
        // Before the first point and after the last: straight to the keys.
        let first = spine_runtime_bezier_value(ends.0, ends.1, &h, points[0][0] / 2.0);
        assert!((first - points[0][1] / 2.0).abs() < 1e-9);
    }

    #[test]
    fn curve_json_forms() {
        let c: Curve = serde_json::from_str("\"stepped\"").unwrap();
        assert_eq!(c, Curve::Stepped);
        let c: Curve = serde_json::from_str("[0.1, 2, 0.3, 4]").unwrap();
        assert_eq!(c, Curve::Bezier(vec![0.1, 2.0, 0.3, 4.0]));
        let err = serde_json::from_str::<Curve>("\"smooth\"").unwrap_err();
        assert!(
            err.to_string().contains("unknown curve \"smooth\""),
            "{err}"
        );
        assert!(serde_json::from_str::<Curve>("3").is_err());
        assert_eq!(
            serde_json::to_string(&Curve::Stepped).unwrap(),
            "\"stepped\""
        );
    }

    #[test]
    fn splitting_a_bezier_leaves_the_motion_unchanged() {
        // Two channels, eased differently; split at a time inside.
        let (t0, t1, t) = (0.5, 2.0, 1.1);
        let (v0, v1) = ([0.0, 10.0], [90.0, -30.0]);
        let numbers = vec![1.2, -20.0, 1.3, 130.0, 0.6, 10.0, 1.9, -30.0];
        let split = split_curve(
            &Curve::Bezier(numbers.clone()),
            (t0, &v0),
            (t1, &v1),
            t,
            true,
        );
        let (Curve::Bezier(before), Curve::Bezier(after)) = (&split.before, &split.after) else {
            panic!("{split:?}");
        };
        for c in 0..2 {
            let h = &numbers[4 * c..4 * c + 4];
            let (hb, ha) = (&before[4 * c..4 * c + 4], &after[4 * c..4 * c + 4]);
            assert!(hb[0] >= t0 && hb[2] <= t && ha[0] >= t && ha[2] <= t1);
            let at_t = bezier_value(t0, v0[c], h, t1, v1[c], t);
            assert!((split.value[c] - at_t).abs() < 1e-9, "{c}");
            for k in 0..=200 {
                let time = t0 + (t1 - t0) * k as f64 / 200.0;
                let whole = bezier_value(t0, v0[c], h, t1, v1[c], time);
                let parts = if time <= t {
                    bezier_value(t0, v0[c], hb, t, split.value[c], time)
                } else {
                    bezier_value(t, split.value[c], ha, t1, v1[c], time)
                };
                assert!(
                    (whole - parts).abs() < 1e-9,
                    "{c} {time}: {whole} vs {parts}"
                );
            }
        }
        // Linear and stepped segments stay so; their value at t is theirs.
        let linear = split_curve(&Curve::Linear, (0.0, &[0.0]), (2.0, &[4.0]), 0.5, true);
        assert_eq!(
            (linear.before, linear.after),
            (Curve::Linear, Curve::Linear)
        );
        assert_eq!(linear.value, vec![1.0]);
        let stepped = split_curve(&Curve::Stepped, (0.0, &[3.0]), (2.0, &[4.0]), 0.5, true);
        assert_eq!(stepped.after, Curve::Stepped);
        assert_eq!(stepped.value, vec![3.0]);
    }

    #[test]
    fn splitting_a_fraction_curve_rescales_both_parts() {
        // One 0..1 curve for all numbers (a cage): each part runs 0..1 over its own segment.
        let h = vec![0.4, 0.0, 0.6, 1.0];
        let (v0, v1) = ([0.0, 0.0], [10.0, 20.0]);
        let split = split_curve(
            &Curve::Bezier(h.clone()),
            (0.0, &v0),
            (1.0, &v1),
            0.3,
            false,
        );
        let f = bezier_value(0.0, 0.0, &h, 1.0, 1.0, 0.3);
        assert!((split.value[0] - 10.0 * f).abs() < 1e-9);
        assert!((split.value[1] - 20.0 * f).abs() < 1e-9);
        let (Curve::Bezier(before), Curve::Bezier(after)) = (&split.before, &split.after) else {
            panic!("{split:?}");
        };
        for k in 0..=100 {
            let time = k as f64 / 100.0;
            let whole = bezier_value(0.0, 0.0, &h, 1.0, 1.0, time);
            let parts = if time <= 0.3 {
                f * bezier_value(0.0, 0.0, before, 0.3, 1.0, time)
            } else {
                f + (1.0 - f) * bezier_value(0.3, 0.0, after, 1.0, 1.0, time)
            };
            assert!((whole - parts).abs() < 1e-9, "{time}");
        }
    }
}
