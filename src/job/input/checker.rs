//! Reading the fields of an input: quantities with units, counts and lists, each checked
//! against its range, every bad field recorded with its path and its value as sent.

use std::cell::RefCell;
use std::collections::{HashMap, HashSet};
use std::rc::Rc;

use serde_json::{json, Value};

use super::units::{is_bare_number, parse_quantity, Dimension, UnitError};
use super::{Field, Quantity};
use crate::job::{echoed, FieldError, InputWarning, JobError, Validated};
use crate::model::{OptionError, Parameter, ParameterError, SolveOption};
use crate::render::format_number;

/// What a field holds, so that the model's own checks land on the field that was read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Source {
    Parameter(Parameter),
    Option(SolveOption),
}

/// Where a field was read: the object holding it, its name, and its item if it is a list.
/// Its path as text is built only for a report: building one for every field read was a
/// tenth of an uncached request's allocations (BENCHMARKS.md, issue 12).
#[derive(Clone, Debug)]
struct Location {
    object: Rc<str>,
    field: &'static str,
    item: Option<usize>,
}

impl Location {
    /// The field's path (`layer.thickness`, `radius[2]`).
    fn path(&self) -> String {
        let mut path = join(&self.object, self.field);
        if let Some(i) = self.item {
            path.push_str(&format!("[{i}]"));
        }
        path
    }
}

/// The path of `field` in the object at `object` (`""`: the object itself).
fn join(object: &str, field: &str) -> String {
    if object.is_empty() {
        field.to_string()
    } else if field.is_empty() {
        object.to_string()
    } else {
        format!("{object}.{field}")
    }
}

/// Collects the errors of one input while its fields are read.
#[derive(Debug, Default)]
pub struct Checker {
    /// Path of the object being read (`""` at the top, `layer`, `base.layer`...).
    prefix: Rc<str>,
    errors: Vec<FieldError>,
    /// The quantities read whose value as sent is not their SI number (text with units),
    /// by path.
    sent: HashMap<String, Value>,
    /// The paths of the fields reported (a field reported once is not reported again).
    reported: HashSet<String>,
    /// Where each model parameter and option was read (the first place).
    paths: Vec<(Source, Location)>,
    warnings: Vec<InputWarning>,
    /// Errors found past [`MAX_ERRORS`].
    omitted: usize,
}

/// Errors listed at most; the rest are counted.
const MAX_ERRORS: usize = 100;

thread_local! {
    /// The parameters the checkers of this thread read, while [`parameters_read`] asks.
    static READ: RefCell<Option<Vec<(String, Parameter)>>> = const { RefCell::new(None) };
}

/// The model parameter each quantity field is read as, by path (`layer.thickness`), by the
/// checkers that `read` runs to their end: so the OpenAPI description gives a field the
/// range of the code that reads it (each parameter at the first place it is read).
pub fn parameters_read(read: impl FnOnce()) -> Vec<(String, Parameter)> {
    READ.with(|recorded| recorded.replace(Some(Vec::new())));
    read();
    READ.with(|recorded| recorded.take()).unwrap_or_default()
}

impl Checker {
    pub fn new() -> Self {
        Checker::default()
    }

    /// The full path of `field` in the object being read (`""`: the object itself).
    pub fn path(&self, field: &str) -> String {
        join(&self.prefix, field)
    }

    /// Where `field` of the object being read is.
    fn at(&self, field: &'static str) -> Location {
        Location {
            object: self.prefix.clone(),
            field,
            item: None,
        }
    }

    /// Reads the object at `field` (absent: `None`) with `read`, its fields' paths under it.
    pub fn nested<'a, T: Default + Clone + 'a, R>(
        &mut self,
        field: Field<'a, T>,
        read: impl FnOnce(&mut Checker, &T) -> R,
    ) -> R {
        let inner = self.path(field.name).into();
        let outer = std::mem::replace(&mut self.prefix, inner);
        let object = field.value.cloned().unwrap_or_default();
        let result = read(self, &object);
        self.prefix = outer;
        result
    }

    /// [`Checker::nested`] for item `index` of the list `list` (its fields' paths under
    /// `list[index]`).
    pub fn item<T, R>(
        &mut self,
        list: &str,
        index: usize,
        item: &T,
        read: impl FnOnce(&mut Checker, &T) -> R,
    ) -> R {
        let inner = self.path(&format!("{list}[{index}]")).into();
        let outer = std::mem::replace(&mut self.prefix, inner);
        let result = read(self, item);
        self.prefix = outer;
        result
    }

