//! Numbers as text for people and for CSV.

use std::fmt::Write;

/// A number as text: plain between 1e-3 and 1e6, scientific elsewhere, always the shortest
/// text that reads back as the same double.
pub fn format_number(x: f64) -> String {
    let mut text = String::with_capacity(24);
    write_number(&mut text, x);
    text
}

/// [`format_number`] appended to `out`, as `{}` writes a plain number and `{:e}` a
/// scientific one. The shortest round-trip digits come from `zmij` (Schubfach; serde_json's
/// formatter, ~20 ns a number where `ryu` took ~29), in its text where that is already this
/// layout (most numbers), else laid out here byte by byte: through `format!` a number cost
/// about 100 ns and an allocation, and a sweep's CSV is mostly numbers.
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
        out.push_str(mantissa);
        out.push('e');
        out.push_str(exponent);
        return;
    }
    // 1e-5 ≤ |x| < 1e-3 or 1e6 ≤ |x| < 1e16: `zmij`'s plain digits, laid out as `{:e}`.
    let (digits, exponent) = Digits::of(shortest.format_finite(magnitude).as_bytes());
    let digits = digits.as_slice();
    let mut laid = Text::default();
    if x < 0.0 {
        laid.push(b'-');
    }
    laid.push(digits[0]);
    if digits.len() > 1 {
        laid.push(b'.');
        laid.extend(&digits[1..]);
    }
    laid.exponent(exponent);
    out.push_str(laid.as_str());
}

/// A number's text while it is laid out.
struct Text {
    bytes: [u8; 40],
    len: usize,
}

impl Default for Text {
    fn default() -> Self {
        Text {
            bytes: [0; 40],
            len: 0,
        }
    }
}

impl Text {
    fn push(&mut self, b: u8) {
        self.bytes[self.len] = b;
        self.len += 1;
    }

    fn extend(&mut self, bytes: &[u8]) {
        self.bytes[self.len..self.len + bytes.len()].copy_from_slice(bytes);
        self.len += bytes.len();
    }

    /// "e" and the exponent, as `{:e}` writes it: no "+", no leading zeros.
    fn exponent(&mut self, exponent: i32) {
        self.push(b'e');
        if exponent < 0 {
            self.push(b'-');
        }
        let e = exponent.unsigned_abs();
        for (power, written) in [(100, e >= 100), (10, e >= 10), (1, true)] {
            if written {
                self.push(b'0' + (e / power % 10) as u8);
            }
        }
    }

    fn as_str(&self) -> &str {
        std::str::from_utf8(&self.bytes[..self.len]).expect("digits, signs and points are ASCII")
    }
}

/// The significant digits of a positive number (no leading or trailing zeros) and the
/// decimal exponent of the first: x = d₀.d₁d₂… × 10^exponent.
struct Digits {
    bytes: [u8; 24],
    len: usize,
}

impl Digits {
    /// From the plain text of a positive finite number: `123.45`, `0.00012`, `1234567.0`.
    fn of(text: &[u8]) -> (Digits, i32) {
        let whole = text.iter().position(|&b| b == b'.').unwrap_or(text.len());
        let mut digits = Digits {
            bytes: [0; 24],
            len: 0,
        };
        let mut leading = 0;
        for &b in text.iter().filter(|&&b| b != b'.') {
            if digits.len == 0 && b == b'0' {
                leading += 1;
            } else if digits.len < digits.bytes.len() {
                digits.bytes[digits.len] = b;
                digits.len += 1;
            }
        }
        while digits.len > 1 && digits.bytes[digits.len - 1] == b'0' {
            digits.len -= 1;
        }
        (digits, whole as i32 - 1 - leading)
    }

    fn as_slice(&self) -> &[u8] {
        &self.bytes[..self.len]
    }
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

    /// `format_number` reads back as `x`, is as short as `format!`'s text and laid out as it
    /// is. Where 17 digits are needed, `zmij` and the standard library may end in different
    /// digits, both reading back as `x` (1 in about 20,000 random doubles).
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
