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
/// did not converge within its bound. The messages reach callers word for word (the service's
/// 422 problems), so each is part of the interface.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A parameter outside its physical range.
    #[error(transparent)]
    InvalidParameter(#[from] ParameterError),
    /// A solver option (strips, boundary points, pressure grid) outside what is offered.
    #[error("{} = {} is out of range; expected {}", .0.option, .0.value, .0.allowed)]
    InvalidOption(OptionError),
    /// Valid parameters whose combination over- or underflows double precision.
    #[error("{what} is not representable in double precision")]
    NotRepresentable { what: String },
    /// Valid parameters that ask for something the model cannot do: a load the system cannot
    /// carry, no particle in contact, a layer pierced through.
    #[error("{0}")]
    OutOfModel(String),
    /// A bracketed root finder ran out of iterations.
    #[error("the {what} did not converge in {iterations} iterations")]
    NoConvergence { what: &'static str, iterations: u32 },
    /// The caller asked the solve to stop ([`crate::Stop`]): past its deadline, cancelled.
    #[error("the solve was stopped by its caller")]
    Stopped,
}

impl ModelError {
    /// The first of a solve's invalid inputs, parameters before options, as its refusal: a
    /// solve checks every input before it does any work, and answers the first problem.
    pub(crate) fn check_inputs(
        parameters: Vec<ParameterError>,
        options: Vec<OptionError>,
    ) -> Result<(), ModelError> {
        match (parameters.into_iter().next(), options.into_iter().next()) {
            (Some(parameter), _) => Err(parameter.into()),
            (None, Some(option)) => Err(ModelError::InvalidOption(option)),
            (None, None) => Ok(()),
        }
    }
}
