//! From one sample per frame to a few editable Bézier keys.
//!
//! In: sample times (seconds, strictly increasing) and values with `N` channels (degrees or
//! px), a tolerance in the values' units, and whether the samples are one loop of a cycle.
//! Out: [`Key`]s at a subset of the sample times whose curves pass within the tolerance of
//! every sample.
//!
//! Each kept sample gets a tangent from its neighbours (central differences; a cycle's two ends
//! share theirs, so the loop is smooth). The segment between two keys is the cubic Hermite of
//! their values and tangents, written as a Spine Bézier whose inner control points sit at a
//! third and two thirds of the segment's time (so time is linear in the curve's parameter and
//! the curve is that Hermite exactly). Keys are chosen greedily, Douglas–Peucker fashion:
//! first and last, then the worst-fitted sample of any segment out of tolerance, until none
//! is. A key's tangent does not depend on which other keys are kept, so adding one never
//! spoils a segment elsewhere.

use crate::anim::curve::Curve;
use crate::anim::timeline::Key;

/// The tangent (value units per second) of each sample; `cyclic`: the first and the last
/// sample are one pose, and share the tangent across the loop.
fn tangents<const N: usize>(times: &[f64], values: &[[f64; N]], cyclic: bool) -> Vec<[f64; N]> {
    let n = times.len();
    let slope = |a: usize, b: usize, dt: f64| -> [f64; N] {
        std::array::from_fn(|c| (values[b][c] - values[a][c]) / dt)
    };
    (0..n)
        .map(|i| {
            if n < 2 {
                [0.0; N]
            } else if i == 0 || i == n - 1 {
                if cyclic && n >= 3 {
                    // The sample before the last and the one after the first, across the seam.
                    let dt = (times[n - 1] - times[n - 2]) + (times[1] - times[0]);
                    let mut m = [0.0; N];
                    for (c, m) in m.iter_mut().enumerate() {
                        let before = values[n - 2][c] - (values[n - 1][c] - values[0][c]);
                        *m = (values[1][c] - before) / dt;
                    }
                    m
                } else if i == 0 {
                    slope(0, 1, times[1] - times[0])
                } else {
                    slope(n - 2, n - 1, times[n - 1] - times[n - 2])
                }
            } else {
                slope(i - 1, i + 1, times[i + 1] - times[i - 1])
            }
        })
        .collect()
}

/// The Hermite segment from key `a` to key `b` at time `t`, channel `c`.
fn hermite<const N: usize>(
    times: &[f64],
    values: &[[f64; N]],
    tangents: &[[f64; N]],
    (a, b): (usize, usize),
    t: f64,
    c: usize,
) -> f64 {
    let dt = times[b] - times[a];
    let s = (t - times[a]) / dt;
    let (s2, s3) = (s * s, s * s * s);
    (2.0 * s3 - 3.0 * s2 + 1.0) * values[a][c]
        + (s3 - 2.0 * s2 + s) * dt * tangents[a][c]
        + (-2.0 * s3 + 3.0 * s2) * values[b][c]
        + (s3 - s2) * dt * tangents[b][c]
}

/// Keys for the samples, within `tolerance` of every sample on every channel.
///
/// `times` and `values` have one entry per sample (at least one); times strictly increase.
pub fn reduce<const N: usize>(
    times: &[f64],
    values: &[[f64; N]],
    tolerance: f64,
    cyclic: bool,
) -> Vec<Key<[f64; N]>> {
    let n = times.len().min(values.len());
    if n == 0 {
        return Vec::new();
    }
    let m = tangents(&times[..n], &values[..n], cyclic);
    let mut kept = vec![false; n];
    kept[0] = true;
    kept[n - 1] = true;
    let mut stack = vec![(0, n - 1)];
    while let Some((a, b)) = stack.pop() {
        let worst = (a + 1..b)
            .map(|i| {
                let err = (0..N)
                    .map(|c| (hermite(times, values, &m, (a, b), times[i], c) - values[i][c]).abs())
                    .fold(0.0, f64::max);
                (err, i)
            })
            .max_by(|x, y| x.0.total_cmp(&y.0).then(y.1.cmp(&x.1)));
        if let Some((err, i)) = worst {
            if err > tolerance {
                kept[i] = true;
                stack.push((a, i));
                stack.push((i, b));
            }
        }
    }
    let keys: Vec<usize> = (0..n).filter(|&i| kept[i]).collect();
    keys.iter()
        .enumerate()
        .map(|(k, &i)| {
            let curve = match keys.get(k + 1) {
                Some(&j) => {
                    let dt = times[j] - times[i];
                    let mut numbers = Vec::with_capacity(4 * N);
                    for c in 0..N {
                        numbers.extend([
                            times[i] + dt / 3.0,
                            values[i][c] + m[i][c] * dt / 3.0,
                            times[j] - dt / 3.0,
                            values[j][c] - m[j][c] * dt / 3.0,
                        ]);
                    }
                    Curve::Bezier(numbers)
                }
                None => Curve::Linear,
            };
            Key {
                time: times[i],
                value: values[i],
                curve,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The value of `keys` at `t` through the animation model's own Bézier evaluation.
    fn play(keys: &[Key<[f64; 1]>], t: f64) -> f64 {
        let k = keys.iter().rposition(|k| k.time <= t).unwrap_or(0);
        let Some(next) = keys.get(k + 1) else {
            return keys[k].value[0];
        };
        let Curve::Bezier(handles) = &keys[k].curve else {
            panic!("a Bézier between keys")
        };
        crate::anim::curve::bezier_value(
            keys[k].time,
            keys[k].value[0],
            handles,
            next.time,
            next.value[0],
            t,
        )
    }

    #[test]
    fn a_sine_gets_few_keys_that_play_within_the_tolerance() {
        let times: Vec<f64> = (0..=120).map(|i| i as f64 / 60.0).collect();
        let values: Vec<[f64; 1]> = times
            .iter()
            .map(|t| [30.0 * (std::f64::consts::TAU * t / 2.0).sin()])
            .collect();
        let keys = reduce(&times, &values, 0.5, true);
        assert!(keys.len() <= 12, "{} keys for a sine", keys.len());
        for (t, v) in times.iter().zip(&values) {
            let got = play(&keys, *t);
            assert!(
                (got - v[0]).abs() <= 0.5 + 1e-9,
                "at {t}: {got} vs {}",
                v[0]
            );
        }
    }

    #[test]
    fn a_straight_line_is_two_keys_and_a_kink_is_kept() {
        let times: Vec<f64> = (0..10).map(f64::from).collect();
        let line: Vec<[f64; 2]> = times.iter().map(|t| [2.0 * t, -t]).collect();
        assert_eq!(reduce(&times, &line, 1e-9, false).len(), 2);
        let kink: Vec<[f64; 1]> = times.iter().map(|&t| [(t - 5.0).abs() * 10.0]).collect();
        let keys = reduce(&times, &kink, 0.1, false);
        assert!(keys.iter().any(|k| k.time == 5.0), "the kink is a key");
    }
}
