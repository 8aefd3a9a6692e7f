//! Content negotiation (RFC 9110 §12.5.1): which of the media types an answer is offered in
//! the client's `Accept` prefers. One function for every route.

/// A media range of an `Accept` header, with its weight and how specific it is.
struct Range<'a> {
    kind: &'a str,
    subtype: &'a str,
    q: f32,
    /// Position in the header: on equal weight and specificity the client's first wins.
    position: usize,
}

impl Range<'_> {
    /// 2 for `type/subtype`, 1 for `type/*`, 0 for `*/*`; `None` if it does not match.
    fn specificity(&self, media_type: &str) -> Option<u8> {
        let (kind, subtype) = media_type.split_once('/')?;
        match (self.kind, self.subtype) {
            ("*", "*") => Some(0),
            (k, "*") if k.eq_ignore_ascii_case(kind) => Some(1),
            (k, s) if k.eq_ignore_ascii_case(kind) && s.eq_ignore_ascii_case(subtype) => Some(2),
            _ => None,
        }
    }
}

/// The index in `offered` (the server's order of preference) of the media type the client
/// prefers, given the values of its `Accept` headers; `None` when it accepts none of them
/// (the caller answers 406). No `Accept` (or no readable range in it) accepts anything.
///
/// Each offered type takes the weight of the most specific range that matches it; the
/// highest weight wins, then the more specific match, then the range the client listed
/// first, then the server's order.
pub fn negotiate<'a>(accept: impl IntoIterator<Item = &'a str>, offered: &[&str]) -> Option<usize> {
    let ranges: Vec<Range> = accept
        .into_iter()
        .flat_map(|value| value.split(','))
        .enumerate()
        .filter_map(|(position, range)| {
            let mut parts = range.split(';').map(str::trim);
            let (kind, subtype) = parts.next()?.split_once('/')?;
            let q = parts
                .filter_map(|p| p.split_once('='))
                .find(|(name, _)| name.trim().eq_ignore_ascii_case("q"))
                .map_or(Some(1.0), |(_, q)| q.trim().parse::<f32>().ok())?;
            let valid = !kind.is_empty() && !subtype.is_empty() && (0.0..=1.0).contains(&q);
            valid.then_some(Range {
                kind,
                subtype,
                q,
                position,
            })
        })
        .collect();
    if ranges.is_empty() {
        return (!offered.is_empty()).then_some(0);
    }
    offered
        .iter()
        .enumerate()
        .filter_map(|(index, media_type)| {
            let (specificity, range) = ranges
                .iter()
                .filter_map(|r| Some((r.specificity(media_type)?, r)))
                .max_by_key(|(specificity, r)| (*specificity, std::cmp::Reverse(r.position)))?;
            (range.q > 0.0).then_some((range.q, specificity, range.position, index))
        })
        .max_by(|a, b| {
            a.0.total_cmp(&b.0)
                .then(a.1.cmp(&b.1))
                .then(b.2.cmp(&a.2))
                .then(b.3.cmp(&a.3))
        })
        .map(|(.., index)| index)
}

#[cfg(test)]
mod tests {
    use super::negotiate;

    const OFFERED: [&str; 3] = ["application/json", "text/csv", "image/svg+xml"];

    #[test]
    fn the_clients_preference_wins_and_the_servers_order_breaks_ties_or_nothing_is_chosen() {
        for (accept, chosen) in [
            ("text/csv", Some("text/csv")),
            ("text/csv, application/json;q=0.5", Some("text/csv")),
            ("application/json, text/csv;q=0.5", Some("application/json")),
            ("application/json", Some("application/json")),
            ("*/*", Some("application/json")),
            ("", Some("application/json")),
            ("text/*", Some("text/csv")),
            ("image/svg+xml", Some("image/svg+xml")),
            ("TEXT/CSV", Some("text/csv")),
            ("text/csv, application/json", Some("text/csv")),
            // A browser's navigation: everything through */*, so the server's first.
            (
                "text/html,application/xhtml+xml,application/xml;q=0.9,*/*;q=0.8",
                Some("application/json"),
            ),
            // The specific range decides even when a wildcard weighs more.
            ("*/*;q=1, text/csv;q=0.1", Some("application/json")),
            ("*/*;q=0.1, application/json;q=0", Some("text/csv")),
            // Nothing acceptable.
            ("text/csv;q=0", None),
            ("image/png", None),
            ("text/html", None),
            ("application/*;q=0, text/plain", None),
        ] {
            let choice = negotiate([accept], &OFFERED).map(|i| OFFERED[i]);
            assert_eq!(choice, chosen, "{accept}");
        }
        assert_eq!(negotiate(["*/*"], &[]), None);
        // Several header lines are one list.
        let chosen = negotiate(["application/json;q=0.2", "text/csv"], &OFFERED);
        assert_eq!(chosen, Some(1));
    }
}
