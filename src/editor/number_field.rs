//! The editor's number fields: every drag-or-type number and every slider is made here, so
//! that none takes a non-finite number.
//!
//! egui parses typed text with Rust's `f64` parser, which reads "NaN", "inf" and "infinity" and
//! turns an overflow such as "1e999" into infinity; the field's range then clamps infinity (and
//! NaN, which sorts past it) to its end, or, without a range, stores it. Here such text is
//! refused like any other text that is not a number: the field keeps its old value. Drags and
//! ranges are as with egui's own widgets.
//!
//! In: the value edited (any of egui's numeric types), a slider's range. Out: the egui widget.

use eframe::egui;
use std::ops::RangeInclusive;

/// A field to drag or type `value` into, refusing non-finite typed numbers.
pub fn number_field<Num: egui::emath::Numeric>(value: &mut Num) -> egui::DragValue<'_> {
    egui::DragValue::new(value).custom_parser(parse_finite)
}

/// A slider over `range` with its number field, refusing non-finite typed numbers.
pub fn slider<Num: egui::emath::Numeric>(
    value: &mut Num,
    range: RangeInclusive<Num>,
) -> egui::Slider<'_> {
    egui::Slider::new(value, range).custom_parser(parse_finite)
}

/// egui's default parsing (whitespace ignored, "−" read as "-"), finite numbers only.
pub fn parse_finite(text: &str) -> Option<f64> {
    let text: String = text
        .chars()
        .filter(|c| !c.is_whitespace())
        .map(|c| if c == '−' { '-' } else { c })
        .collect();
    text.parse::<f64>().ok().filter(|x| x.is_finite())
}

#[cfg(test)]
mod tests {
    use super::parse_finite;

    #[test]
    fn finite_numbers_parse_as_egui_reads_them_and_the_rest_is_refused() {
        assert_eq!(parse_finite(" 1 000.5 "), Some(1000.5));
        assert_eq!(parse_finite("−2"), Some(-2.0));
        assert_eq!(parse_finite("1e3"), Some(1000.0));
        for bad in [
            "NaN", "nan", "inf", "-inf", "infinity", "1e999", "-1e999", "", "1.2.3",
        ] {
            assert_eq!(parse_finite(bad), None, "{bad}");
        }
    }
}
