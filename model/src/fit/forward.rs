//! The model's value at one measured point, and its sensitivities to the layer.
//!
//! For one particle on the local law, docs/model.md §3 gives the structure: A = A₀ · α(ξ, κ)
//! with A₀ = 2√(πRP H/E_L), ξ = V T_σ / r₀ and r₀ ∝ (H/E_L)^{1/4}; μ = τ_a A / P with
//! τ_a = E_L/(2000(1 + ν)). So every sensitivity in logarithms follows from two:
//! g = ∂ ln α/∂ ln ξ (one solve at a slightly higher speed) and ∂ ln α/∂κ (one solve at a
//! slightly larger κ). Such a point costs at most three solves, whatever the number of
//! parameters; a point at rest costs one.
//!
//! On the layer as a continuum (docs/model.md §8) the layer enters through two lengths, not
//! one: measured in Hertz's radius a_H = (3PR/4E*)^{1/3} ∝ E_L^{−1/3}, A = π a_H² F(H/a_H,
//! V T_σ/a_H, κ, ν). So ∂ ln A/∂ ln H = g_H (one solve at a slightly thicker layer),
//! ∂ ln A/∂ ln T_σ = ∂ ln A/∂ ln V = g_V, and ∂ ln A/∂ ln E_L = −2/3 + (g_H + g_V)/3: four
//! solves at most, two at rest. (The local law is the case g_H = 1/2 − g_V/4.) At rest the
//! continuum's area is the table of its axisymmetric solver's ([`continuum::static_area`]),
//! rolling it is solved on the grid ([`Point::step`]).
//!
//! A three-body system (docs/model.md §4) mixes particles of every size and the upper surface's
//! contacts, so it has no such structure: its sensitivities are forward differences in T_σ
//! (at fixed κ), κ, E_L and H, four more solves (two at rest, where the times have no effect).
//! So has a particle's own friction (docs/model.md §11): the least of x_p/2R and the two
//! contacts' capacities, the upper one independent of the layer; it is differenced alike.

use super::super::continuum;
use super::super::counterface::UpperSurface;
use super::super::motion;
use super::super::tables::{self, Use};
use super::super::three_body::{
    self, LayerContact, LayerCurves, OperatingPoint, ThreeBody, ThreeBodyOptions,
};
use super::super::{Layer, ModelError, Quadrature, Rolling, SolveOptions, Stop};

/// The layer's law the model is solved with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Law {
    /// The paper's local law (docs/model.md §3).
    #[default]
    Local,
    /// The layer as a continuum (docs/model.md §8); a system's layer contact is then the
    /// continuum's too.
    Continuum,
}

impl Law {
    /// The law a point is solved with under the fit's law: a three-body system whose layer
    /// contact is the continuum's is on the continuum whatever the fit's law.
    pub fn at(self, setting: &Setting) -> Law {
        match setting {
            Setting::System { system, .. } if system.layer_contact == LayerContact::Continuum => {
                Law::Continuum
            }
            _ => self,
        }
    }
}

/// What was measured at a point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Measured {
    /// μ (eq. 12).
    FrictionCoefficient,
    /// A (m²).
    ContactArea,
    /// The friction the particles really transmit (docs/model.md §11): a particle's T/P,
    /// rolling or sliding, or a system's (Σ T + τ_s A_s1s2)/W.
    ParticleFriction,
}

/// Where the measured particles roll.
// A system is some 260 bytes, a particle 16: a fit holds at most `max_sweep_points` points,
// so the waste is bounded (≤ 3 MB), and points stay `Copy`.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setting {
    /// One particle of radius R (m) under load P (N), against the counterface `upper`
    /// (which matters only to the particle's friction, [`Measured::ParticleFriction`]).
    Particle {
        radius: f64,
        load: f64,
        upper: UpperSurface,
    },
    /// A three-body system at total load W (N); its layer, speed and operating point are the
    /// fit's. Its friction coefficient is measured (eq. 12's, or the particles' own).
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

