//! The model's value at one measured point, and its sensitivities to the layer.
//!
//! For one particle, docs/model.md §3 gives the structure: A = A₀ · α(ξ, κ) with
//! A₀ = 2√(πRP H/E_L), ξ = V T_σ / r₀ and r₀ ∝ (H/E_L)^{1/4}; μ = τ_a A / P with
//! τ_a = E_L/(2000(1 + ν)). So every sensitivity in logarithms follows from two:
//! g = ∂ ln α/∂ ln ξ (one solve at a slightly higher speed) and ∂ ln α/∂κ (one solve at a
//! slightly larger κ). Such a point costs at most three solves, whatever the number of
//! parameters; a point at rest costs one.
//!
//! A three-body system (docs/model.md §4) mixes particles of every size and the upper surface's
//! contacts, so it has no such structure: its sensitivities are forward differences in T_σ
//! (at fixed κ), κ, E_L and H, four more solves (two at rest, where the times have no effect).

use super::super::tables::{self, Use};
use super::super::three_body::{self, OperatingPoint, ThreeBody, ThreeBodyOptions};
use super::super::{Layer, ModelError, Quadrature, Rolling, SolveOptions};

/// What was measured at a point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Measured {
    /// μ (eq. 12).
    FrictionCoefficient,
    /// A (m²).
    ContactArea,
}

/// Where the measured particles roll.
// A system is some 260 bytes, a particle 16: a fit holds at most `max_sweep_points` points,
// so the waste is bounded (≤ 3 MB), and points stay `Copy`.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setting {
    /// One particle of radius R (m) under load P (N).
    Particle { radius: f64, load: f64 },
    /// A three-body system at total load W (N); its layer, speed and operating point are the
    /// fit's. Only its friction coefficient is measured.
    System {
        system: ThreeBody,
        options: ThreeBodyOptions,
        total_load: f64,
    },
}

/// The operating condition of a measured point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    pub setting: Setting,
    /// V (m/s).
    pub velocity: f64,
    pub measured: Measured,
}

/// ∂ ln y/∂ ln p at fixed T_σ, κ, E_L and H, except `kappa`: ∂ ln y/∂κ.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sensitivity {
    pub relaxation_time: f64,
    pub kappa: f64,
    pub elastic_modulus: f64,
    pub thickness: f64,
}

/// Relative step of the finite differences in ξ and κ: the solve is accurate to ≈ 1e-12,
/// so the difference errs by ≈ 1e-7 from rounding and ≈ 1e-5 from curvature.
const STEP: f64 = 1e-5;

impl Point {
    /// The model's value of what was measured, on `layer`.
    pub fn value(&self, layer: &Layer) -> Result<f64, ModelError> {
        self.solve(layer, self.velocity)
    }

    /// The value and its sensitivities.
    pub fn value_and_sensitivity(&self, layer: &Layer) -> Result<(f64, Sensitivity), ModelError> {
        let y = self.value(layer)?;
        let sensitivity = match self.setting {
            Setting::Particle { .. } => self.structured(layer, y)?,
            Setting::System { .. } => self.differenced(layer, y)?,
        };
        Ok((y, sensitivity))
    }

    /// The sensitivities of a particle, through the similarity structure.
    fn structured(&self, layer: &Layer, y: f64) -> Result<Sensitivity, ModelError> {
        // At rest α = 1 whatever ξ and κ: only A₀ and τ_a depend on the layer.
        let (g, dk) = if self.velocity == 0.0 {
            (0.0, 0.0)
        } else {
            let faster = self.solve(layer, self.velocity * (1.0 + STEP))?;
            let g = (faster / y).ln() / (1.0 + STEP).ln();
            (g, self.kappa_sensitivity(layer, y)?)
        };
        // ln A = ln A₀ + ln α: ln A₀ has −½ ln E_L + ½ ln H, ln ξ has ¼ ln E_L − ¼ ln H.
        let tau = match self.measured {
            Measured::FrictionCoefficient => 1.0,
            Measured::ContactArea => 0.0,
        };
        Ok(Sensitivity {
            relaxation_time: g,
            kappa: dk,
            elastic_modulus: -0.5 + 0.25 * g + tau,
            thickness: 0.5 - 0.25 * g,
        })
    }

