//! Physical quantities as people type them: SI numbers (`2.5e-8`), or strings with a unit
//! (`"25 nm"`, `"1.2 nN"`, `"4 nm/s"`, `"3 GPa"`, `"100 ms"`, `"1 mm^2"`, `"1e12 m^-2"`).
//!
//! A unit is a product of SI symbols (m, g, s, N, Pa), each with an optional SI prefix and an
//! integer power (`^2`, `²`, `^-1`, `⁻²`), joined by `/`, `*`, `·` or spaces; `1/m^2` works.
//! The parser tracks dimensions, so `"radius": "3 GPa"` is refused as a pressure.
//! Temperatures are in K, or in °C (`"40 °C"`, also `℃` and `degC`), which is shifted by
//! 273.15 K: the fields that take a temperature are absolute ones.

use std::fmt;

/// Powers of (metre, kilogram, second, kelvin).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dimension([i8; 4]);

impl Dimension {
    pub const NONE: Dimension = Dimension([0, 0, 0, 0]);
    pub const LENGTH: Dimension = Dimension([1, 0, 0, 0]);
    pub const AREA: Dimension = Dimension([2, 0, 0, 0]);
    pub const PER_AREA: Dimension = Dimension([-2, 0, 0, 0]);
    pub const TIME: Dimension = Dimension([0, 0, 1, 0]);
    pub const SPEED: Dimension = Dimension([1, 0, -1, 0]);
    pub const FORCE: Dimension = Dimension([1, 1, -2, 0]);
    pub const PRESSURE: Dimension = Dimension([-1, 1, -2, 0]);
    pub const TEMPERATURE: Dimension = Dimension([0, 0, 0, 1]);
    pub const MASS: Dimension = Dimension([0, 1, 0, 0]);

    /// The named dimensions, with their SI unit and an example as people type it.
    const NAMED: [(Dimension, &'static str, &'static str, &'static str); 10] = [
        (Dimension::NONE, "a plain number", "", "0.35"),
        (Dimension::LENGTH, "a length", "m", "25 nm"),
        (Dimension::AREA, "an area", "m²", "1 mm^2"),
        (Dimension::PER_AREA, "a number per area", "m⁻²", "1e12 m^-2"),
        (Dimension::TIME, "a time", "s", "100 ms"),
        (Dimension::SPEED, "a speed", "m/s", "4 nm/s"),
        (Dimension::FORCE, "a force", "N", "1.2 nN"),
        (Dimension::PRESSURE, "a pressure", "Pa", "3 GPa"),
        (Dimension::TEMPERATURE, "a temperature", "K", "25 °C"),
        (Dimension::MASS, "a mass", "kg", "2 mg"),
    ];

    fn named(self) -> Option<(&'static str, &'static str, &'static str)> {
        Self::NAMED
            .iter()
            .find(|(d, ..)| *d == self)
            .map(|(_, name, unit, example)| (*name, *unit, *example))
    }

    /// The SI unit symbol ("" for plain numbers).
    pub fn si_unit(self) -> String {
        match self.named() {
            Some((_, unit, _)) => unit.to_string(),
            None => self.to_string(),
        }
    }

    /// What a value of this dimension looks like, for error messages.
    pub fn describe(self) -> String {
        match self.named() {
            Some((name, "", _)) => name.to_string(),
            Some((name, unit, example)) => {
                format!("{name} (a number in {unit}, or a string such as \"{example}\")")
            }
            None => format!("a quantity in {self}"),
        }
    }

    /// The dimension of an SI unit expression such as `m/s` or `m^-2` (`""` for a plain
    /// number).
    pub fn of_unit(unit: &str) -> Option<Dimension> {
        if unit.is_empty() {
            return Some(Dimension::NONE);
        }
        parse_unit(unit).ok().map(|(_, dimension)| dimension)
    }

    /// `self · other^power`, if every base power stays within ±[`MAX_DIMENSION`].
    fn add(self, other: Dimension, power: i8) -> Option<Dimension> {
        let mut d = self.0;
        for (d, o) in d.iter_mut().zip(other.0) {
            *d = o
                .checked_mul(power)
                .and_then(|p| d.checked_add(p))
                .filter(|p| p.abs() <= MAX_DIMENSION)?;
        }
        Some(Dimension(d))
    }
}

impl fmt::Display for Dimension {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some((name, _, _)) = self.named() {
            return f.write_str(name);
        }
        let parts: Vec<String> = ["m", "kg", "s", "K"]
            .iter()
            .zip(self.0)
            .filter(|(_, p)| *p != 0)
            .map(|(s, p)| {
                if p == 1 {
                    s.to_string()
                } else {
                    format!("{s}^{p}")
                }
            })
            .collect();
        f.write_str(&parts.join("·"))
    }
}