    fn remember(&mut self, source: Source, at: &Location) {
        if !self.paths.iter().any(|(s, _)| *s == source) {
            self.paths.push((source, at.clone()));
        }
    }

    /// The SI value of the quantity `field`, the model's `parameter` (whose unit fixes the
    /// dimension); `default` if absent, NaN (with an error recorded) if unreadable.
    pub fn quantity(&mut self, field: Field<Quantity>, parameter: Parameter, default: f64) -> f64 {
        self.optional(field, parameter).unwrap_or(default)
    }

    /// [`Checker::quantity`] for a field that may be absent.
    pub fn optional(&mut self, field: Field<Quantity>, parameter: Parameter) -> Option<f64> {
        let at = self.at(field.name);
        self.remember(Source::Parameter(parameter), &at);
        Some(self.read(&at, field.value?, parameter))
    }

    /// [`Checker::optional`] for a field the object needs (`when`: "with asperities").
    pub fn required(&mut self, field: Field<Quantity>, parameter: Parameter, when: &str) -> f64 {
        self.optional(field, parameter).unwrap_or_else(|| {
            self.missing(field.name, &dimension(parameter).describe(), when);
            f64::NAN
        })
    }

    /// Records that `field` (in the object being read) is absent though needed (`when`:
    /// "with asperities", or "" if always): `asperities.density is required with asperities;
    /// expected a number per area (…)`.
    pub fn missing(&mut self, field: &str, allowed: &str, when: &str) {
        let path = self.path(field);
        let when = if when.is_empty() {
            String::new()
        } else {
            format!(" {when}")
        };
        let message = format!("{path} is required{when}; expected {allowed}");
        self.report(FieldError {
            field: path,
            value: Value::Null,
            allowed: allowed.to_string(),
            message,
        });
    }

    /// A count such as a number of nodes, the solver `option` (its range is the model's to
    /// check, see [`Checker::options`]).
    pub fn count(&mut self, field: Field<usize>, option: SolveOption) -> Option<usize> {
        self.remember(Source::Option(option), &self.at(field.name));
        field.value.copied()
    }

