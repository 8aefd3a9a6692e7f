//! Numbers as a person reads them: a quantity in the SI prefix that suits its size ("651 nm",
//! "5.52 N", "3 GPa", "0.2 µm²", "100 ms"), a count with its thousands grouped ("54,500
//! particles"). Every message of the model and of the layers above it (refusals, validity
//! notes, input errors, a picture's labels and axes) writes its numbers through here, so that
//! a number reads the same wherever it is shown, and never as `5.516918141089171e0 N`. Pure
//! string formatting: it lives in the model, the bottom layer, so that every layer can use it.
//!
//! A value echoed back from the input is the exception: it is written exactly as sent
//! (`render::format_number`), so that the sender finds it in what they sent.

use std::fmt::Write;

/// Significant digits of a number in a message: enough to compare values, few enough to
/// read at a glance.
pub const DIGITS: usize = 3;

/// SI prefixes a unit is shown with: powers of ten and symbols, largest first.
type Prefixes = &'static [(i32, &'static str)];

/// Prefixes of lengths, forces and speeds.
const SMALL: [(i32, &str); 6] = [
    (3, "k"),
    (0, ""),
    (-3, "m"),
    (-6, "µ"),
    (-9, "n"),
    (-12, "p"),
];
/// Prefixes of times (no kiloseconds: a person reads hours, and the model's times are short).
const TIME: [(i32, &str); 5] = [(0, ""), (-3, "m"), (-6, "µ"), (-9, "n"), (-12, "p")];
/// Prefixes of pressures (moduli, hardnesses).
const LARGE: [(i32, &str); 4] = [(9, "G"), (6, "M"), (3, "k"), (0, "")];

/// The symbol an SI unit is printed with, the power its prefix is raised to (2 for an area)
/// and its prefixes; `None` for a unit shown as it is, without prefix (`m^-2`, `Pa/m`, "").
fn family(unit: &str) -> Option<(&'static str, i32, Prefixes)> {
    Some(match unit {
        "m" => ("m", 1, &SMALL),
        "m^2" | "m²" => ("m²", 2, &SMALL),
        "m/s" => ("m/s", 1, &SMALL),
        "N" => ("N", 1, &SMALL),
        "s" => ("s", 1, &TIME),
        "Pa" => ("Pa", 1, &LARGE),
        _ => return None,
    })
}

/// The unit a person reads values of size `size` in, for the SI unit `unit`: the factor that
/// turns SI values into it, and its symbol (`("m", 2.5e-8)` gives `(1e9, "nm")`). The
/// largest prefix the value reaches one of; areas step by 10⁶ between prefixes, so one
/// reaching a hundredth of one is shown in it (0.2 µm² rather than 2e5 nm²). A unit without
/// prefixes (`m^-2`) comes back as it is, with the factor 1.
pub fn prefixed(unit: &str, size: f64) -> (f64, String) {
    match prefix(unit, size) {
        Some((factor, prefix, symbol)) => (factor, format!("{prefix}{symbol}")),
        None => (1.0, unit.to_string()),
    }
}

/// [`prefixed`] as the factor, the prefix and the unit's symbol; `None` for a unit without
/// prefixes.
fn prefix(unit: &str, size: f64) -> Option<(f64, &'static str, &'static str)> {
    let (symbol, power, prefixes) = family(unit)?;
    let size = size.abs();
    let least = if power == 2 { 1e-2 } else { 1.0 };
    let (exponent, prefix) = prefixes
        .iter()
        .find(|(exponent, _)| size >= least * 10f64.powi(exponent * power))
        .unwrap_or(&prefixes[prefixes.len() - 1]);
    Some((10f64.powi(-exponent * power), prefix, symbol))
}

/// `x`, a value in the SI unit `unit` (as the model names units: `m`, `N`, `Pa`, `s`, `m^2`,
/// `m/s`; `""` for a plain number), as a person reads it: in the prefix that suits it, to
/// [`DIGITS`] significant digits: "651 nm", "5.52 N", "10 N", "0.0947"; in powers of ten of
/// the unit itself when no prefix suits it ("6.79e-82 m", "1e12 m^-2").
pub fn quantity(x: f64, unit: &str) -> String {
    quantity_to(x, unit, DIGITS)
}

