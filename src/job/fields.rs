//! Reading the fields of an input: shape errors with their path, quantities with units,
//! range errors with the value as sent. Every bad field is reported, not just the first.

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use utoipa::ToSchema;

use super::units::{parse_quantity, Dimension, UnitError};
use super::{FieldError, JobError};
use crate::model::{OptionError, Parameter, ParameterError, SolveOption};

/// A quantity as sent: an SI number, or a string with a unit such as `"25 nm"`, `"1.2 nN"`,
/// `"4 nm/s"`, `"3 GPa"` or `"100 ms"` (its dimension must be the field's).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(untagged)]
pub enum Quantity {
    Number(f64),
    Text(String),
}

impl Quantity {
    fn sent(&self) -> Value {
        match self {
            Quantity::Number(x) => Value::from(*x),
            Quantity::Text(s) => Value::from(s.as_str()),
        }
    }
}

/// The field of a model parameter in the rolling and three-body inputs.
pub fn parameter_field(parameter: Parameter) -> &'static str {
    use Parameter::*;
    match parameter {
        Radius => "radius",
        Load => "load",
        Velocity => "velocity",
        ElasticModulus => "layer.elastic_modulus",
        Thickness => "layer.thickness",
        PoissonRatio => "layer.poisson_ratio",
        RetardationTime => "layer.retardation_time",
        RelaxationTime => "layer.relaxation_time",
        MeanDiameter => "distribution.mean_diameter",
        StdDiameter => "distribution.std_diameter",
        MinDiameter => "distribution.min_diameter",
        MaxDiameter => "distribution.max_diameter",
        ArealDensity => "distribution.areal_density",
        NominalArea => "nominal_area",
        UpperModulus => "upper_surface.elastic_modulus",
        UpperPoissonRatio => "upper_surface.poisson_ratio",
        UpperHardness => "upper_surface.hardness",
        ParticleModulus => "particle.elastic_modulus",
        ParticlePoissonRatio => "particle.poisson_ratio",
        AsperityDensity => "asperities.density",
        TipRadius => "asperities.tip_radius",
        HeightStd => "asperities.height_std",
        AsperityHardness => "asperities.hardness",
        Separation => "operating.separation",
        TotalLoad => "operating.total_load",
        ParticleLoad => "operating.particle_load",
    }
}

/// Deserializes `value` as `T`; a misshapen field is reported with its path under `prefix`.
pub fn deserialize<T: DeserializeOwned>(value: Value, prefix: &str) -> Result<T, JobError> {
    serde_path_to_error::deserialize(value).map_err(|e| {
        let inner = e.path().to_string();
        let field = match (prefix, inner.as_str()) {
            (p, ".") => p.to_string(),
            ("", i) => i.to_string(),
            (p, i) => format!("{p}.{i}"),
        };
        JobError::Schema {
            field,
            message: e.into_inner().to_string(),
        }
    })
}

/// Collects the errors of one input while its fields are read.
pub struct Checker {
    prefix: String,
    errors: Vec<FieldError>,
    /// Each quantity read: its path and the value as sent.
    sent: Vec<(String, Value)>,
}

impl Checker {
    /// A checker whose paths start with `prefix` (e.g. `base`), or "" at the top.
    pub fn new(prefix: &str) -> Self {
        Checker {
            prefix: prefix.to_string(),
            errors: Vec::new(),
            sent: Vec::new(),
        }
    }

    /// The full path of `field`.
    pub fn path(&self, field: &str) -> String {
        if self.prefix.is_empty() {
            field.to_string()
        } else {
            format!("{}.{field}", self.prefix)
        }
    }

    /// The SI value of a quantity field, `default` if absent, NaN (with an error recorded)
    /// if it cannot be read as `dimension`.
    pub fn quantity(
        &mut self,
        field: &str,
        quantity: Option<&Quantity>,
        dimension: Dimension,
        default: f64,
    ) -> f64 {
        let path = self.path(field);
        let Some(quantity) = quantity else {
            return default;
        };
        self.sent.push((path.clone(), quantity.sent()));
        let parsed = match quantity {
            Quantity::Number(x) => Ok(*x),
            Quantity::Text(text) => parse_quantity(text, dimension),
        };
        parsed.unwrap_or_else(|e| {
            self.unreadable(path, quantity.sent(), dimension, &e);
            f64::NAN
        })
    }

    fn unreadable(&mut self, field: String, value: Value, expected: Dimension, e: &UnitError) {
        let allowed = expected.describe();
        let message = format!("{field}: {value} {e}; expected {allowed}");
        self.errors.push(FieldError {
            field,
            value,
            allowed,
            message,
        });
    }

    /// Records a value outside its range, unless the field (or the object holding it) was
    /// already reported: a value read as NaN after an error says nothing new.
    pub fn out_of_range(&mut self, field: &str, value: f64, unit: &str, allowed: &str) {
        let path = self.path(field);
        let covered = |e: &FieldError| {
            path == e.field
                || path
                    .strip_prefix(e.field.as_str())
                    .is_some_and(|rest| rest.starts_with('.'))
        };
        if self.errors.iter().any(covered) {
            return;
        }
        let sent = self
            .sent
            .iter()
            .find(|(p, _)| *p == path)
            .map_or_else(|| Value::from(value), |(_, v)| v.clone());
        let number = super::format_number(value);
        let si = if unit.is_empty() {
            number
        } else {
            format!("{number} {unit}")
        };
        let message = match &sent {
            Value::String(s) => {
                format!("{path} = \"{s}\" ({si}) is out of range: allowed {allowed}")
            }
            _ => format!("{path} = {si} is out of range: allowed {allowed}"),
        };
        self.errors.push(FieldError {
            field: path,
            value: sent,
            allowed: allowed.to_string(),
            message,
        });
    }

    /// Records the model's range violations, each at the field of its parameter.
    pub fn parameters(&mut self, errors: Vec<ParameterError>) {
        for e in errors {
            let field = parameter_field(e.parameter);
            self.out_of_range(field, e.value, e.parameter.unit(), &e.allowed);
        }
    }

    /// Records the model's option violations, each at the field of its option.
    pub fn options(&mut self, errors: Vec<OptionError>) {
        for e in errors {
            let field = match e.option {
                SolveOption::Strips => "options.strips",
                SolveOption::BoundaryPoints => "options.boundary_points",
                SolveOption::PressureGrid => "options.pressure_grid",
                SolveOption::DiameterNodes => "options.diameter_nodes",
            };
            self.out_of_range(field, e.value as f64, "", &e.allowed);
        }
    }

    /// Records an error that is not a range (e.g. an empty list).
    pub fn invalid(&mut self, field: &str, value: Value, allowed: &str) {
        let path = self.path(field);
        let message = format!("{path}: {value} is not allowed: allowed {allowed}");
        self.errors.push(FieldError {
            field: path,
            value,
            allowed: allowed.to_string(),
            message,
        });
    }

    /// Moves another checker's errors into this one.
    pub fn absorb(&mut self, other: Checker) {
        self.errors.extend(other.errors);
    }

    /// The recorded errors, as the job's error.
    pub fn into_error(self) -> JobError {
        JobError::Invalid(self.errors)
    }

    /// `Ok(value)` if no field was bad, else every error.
    pub fn finish<T>(self, value: T) -> Result<T, JobError> {
        if self.errors.is_empty() {
            Ok(value)
        } else {
            Err(JobError::Invalid(self.errors))
        }
    }
}
