//! "Did you mean": the closest of the names a file has to one the user gave that matches none,
//! and a list of names short enough for a one-line error.
//!
//! Errors keep the suggestion and the names as typed fields (`suggestion: Option<String>`,
//! `known: Vec<String>`) and format them in their `Display` with [`did_you_mean`] and
//! [`listed`].

/// How alike two names must be for one to be offered for the other, as a fraction
/// (numerator, denominator): their normalized Damerau–Levenshtein similarity, `1 − edits /
/// longer length` (an edit inserts, deletes or replaces a character, or swaps two neighbours),
/// compared without case, at least 3/5 (compared exactly, in integers). So a name of 3 or 4
/// characters may be one edit off (`arn` → `arm`, `wlak` → `walk`), one of 5 two (`arm` →
/// `arm_l`, `walkk` → `walk`), one of 10 four; `head` is not offered for `hand` (1/2), nor `walk`
/// for `moonwalk` (1/2).
pub const MIN_SIMILARITY: (usize, usize) = (3, 5);

/// At most this many names are listed in one message ([`listed`]); the rest are counted.
pub const MAX_LISTED: usize = 12;

/// The name of `candidates` most like `name` (see [`MIN_SIMILARITY`]), if one is alike enough;
/// of equally alike names, the first. Case is ignored in the comparison, so `Walk` finds
/// `walk`; `name` itself is returned when it is a candidate.
pub fn closest<I, S>(name: &str, candidates: I) -> Option<String>
where
    I: IntoIterator<Item = S>,
    S: AsRef<str>,
{
    let wanted = name.to_lowercase();
    let (num, den) = MIN_SIMILARITY;
    // The best so far: (edits, longer length, the name); a ratio edits / length lower is better.
    let mut best: Option<(usize, usize, String)> = None;
    for candidate in candidates {
        let candidate = candidate.as_ref();
        let lower = candidate.to_lowercase();
        let edits = strsim::damerau_levenshtein(&wanted, &lower);
        let len = wanted.chars().count().max(lower.chars().count());
        // 1 − edits/len ≥ num/den, in integers.
        let alike = (len - edits.min(len)) * den >= num * len;
        let better = best.as_ref().is_none_or(|(e, l, _)| edits * l < e * len);
        if alike && better {
            best = Some((edits, len, candidate.to_string()));
        }
    }
    best.map(|(_, _, found)| found)
}

/// `names` as owned strings, for an error's `known` field.
pub fn owned<I, S>(names: I) -> Vec<String>
where
    I: IntoIterator<Item = S>,
    S: AsRef<str>,
{
    names.into_iter().map(|n| n.as_ref().to_string()).collect()
}

/// `"; did you mean 'walk'?"` for a suggestion, nothing without one: what follows the "no such
/// name" part of a message.
pub fn did_you_mean(suggestion: &Option<String>) -> String {
    match suggestion {
        Some(name) => format!("; did you mean '{name}'?"),
        None => String::new(),
    }
}

/// The names comma-separated, `none` when there are none, and past [`MAX_LISTED`] the count of
/// the others (`a, b, …, l and 30 more`).
pub fn listed(names: &[String]) -> String {
    if names.is_empty() {
        return "none".to_string();
    }
    let shown = names[..names.len().min(MAX_LISTED)].join(", ");
    match names.len().saturating_sub(MAX_LISTED) {
        0 => shown,
        more => format!("{shown} and {more} more"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offers_the_closest_name_alike_enough() {
        let anims = ["hop", "lift", "walk", "wave"];
        assert_eq!(closest("walkk", anims).as_deref(), Some("walk"));
        assert_eq!(closest("wlak", anims).as_deref(), Some("walk"), "a swap");
        assert_eq!(closest("Walk", anims).as_deref(), Some("walk"), "case");
        assert_eq!(closest("walk", anims).as_deref(), Some("walk"), "itself");
        assert_eq!(closest("moonwalk", anims), None);
        assert_eq!(closest("nope", ["pail"]), None);
        assert_eq!(closest("head", ["hand"]), None);
        assert_eq!(
            closest("sholder", ["hip", "shoulder"]).as_deref(),
            Some("shoulder")
        );
        assert_eq!(closest("walk", Vec::<String>::new()), None);
        assert_eq!(closest("", ["a"]), None);
    }

    #[test]
    fn the_threshold_is_inclusive_and_ties_go_to_the_first() {
        // 3 characters, one replaced: similarity 2/3.
        assert_eq!(closest("arn", ["leg", "arm"]).as_deref(), Some("arm"));
        // "arm" → "arm_l" or "arm_r": two insertions in five, exactly 0.6; the first wins.
        assert_eq!(closest("arm", ["arm_r", "arm_l"]).as_deref(), Some("arm_r"));
        assert_eq!(closest("arm", ["arm_l", "arm_r"]).as_deref(), Some("arm_l"));
        // A closer one later in the list still wins.
        assert_eq!(closest("arm_", ["arm_l", "arm_"]).as_deref(), Some("arm_"));
        // Two edits in four: 0.5, below the threshold.
        assert_eq!(closest("ab", ["abcd"]), None);
    }

    #[test]
    fn lists_fit_on_a_line() {
        assert_eq!(listed(&[]), "none");
        assert_eq!(listed(&owned(["hop", "walk"])), "hop, walk");
        let many: Vec<String> = (0..40).map(|i| format!("s{i}")).collect();
        let line = listed(&many);
        assert!(line.starts_with("s0, s1, "), "{line}");
        assert!(line.ends_with("s11 and 28 more"), "{line}");
        assert_eq!(did_you_mean(&Some("walk".into())), "; did you mean 'walk'?");
        assert_eq!(did_you_mean(&None), "");
    }
}