/// Why a quantity string could not be read.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum UnitError {
    /// No number at the start.
    #[error("does not start with a number")]
    NoNumber,
    /// A unit symbol that is not an SI symbol with an SI prefix.
    #[error(
        "has an unknown unit \"{0}\" ({hint}SI symbols m, g, s, N, Pa, K with SI prefixes, or °C)",
        hint = respelled(.0).map_or(String::new(), |unit| format!("did you mean \"{unit}\"? "))
    )]
    UnknownUnit(String),
    /// A unit power out of range (`m^127`).
    #[error(
        "has a unit power out of range in \"{0}\" (allowed: −{max} to {max} per symbol, at \
         most {all} in all)",
        max = MAX_POWER,
        all = MAX_DIMENSION
    )]
    Power(String),
    /// A valid unit of another dimension than the field's.
    #[error("is {found}")]
    WrongDimension {
        found: Dimension,
        expected: Dimension,
    },
    /// A mass where a force is expected (a load typed in kg, as on a balance).
    #[error("is a mass, not a force: it weighs {} under standard gravity", crate::model::text::quantity(*.weight, "N"))]
    MassForForce {
        /// Its weight (N).
        weight: f64,
    },
}

/// Largest power of one symbol in a unit (`m^4`): beyond it a unit is a typo, not a unit.
const MAX_POWER: i8 = 4;
/// Largest power of a base unit (m, kg, s) in a whole unit expression.
const MAX_DIMENSION: i8 = 8;

/// SI prefixes as powers of ten; both micro signs and `u` are accepted.
const PREFIXES: [(&str, i32); 22] = [
    ("Y", 24),
    ("Z", 21),
    ("E", 18),
    ("P", 15),
    ("T", 12),
    ("G", 9),
    ("M", 6),
    ("k", 3),
    ("h", 2),
    ("da", 1),
    ("", 0),
    ("d", -1),
    ("c", -2),
    ("m", -3),
    ("u", -6),
    ("µ", -6),
    ("μ", -6),
    ("n", -9),
    ("p", -12),
    ("f", -15),
    ("a", -18),
    ("z", -21),
];

/// SI symbols with the power of ten to SI base units and their dimension.
const SYMBOLS: [(&str, i32, Dimension); 6] = [
    ("Pa", 0, Dimension::PRESSURE),
    ("N", 0, Dimension::FORCE),
    ("m", 0, Dimension::LENGTH),
    ("g", -3, Dimension::MASS),
    ("s", 0, Dimension::TIME),
    ("K", 0, Dimension::TEMPERATURE),
];

/// The spellings of degrees Celsius, a temperature 273.15 K above its number.
const CELSIUS: [&str; 3] = ["°C", "℃", "degC"];
/// 0 °C in K.
const CELSIUS_ZERO: f64 = 273.15;

/// Reads `text` as a quantity of dimension `expected` and returns its value in SI units;
/// a number without a unit is taken as SI.
///
/// Every unit is a power of ten of SI, so the decimal exponent is shifted before the number
/// is rounded once: `"100 nm"` gives exactly the double nearest 1e-7, as `1e-7` does, and
/// both have one canonical form.
pub fn parse_quantity(text: &str, expected: Dimension) -> Result<f64, UnitError> {
    let text = text.trim();
    let split = number_length(text);
    if split == 0 {
        return Err(UnitError::NoNumber);
    }
    let number = &text[..split];
    let (mantissa, exponent) = match number.find(['e', 'E']) {
        Some(i) => (
            &number[..i],
            number[i + 1..]
                .parse::<i32>()
                .map_err(|_| UnitError::NoNumber)?,
        ),
        None => (number, 0),
    };
    let unit = text[split..].trim();
    if CELSIUS.contains(&unit) {
        if expected != Dimension::TEMPERATURE {
            return Err(UnitError::WrongDimension {
                found: Dimension::TEMPERATURE,
                expected,
            });
        }
        let celsius: f64 = number.parse().map_err(|_| UnitError::NoNumber)?;
        return Ok(celsius + CELSIUS_ZERO);
    }
    // A bare number in a string is SI, as a JSON number is.
    let (power, found) = if unit.is_empty() {
        (0, expected)
    } else {
        parse_unit(unit)?
    };
    let value: f64 = format!("{mantissa}e{}", exponent.saturating_add(power))
        .parse()
        .map_err(|_| UnitError::NoNumber)?;
    match (found, expected) {
        _ if found == expected => Ok(value),
        (Dimension::MASS, Dimension::FORCE) => Err(UnitError::MassForForce {
            weight: value * STANDARD_GRAVITY,
        }),
        _ => Err(UnitError::WrongDimension { found, expected }),
    }
}

