//! The viscoelastic (Kelvin / standard linear solid) layer and the physical ranges of every
//! parameter of a rolling contact (docs/model.md §1).

use std::fmt;

use super::spectrum::Terms;
use super::text::quantity;

/// A thin Kelvin layer bonded to a rigid base (docs/model.md eq. 4): locally
/// v + T_ε ∂v/∂t = (H/E_L)(p + T_σ ∂p/∂t).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layer {
    /// E_L, relaxed longitudinal modulus (Pa); the paper takes the tangential modulus equal.
    pub elastic_modulus: f64,
    /// H (m).
    pub thickness: f64,
    /// ν.
    pub poisson_ratio: f64,
    /// T_ε (s), ≥ T_σ.
    pub retardation_time: f64,
    /// T_σ (s), > 0.
    pub relaxation_time: f64,
    /// The further terms of a Prony series beyond the Kelvin one, as (κ_j = E_j/E_L, τ_j)
    /// (none for the paper's layer; docs/model.md §9, [`crate::spectrum`]).
    pub arms: Terms,
}

impl Default for Layer {
    /// docs/model.md §5: E_L = 3 GPa, H = 100 nm, ν = 0.35, T_ε = 0.5 s, T_σ = 0.1 s.
    fn default() -> Self {
        Layer {
            elastic_modulus: 3e9,
            thickness: 100e-9,
            poisson_ratio: 0.35,
            retardation_time: 0.5,
            relaxation_time: 0.1,
            arms: Terms::default(),
        }
    }
}

impl Layer {
    /// k = E_L/H, the relaxed foundation stiffness (Pa/m).
    pub fn stiffness(&self) -> f64 {
        self.elastic_modulus / self.thickness
    }

    /// κ = (T_ε − T_σ)/T_σ, the strength of the viscosity: the instantaneous stiffness is
    /// k(1 + κ) (docs/model.md §1).
    ///
    /// Written as a difference over T_σ, not as T_ε/T_σ − 1: the quotient rounds by up to
    /// ε/2 ≈ 1.1e-16 before the 1 is taken off, a relative error of 1e-16/κ in κ and so in
    /// everything that vanishes with it (x_c, x_p, μ_r erred by 5.6e-5 at T_ε − T_σ = 1e-13 s,
    /// T_σ = 0.1 s). T_ε − T_σ is exact whenever T_ε ≤ 2T_σ (Sterbenz), so κ is then correct
    /// to one rounding.
    pub fn kappa(&self) -> f64 {
        (self.retardation_time - self.relaxation_time) / self.relaxation_time
    }

    /// G = E/(2(1 + ν)) (eq. 13).
    pub fn shear_modulus(&self) -> f64 {
        self.elastic_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }

    /// τ_a = G/1000, the interfacial shear strength of Adams et al. (eq. 12).
    pub fn interfacial_shear_strength(&self) -> f64 {
        self.shear_modulus() / 1000.0
    }

    /// Every parameter outside its physical range.
    pub fn violations(&self) -> Vec<ParameterError> {
        let mut errors = Parameter::check_all([
            (Parameter::ElasticModulus, self.elastic_modulus),
            (Parameter::Thickness, self.thickness),
            (Parameter::PoissonRatio, self.poisson_ratio),
            (Parameter::RelaxationTime, self.relaxation_time),
            (Parameter::RetardationTime, self.retardation_time),
        ]);
        let times_valid = errors.iter().all(|e| {
            !matches!(
                e.parameter,
                Parameter::RelaxationTime | Parameter::RetardationTime
            )
        });
        if times_valid && self.retardation_time < self.relaxation_time {
            errors.push(ParameterError {
                parameter: Parameter::RetardationTime,
                value: self.retardation_time,
                allowed: format!(
                    "≥ relaxation time T_σ = {} (T_ε ≥ T_σ; equal means elastic)",
                    quantity(self.relaxation_time, "s")
                ),
            });
        }
        for (strength, time) in self.arms.iter() {
            let modulus = strength * self.elastic_modulus;
            errors.extend(Parameter::PronyModulus.check(modulus).err());
            errors.extend(Parameter::PronyTime.check(time).err());
        }
        errors
    }
}

/// A named input of the model, with its physical range.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Parameter {
    Radius,
    Load,
    Velocity,
    ElasticModulus,
    Thickness,
    PoissonRatio,
    RetardationTime,
    RelaxationTime,
    /// x_a of the three-body model (docs/model.md §4).
    MeanDiameter,
    /// σ_a.
    StdDiameter,
    MinDiameter,
    MaxDiameter,
    /// η_a, particles per unit area.
    ArealDensity,
    /// A_n.
    NominalArea,
    UpperModulus,
    UpperPoissonRatio,
    UpperHardness,
    /// τ_u, the shear strength of the particles' contact with the upper surface.
    UpperShearStrength,
    ParticleModulus,
    ParticlePoissonRatio,
    /// η_s, asperities per unit area.
    AsperityDensity,
    /// β_s.
    TipRadius,
    /// σ_s.
    HeightStd,
    /// H_s.
    AsperityHardness,
    /// d.
    Separation,
    /// W.
    TotalLoad,
    /// Mean load per particle in contact.
    ParticleLoad,
    /// κ = (T_ε − T_σ)/T_σ, as a fit gives it.
    Kappa,
    /// k = E_L/H, as a fit gives it.
    Stiffness,
    /// μ, as measured.
    FrictionCoefficient,
    /// A, as measured.
    ContactArea,
    /// E_j, the modulus of one term of a Prony series.
    PronyModulus,
    /// τ_j, the time of one term of a Prony series.
    PronyTime,
    /// T, the layer's temperature (absolute).
    Temperature,
    /// T_ref, the temperature at which a series' times hold.
    ReferenceTemperature,
    /// C₁ of the WLF shift.
    WlfC1,
    /// C₂ of the WLF shift.
    WlfC2,
    /// A fit's factor on every modulus.
    ModulusScale,
    /// A fit's factor on every time.
    ShiftFactor,
}

