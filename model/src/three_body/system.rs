//! What a three-body solve is asked: the surfaces, the particles, the layer and the operating
//! point (docs/model.md §4, defaults of §5), and the solve's options, each able to say what of
//! it lies outside its range before anything is solved.

use super::asperities::Asperities;
use super::distribution::Diameters;
use crate::counterface::UpperSurface;
use crate::text::quantity;
use crate::{Layer, OptionError, Parameter, ParameterError, Quadrature, SolveOption};

/// Diameter nodes used when a job does not ask for a number: the particle sums then agree
/// with 512 nodes to better than 1e-10 (tested).
pub const DEFAULT_DIAMETER_NODES: usize = 48;
/// Largest number of diameter nodes offered.
pub const MAX_DIAMETER_NODES: usize = 1024;

/// The particles' material; rigid by default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Particle {
    /// E_a (Pa); `None` for rigid particles.
    pub elastic_modulus: Option<f64>,
    /// ν_a (matters only for a finite E_a).
    pub poisson_ratio: f64,
}

impl Default for Particle {
    fn default() -> Self {
        Particle {
            elastic_modulus: None,
            poisson_ratio: 0.3,
        }
    }
}

/// How the layer takes a particle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LayerContact {
    /// The rolling contact of docs/model.md §3 at the job's speed (default).
    #[default]
    KelvinLayer,
    /// Hertz with E_s2a (the paper's eq. 6 reading); independent of speed.
    Hertz,
    /// The layer as a continuum (docs/model.md §8) at the job's speed, the particle rigid
    /// as in the Kelvin-layer contact: through [`crate::three_body::LayerCurves`].
    Continuum,
}

/// What fixes the separation d.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OperatingPoint {
    /// d itself (m).
    Separation(f64),
    /// The total load W (N): d solves W(d) = W.
    TotalLoad(f64),
    /// The mean load per particle in contact (N): d solves W_a/n_a = P.
    ParticleLoad(f64),
}

/// A kind of operating point: the parameter that bounds its value, and the point of a value.
pub type OperatingKind = (Parameter, fn(f64) -> OperatingPoint);

impl OperatingPoint {
    /// The kinds of operating point, each with the parameter that bounds its value, in the
    /// order inputs list them (separation, total load, particle load).
    pub const KINDS: [OperatingKind; 3] = [
        (Parameter::Separation, OperatingPoint::Separation),
        (Parameter::TotalLoad, OperatingPoint::TotalLoad),
        (Parameter::ParticleLoad, OperatingPoint::ParticleLoad),
    ];

    /// The position of the operating point's kind in [`OperatingPoint::KINDS`].
    pub fn kind(self) -> usize {
        match self {
            OperatingPoint::Separation(_) => 0,
            OperatingPoint::TotalLoad(_) => 1,
            OperatingPoint::ParticleLoad(_) => 2,
        }
    }

    /// The parameter whose value the operating point gives.
    pub fn parameter(self) -> Parameter {
        OperatingPoint::KINDS[self.kind()].0
    }

    /// The separation, total load or mean particle load given.
    pub fn value(self) -> f64 {
        match self {
            OperatingPoint::Separation(x)
            | OperatingPoint::TotalLoad(x)
            | OperatingPoint::ParticleLoad(x) => x,
        }
    }
}

/// A three-body system and its operating point (docs/model.md §4, defaults of §5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThreeBody {
    pub diameters: Diameters,
    /// η_a, particles per unit area (m⁻²).
    pub areal_density: f64,
    /// A_n (m²).
    pub nominal_area: f64,
    pub upper: UpperSurface,
    pub particle: Particle,
    pub layer: Layer,
    pub layer_contact: LayerContact,
    pub asperities: Option<Asperities>,
    /// V, rolling speed of the particles (m/s).
    pub velocity: f64,
    pub operating: OperatingPoint,
}

impl ThreeBody {
    /// docs/model.md §5: A_n = 1 mm², η_a = 1e12 m⁻², x_a = 50 nm, σ_a = 5 nm, steel upper surface,
    /// rigid particles, the default layer, V = 4 nm/s, no asperities; at `operating`.
    pub fn with_defaults(operating: OperatingPoint) -> Self {
        ThreeBody {
            diameters: Diameters::with_default_bounds(50e-9, 5e-9),
            areal_density: 1e12,
            nominal_area: 1e-6,
            upper: UpperSurface::default(),
            particle: Particle::default(),
            layer: Layer::default(),
            layer_contact: LayerContact::default(),
            asperities: None,
            velocity: 4e-9,
            operating,
        }
    }

