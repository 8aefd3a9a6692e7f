//! The model's value at one measured point, and its sensitivities to the layer.
//!
//! MODEL.md §3 gives the structure: A = A₀ · α(ξ, κ) with A₀ = 2√(πRP H/E_L),
//! ξ = V T_σ / r₀ and r₀ ∝ (H/E_L)^{1/4}; μ = τ_a A / P with τ_a = E_L/(2000(1 + ν)). So
//! every sensitivity in logarithms follows from two: g = ∂ ln α/∂ ln ξ (one solve at a
//! slightly higher speed) and ∂ ln α/∂κ (one solve at a slightly larger κ). A point costs at
//! most three solves, whatever the number of parameters; a point at rest costs one.

use super::super::tables::{self, Use};
use super::super::{Layer, ModelError, Quadrature, Rolling, SolveOptions};

/// What was measured at a point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Measured {
    /// μ (eq. 12).
    FrictionCoefficient,
    /// A (m²).
    ContactArea,
}

/// The operating condition of a measured point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// R (m).
    pub radius: f64,
    /// P (N).
    pub load: f64,
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

    /// The value and, if `sensitive`, its sensitivities.
    pub fn value_and_sensitivity(
        &self,
        layer: &Layer,
        sensitive: bool,
    ) -> Result<(f64, Option<Sensitivity>), ModelError> {
        let y = self.value(layer)?;
        if !sensitive {
            return Ok((y, None));
        }
        // At rest α = 1 whatever ξ and κ: only A₀ and τ_a depend on the layer.
        let (g, dk) = if self.velocity == 0.0 {
            (0.0, 0.0)
        } else {
            let faster = self.solve(layer, self.velocity * (1.0 + STEP))?;
            let g = (faster / y).ln() / (1.0 + STEP).ln();
            let kappa = layer.kappa();
            let dkappa = STEP * kappa.max(1e-3);
            let stiffer = Layer {
                retardation_time: layer.relaxation_time * (1.0 + kappa + dkappa),
                ..*layer
            };
            let dk = (self.solve(&stiffer, self.velocity)? / y).ln() / dkappa;
            (g, dk)
        };
        // ln A = ln A₀ + ln α: ln A₀ has −½ ln E_L + ½ ln H, ln ξ has ¼ ln E_L − ¼ ln H.
        let tau = match self.measured {
            Measured::FrictionCoefficient => 1.0,
            Measured::ContactArea => 0.0,
        };
        let sensitivity = Sensitivity {
            relaxation_time: g,
            kappa: dk,
            elastic_modulus: -0.5 + 0.25 * g + tau,
            thickness: 0.5 - 0.25 * g,
        };
        Ok((y, Some(sensitivity)))
    }

    fn solve(&self, layer: &Layer, velocity: f64) -> Result<f64, ModelError> {
        let rolling = Rolling {
            radius: self.radius,
            load: self.load,
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
        for measured in [Measured::FrictionCoefficient, Measured::ContactArea] {
            let point = Point {
                radius: 25e-9,
                load: 1e-9,
                velocity: 6e-9,
                measured,
            };
            let (y, s) = point.value_and_sensitivity(&base, true).unwrap();
            let s = s.unwrap();
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
                    "{measured:?} {parameter:?}: {analytic} vs {numeric} (y = {y})"
                );
            }
        }
    }
}