    /// The sensitivities by forward differences in each of T_σ (κ fixed), κ, E_L and H.
    fn differenced(&self, layer: &Layer, y: f64) -> Result<Sensitivity, ModelError> {
        let log_step = (1.0 + STEP).ln();
        let along = |changed: Layer| -> Result<f64, ModelError> {
            Ok((self.solve(&changed, self.velocity)? / y).ln() / log_step)
        };
        let (relaxation_time, kappa) = if self.velocity == 0.0 {
            (0.0, 0.0)
        } else {
            let slower = Layer {
                relaxation_time: layer.relaxation_time * (1.0 + STEP),
                retardation_time: layer.retardation_time * (1.0 + STEP),
                ..*layer
            };
            (along(slower)?, self.kappa_sensitivity(layer, y)?)
        };
        Ok(Sensitivity {
            relaxation_time,
            kappa,
            elastic_modulus: along(Layer {
                elastic_modulus: layer.elastic_modulus * (1.0 + STEP),
                ..*layer
            })?,
            thickness: along(Layer {
                thickness: layer.thickness * (1.0 + STEP),
                ..*layer
            })?,
        })
    }

    /// ∂ ln y/∂κ at fixed T_σ, by a forward difference.
    fn kappa_sensitivity(&self, layer: &Layer, y: f64) -> Result<f64, ModelError> {
        let kappa = layer.kappa();
        let dkappa = STEP * kappa.max(1e-3);
        let stiffer = Layer {
            retardation_time: layer.relaxation_time * (1.0 + kappa + dkappa),
            ..*layer
        };
        Ok((self.solve(&stiffer, self.velocity)? / y).ln() / dkappa)
    }

    fn solve(&self, layer: &Layer, velocity: f64) -> Result<f64, ModelError> {
        match self.setting {
            Setting::Particle { radius, load } => {
                let rolling = Rolling {
                    radius,
                    load,
                    velocity,
                    layer: *layer,
                };
                let options = SolveOptions::integrals_only(Quadrature::default());
                let solution = tables::solve(&rolling, &options, Use::Exact)?;
                Ok(match self.measured {
                    Measured::FrictionCoefficient => solution.friction_coefficient,
                    Measured::ContactArea => solution.contact_area,
                })
            }
            Setting::System {
                system,
                options,
                total_load,
            } => {
                let system = ThreeBody {
                    layer: *layer,
                    velocity,
                    operating: OperatingPoint::TotalLoad(total_load),
                    ..system
                };
                Ok(three_body::solve(&system, &options)?
                    .rolling
                    .friction_coefficient)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{FitParameter, Parameterization};
    use super::*;

    /// The sensitivities, through the chain rule of each parameterization, match finite
    /// differences of the value in the parameter itself.
    #[test]
    fn sensitivities_match_finite_differences_in_every_parameter() {
        let base = Layer::default();
        let particle = Setting::Particle {
            radius: 25e-9,
            load: 1e-9,
        };
        let system = Setting::System {
            system: ThreeBody::with_defaults(OperatingPoint::TotalLoad(1e-3)),
            options: ThreeBodyOptions::default(),
            total_load: 1e-3,
        };
        for (setting, measured) in [
            (particle, Measured::FrictionCoefficient),
            (particle, Measured::ContactArea),
            (system, Measured::FrictionCoefficient),
        ] {
            let point = Point {
                setting,
                velocity: 6e-9,
                measured,
            };
            let (y, s) = point.value_and_sensitivity(&base).unwrap();
            for parameter in FitParameter::ALL {
                let p = Parameterization {
                    base,
                    free: vec![parameter],
                };
                let x = parameter.of(&base);
                let h = 1e-4;
                let up = point.value(&p.layer(&[x * (1.0 + h)])).unwrap();
                let down = point.value(&p.layer(&[x / (1.0 + h)])).unwrap();
                let numeric = (up / down).ln() / (2.0 * (1.0 + h).ln());
                let analytic = p.log_derivatives(&s, base.kappa())[0];
                assert!(
                    (analytic - numeric).abs() < 1e-4 * numeric.abs().max(0.1),
                    "{setting:?} {measured:?} {parameter:?}: {analytic} vs {numeric} (y = {y})"
                );
            }
        }
    }
}
