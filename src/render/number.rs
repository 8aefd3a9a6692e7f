//! Numbers as text for people and for CSV.

/// A number as text: plain between 1e-3 and 1e6, scientific elsewhere, always the shortest
/// text that reads back as the same double.
pub fn format_number(x: f64) -> String {
    if x == 0.0 || (1e-3..1e6).contains(&x.abs()) || !x.is_finite() {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::format_number;

    #[test]
    fn plain_in_the_middle_scientific_at_the_ends_and_exact_everywhere() {
        for (x, text) in [
            (0.0, "0"),
            (0.35, "0.35"),
            (1e-9, "1e-9"),
            (8.5234e-17, "8.5234e-17"),
            (3e9, "3e9"),
            (-4e-9, "-4e-9"),
        ] {
            assert_eq!(format_number(x), text);
            assert_eq!(text.parse::<f64>().unwrap(), x);
        }
    }
}
