//! Numbers as text for people and for CSV.

use std::fmt::Write;

/// A number as text: plain between 1e-3 and 1e6, scientific elsewhere, always the shortest
/// text that reads back as the same double.
pub fn format_number(x: f64) -> String {
    let mut text = String::with_capacity(24);
    write_number(&mut text, x);
    text
}

/// [`format_number`] appended to `out`, laid out as `{}` and `{:e}` would, from the shortest
/// digits of `zmij` (Schubfach, ~20 ns a number where `ryu` took ~29): through `format!` a
/// number cost about 100 ns and an allocation, and a sweep's CSV is mostly numbers.
pub fn write_number(out: &mut String, x: f64) {
    if x == 0.0 || !x.is_finite() {
        // "0", "-0", "inf", "NaN": as `{}` writes them.
        let _ = write!(out, "{x}");
        return;
    }
    let mut shortest = zmij::Buffer::new();
    let magnitude = x.abs();
    // `zmij` writes plain decimals from 1e-5 to 1e16 ("1.0" for 1) and `{:e}`'s form
    // elsewhere, but with "e+" for a positive exponent: where that is also this layout, its
    // text is the answer as it stands.
    if (1e-3..1e6).contains(&magnitude) || magnitude < 1e-5 {
        let text = shortest.format_finite(x);
        out.push_str(text.strip_suffix(".0").unwrap_or(text));
        return;
    }
    if magnitude >= 1e16 {
        let text = shortest.format_finite(x);
        let (mantissa, exponent) = text
            .split_once("e+")
            .expect("zmij writes 1e16 up as d.ddde+N");
        let _ = write!(out, "{mantissa}e{exponent}");
        return;
    }
    // 1e-5 ≤ |x| < 1e-3 or 1e6 ≤ |x| < 1e16: `zmij`'s plain digits ("0.000123",
    // "1234567.0"), laid out as `{:e}`: x = d₀.d₁d₂… × 10^exponent.
    let text = shortest.format_finite(magnitude);
    let significant = text.trim_start_matches(['0', '.']);
    let leading = text[..text.len() - significant.len()].matches('0').count();
    let exponent = text.find('.').unwrap_or(text.len()) as i32 - 1 - leading as i32;
    let mut digits = significant
        .trim_end_matches(['0', '.'])
        .chars()
        .filter(|&c| c != '.');
    if x < 0.0 {
        out.push('-');
    }
    out.extend(digits.next());
    if let Some(second) = digits.next() {
        out.push('.');
        out.push(second);
        out.extend(digits);
    }
    // As `{:e}` writes it: no "+", no leading zeros.
    let _ = write!(out, "e{exponent}");
}

#[cfg(test)]
mod tests {
    use super::format_number;
    use proptest::prelude::*;

    #[test]
    fn plain_in_the_middle_scientific_at_the_ends_and_exact_everywhere() {
        for (x, text) in [
            (0.0, "0"),
            (-0.0, "-0"),
            (0.35, "0.35"),
            (1e-9, "1e-9"),
            (8.5234e-17, "8.5234e-17"),
            (3e9, "3e9"),
            (-4e-9, "-4e-9"),
            (100000.0, "100000"),
            (1e6, "1e6"),
            (0.001, "0.001"),
            (0.000999, "9.99e-4"),
            (123.45, "123.45"),
            (5e-324, "5e-324"),
            (f64::MAX, "1.7976931348623157e308"),
        ] {
            assert_eq!(format_number(x), text);
            assert_eq!(text.parse::<f64>().unwrap(), x);
        }
    }

    /// What `{}` and `{:e}` write, as the numbers were formatted before `ryu` and `zmij`.
    fn through_format(x: f64) -> String {
        if x == 0.0 || (1e-3..1e6).contains(&x.abs()) || !x.is_finite() {
            format!("{x}")
        } else {
            format!("{x:e}")
        }
    }

    /// `format_number` reads back as `x`, laid out as `format!` does; with 17 digits, `zmij` and
    /// `format!` may end in different digits, both reading back as `x` (1 in 20,000 doubles).
    fn check(x: f64) -> Result<(), TestCaseError> {
        let (ours, theirs) = (format_number(x), through_format(x));
        if !x.is_nan() {
            prop_assert_eq!(ours.parse::<f64>().unwrap(), x, "{}", ours);
        }
        prop_assert_eq!(ours.len(), theirs.len(), "{} vs {}", ours, theirs);
        let digits = |t: &str| t.bytes().filter(u8::is_ascii_digit).count();
        let differ = ours
            .bytes()
            .zip(theirs.bytes())
            .filter(|(a, b)| a != b)
            .count();
        prop_assert!(
            ours == theirs || (differ == 1 && digits(&ours) >= 17),
            "{} vs {}",
            ours,
            theirs
        );
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]
        /// Every double, by its bits.
        #[test]
        fn every_double_is_laid_out_as_format_lays_it_out(bits in any::<u64>()) {
            check(f64::from_bits(bits))?;
        }

        /// The same where answers live: 1e-20 to 1e12, both signs, few digits and many.
        #[test]
        fn answers_are_laid_out_as_format_lays_them_out(m in 1.0f64..10.0, e in -20i32..12, digits in 1u32..17) {
            let scale = 10f64.powi(digits as i32 - 1);
            let x = (m * scale).round() / scale * 10f64.powi(e);
            check(x)?;
            check(-x)?;
        }
    }
}
