//! Why the model could not produce a number. It never produces a wrong or non-finite one.

use std::fmt;

use super::ParameterError;

/// A failure of the model: bad parameters, an unrepresentable scale, or a root finder that
/// did not converge within its bound.
#[derive(Clone, Debug, PartialEq)]
pub enum ModelError {
    /// A parameter outside its physical range.
    InvalidParameter(ParameterError),
    /// A quadrature size outside what is offered.
    InvalidQuadrature { size: usize, allowed: String },
    /// A solver option (boundary points, pressure grid) outside what is offered.
    InvalidOption {
        option: &'static str,
        value: usize,
        allowed: String,
    },
    /// Valid parameters whose combination over- or underflows double precision.
    NotRepresentable { what: String },
    /// A bracketed root finder ran out of iterations.
    NoConvergence { what: &'static str, iterations: u32 },
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ModelError::InvalidParameter(e) => e.fmt(f),
            ModelError::InvalidQuadrature { size, allowed } => {
                write!(
                    f,
                    "quadrature size {size} is out of range: allowed {allowed}"
                )
            }
            ModelError::InvalidOption {
                option,
                value,
                allowed,
            } => write!(f, "{option} = {value} is out of range: allowed {allowed}"),
            ModelError::NotRepresentable { what } => {
                write!(f, "{what} is not representable in double precision")
            }
            ModelError::NoConvergence { what, iterations } => {
                write!(f, "the {what} did not converge in {iterations} iterations")
            }
        }
    }
}

impl std::error::Error for ModelError {}

impl From<ParameterError> for ModelError {
    fn from(e: ParameterError) -> Self {
        ModelError::InvalidParameter(e)
    }
}