    /// Every parameter outside its physical range, and every inconsistency between them.
    pub fn violations(&self) -> Vec<ParameterError> {
        use Parameter::*;
        let mut errors = Parameter::check_all(self.ranged());
        errors.extend(self.upper.violations());
        errors.extend(self.layer.violations());
        let diameters_valid = !errors.iter().any(|e| {
            matches!(
                e.parameter,
                MeanDiameter | StdDiameter | MinDiameter | MaxDiameter
            )
        });
        // Bounds derived from an invalid mean or deviation say nothing more.
        if diameters_valid {
            errors.extend(self.diameter_bounds_violation());
        }
        errors
    }

    /// Each parameter given with its value, to be checked against its own range; the
    /// optional ones only when given.
    fn ranged(&self) -> Vec<(Parameter, f64)> {
        use Parameter::*;
        let d = &self.diameters;
        let mut checks = vec![
            (MeanDiameter, d.mean),
            (StdDiameter, d.std),
            (MinDiameter, d.min),
            (MaxDiameter, d.max),
            (ArealDensity, self.areal_density),
            (NominalArea, self.nominal_area),
            (ParticlePoissonRatio, self.particle.poisson_ratio),
            (Velocity, self.velocity),
        ];
        checks.extend(self.particle.elastic_modulus.map(|e| (ParticleModulus, e)));
        if let Some(a) = &self.asperities {
            checks.extend([
                (AsperityDensity, a.density),
                (TipRadius, a.tip_radius),
                (HeightStd, a.height_std),
                (AsperityHardness, a.hardness),
            ]);
        }
        checks.push(match self.operating {
            OperatingPoint::Separation(x) => (Separation, x),
            OperatingPoint::TotalLoad(x) => (TotalLoad, x),
            OperatingPoint::ParticleLoad(x) => (ParticleLoad, x),
        });
        checks
    }

    /// Diameter bounds that leave no particle to sum over, each diameter valid alone: a
    /// single size outside its own bounds, bounds in the wrong order, or bounds so far out
    /// in the Gaussian's tails that it holds nothing between them.
    fn diameter_bounds_violation(&self) -> Option<ParameterError> {
        let d = &self.diameters;
        let allowed = if d.is_single_size() {
            if d.min <= d.mean && d.mean <= d.max {
                return None;
            }
            format!(
                "x_min ≤ x_a ≤ x_max when σ_a = 0 (x_a = {})",
                quantity(d.mean, "m")
            )
        } else if d.min >= d.max {
            format!("> minimum diameter {}", quantity(d.min, "m"))
        } else if [d.mean, d.std, d.min, d.max].iter().all(|x| x.is_finite())
            && d.normaliser() <= 1e-300
        {
            format!(
                "bounds that hold some of the Gaussian N({}, ({})²)",
                quantity(d.mean, "m"),
                quantity(d.std, "m")
            )
        } else {
            return None;
        };
        Some(ParameterError {
            parameter: Parameter::MaxDiameter,
            value: d.max,
            allowed,
        })
    }
}

/// How the solve is discretised.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ThreeBodyOptions {
    /// Gauss nodes over the diameters in contact.
    pub diameter_nodes: usize,
    /// The strip rule of the rolling contacts behind `kelvin_layer`.
    pub quadrature: Quadrature,
}

impl Default for ThreeBodyOptions {
    fn default() -> Self {
        ThreeBodyOptions {
            diameter_nodes: DEFAULT_DIAMETER_NODES,
            quadrature: Quadrature::default(),
        }
    }
}

impl ThreeBodyOptions {
    /// Every option outside its offered range.
    pub fn violations(&self) -> Vec<OptionError> {
        let mut errors: Vec<OptionError> = self.quadrature.check().err().into_iter().collect();
        if !(2..=MAX_DIAMETER_NODES).contains(&self.diameter_nodes) {
            errors.push(OptionError {
                option: SolveOption::DiameterNodes,
                value: self.diameter_nodes,
                allowed: format!("2 ≤ n ≤ {MAX_DIAMETER_NODES}"),
            });
        }
        errors
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `kind` and `parameter` agree with the table inputs read operating points by.
    #[test]
    fn each_operating_point_finds_its_own_kind_in_the_table() {
        for (i, (parameter, point)) in OperatingPoint::KINDS.into_iter().enumerate() {
            let point = point(2.5);
            assert_eq!(point.kind(), i);
            assert_eq!(point.parameter(), parameter);
            assert_eq!(point.value(), 2.5);
        }
    }
}
