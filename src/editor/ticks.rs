//! Axis ticks at "nice" numbers: multiples of 1, 2 or 5 × 10ᵏ (Heckbert, "Nice numbers for
//! graph labels", Graphics Gems 1990), as plots and graph editors label their axes.
//!
//! In: an interval `low..=high` (any unit) and the most ticks wanted. Out: the tick values
//! inside the interval, increasing, and the step between them.

/// The ticks of `low..=high` at the smallest nice step that cuts it into at most
/// `max_count` steps (so at most `max_count + 1` ticks): `(step, values)`. An empty or non-finite interval, or `max_count` 0, has none.
pub fn nice_ticks(low: f64, high: f64, max_count: usize) -> (f64, Vec<f64>) {
    let span = high - low;
    if max_count == 0 || !span.is_finite() || span <= 0.0 {
        return (0.0, Vec::new());
    }
    let raw = span / max_count as f64;
    let decade = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * decade);
    let first = (low / step).ceil() as i64;
    let last = (high / step).floor() as i64;
    let values = (first..=last)
        .map(|k| {
            let v = k as f64 * step;
            // −0 and 1e-17-sized leftovers print as 0.
            if v.abs() < step * 1e-9 {
                0.0
            } else {
                v
            }
        })
        .collect();
    (step, values)
}

/// A tick's label: as many decimals as the step needs, no more.
pub fn tick_label(value: f64, step: f64) -> String {
    let decimals = if step > 0.0 && step < 1.0 {
        (-step.log10()).ceil().clamp(0.0, 9.0) as usize
    } else {
        0
    };
    format!("{value:.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_are_one_two_or_five_times_a_power_of_ten() {
        assert_eq!(
            nice_ticks(0.0, 20.0, 5),
            (5.0, vec![0.0, 5.0, 10.0, 15.0, 20.0])
        );
        assert_eq!(nice_ticks(-1.3, 1.3, 6).1, vec![-1.0, -0.5, 0.0, 0.5, 1.0]);
        let (step, values) = nice_ticks(0.93, 1.07, 4);
        assert!((step - 0.05).abs() < 1e-12, "{step}");
        let expected = [0.95, 1.0, 1.05];
        assert_eq!(values.len(), 3);
        assert!(
            values
                .iter()
                .zip(expected)
                .all(|(v, e)| (v - e).abs() < 1e-12),
            "{values:?}"
        );
        let (step, values) = nice_ticks(0.0, 3.0, 8);
        assert_eq!(step, 0.5);
        assert_eq!(values.len(), 7);
    }

    #[test]
    fn never_more_than_asked_and_none_for_empty_intervals() {
        for (low, high) in [(0.0, 1.0), (-7.3, 112.0), (1e-6, 3e-6), (-360.0, 360.0)] {
            for count in 1..12 {
                let (step, values) = nice_ticks(low, high, count);
                assert!(
                    values.len() <= count + 1,
                    "{low}..{high} / {count}: {values:?}"
                );
                assert!(values
                    .iter()
                    .all(|v| *v >= low - 1e-12 && *v <= high + 1e-12));
                assert!(values
                    .windows(2)
                    .all(|w| (w[1] - w[0] - step).abs() < step * 1e-6));
            }
        }
        assert!(nice_ticks(1.0, 1.0, 5).1.is_empty());
        assert!(nice_ticks(0.0, f64::INFINITY, 5).1.is_empty());
        assert!(nice_ticks(0.0, 1.0, 0).1.is_empty());
    }

    #[test]
    fn labels_carry_the_decimals_the_step_needs() {
        assert_eq!(tick_label(15.0, 5.0), "15");
        assert_eq!(tick_label(0.5, 0.5), "0.5");
        assert_eq!(tick_label(0.95, 0.05), "0.95");
        let zero = nice_ticks(-0.3, 0.3, 3).1[1];
        assert_eq!(tick_label(zero, 0.2), "0.0");
    }
}
