//! Numbers as messages show them to people: `0.5`, `-5`, `240` as written, and only magnitudes
//! of 10⁶ or more, or below 10⁻³, in exponent form (`1e300`, `2.5e-7`), so that a typo's
//! 300-digit number stays one short line and an ordinary one does not read `5e0`.

use std::fmt;

/// `f64` shown for a message (see the module doc). NaN and infinities as Rust writes them
/// (`NaN`, `inf`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shown(pub f64);

impl fmt::Display for Shown {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        if x.is_finite() && x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
            write!(f, "{x:e}")
        } else {
            write!(f, "{x}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Shown;

    #[test]
    fn ordinary_numbers_as_written_and_extreme_ones_short() {
        let shown = |x: f64| Shown(x).to_string();
        assert_eq!(shown(-5.0), "-5");
        assert_eq!(shown(0.0), "0");
        assert_eq!(shown(0.25), "0.25");
        assert_eq!(shown(240.0), "240");
        assert_eq!(shown(1e300), "1e300");
        assert_eq!(shown(-2.5e-7), "-2.5e-7");
        assert_eq!(shown(f64::NAN), "NaN");
        assert_eq!(shown(f64::INFINITY), "inf");
    }
}
