//! What a rolling solve is asked: the particle and layer (docs/model.md §3) and the solver's
//! options, each able to say what of it lies outside its range before anything is solved.

use crate::{Layer, OptionError, Parameter, ParameterError, Quadrature, SolveOption};

/// Largest number of boundary points a solve returns.
pub const MAX_BOUNDARY_POINTS: usize = 10_001;
/// Largest pressure grid (points per side).
pub const MAX_PRESSURE_GRID: usize = 501;

/// One particle rolling over the layer: the inputs of docs/model.md §3.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rolling {
    /// R (m).
    pub radius: f64,
    /// P (N).
    pub load: f64,
    /// V (m/s), ≥ 0; the sphere rolls in +x.
    pub velocity: f64,
    pub layer: Layer,
}

impl Default for Rolling {
    /// docs/model.md §5: R = 25 nm, P = 1 nN, V = 4 nm/s on the default layer.
    fn default() -> Self {
        Rolling {
            radius: 25e-9,
            load: 1e-9,
            velocity: 4e-9,
            layer: Layer::default(),
        }
    }
}

impl Rolling {
    /// Every parameter outside its physical range.
    pub fn violations(&self) -> Vec<ParameterError> {
        let mut errors = Parameter::check_all([
            (Parameter::Radius, self.radius),
            (Parameter::Load, self.load),
            (Parameter::Velocity, self.velocity),
        ]);
        errors.extend(self.layer.violations());
        errors
    }
}

/// What to compute besides the integral quantities, and how.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SolveOptions {
    pub quadrature: Quadrature,
    /// Points of the contact boundary to return, spread evenly in θ over −r ≤ y ≤ r
    /// (0: none).
    pub boundary_points: usize,
    /// Pressure on an n × n grid over the square [−r, r]², if asked.
    pub pressure_grid: Option<usize>,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            quadrature: Quadrature::default(),
            boundary_points: 41,
            pressure_grid: None,
        }
    }
}

impl SolveOptions {
    /// Options that ask only for the integral quantities (used by sweeps).
    pub fn integrals_only(quadrature: Quadrature) -> Self {
        SolveOptions {
            quadrature,
            boundary_points: 0,
            pressure_grid: None,
        }
    }

    /// Every option outside its offered range.
    pub fn violations(&self) -> Vec<OptionError> {
        let mut errors: Vec<OptionError> = self.quadrature.check().err().into_iter().collect();
        if self.boundary_points > MAX_BOUNDARY_POINTS {
            errors.push(OptionError {
                option: SolveOption::BoundaryPoints,
                value: self.boundary_points,
                allowed: format!("0 ≤ n ≤ {MAX_BOUNDARY_POINTS}"),
            });
        }
        if let Some(n) = self
            .pressure_grid
            .filter(|n| !(2..=MAX_PRESSURE_GRID).contains(n))
        {
            errors.push(OptionError {
                option: SolveOption::PressureGrid,
                value: n,
                allowed: format!("2 ≤ n ≤ {MAX_PRESSURE_GRID}"),
            });
        }
        errors
    }
}
