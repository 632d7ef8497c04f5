//! The one "did you mean" helper: the nearest of a list of names by edit distance.

/// The candidate nearest to `name` by Damerau-Levenshtein distance, if it is close enough
/// (at most half the candidate's length, counting short names as three characters).
pub fn nearest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    candidates
        .into_iter()
        .map(|c| (strsim::damerau_levenshtein(name, c), c))
        .filter(|(d, c)| *d <= (c.len().max(3) / 2))
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// The hint ` (did you mean `x`?)` for the candidate nearest to `name`, or an empty string.
pub fn did_you_mean<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
    nearest(name, candidates)
        .map(|n| format!(" (did you mean `{n}`?)"))
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hints_only_close_names() {
        let names = ["stiffness", "weights", "damping"];
        assert_eq!(
            did_you_mean("stifness", names),
            " (did you mean `stiffness`?)"
        );
        assert_eq!(did_you_mean("viscosity", names), "");
        assert_eq!(nearest("wieghts", names), Some("weights"));
    }
}
