//! Why the model could not produce a number. It never produces a wrong or non-finite one.

use std::fmt;

use super::ParameterError;

/// A solver option whose size is bounded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SolveOption {
    /// Strips (Gauss nodes or midpoint strips) in the half-width.
    Strips,
    BoundaryPoints,
    PressureGrid,
    /// Gauss nodes over the particle diameters (three-body).
    DiameterNodes,
}

impl fmt::Display for SolveOption {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SolveOption::Strips => "strips",
            SolveOption::BoundaryPoints => "boundary points",
            SolveOption::PressureGrid => "pressure grid",
            SolveOption::DiameterNodes => "diameter nodes",
        })
    }
}

/// A solver option outside what is offered.
#[derive(Clone, Debug, PartialEq)]
pub struct OptionError {
    pub option: SolveOption,
    pub value: usize,
    /// The allowed range, as text.
    pub allowed: String,
}

/// A failure of the model: bad parameters, an unrepresentable scale, or a root finder that
/// did not converge within its bound.
#[derive(Clone, Debug, PartialEq)]
pub enum ModelError {
    /// A parameter outside its physical range.
    InvalidParameter(ParameterError),
    /// A solver option (strips, boundary points, pressure grid) outside what is offered.
    InvalidOption(OptionError),
    /// Valid parameters whose combination over- or underflows double precision.
    NotRepresentable { what: String },
    /// Valid parameters that ask for something the model cannot do: a load the system cannot
    /// carry, no particle in contact, a layer pierced through.
    OutOfModel(String),
    /// A bracketed root finder ran out of iterations.
    NoConvergence { what: &'static str, iterations: u32 },
    /// The caller asked the solve to stop ([`crate::Stop`]): past its deadline, cancelled.
    Stopped,
}

impl fmt::Display for ModelError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ModelError::InvalidParameter(e) => e.fmt(f),
            ModelError::InvalidOption(e) => write!(
                f,
                "{} = {} is out of range; expected {}",
                e.option, e.value, e.allowed
            ),
            ModelError::NotRepresentable { what } => {
                write!(f, "{what} is not representable in double precision")
            }
            ModelError::OutOfModel(why) => f.write_str(why),
            ModelError::NoConvergence { what, iterations } => {
                write!(f, "the {what} did not converge in {iterations} iterations")
            }
            ModelError::Stopped => f.write_str("the solve was stopped by its caller"),
        }
    }
}

impl std::error::Error for ModelError {}

impl From<ParameterError> for ModelError {
    fn from(e: ParameterError) -> Self {
        ModelError::InvalidParameter(e)
    }
}