/// ∂ ln y/∂ ln p at fixed T_σ, κ, E_L and H, except `kappa`: ∂ ln y/∂κ. `relaxation_time`
/// scales every time of the layer (its Prony series' too) and `elastic_modulus` every
/// modulus: both hold the series' shape.
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
/// The same on the continuum, for a particle at rest and otherwise ([`Point::step`]).
const STATIC_CONTINUUM_STEP: f64 = 1e-4;
const CONTINUUM_STEP: f64 = 3e-2;

impl Point {
    /// Whether the point is solved on the continuum under the fit's `law` ([`Law::at`]).
    pub fn on_continuum(&self, law: Law) -> bool {
        law.at(&self.setting) == Law::Continuum
    }

    /// The relative step of the finite differences under `law`: the local solve is
    /// accurate to ≈ 1e-12, so [`STEP`]. A particle at rest on the continuum is a table
    /// with continuous slopes: [`STATIC_CONTINUUM_STEP`]. Anything else on the continuum
    /// is solved on a pixel grid (a system's curves too, at rest or rolling), whose area
    /// moves in steps of up to 4e-3 of itself where an edge crosses a pixel's centre as a
    /// parameter moves (a few 1e-4 between): a step of [`CONTINUUM_STEP`] keeps such a jump
    /// to a tenth of a sensitivity.
    fn step(&self, law: Law) -> f64 {
        match (law.at(&self.setting), self.setting) {
            (Law::Local, _) => STEP,
            (Law::Continuum, Setting::Particle { .. }) if self.velocity == 0.0 => {
                STATIC_CONTINUUM_STEP
            }
            (Law::Continuum, _) => CONTINUUM_STEP,
        }
    }

    /// The solves a value with its sensitivities takes ([`Point::value_and_sensitivity`]):
    /// the value's, and for a particle's area or eq. 12's μ one each for its speed and κ
    /// when it rolls and its thickness on the continuum; by differences (a system, a
    /// particle's own friction) one each for E_L and H, and T_σ and κ when it rolls.
    pub fn solves_with_sensitivity(&self, law: Law) -> u64 {
        let rolls = u64::from(self.velocity > 0.0);
        match (self.structured_setting(), law.at(&self.setting)) {
            (true, Law::Local) => 1 + 2 * rolls,
            (true, Law::Continuum) => 2 + 2 * rolls,
            (false, _) => 3 + 2 * rolls,
        }
    }

    /// Whether the value has the similarity structure of the module doc: a particle's
    /// area or eq. 12's μ. A particle's own friction holds μ_roll = x_p/2R, of another
    /// structure, and the upper contact's capacity, of none.
    fn structured_setting(&self) -> bool {
        matches!(self.setting, Setting::Particle { .. })
            && self.measured != Measured::ParticleFriction
    }

    /// The model's value of what was measured, on `layer` under `law`.
    pub fn value(&self, layer: &Layer, law: Law, stop: Stop) -> Result<f64, ModelError> {
        self.solve(layer, self.velocity, law, stop)
    }

    /// The value and its sensitivities.
    pub fn value_and_sensitivity(
        &self,
        layer: &Layer,
        law: Law,
        stop: Stop,
    ) -> Result<(f64, Sensitivity), ModelError> {
        let y = self.value(layer, law, stop)?;
        let sensitivity = if self.structured_setting() {
            self.structured(layer, y, law, stop)?
        } else {
            self.differenced(layer, y, law, stop)?
        };
        Ok((y, sensitivity))
    }

