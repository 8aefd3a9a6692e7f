//! The counterface: the rigid-backed upper surface a particle rolls against (docs/model.md §4,
//! §11), how it takes a particle, and how much tangential force that contact can transmit.
//! A single particle and a three-body system's particles meet the same surface.

use std::f64::consts::PI;

use crate::limits::hertz_force;
use crate::{Parameter, ParameterError};

/// How the upper surface deforms where a particle presses into it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UpperContact {
    /// Hertz (docs/model.md §4, default).
    #[default]
    Elastic,
    /// Fully plastic at the surface's hardness (Horng's option).
    Plastic,
}

/// The rigid-backed upper surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpperSurface {
    /// E₁ (Pa).
    pub elastic_modulus: f64,
    /// ν₁.
    pub poisson_ratio: f64,
    pub contact: UpperContact,
    /// H₁ (Pa), needed for plastic contact.
    pub hardness: Option<f64>,
    /// τ_u (Pa), the interfacial shear strength of the particle's contact with it; `None`
    /// for G₁/1000 (docs/model.md §11, as eq. 12's τ_a = G/1000 of the layer).
    pub shear_strength: Option<f64>,
}

impl Default for UpperSurface {
    /// Steel: 210 GPa, ν = 0.3 (docs/model.md §5).
    fn default() -> Self {
        UpperSurface {
            elastic_modulus: 210e9,
            poisson_ratio: 0.3,
            contact: UpperContact::Elastic,
            hardness: None,
            shear_strength: None,
        }
    }
}

impl UpperSurface {
    /// Every field outside its range, and a plastic contact without a hardness.
    pub fn violations(&self) -> Vec<ParameterError> {
        let mut checks = vec![
            (Parameter::UpperModulus, self.elastic_modulus),
            (Parameter::UpperPoissonRatio, self.poisson_ratio),
        ];
        checks.extend(self.hardness.map(|h| (Parameter::UpperHardness, h)));
        checks.extend(
            self.shear_strength
                .map(|t| (Parameter::UpperShearStrength, t)),
        );
        let mut errors = Parameter::check_all(checks);
        if self.contact == UpperContact::Plastic && self.hardness.is_none() {
            errors.push(ParameterError {
                parameter: Parameter::UpperHardness,
                value: f64::NAN,
                allowed: "a hardness (Pa) for plastic contact".to_string(),
            });
        }
        errors
    }

    /// τ_u (Pa): the given shear strength, or G₁/1000 with G₁ = E₁/(2(1+ν₁)).
    pub fn shear_strength(&self) -> f64 {
        self.shear_strength
            .unwrap_or(self.elastic_modulus / (2.0 * (1.0 + self.poisson_ratio)) / 1000.0)
    }

    /// How the surface takes a particle whose own compliance (1 − ν_a²)/E_a is
    /// `particle_compliance` (0 when rigid): Hertz with E_s1a, or plastic at H₁.
    pub fn law(&self, particle_compliance: f64) -> UpperLaw {
        match (self.contact, self.hardness) {
            (UpperContact::Plastic, Some(hardness)) => UpperLaw::Plastic { hardness },
            _ => UpperLaw::Elastic {
                modulus: 1.0
                    / (compliance(self.elastic_modulus, self.poisson_ratio) + particle_compliance),
            },
        }
    }
}

/// (1 − ν²)/E, a body's share of a contact's compliance (1/E* = Σ (1 − ν²)/E).
pub fn compliance(modulus: f64, poisson_ratio: f64) -> f64 {
    (1.0 - poisson_ratio * poisson_ratio) / modulus
}

/// How the upper surface takes a particle of radius R = x/2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum UpperLaw {
    /// Hertz with the composite modulus E_s1a: F = (4/3)E_s1a R^{1/2} ω₁^{3/2}, A₁ = πRω₁.
    Elastic { modulus: f64 },
    /// Fully plastic (Horng): A₁ = 2πRω₁ = πxω₁, F = H₁A₁.
    Plastic { hardness: f64 },
}

impl UpperLaw {
    /// Force (N) at interference ω₁.
    pub fn force(&self, radius: f64, omega: f64) -> f64 {
        match *self {
            UpperLaw::Elastic { modulus } => hertz_force(modulus, radius, omega),
            UpperLaw::Plastic { hardness } => hardness * self.area(radius, omega),
        }
    }

    /// Contact area (m²) at interference ω₁.
    pub fn area(&self, radius: f64, omega: f64) -> f64 {
        match self {
            UpperLaw::Elastic { .. } => PI * radius * omega,
            UpperLaw::Plastic { .. } => 2.0 * PI * radius * omega,
        }
    }

    /// The interference ω₁ that carries `force`: the inverse of [`UpperLaw::force`].
    pub fn interference(&self, radius: f64, force: f64) -> f64 {
        match *self {
            UpperLaw::Elastic { modulus } => {
                (3.0 * force / (4.0 * modulus * radius.sqrt())).powf(2.0 / 3.0)
            }
            UpperLaw::Plastic { hardness } => force / (2.0 * PI * radius * hardness),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_upper_law_inverts() {
        for upper in [
            UpperLaw::Elastic { modulus: 2.3e11 },
            UpperLaw::Plastic { hardness: 2e9 },
        ] {
            let omega = 3e-11;
            let force = upper.force(25e-9, omega);
            assert!((upper.interference(25e-9, force) / omega - 1.0).abs() < 1e-14);
        }
    }

    /// docs/model.md §11: steel's τ_u = G₁/1000 = 80.77 MPa, and a rigid sphere of 25 nm
    /// under 1 nN on it has E* = 230.8 GPa and Hertz's a = (3PR/4E*)^{1/3} = 0.43312 nm,
    /// A_u = 0.5893 nm² (§11 prints a = 0.4334 nm and A_u = 0.590 nm²: a³ = 8.125e-29 m³
    /// gives 0.43312 nm; its μ_cap,u = 0.0476 holds either way).
    #[test]
    fn steel_takes_the_default_particle_as_section_11_says() {
        let steel = UpperSurface::default();
        assert!((steel.shear_strength() / 80.769_230_769e6 - 1.0).abs() < 1e-9);
        let law = steel.law(0.0);
        let UpperLaw::Elastic { modulus } = law else {
            panic!("steel is elastic")
        };
        assert!((modulus / 230.769_230_769e9 - 1.0).abs() < 1e-9);
        let area = law.area(25e-9, law.interference(25e-9, 1e-9));
        let a = (area / PI).sqrt();
        let hertz = (3.0 * 1e-9 * 25e-9 / (4.0 * modulus)).cbrt();
        assert!((a / hertz - 1.0).abs() < 1e-12, "{a:e}");
        assert!((a / 0.43312e-9 - 1.0).abs() < 2e-5, "{a:e}");
        assert!((area / 0.5893e-18 - 1.0).abs() < 1e-4, "{area:e}");
        let given = UpperSurface {
            shear_strength: Some(5e7),
            ..steel
        };
        assert_eq!(given.shear_strength(), 5e7);
    }
}