/// [`quantity`] to `digits` significant digits (a picture's legend tells close values apart
/// with four).
pub fn quantity_to(x: f64, unit: &str, digits: usize) -> String {
    // Written into one string: validity notes write several on every answer.
    let mut text = String::with_capacity(16);
    let base = family(unit).map_or(unit, |(symbol, ..)| symbol);
    if x == 0.0 || !x.is_finite() {
        // -0 reads as 0.
        let _ = write!(text, "{}", if x == 0.0 { 0.0 } else { x });
        return with_unit(text, "", base);
    }
    let (factor, prefix, symbol) = match prefix(unit, x) {
        Some((factor, prefix, symbol)) => (factor, prefix, symbol),
        None => (1.0, "", unit),
    };
    let scaled = x * factor;
    if (1e-2..1e4).contains(&scaled.abs()) {
        write_significant(&mut text, scaled, digits);
        with_unit(text, prefix, symbol)
    } else {
        text.push_str(&scientific(x, digits));
        with_unit(text, "", base)
    }
}

/// A number of things, `one` or `many` of them, as a person reads it: "1 particle",
/// "0.42 particles", "2 jobs". An exact count is written exactly, its thousands grouped
/// ("1,048,576 bytes"); a count that is an estimate (a mean number of particles) to
/// [`DIGITS`] significant digits ("54,500 particles"); beyond 10¹⁵ in powers of ten.
pub fn count(x: f64, one: &str, many: &str) -> String {
    let noun = if x == 1.0 { one } else { many };
    let number = if x.abs() >= 1e15 || !x.is_finite() {
        quantity(x, "")
    } else if x.fract() == 0.0 {
        grouped(x)
    } else {
        let step = 10f64.powi(magnitude(x) + 1 - DIGITS as i32);
        let rounded = (x / step).round() * step;
        if rounded.abs() >= 1e3 {
            grouped(rounded)
        } else {
            quantity(x, "")
        }
    };
    format!("{number} {noun}")
}

/// The decimal exponent of `x` (finite, not 0): 2 for 651.
fn magnitude(x: f64) -> i32 {
    x.abs().log10().floor() as i32
}

/// `x` (finite, not 0) to `digits` significant digits in plain decimals, without trailing
/// zeros, appended to `text`: 5.58, 651, 1230, 0.0947.
fn write_significant(text: &mut String, x: f64, digits: usize) {
    let decimals = digits as i32 - 1 - magnitude(x);
    if decimals <= 0 {
        let step = 10f64.powi(-decimals);
        let _ = write!(text, "{:.0}", (x / step).round() * step);
        return;
    }
    let start = text.len();
    let _ = write!(text, "{x:.prec$}", prec = decimals as usize);
    // Rounding may carry into a new digit (9.996 → "10.00"): the zeros go either way.
    let kept = text[start..]
        .trim_end_matches('0')
        .trim_end_matches('.')
        .len();
    text.truncate(start + kept);
}

/// `x` in powers of ten, to `digits` significant digits: 6.79e-82, 1e12, 5.5e-6.
fn scientific(x: f64, digits: usize) -> String {
    let text = format!("{x:.prec$e}", prec = digits.saturating_sub(1));
    let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
    let mantissa = if mantissa.contains('.') {
        mantissa.trim_end_matches('0').trim_end_matches('.')
    } else {
        mantissa
    };
    format!("{mantissa}e{exponent}")
}

/// An integer with its thousands grouped: 54,500.
fn grouped(x: f64) -> String {
    let digits = format!("{:.0}", x.abs());
    let mut text = String::new();
    for (i, digit) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            text.push(',');
        }
        text.push(digit);
    }
    if x < 0.0 {
        text.insert(0, '-');
    }
    text
}