    /// The sensitivities of a particle, through the similarity structure (see the module
    /// doc): on the local law from g_V and ∂ ln α/∂κ, on the continuum from g_H as well.
    fn structured(
        &self,
        layer: &Layer,
        y: f64,
        law: Law,
        stop: Stop,
    ) -> Result<Sensitivity, ModelError> {
        let log_step = (1.0 + self.step(law)).ln();
        // At rest α = 1 whatever ξ and κ: only A₀ and τ_a depend on the layer.
        let (g, dk) = if self.velocity == 0.0 {
            (0.0, 0.0)
        } else {
            let faster = self.solve(layer, self.velocity * (1.0 + self.step(law)), law, stop)?;
            let g = (faster / y).ln() / log_step;
            (g, self.kappa_sensitivity(layer, y, law, stop)?)
        };
        let thickness = match law {
            // ln A₀ has ½ ln H, ln ξ has −¼ ln H.
            Law::Local => 0.5 - 0.25 * g,
            Law::Continuum => {
                let thicker = Layer {
                    thickness: layer.thickness * (1.0 + self.step(law)),
                    ..*layer
                };
                (self.solve(&thicker, self.velocity, law, stop)? / y).ln() / log_step
            }
        };
        // μ = τ_a A/P carries τ_a ∝ E_L; the area does not.
        let tau = f64::from(u8::from(self.measured == Measured::FrictionCoefficient));
        Ok(Sensitivity {
            relaxation_time: g,
            kappa: dk,
            elastic_modulus: -2.0 / 3.0 + (thickness + g) / 3.0 + tau,
            thickness,
        })
    }

    /// The sensitivities by forward differences in each of T_σ (κ fixed), κ, E_L and H.
    fn differenced(
        &self,
        layer: &Layer,
        y: f64,
        law: Law,
        stop: Stop,
    ) -> Result<Sensitivity, ModelError> {
        let step = self.step(law);
        let log_step = (1.0 + step).ln();
        let along = |changed: Layer| -> Result<f64, ModelError> {
            Ok((self.solve(&changed, self.velocity, law, stop)? / y).ln() / log_step)
        };
        let (relaxation_time, kappa) = if self.velocity == 0.0 {
            (0.0, 0.0)
        } else {
            (
                along(layer.with_times_scaled(1.0 + step))?,
                self.kappa_sensitivity(layer, y, law, stop)?,
            )
        };
        Ok(Sensitivity {
            relaxation_time,
            kappa,
            elastic_modulus: along(Layer {
                elastic_modulus: layer.elastic_modulus * (1.0 + step),
                ..*layer
            })?,
            thickness: along(Layer {
                thickness: layer.thickness * (1.0 + step),
                ..*layer
            })?,
        })
    }

    /// ∂ ln y/∂κ at fixed T_σ, by a forward difference.
    fn kappa_sensitivity(
        &self,
        layer: &Layer,
        y: f64,
        law: Law,
        stop: Stop,
    ) -> Result<f64, ModelError> {
        let kappa = layer.kappa();
        // On the continuum κ moves the grid (its pixel follows the stiff layer's contact),
        // so its step is never below the grid's: relative to 1 + κ, not to κ.
        let dkappa = match law.at(&self.setting) {
            Law::Local => self.step(law) * kappa.max(1e-3),
            Law::Continuum => self.step(law) * (1.0 + kappa),
        };
        let stiffer = Layer {
            retardation_time: layer.relaxation_time * (1.0 + kappa + dkappa),
            ..*layer
        };
        Ok((self.solve(&stiffer, self.velocity, law, stop)? / y).ln() / dkappa)
    }