    /// A list of at most `max` values of `parameter`, each checked against its range;
    /// absent, the list of `base` alone. A longer list is refused without reading its values.
    pub fn list(
        &mut self,
        field: Field<Vec<Quantity>>,
        parameter: Parameter,
        base: f64,
        max: usize,
    ) -> Vec<f64> {
        let Some(values) = field.value else {
            return vec![base];
        };
        if values.is_empty() {
            self.invalid(field.name, json!([]), "a list of at least one value");
        }
        if values.len() > max {
            let allowed = format!("at most {max} values (a sweep's points at most)");
            self.invalid(field.name, json!(values.len()), &allowed);
            return Vec::new();
        }
        let list = self.at(field.name);
        values
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let at = Location {
                    item: Some(i),
                    ..list.clone()
                };
                let x = self.read(&at, q, parameter);
                if let Err(e) = parameter.check(x) {
                    self.out_of_range_at(at.path(), x, parameter.unit(), &e.allowed);
                }
                x
            })
            .collect()
    }

    /// Reads one quantity at `at`; a bare number, or a string holding one without a unit
    /// (`"50"`), far from the field's scale is read as sent (SI) with a warning.
    fn read(&mut self, at: &Location, quantity: &Quantity, parameter: Parameter) -> f64 {
        let (parsed, bare) = match quantity {
            Quantity::Number(x) => (Ok(*x), true),
            Quantity::Text(text) => (
                parse_quantity(text, dimension(parameter)),
                is_bare_number(text),
            ),
        };
        if let (true, Ok(x)) = (bare, &parsed) {
            if let Some(message) = implausible(parameter, *x) {
                let path = at.path();
                self.warnings.push(InputWarning {
                    message: format!("{path}: {message}"),
                    field: path,
                    value: quantity.sent(),
                });
            }
        }
        // -0 is 0: one value, one canonical form, one cache key.
        let read = parsed.map(super::si);
        // A report of a value out of range shows it as sent, or as its SI number when that
        // is how it was sent.
        let as_sent = match (quantity, &read) {
            (Quantity::Number(x), Ok(si)) => x.to_bits() == si.to_bits(),
            _ => false,
        };
        if !as_sent {
            self.sent.insert(at.path(), quantity.sent());
        }
        read.unwrap_or_else(|e| {
            self.unreadable(at.path(), quantity.sent(), dimension(parameter), &e);
            f64::NAN
        })
    }

    /// Warns of a bare number `x` (SI, as it has no unit) far from the scale of `parameter`,
    /// read from `cell` at `place` of `field` (in the object being read) — a field holding
    /// several values, such as a CSV's rows: `layer.prony_csv (row 3, E_j): 6 is 6 Pa; did you
    /// mean "6 GPa"?`. The same warning as a bare number sent in a field of its own.
    pub fn bare_cell(
        &mut self,
        field: &str,
        place: &str,
        cell: &str,
        parameter: Parameter,
        x: f64,
    ) {
        if let Some(message) = implausible(parameter, x) {
            let path = self.path(field);
            self.warnings.push(InputWarning {
                message: format!("{path} ({place}): {message}"),
                field: path,
                value: Value::from(echoed(cell)),
            });
        }
    }

    fn unreadable(&mut self, field: String, value: Value, expected: Dimension, e: &UnitError) {
        let allowed = expected.describe();
        let message = format!("{field}: {value} {e}; expected {allowed}");
        self.report(FieldError {
            field,
            value,
            allowed,
            message,
        });
    }

    /// Records an error; past [`MAX_ERRORS`] only counts it, so that the answer to a huge
    /// bad input stays small.
    fn report(&mut self, error: FieldError) {
        self.reported.insert(error.field.clone());
        if self.errors.len() < MAX_ERRORS {
            self.errors.push(error);
        } else {
            self.omitted += 1;
        }
    }

    /// Records a value of `field` (in the object being read) outside its range.
    pub fn out_of_range(&mut self, field: &str, value: f64, unit: &str, allowed: &str) {
        let path = self.path(field);
        self.out_of_range_at(path, value, unit, allowed);
    }

    /// Records a value outside its range, unless the field (or the object holding it) was
    /// already reported: a value read as NaN after an error says nothing new. Linear in the
    /// depth of the path, whatever the number of errors.
    fn out_of_range_at(&mut self, path: String, value: f64, unit: &str, allowed: &str) {
        let mut ancestors = path.match_indices('.').map(|(i, _)| &path[..i]);
        if self.reported.contains(&path) || ancestors.any(|a| self.reported.contains(a)) {
            return;
        }
        let sent = self
            .sent
            .get(&path)
            .cloned()
            .unwrap_or_else(|| Value::from(value));
        // The value as sent, so that the sender finds it: text as typed, a number exactly
        // (rounded, 0.09999 s would read as the 100 ms it must not be below).
        let shown = match &sent {
            Value::String(s) => format!("\"{s}\""),
            _ if unit.is_empty() => format_number(value),
            _ => format!("{} {unit}", format_number(value)),
        };
        let message = format!("{path} = {shown} is out of range; expected {allowed}");
        self.report(FieldError {
            field: path,
            value: sent,
            allowed: allowed.to_string(),
            message,
        });
    }

    /// The path a parameter or option was read at (its name if it was never read).
    fn path_of(&self, source: Source, name: impl FnOnce() -> String) -> String {
        self.paths
            .iter()
            .find(|(s, _)| *s == source)
            .map_or_else(name, |(_, at)| at.path())
    }

    /// Records the model's range violations, each at the field its parameter was read from.
    pub fn parameters(&mut self, errors: Vec<ParameterError>) {
        for e in errors {
            let path = self.path_of(Source::Parameter(e.parameter), || e.parameter.to_string());
            self.out_of_range_at(path, e.value, e.parameter.unit(), &e.allowed);
        }
    }

    /// Records the model's option violations, each at the field its option was read from.
    pub fn options(&mut self, errors: Vec<OptionError>) {
        for e in errors {
            let path = self.path_of(Source::Option(e.option), || e.option.to_string());
            self.out_of_range_at(path, e.value as f64, "", &e.allowed);
        }
    }

    /// Records an error of `field` that is not a range (e.g. an empty list): `vary.radius: []
    /// is not a valid value; expected a list of at least one value`. With `value` null there
    /// is nothing to echo, and `allowed` says it all (`checks[0].job: a valid job: …`).
    pub fn invalid(&mut self, field: &str, value: Value, allowed: &str) {
        let path = self.path(field);
        let message = match value {
            Value::Null => format!("{path}: {allowed}"),
            _ => format!("{path}: {value} is not a valid value; expected {allowed}"),
        };
        self.report(FieldError {
            field: path,
            value,
            allowed: allowed.to_string(),
            message,
        });
    }

    /// Hands the parameters read to [`parameters_read`], if it asks.
    fn record(&self) {
        READ.with(|recorded| {
            if let Some(recorded) = recorded.borrow_mut().as_mut() {
                recorded.extend(self.paths.iter().filter_map(|(source, at)| match source {
                    Source::Parameter(parameter) => Some((at.path(), *parameter)),
                    Source::Option(_) => None,
                }));
            }
        });
    }

    /// The recorded errors, as the job's error (the last one counting those not listed).
    pub fn into_error(mut self) -> JobError {
        self.record();
        if self.omitted > 0 {
            let n = self.omitted;
            self.errors.push(FieldError {
                field: String::new(),
                value: Value::from(n),
                allowed: String::new(),
                message: format!("and {n} more errors like these, not listed"),
            });
        }
        JobError::Invalid(self.errors)
    }

    /// The job read, with the input's warnings, if no field was bad; else every error.
    pub fn finish<T>(self, job: T) -> Result<Validated<T>, JobError> {
        if self.errors.is_empty() {
            self.record();
            Ok(Validated {
                job,
                warnings: self.warnings,
            })
        } else {
            Err(self.into_error())
        }
    }
}