/// `number` followed by its unit, `prefix` and `symbol`, if it has one.
fn with_unit(mut number: String, prefix: &str, symbol: &str) -> String {
    if !symbol.is_empty() {
        number.push(' ');
        number.push_str(prefix);
        number.push_str(symbol);
    }
    number
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths_read_as_people_write_them() {
        assert_eq!(quantity(651.47e-9, "m"), "651 nm");
        assert_eq!(quantity(5.5842e-9, "m"), "5.58 nm");
        assert_eq!(quantity(1e-7, "m"), "100 nm");
        assert_eq!(quantity(2.1e-6, "m"), "2.1 µm");
        assert_eq!(quantity(25.0, "m"), "25 m");
        assert_eq!(quantity(3e-13, "m"), "0.3 pm");
        assert_eq!(quantity(6.79e-82, "m"), "6.79e-82 m");
        assert_eq!(quantity(0.0, "m"), "0 m");
        assert_eq!(quantity(-0.0, "m"), "0 m");
        assert_eq!(quantity(-4e-9, "m/s"), "-4 nm/s");
    }

    #[test]
    fn every_unit_of_the_model_has_its_prefixes() {
        for (x, unit, text) in [
            (1e1, "N", "10 N"),
            (1e3, "N", "1 kN"),
            (2500.0, "m", "2.5 km"),
            (5.516918141089171, "N", "5.52 N"),
            (5.516918141089171e-6, "N", "5.52 µN"),
            (1.2e-9, "N", "1.2 nN"),
            (3e9, "Pa", "3 GPa"),
            (3e8, "Pa", "300 MPa"),
            (2e12, "Pa", "2000 GPa"),
            (5e13, "Pa", "5e13 Pa"),
            (0.1, "s", "100 ms"),
            (0.5, "s", "500 ms"),
            (2e6, "s", "2e6 s"),
            (4e-9, "m/s", "4 nm/s"),
            (8.5234e-17, "m^2", "85.2 nm²"),
            (2e-13, "m²", "0.2 µm²"),
            (1e-3, "m^2", "1000 mm²"),
            (1e12, "m^-2", "1e12 m^-2"),
            (0.0947, "", "0.0947"),
            (42.03, "", "42"),
            (3592.4, "", "3590"),
            (9.996, "", "10"),
            (0.001, "", "1e-3"),
            (f64::NAN, "m", "NaN m"),
        ] {
            assert_eq!(quantity(x, unit), text, "{x} {unit}");
        }
        assert_eq!(quantity_to(1.2345e-9, "N", 4), "1.234 nN");
    }

    #[test]
    fn the_unit_for_a_size_is_the_largest_prefix_it_reaches() {
        assert_eq!(prefixed("m", 2.5e-8), (1e9, "nm".to_string()));
        assert_eq!(prefixed("m^2", 8.5e-17), (1e18, "nm²".to_string()));
        assert_eq!(prefixed("N", 1e-9).1, "nN");
        assert_eq!(prefixed("m/s", 4e-9).1, "nm/s");
        assert_eq!(prefixed("Pa", 3e8).1, "MPa");
        assert_eq!(prefixed("s", 0.1).1, "ms");
        assert_eq!(prefixed("m^-2", 1e12), (1.0, "m^-2".to_string()));
        assert_eq!(prefixed("", 0.1), (1.0, String::new()));
    }

    #[test]
    fn counts_are_grouped_exact_when_exact_and_rounded_when_estimated() {
        assert_eq!(count(1.0, "particle", "particles"), "1 particle");
        assert_eq!(count(2.0, "job", "jobs"), "2 jobs");
        assert_eq!(count(0.0, "job", "jobs"), "0 jobs");
        assert_eq!(count(0.42, "particle", "particles"), "0.42 particles");
        assert_eq!(count(54_450.0, "particle", "particles"), "54,450 particles");
        assert_eq!(
            count(54_449.87, "particle", "particles"),
            "54,400 particles"
        );
        assert_eq!(count(54_450.2, "particle", "particles"), "54,500 particles");
        assert_eq!(count(1_048_576.0, "byte", "bytes"), "1,048,576 bytes");
        assert_eq!(count(999.6, "particle", "particles"), "1,000 particles");
        assert_eq!(count(1.5e15, "particle", "particles"), "1.5e15 particles");
    }
}
