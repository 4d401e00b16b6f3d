//! "Did you mean ...?": the valid name closest to a misspelt one.

/// The candidate closest to `word`, if one is close enough to be what was meant: a few
/// edits away relative to its length (Damerau-Levenshtein, so swapped letters count once), or
/// sharing a long prefix (Jaro-Winkler, for truncated names such as `range` for `range_max`).
/// Case is ignored. Ties go to the earlier candidate, so the answer is deterministic.
pub(crate) fn closest<'a>(word: &str, candidates: &[&'a str]) -> Option<&'a str> {
    let word = word.to_lowercase();
    let mut best: Option<(f64, &'a str)> = None;
    for &candidate in candidates {
        let lowered = candidate.to_lowercase();
        let edits = strsim::normalized_damerau_levenshtein(&word, &lowered);
        let prefix = strsim::jaro_winkler(&word, &lowered);
        if edits < 0.6 && prefix < 0.85 {
            continue;
        }
        let score = edits.max(prefix);
        if best.is_none_or(|(best_score, _)| score > best_score) {
            best = Some((score, candidate));
        }
    }
    best.map(|(_, candidate)| candidate)
}

/// `` `a`, `b` or `c` `` for messages.
pub(crate) fn list(names: &[&str]) -> String {
    match names {
        [] => "nothing".to_owned(),
        [one] => format!("`{one}`"),
        [init @ .., last] => {
            let init: Vec<String> = init.iter().map(|name| format!("`{name}`")).collect();
            format!("{} or `{last}`", init.join(", "))
        }
    }
}

/// `a, b, c` for lists of kinds.
pub(crate) fn plain_list(names: &[&str]) -> String {
    names.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    const SENSOR_FIELDS: &[&str] = &[
        "width",
        "height",
        "hfov",
        "range_min",
        "range_max",
        "rate_hz",
        "mount",
        "ray_grid",
        "quality",
    ];

    #[test]
    fn typos_find_their_field() {
        assert_eq!(closest("rnage_max", SENSOR_FIELDS), Some("range_max"));
        assert_eq!(closest("range_mx", SENSOR_FIELDS), Some("range_max"));
        assert_eq!(closest("Rate_Hz", SENSOR_FIELDS), Some("rate_hz"));
        assert_eq!(closest("raygrid", SENSOR_FIELDS), Some("ray_grid"));
        assert_eq!(
            closest("kingfsher", &["kingfisher", "iris"]),
            Some("kingfisher")
        );
    }

    #[test]
    fn unrelated_words_get_no_suggestion() {
        assert_eq!(closest("colour", SENSOR_FIELDS), None);
        assert_eq!(closest("eaae", &["scripted"]), None);
        assert_eq!(closest("", SENSOR_FIELDS), None);
        assert_eq!(closest("x", &[]), None);
    }

    #[test]
    fn lists_read_as_english() {
        assert_eq!(list(&[]), "nothing");
        assert_eq!(list(&["a"]), "`a`");
        assert_eq!(list(&["a", "b", "c"]), "`a`, `b` or `c`");
        assert_eq!(plain_list(&["box", "sphere"]), "box, sphere");
    }
}