/// What is implausible about a bare (unit-less, so SI) number for `parameter`, and the
/// form the sender may have meant (docs/model.md §7): a length above 1 mm, a load above 1 N, a
/// speed above 1 m/s, a modulus below 1 kPa or above 1 TPa, a time above 1e6 s.
fn implausible(parameter: Parameter, x: f64) -> Option<String> {
    use Parameter::*;
    let (limit_low, limit_high, meant) = match parameter {
        Radius | Thickness | MeanDiameter | StdDiameter | MinDiameter | MaxDiameter | TipRadius
        | HeightStd | Separation => (0.0, 1e-3, Some("nm")),
        Load | ParticleLoad => (0.0, 1.0, Some("nN")),
        Velocity => (0.0, 1.0, Some("nm/s")),
        ElasticModulus | UpperModulus | ParticleModulus | UpperHardness | UpperShearStrength
        | AsperityHardness | PronyModulus => (1e3, 1e12, None),
        RetardationTime | RelaxationTime | PronyTime => (0.0, 1e6, Some("ms")),
        PoissonRatio | UpperPoissonRatio | ParticlePoissonRatio | ArealDensity | NominalArea
        | AsperityDensity | TotalLoad | Kappa | Stiffness | FrictionCoefficient | ContactArea
        | Temperature | ReferenceTemperature | WlfC1 | WlfC2 | ModulusScale | ShiftFactor => {
            return None
        }
    };
    if !(x.is_finite() && x > 0.0) || (limit_low..=limit_high).contains(&x) {
        return None;
    }
    let number = format_number(x);
    let si = format!("{number} {}", parameter.unit());
    let suggestion = match meant {
        Some(unit) => Some(format!("\"{number} {unit}\"")),
        // A modulus too small for a solid was most likely meant in GPa; one above 1 TPa
        // (stiffer than diamond) has no likely reading.
        None if x < limit_low => Some(format!("\"{number} GPa\"")),
        None => None,
    };
    Some(match suggestion {
        Some(meant) => format!("{number} is {si}; did you mean {meant}?"),
        None => format!("{number} is {si}, above 1 TPa: stiffer than any solid"),
    })
}