    fn solve(&self, layer: &Layer, velocity: f64, law: Law, stop: Stop) -> Result<f64, ModelError> {
        match self.setting {
            Setting::Particle {
                radius,
                load,
                upper,
            } => {
                let rolling = Rolling {
                    radius,
                    load,
                    velocity,
                    layer: *layer,
                };
                let options = SolveOptions::integrals_only(Quadrature::default());
                // A, and x_p/R (0 at rest).
                let (area, resistance) = match law {
                    Law::Local => {
                        let s = tables::solve(&rolling, &options, Use::Exact)?;
                        (s.contact_area, s.rolling_resistance_coefficient)
                    }
                    // At rest the table of the axisymmetric solver's areas: within 0.5 % of
                    // it, smooth in the parameters and 160 ns, where the grid is within
                    // 0.7 %, moves in steps and takes 5 ms (the solver itself, 20 ms).
                    Law::Continuum if velocity == 0.0 => {
                        (continuum::static_area(radius, load, layer), 0.0)
                    }
                    Law::Continuum => {
                        let s = continuum::solve(&rolling, &options, stop)?;
                        (s.contact_area, s.rolling_resistance_coefficient)
                    }
                };
                let tau = layer.interfacial_shear_strength();
                Ok(match self.measured {
                    Measured::FrictionCoefficient => tau * area / load,
                    Measured::ContactArea => area,
                    Measured::ParticleFriction => {
                        motion::particle(radius, load, resistance, area, tau, &upper).friction
                    }
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
                    layer_contact: match law.at(&self.setting) {
                        Law::Local => system.layer_contact,
                        Law::Continuum => LayerContact::Continuum,
                    },
                    ..system
                };
                let curves = match system.layer_contact {
                    LayerContact::Continuum => Some(LayerCurves::build(&system, stop)?),
                    _ => None,
                };
                let solution = three_body::solve_with(&system, &options, curves.as_ref())?;
                Ok(match self.measured {
                    Measured::ParticleFriction => solution.motion.friction,
                    _ => solution.rolling.friction_coefficient,
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{FitParameter, Parameterization};
    use super::*;

    /// The sensitivities, through the chain rule of each parameterization, match finite
    /// differences of the value in the parameter itself: on the local law to 1e-4, on the
    /// continuum at rest to 1e-3. (Rolling on the continuum the grid's area moves in steps
    /// of up to 4e-3 ([`Point::step`]), so no difference quotient is exact enough to check
    /// against; the rolling continuum fit is tested whole, tests/service/fit_continuum.rs.)
    /// On a layer of a four-term Prony series the factors on all moduli and all times are
    /// checked as well (its single Kelvin times are not offered for it).
    #[test]
    fn sensitivities_match_finite_differences_in_every_parameter() {
        let material =
            Layer::from_prony(3e9, 100e-9, 0.35, &[(6e9, 0.01), (4.5e9, 0.1), (3e9, 1.0)]).unwrap();
        for base in [Layer::default(), material] {
            sensitivities_match_on(base);
        }
    }

    fn sensitivities_match_on(base: Layer) {
        let particle = Setting::Particle {
            radius: 25e-9,
            load: 1e-9,
            upper: UpperSurface::default(),
        };
        let system = Setting::System {
            system: ThreeBody::with_defaults(OperatingPoint::TotalLoad(1e-3)),
            options: ThreeBodyOptions::default(),
            total_load: 1e-3,
        };
        for (setting, measured, law, velocity) in [
            (particle, Measured::FrictionCoefficient, Law::Local, 6e-9),
            (particle, Measured::ContactArea, Law::Local, 6e-9),
            (system, Measured::FrictionCoefficient, Law::Local, 6e-9),
            (particle, Measured::ParticleFriction, Law::Local, 6e-9),
            (system, Measured::ParticleFriction, Law::Local, 6e-9),
            (particle, Measured::ContactArea, Law::Continuum, 0.0),
            (particle, Measured::FrictionCoefficient, Law::Continuum, 0.0),
        ] {
            let point = Point {
                setting,
                velocity,
                measured,
            };
            let (y, s) = point
                .value_and_sensitivity(&base, law, Stop::NEVER)
                .unwrap();
            let (h, tolerance) = match law {
                Law::Local => (1e-4, 1e-4),
                Law::Continuum => (1e-3, 1e-3),
            };
            for parameter in FitParameter::ALL {
                if !base.arms.is_empty() && parameter.is_kelvin_time() {
                    continue;
                }
                let p = Parameterization {
                    base,
                    free: vec![parameter],
                    law,
                };
                let x = parameter.of(&base);
                let up = point
                    .value(&p.layer(&[x * (1.0 + h)]), law, Stop::NEVER)
                    .unwrap();
                let down = point
                    .value(&p.layer(&[x / (1.0 + h)]), law, Stop::NEVER)
                    .unwrap();
                let numeric = (up / down).ln() / (2.0 * (1.0 + h).ln());
                let analytic = p.log_derivatives(&s, base.kappa())[0];
                assert!(
                    (analytic - numeric).abs() < tolerance * numeric.abs().max(0.1),
                    "{setting:?} {measured:?} {law:?} {parameter:?}: {analytic} vs {numeric} \
                     (y = {y})"
                );
            }
        }
    }
}