impl Parameter {
    /// The SI unit of the parameter ("" for dimensionless).
    pub fn unit(self) -> &'static str {
        use Parameter::*;
        match self {
            Radius | Thickness | MeanDiameter | StdDiameter | MinDiameter | MaxDiameter
            | TipRadius | HeightStd | Separation => "m",
            Load | TotalLoad | ParticleLoad => "N",
            Velocity => "m/s",
            ElasticModulus | UpperModulus | UpperHardness | UpperShearStrength
            | ParticleModulus | AsperityHardness | PronyModulus => "Pa",
            PoissonRatio | UpperPoissonRatio | ParticlePoissonRatio => "",
            RetardationTime | RelaxationTime | PronyTime => "s",
            Temperature | ReferenceTemperature | WlfC2 => "K",
            ArealDensity | AsperityDensity => "m^-2",
            NominalArea | ContactArea => "m^2",
            Kappa | FrictionCoefficient | WlfC1 | ModulusScale | ShiftFactor => "",
            Stiffness => "Pa/m",
        }
    }

    /// Whether zero is allowed (else the value must be positive).
    fn may_be_zero(self) -> bool {
        use Parameter::*;
        matches!(self, Velocity | StdDiameter | MinDiameter | Separation)
    }

    fn is_poisson_ratio(self) -> bool {
        use Parameter::*;
        matches!(
            self,
            PoissonRatio | UpperPoissonRatio | ParticlePoissonRatio
        )
    }

    /// The allowed range, as text.
    pub fn allowed(self) -> String {
        let unit = self.unit();
        if self.is_poisson_ratio() {
            "0 ≤ ν < 0.5".to_string()
        } else if self.may_be_zero() {
            format!("finite and ≥ 0 {unit}").trim_end().to_string()
        } else {
            format!("finite and > 0 {unit}").trim_end().to_string()
        }
    }

    /// Each of `values` outside its parameter's own range, in order: every input struct
    /// checks its fields this way, then adds its own cross-checks.
    pub(crate) fn check_all(
        values: impl IntoIterator<Item = (Parameter, f64)>,
    ) -> Vec<ParameterError> {
        values
            .into_iter()
            .filter_map(|(parameter, value)| parameter.check(value).err())
            .collect()
    }

    /// Checks one value against the parameter's own range (not the cross-checks, such as
    /// T_ε ≥ T_σ, that [`Layer::violations`] adds).
    pub fn check(self, value: f64) -> Result<(), ParameterError> {
        let ok = value.is_finite()
            && if self.is_poisson_ratio() {
                (0.0..0.5).contains(&value)
            } else if self.may_be_zero() {
                value >= 0.0
            } else {
                value > 0.0
            };
        if ok {
            Ok(())
        } else {
            Err(ParameterError {
                parameter: self,
                value,
                allowed: self.allowed(),
            })
        }
    }
}

impl fmt::Display for Parameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Parameter::Radius => "radius",
            Parameter::Load => "load",
            Parameter::Velocity => "velocity",
            Parameter::ElasticModulus => "elastic modulus",
            Parameter::Thickness => "thickness",
            Parameter::PoissonRatio => "Poisson ratio",
            Parameter::RetardationTime => "retardation time",
            Parameter::RelaxationTime => "relaxation time",
            Parameter::MeanDiameter => "mean diameter",
            Parameter::StdDiameter => "diameter standard deviation",
            Parameter::MinDiameter => "minimum diameter",
            Parameter::MaxDiameter => "maximum diameter",
            Parameter::ArealDensity => "particles per unit area",
            Parameter::NominalArea => "nominal area",
            Parameter::UpperModulus => "upper surface elastic modulus",
            Parameter::UpperPoissonRatio => "upper surface Poisson ratio",
            Parameter::UpperHardness => "upper surface hardness",
            Parameter::UpperShearStrength => "upper surface shear strength",
            Parameter::ParticleModulus => "particle elastic modulus",
            Parameter::ParticlePoissonRatio => "particle Poisson ratio",
            Parameter::AsperityDensity => "asperities per unit area",
            Parameter::TipRadius => "asperity tip radius",
            Parameter::HeightStd => "asperity height standard deviation",
            Parameter::AsperityHardness => "asperity hardness",
            Parameter::Separation => "separation",
            Parameter::TotalLoad => "total load",
            Parameter::ParticleLoad => "mean particle load",
            Parameter::Kappa => "κ",
            Parameter::Stiffness => "stiffness",
            Parameter::FrictionCoefficient => "friction coefficient",
            Parameter::ContactArea => "contact area",
            Parameter::PronyModulus => "Prony term modulus",
            Parameter::PronyTime => "Prony term time",
            Parameter::Temperature => "temperature",
            Parameter::ReferenceTemperature => "reference temperature",
            Parameter::WlfC1 => "WLF C1",
            Parameter::WlfC2 => "WLF C2",
            Parameter::ModulusScale => "modulus scale",
            Parameter::ShiftFactor => "shift factor",
        })
    }
}

/// A parameter outside its physical range. The message names the parameter, its value with
/// its unit, and the range allowed, so a caller can mend the input from it alone.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "{parameter} = {} is out of range; expected {allowed}",
    quantity(*.value, .parameter.unit())
)]
pub struct ParameterError {
    pub parameter: Parameter,
    pub value: f64,
    /// The allowed range, as text.
    pub allowed: String,
}