/// The dimension of a parameter's values, read off its SI unit.
fn dimension(parameter: Parameter) -> Dimension {
    Dimension::of_unit(parameter.unit()).expect("the model's units are SI unit expressions")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bare_number_far_from_its_field_s_scale_is_named_with_what_was_meant() {
        assert_eq!(
            implausible(Parameter::Radius, 25.0).unwrap(),
            "25 is 25 m; did you mean \"25 nm\"?"
        );
        assert_eq!(
            implausible(Parameter::ElasticModulus, 3.0).unwrap(),
            "3 is 3 Pa; did you mean \"3 GPa\"?"
        );
        assert!(implausible(Parameter::ElasticModulus, 1e300)
            .unwrap()
            .contains("above 1 TPa"));
        assert!(implausible(Parameter::Load, 2.0)
            .unwrap()
            .contains("\"2 nN\""));
        assert!(implausible(Parameter::RelaxationTime, 2e6)
            .unwrap()
            .contains("ms"));
        for (parameter, x) in [
            (Parameter::Radius, 25e-9),
            (Parameter::Radius, -1.0),
            (Parameter::Velocity, 0.0),
            (Parameter::ElasticModulus, 3e9),
            (Parameter::PoissonRatio, 30.0),
            (Parameter::TotalLoad, 5.0),
        ] {
            assert_eq!(implausible(parameter, x), None, "{parameter} {x}");
        }
    }

    /// The warning of a bare number, for the same number sent as a string without a unit,
    /// at the top and in a nested object.
    #[test]
    fn a_string_without_a_unit_is_warned_like_the_bare_number() {
        let read = |value: Quantity| {
            let mut checker = Checker::new();
            let field = Field {
                name: "radius",
                value: Some(&value),
            };
            let x = checker.quantity(field, Parameter::Radius, 1e-8);
            let thickness = Field {
                name: "thickness",
                value: Some(&value),
            };
            let layer = Field {
                name: "layer",
                value: Some(&()),
            };
            checker.nested(layer, |c, _| {
                c.quantity(thickness, Parameter::Thickness, 1e-7)
            });
            let messages: Vec<String> = checker.warnings.into_iter().map(|w| w.message).collect();
            (x, messages)
        };
        let expected = [
            "radius: 50 is 50 m; did you mean \"50 nm\"?",
            "layer.thickness: 50 is 50 m; did you mean \"50 nm\"?",
        ];
        assert_eq!(
            read(Quantity::Number(50.0)),
            (50.0, expected.map(String::from).to_vec())
        );
        assert_eq!(
            read(Quantity::Text(" 50 ".into())),
            (50.0, expected.map(String::from).to_vec())
        );
        assert_eq!(read(Quantity::Text("50 m".into())), (50.0, Vec::new()));
    }

    /// Out-of-range values in a list, each reported at its path with its value as sent: as
    /// text, as a number, and -0 (which reads as 0).
    #[test]
    fn a_value_out_of_range_is_reported_at_its_path_as_sent() {
        let mut checker = Checker::new();
        let list = vec![
            Quantity::Text("-5 nm".into()),
            Quantity::Number(-2.0),
            Quantity::Number(-0.0),
            Quantity::Number(1e-8),
        ];
        let field = Field {
            name: "radius",
            value: Some(&list),
        };
        let read = checker.nested(
            Field {
                name: "base",
                value: Some(&()),
            },
            |checker, _| checker.list(field, Parameter::Radius, 1e-8, 10),
        );
        assert_eq!(read[..2], [-5e-9, -2.0]);
        let JobError::Invalid(errors) = checker.into_error() else {
            panic!("not invalid");
        };
        let reported: Vec<_> = errors
            .iter()
            .map(|e| (e.field.as_str(), e.value.to_string()))
            .collect();
        assert_eq!(
            reported,
            [
                ("base.radius[0]", "\"-5 nm\"".to_string()),
                ("base.radius[1]", "-2.0".to_string()),
                ("base.radius[2]", "-0.0".to_string()),
            ]
        );
        assert_eq!(
            errors[0].message,
            "base.radius[0] = \"-5 nm\" is out of range; expected finite and > 0 m"
        );
        assert_eq!(
            errors[1].message,
            "base.radius[1] = -2 m is out of range; expected finite and > 0 m"
        );
    }

    #[test]
    fn every_parameter_has_the_dimension_of_its_unit() {
        use Parameter::*;
        for (parameter, expected) in [
            (Radius, Dimension::LENGTH),
            (Load, Dimension::FORCE),
            (Velocity, Dimension::SPEED),
            (ElasticModulus, Dimension::PRESSURE),
            (PoissonRatio, Dimension::NONE),
            (RelaxationTime, Dimension::TIME),
            (ArealDensity, Dimension::PER_AREA),
            (NominalArea, Dimension::AREA),
            (AsperityDensity, Dimension::PER_AREA),
            (ParticleLoad, Dimension::FORCE),
        ] {
            assert_eq!(dimension(parameter), expected, "{parameter}");
        }
    }
}