/// g₀ (m/s²), by definition (CGPM 1901): what a mass given for a load weighs.
const STANDARD_GRAVITY: f64 = 9.806_65;

/// Whether `text` is a number in degrees Celsius (`"25 °C"`).
pub fn names_celsius(text: &str) -> bool {
    let text = text.trim();
    CELSIUS.contains(&text[number_length(text)..].trim())
}

/// Whether `text` is a number without a unit (`"50"`, `" 2.5e-8 "`): SI, as a JSON number
/// is, and so as implausible as one far from its field's scale (docs/model.md §7).
pub fn is_bare_number(text: &str) -> bool {
    let text = text.trim();
    let length = number_length(text);
    length > 0 && length == text.len()
}

/// Length of the leading decimal number (sign, digits, point, exponent) of `text`.
fn number_length(text: &str) -> usize {
    let bytes = text.as_bytes();
    let digits = |mut i: usize| {
        while i < bytes.len() && bytes[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    let mut i = usize::from(matches!(bytes.first(), Some(b'+' | b'-')));
    let start = i;
    i = digits(i);
    if bytes.get(i) == Some(&b'.') {
        i = digits(i + 1);
    }
    if i == start || (i == start + 1 && bytes[start] == b'.') {
        return 0;
    }
    if matches!(bytes.get(i), Some(b'e' | b'E')) {
        let mut j = i + 1;
        if matches!(bytes.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        let end = digits(j);
        if end > j {
            i = end;
        }
    }
    i
}

/// Power of ten to SI and dimension of a unit expression ("" is a plain number).
fn parse_unit(unit: &str) -> Result<(i32, Dimension), UnitError> {
    let unknown = || UnitError::UnknownUnit(unit.to_string());
    let (mut ten_power, mut dimension) = (0, Dimension::NONE);
    let mut sign = 1;
    let mut token = String::new();
    let mut terms: Vec<(String, i8)> = Vec::new();
    for c in unit.chars().chain(std::iter::once(' ')) {
        match c {
            '/' | '*' | '·' | ' ' => {
                if !token.is_empty() {
                    terms.push((std::mem::take(&mut token), sign));
                }
                if c == '/' {
                    sign = -1;
                }
            }
            _ => token.push(c),
        }
    }
    for (i, (term, sign)) in terms.iter().enumerate() {
        if i == 0 && term == "1" && *sign == 1 {
            continue; // "1/m^2"
        }
        let (symbol, power) = split_power(term).ok_or_else(unknown)?;
        let (scale, dim) = parse_symbol(symbol).ok_or_else(unknown)?;
        let out_of_range = || UnitError::Power(unit.to_string());
        let power = i8::try_from(power)
            .ok()
            .filter(|p| p.abs() <= MAX_POWER)
            .ok_or_else(out_of_range)?
            * sign;
        ten_power += scale * i32::from(power);
        dimension = dimension.add(dim, power).ok_or_else(out_of_range)?;
    }
    Ok((ten_power, dimension))
}

/// `unit` with each unknown symbol replaced by the known one spelled alike but for case
/// (`Gpa` → `GPa`, `NM` → `nm`... the one with most letters in the case typed), if that makes
/// a unit.
fn respelled(unit: &str) -> Option<String> {
    let mut out = String::new();
    for piece in unit.split_inclusive(['/', '*', '·', ' ']) {
        let term = piece.trim_end_matches(['/', '*', '·', ' ']);
        let (symbol, _) = split_power(term)?;
        let known = match parse_symbol(symbol) {
            Some(_) => symbol.to_string(),
            None => PREFIXES
                .iter()
                .flat_map(|(p, _)| SYMBOLS.iter().map(move |(s, ..)| format!("{p}{s}")))
                .filter(|k| k.to_lowercase() == symbol.to_lowercase())
                .max_by_key(|k| {
                    k.chars()
                        .zip(symbol.chars())
                        .filter(|(a, b)| a == b)
                        .count()
                })?,
        };
        out.push_str(&known);
        out.push_str(&piece[symbol.len()..]);
    }
    (out != unit && parse_unit(&out).is_ok()).then_some(out)
}

/// Splits "mm^2", "m²", "m^-2", "m⁻²" into the symbol and its power.
fn split_power(term: &str) -> Option<(&str, i64)> {
    if let Some((symbol, power)) = term.split_once('^') {
        return Some((symbol, power.parse().ok()?));
    }
    let superscripts = ['⁻', '¹', '²', '³', '⁴'];
    let start = term
        .char_indices()
        .find(|(_, c)| superscripts.contains(c))
        .map_or(term.len(), |(i, _)| i);
    let (symbol, sup) = term.split_at(start);
    if sup.is_empty() {
        return Some((symbol, 1));
    }
    let (negative, digits) = match sup.strip_prefix('⁻') {
        Some(rest) => (true, rest),
        None => (false, sup),
    };
    let power = match digits {
        "¹" => 1,
        "²" => 2,
        "³" => 3,
        "⁴" => 4,
        _ => return None,
    };
    Some((symbol, if negative { -power } else { power }))
}

/// A prefixed SI symbol such as "nm", "GPa", "ms", "µm": its power of ten and dimension.
fn parse_symbol(term: &str) -> Option<(i32, Dimension)> {
    SYMBOLS.iter().find_map(|(symbol, scale, dim)| {
        let prefix = term.strip_suffix(symbol)?;
        let (_, prefix_scale) = PREFIXES.iter().find(|(p, _)| *p == prefix)?;
        Some((prefix_scale + scale, *dim))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_units_people_type() {
        let cases = [
            ("25 nm", Dimension::LENGTH, 25e-9),
            ("25nm", Dimension::LENGTH, 25e-9),
            ("1.2 nN", Dimension::FORCE, 1.2e-9),
            ("4 nm/s", Dimension::SPEED, 4e-9),
            ("4 µm/s", Dimension::SPEED, 4e-6),
            ("4 um/s", Dimension::SPEED, 4e-6),
            ("3 GPa", Dimension::PRESSURE, 3e9),
            ("100 ms", Dimension::TIME, 0.1),
            ("0.5 s", Dimension::TIME, 0.5),
            ("1 mm^2", Dimension::AREA, 1e-6),
            ("1 mm²", Dimension::AREA, 1e-6),
            ("1e12 m^-2", Dimension::PER_AREA, 1e12),
            ("1e12 /m^2", Dimension::PER_AREA, 1e12),
            ("1e12 1/m²", Dimension::PER_AREA, 1e12),
            ("1e12 m⁻²", Dimension::PER_AREA, 1e12),
            ("2.5e-8 m", Dimension::LENGTH, 2.5e-8),
            ("2.5E-8", Dimension::LENGTH, 2.5e-8),
            ("100 nm", Dimension::LENGTH, 1e-7),
            ("0.1 s", Dimension::TIME, 0.1),
            ("1e3 mm", Dimension::LENGTH, 1.0),
            ("210 kN/mm^2", Dimension::PRESSURE, 210e9),
            ("0.35", Dimension::NONE, 0.35),
            (" -4 nm/s ", Dimension::SPEED, -4e-9),
            ("300 K", Dimension::TEMPERATURE, 300.0),
            ("25 °C", Dimension::TEMPERATURE, 298.15),
            ("-10℃", Dimension::TEMPERATURE, 263.15),
            ("40 degC", Dimension::TEMPERATURE, 313.15),
        ];
        for (text, dim, expected) in cases {
            let got = parse_quantity(text, dim).unwrap_or_else(|e| panic!("{text}: {e}"));
            // Exactly the double nearest the decimal value: one canonical form per quantity.
            assert_eq!(got, expected, "{text}");
        }
    }

    #[test]
    fn a_number_without_a_unit_is_bare() {
        for text in ["50", " 2.5e-8 ", "-4", "1E3", ".5"] {
            assert!(is_bare_number(text), "{text}");
        }
        for text in ["50 nm", "50nm", "", "e3", "1e3 m", "twenty"] {
            assert!(!is_bare_number(text), "{text}");
        }
    }

    #[test]
    fn refuses_a_wrong_dimension_and_says_what_it_is() {
        let err = parse_quantity("3 GPa", Dimension::LENGTH).unwrap_err();
        assert_eq!(
            err,
            UnitError::WrongDimension {
                found: Dimension::PRESSURE,
                expected: Dimension::LENGTH
            }
        );
        assert_eq!(err.to_string(), "is a pressure");
        assert!(parse_quantity("25 nm", Dimension::SPEED).is_err());
        assert_eq!(
            parse_quantity("25 °C", Dimension::TIME),
            Err(UnitError::WrongDimension {
                found: Dimension::TEMPERATURE,
                expected: Dimension::TIME
            })
        );
    }

    #[test]
    fn a_mass_given_for_a_force_is_told_its_weight() {
        let err = parse_quantity("1 kg", Dimension::FORCE).unwrap_err();
        assert_eq!(
            err.to_string(),
            "is a mass, not a force: it weighs 9.81 N under standard gravity"
        );
        let err = parse_quantity("100 mg", Dimension::FORCE).unwrap_err();
        assert!(err
            .to_string()
            .ends_with("weighs 981 µN under standard gravity"));
        assert_eq!(
            parse_quantity("1 kg", Dimension::LENGTH)
                .unwrap_err()
                .to_string(),
            "is a mass"
        );
    }

    #[test]
    fn refuses_unknown_units_and_missing_numbers() {
        assert!(matches!(
            parse_quantity("25 furlongs", Dimension::LENGTH),
            Err(UnitError::UnknownUnit(_))
        ));
        assert!(matches!(
            parse_quantity("25 Nm", Dimension::LENGTH),
            Err(UnitError::UnknownUnit(_))
        ));
        // A symbol in the wrong case is told its spelling.
        for (typed, meant) in [("3 Gpa", "GPa"), ("4 NM/S", "nm/s"), ("2 mpa", "mPa")] {
            let err = parse_quantity(typed, Dimension::PRESSURE).unwrap_err();
            assert!(
                err.to_string()
                    .contains(&format!("did you mean \"{meant}\"?")),
                "{typed}: {err}"
            );
        }
        let err = parse_quantity("25 furlongs", Dimension::LENGTH).unwrap_err();
        assert!(!err.to_string().contains("did you mean"), "{err}");
        assert_eq!(
            parse_quantity("nm", Dimension::LENGTH),
            Err(UnitError::NoNumber)
        );
        assert_eq!(
            parse_quantity("", Dimension::LENGTH),
            Err(UnitError::NoNumber)
        );
        assert_eq!(
            parse_quantity(".", Dimension::LENGTH),
            Err(UnitError::NoNumber)
        );
    }

    #[test]
    fn si_unit_expressions_have_their_dimension() {
        for (unit, dimension) in [
            ("", Dimension::NONE),
            ("m", Dimension::LENGTH),
            ("m^2", Dimension::AREA),
            ("m^-2", Dimension::PER_AREA),
            ("s", Dimension::TIME),
            ("m/s", Dimension::SPEED),
            ("N", Dimension::FORCE),
            ("Pa", Dimension::PRESSURE),
        ] {
            assert_eq!(Dimension::of_unit(unit), Some(dimension), "{unit}");
        }
        assert_eq!(Dimension::of_unit("parsec"), None);
    }

    #[test]
    fn unit_powers_are_bounded_and_never_overflow() {
        for text in [
            "25 m^127 m^127 m^3",
            "25 m^5",
            "25 m^99999999999999999",
            "25 m^4 m^4 m^4",
            "25 m m m m m m m m m",
        ] {
            let err = parse_quantity(text, Dimension::LENGTH).unwrap_err();
            assert!(matches!(err, UnitError::Power(_)), "{text}: {err:?}");
            assert!(err.to_string().contains("out of range"), "{err}");
        }
        let many = format!("1 {}", "m/".repeat(100_000));
        assert!(parse_quantity(&many, Dimension::LENGTH).is_err());
        assert_eq!(parse_quantity("1 m^4/m^3", Dimension::LENGTH), Ok(1.0));
    }

    #[test]
    fn describes_dimensions_for_error_messages() {
        assert_eq!(
            Dimension::LENGTH.describe(),
            "a length (a number in m, or a string such as \"25 nm\")"
        );
        assert_eq!(Dimension([1, 1, 0, 0]).to_string(), "m·kg");
    }
}
