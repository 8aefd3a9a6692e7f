//! The three-body solve: the layer's law for the system's contact, the sums over the
//! particle sizes at one separation, and the separation at the operating point.

use std::sync::Arc;

use super::asperities::Zmc;
use super::contact::{squeeze, LayerLaw};
use super::curves::LayerCurves;
use super::state::{
    Areas, ContactState, Loads, SystemMotion, ThreeBodySolution, ThreeBodyVerification,
};
use super::system::{LayerContact, OperatingPoint, ThreeBody, ThreeBodyOptions};
use super::traction::Population;
use crate::counterface::{compliance, UpperLaw};
use crate::motion::{Mode, Motion};
use crate::quadrature::{gauss_legendre, GaussRule};
use crate::roots::brent;
use crate::similarity::SimilarityTable;
use crate::tables;
use crate::text::quantity;
use crate::{ModelError, Stop};

/// The substitution x = d + (x_max − d)τ⁴ turns the (x − d)^{3/2} edge of the integrands
/// into τ⁶: smooth enough for Gauss–Legendre to converge fast.
pub(super) const EDGE_POWER: i32 = 4;

/// Solves the three-body system (docs/model.md §4); with the `continuum` layer contact,
/// its curves are built here, to the end ([`LayerCurves::build`]; [`solve_with`] takes them
/// built, as a caller that may stop them builds them).
pub fn solve(
    system: &ThreeBody,
    options: &ThreeBodyOptions,
) -> Result<ThreeBodySolution, ModelError> {
    if let Some(e) = system.violations().into_iter().next() {
        return Err(e.into());
    }
    let curves = match system.layer_contact {
        LayerContact::Continuum => Some(LayerCurves::build(system, Stop::NEVER)?),
        _ => None,
    };
    solve_with(system, options, curves.as_ref())
}

/// [`solve`] with the continuum layer's curves given (needed for, and used only by, the
/// `continuum` layer contact).
pub fn solve_with(
    system: &ThreeBody,
    options: &ThreeBodyOptions,
    curves: Option<&LayerCurves>,
) -> Result<ThreeBodySolution, ModelError> {
    ModelError::check_inputs(system.violations(), options.violations())?;
    let table = kelvin_table(system, options)?;
    let layer_table_error = table.as_ref().map(|t| t.error());
    let (rolling_law, resting_law) = layer_laws(system, table, curves)?;
    let rolling = Model::new(system, rolling_law, options.diameter_nodes);
    let fixed = Model::new(system, resting_law, options.diameter_nodes);
    let (state, iterations, residual) = rolling.operate()?;
    let (static_state, ..) = if system.velocity > 0.0 && system.layer_contact != LayerContact::Hertz
    {
        fixed.operate()?
    } else {
        (state, iterations, residual)
    };
    let (motion, coarse_traction) = rolling.motion(&state, options.diameter_nodes)?;
    let quadrature_error_estimate = rolling
        .diameter_error(&state, options.diameter_nodes)?
        .max(relative_change(coarse_traction, motion.particle_traction));
    let layer_contact_error = (system.layer_contact == LayerContact::Continuum)
        .then(|| layer_contact_error(system, &state, &static_state, &motion));
    let solution = ThreeBodySolution {
        rolling: state,
        static_state,
        motion,
        verification: ThreeBodyVerification {
            diameter_nodes: options.diameter_nodes,
            separation_iterations: iterations,
            load_residual: residual,
            quadrature_error_estimate,
            layer_table_error,
            layer_contact_error,
            converged: true,
        },
    };
    ensure_finite(&solution)?;
    Ok(solution)
}

/// The similarity table behind the rolling Kelvin-layer contacts: solving each particle's
/// load equation through it rather than by strip sums is what makes a size sum affordable.
/// None at rest, or for a layer without viscosity, whose contacts are closed forms.
fn kelvin_table(
    system: &ThreeBody,
    options: &ThreeBodyOptions,
) -> Result<Option<Arc<SimilarityTable>>, ModelError> {
    let kappa = system.layer.kappa();
    Ok(match system.layer_contact {
        LayerContact::KelvinLayer if system.velocity > 0.0 && !system.layer.arms.is_empty() => {
            Some(Arc::new(tables::of_series(
                &system.layer,
                options.quadrature,
            )?))
        }
        LayerContact::KelvinLayer if system.velocity > 0.0 && kappa > 0.0 => {
            Some(tables::get_or_build(kappa, options.quadrature)?)
        }
        _ => None,
    })
}

/// The laws by which the layer takes a particle with rolling and at rest, for the system's
/// layer contact: the Kelvin layer's through `table` when rolling, Hertz's alike at both
/// speeds, the continuum's from its `curves`.
fn layer_laws(
    system: &ThreeBody,
    table: Option<Arc<SimilarityTable>>,
    curves: Option<&LayerCurves>,
) -> Result<(LayerLaw, LayerLaw), ModelError> {
    let layer = &system.layer;
    Ok(match (system.layer_contact, curves) {
        (LayerContact::KelvinLayer, _) => (
            LayerLaw::Kelvin {
                stiffness: layer.stiffness(),
                relaxation_length: system.velocity * layer.relaxation_time,
                table,
            },
            LayerLaw::Kelvin {
                stiffness: layer.stiffness(),
                relaxation_length: 0.0,
                table: None,
            },
        ),
        (LayerContact::Hertz, _) => {
            let hertz = LayerLaw::Hertz {
                modulus: Model::layer_modulus(system),
            };
            (hertz.clone(), hertz)
        }
        (LayerContact::Continuum, Some(curves)) => (
            LayerLaw::Continuum {
                curve: curves.rolling.clone(),
            },
            LayerLaw::Continuum {
                curve: curves.resting.clone(),
            },
        ),
        (LayerContact::Continuum, None) => {
            return Err(ModelError::OutOfModel(
                "the continuum layer contact needs its curves (LayerCurves)".to_string(),
            ))
        }
    })
}

/// The continuum contacts' bound on the error of A_s2a, W_a and Σ T, with rolling and at
/// rest, the worse. At a given load the force's error moves the separation, and the areas
/// and forces follow the load (A_s2a grows about as W does): the two errors add.
fn layer_contact_error(
    system: &ThreeBody,
    state: &ContactState,
    resting: &ContactState,
    motion: &SystemMotion,
) -> f64 {
    let moved = |s: &ContactState| match system.operating {
        OperatingPoint::Separation(_) => 0.0,
        _ => s.layer_load_error,
    };
    let bound = |s: &ContactState| s.layer_error + moved(s);
    bound(state)
        .max(bound(resting))
        .max(motion.traction_error + moved(state))
}

/// Refuses to hand out a non-finite number (serde_json would write it as a silent `null`).
fn ensure_finite(solution: &ThreeBodySolution) -> Result<(), ModelError> {
    let verification = &solution.verification;
    let numbers = [solution.rolling, solution.static_state]
        .into_iter()
        .flat_map(|s| {
            [
                s.separation,
                s.particles_in_contact,
                s.areas.total,
                s.areas.particle_layer,
                s.loads.total,
                s.friction_coefficient,
                s.mean_area().unwrap_or(0.0),
                s.mean_load().unwrap_or(0.0),
            ]
        });
    if numbers
        .chain([
            verification.load_residual,
            verification.quadrature_error_estimate,
            solution.motion.friction,
            solution.motion.particle_traction,
        ])
        .all(f64::is_finite)
    {
        Ok(())
    } else {
        Err(ModelError::NotRepresentable {
            what: "a result of this three-body job".to_string(),
        })
    }
}

/// |a/b − 1|, or 0 where b is.
fn relative_change(a: f64, b: f64) -> f64 {
    if b == 0.0 {
        0.0
    } else {
        (a / b - 1.0).abs()
    }
}

/// The system at one speed, ready to be evaluated at any separation.
#[derive(Clone, Debug)]
struct Model<'a> {
    system: &'a ThreeBody,
    upper: UpperLaw,
    layer: LayerLaw,
    zmc: Option<Zmc>,
    /// τ_a of the layer and τ_s of the softer surface (Pa).
    shear_strengths: (f64, f64),
    /// Gauss–Legendre nodes and weights on [−1, 1] for the diameters.
    nodes: GaussRule,
}

impl<'a> Model<'a> {
    fn new(system: &'a ThreeBody, layer_law: LayerLaw, nodes: usize) -> Self {
        let upper = &system.upper;
        let layer = &system.layer;
        let pair_modulus = 1.0
            / (compliance(upper.elastic_modulus, upper.poisson_ratio)
                + compliance(layer.elastic_modulus, layer.poisson_ratio));
        let (soft_modulus, soft_poisson) = if layer.elastic_modulus <= upper.elastic_modulus {
            (layer.elastic_modulus, layer.poisson_ratio)
        } else {
            (upper.elastic_modulus, upper.poisson_ratio)
        };
        Model {
            system,
            upper: upper.law(Self::particle_compliance(system)),
            layer: layer_law,
            zmc: system
                .asperities
                .map(|a| Zmc::new(a, pair_modulus, soft_poisson)),
            shear_strengths: (
                layer.interfacial_shear_strength(),
                soft_modulus / (2.0 * (1.0 + soft_poisson)) / 1000.0,
            ),
            nodes: gauss_legendre(nodes),
        }
    }

    /// (1 − ν_a²)/E_a of the particles (0 when rigid).
    fn particle_compliance(system: &ThreeBody) -> f64 {
        system
            .particle
            .elastic_modulus
            .map_or(0.0, |e| compliance(e, system.particle.poisson_ratio))
    }

    /// E_s2a of the layer and the particle (docs/model.md §4): a finite particle modulus
    /// enters the Hertz layer contact; the Kelvin-layer and continuum contacts take the
    /// particle rigid.
    fn layer_modulus(system: &ThreeBody) -> f64 {
        let layer = &system.layer;
        1.0 / (compliance(layer.elastic_modulus, layer.poisson_ratio)
            + Self::particle_compliance(system))
    }

    /// Every quantity of the system at separation d.
    fn state(&self, separation: f64) -> Result<ContactState, ModelError> {
        let system = self.system;
        let count = system.nominal_area * system.areal_density;
        let d = &system.diameters;
        let (mut a1, mut a2, mut load) = (0.0, 0.0, 0.0);
        // Σ A₂ε and Σ Fε, ε each contact's layer error.
        let (mut a2_error, mut load_error) = (0.0, 0.0);
        if d.is_single_size() {
            if d.mean > separation {
                let s = squeeze(&self.upper, &self.layer, d.mean, d.mean - separation)?;
                (a1, a2, load) = (s.upper_area, s.layer_area, s.force);
                (a2_error, load_error) = (a2 * s.layer_error, load * s.layer_error);
            }
        } else {
            let lo = separation.max(d.min);
            if lo < d.max {
                // x = d + L τ⁴ over τ ∈ [τ_lo, 1].
                let span = d.max - separation;
                let tau_lo = ((lo - separation) / span).powf(1.0 / f64::from(EDGE_POWER));
                let (x, w) = &*self.nodes;
                for (t, w) in x.iter().zip(w) {
                    let tau = tau_lo + (1.0 - tau_lo) * 0.5 * (t + 1.0);
                    let omega = span * tau.powi(EDGE_POWER);
                    let diameter = separation + omega;
                    let weight = w
                        * 0.5
                        * (1.0 - tau_lo)
                        * f64::from(EDGE_POWER)
                        * span
                        * tau.powi(EDGE_POWER - 1)
                        * d.density(diameter);
                    let s = squeeze(&self.upper, &self.layer, diameter, omega)?;
                    a1 += weight * s.upper_area;
                    a2 += weight * s.layer_area;
                    load += weight * s.force;
                    a2_error += weight * s.layer_area * s.layer_error;
                    load_error += weight * s.force * s.layer_error;
                }
            }
        }
        let largest = if d.max > separation {
            squeeze(&self.upper, &self.layer, d.max, d.max - separation)?.layer_penetration
        } else {
            0.0
        };
        let (surface_area, surface_load) = self
            .zmc
            .map_or((0.0, 0.0), |z| z.totals(separation, system.nominal_area));
        let areas = Areas {
            surface_surface: surface_area,
            particle_upper: count * a1,
            particle_layer: count * a2,
            total: surface_area + count * a1,
        };
        let loads = Loads {
            asperities: surface_load,
            particles: count * load,
            total: surface_load + count * load,
        };
        let (tau_a, tau_s) = self.shear_strengths;
        Ok(ContactState {
            separation,
            particles_in_contact: count * d.fraction_above(separation),
            areas,
            loads,
            max_layer_penetration: largest,
            friction_coefficient: (tau_a * areas.particle_layer + tau_s * areas.surface_surface)
                / loads.total,
            layer_error: if a2 > 0.0 {
                (a2_error / a2).max(load_error / load)
            } else {
                0.0
            },
            layer_load_error: if load > 0.0 { load_error / load } else { 0.0 },
        })
    }

    /// The largest relative change of the particle areas and load at `state`'s separation
    /// when the diameter nodes are halved (to no fewer than 2): the estimate of the size
    /// sum's quadrature error.
    fn diameter_error(&self, state: &ContactState, nodes: usize) -> Result<f64, ModelError> {
        let coarse = Model {
            nodes: gauss_legendre((nodes / 2).max(2)),
            ..self.clone()
        };
        let check = coarse.state(state.separation)?;
        Ok([
            relative_change(check.areas.particle_upper, state.areas.particle_upper),
            relative_change(check.areas.particle_layer, state.areas.particle_layer),
            relative_change(check.loads.particles, state.loads.particles),
        ]
        .into_iter()
        .fold(0.0, f64::max))
    }

    /// How the particles move at `state`'s separation (docs/model.md §11), their size sum
    /// under the model's nodes on each piece between changes of mode (the friction adds
    /// the asperities' τ_s A_s1s2 to the particles' Σ T, over W), and Σ T with half the
    /// `nodes`.
    fn motion(
        &self,
        state: &ContactState,
        nodes: usize,
    ) -> Result<(SystemMotion, f64), ModelError> {
        let separation = state.separation;
        let (tau_a, tau_s) = self.shear_strengths;
        let tau_u = self.system.upper.shear_strength();
        let population = Population {
            diameters: &self.system.diameters,
            separation,
            count: self.system.nominal_area * self.system.areal_density,
            particle: |diameter: f64| {
                let s = squeeze(&self.upper, &self.layer, diameter, diameter - separation)?;
                if s.force <= 0.0 {
                    // Touching, not squeezed (x = d to rounding): no load, nothing to roll.
                    let idle = Motion::new(0.0, 0.0, f64::INFINITY, f64::INFINITY);
                    return Ok((idle, 0.0, 0.0));
                }
                let radius = 0.5 * diameter;
                let shift = self.layer.pressure_centre(radius, s.layer_penetration);
                let motion = Motion::new(
                    0.0,
                    shift / radius,
                    tau_u * s.upper_area / s.force,
                    tau_a * s.layer_area / s.force,
                );
                // Rolling, T = F x_p/2R; sliding, τA (the upper A₁ ∝ F^{2/3}).
                let error = match motion.mode {
                    Mode::Rolls => {
                        s.layer_error + self.layer.pressure_error(radius, s.layer_penetration)
                    }
                    _ => s.layer_error,
                };
                Ok((motion, s.force, error))
            },
        };
        let coarse = gauss_legendre((nodes / 2).max(2));
        let (mut motion, coarse_traction) = population.motion(&self.nodes, &coarse)?;
        motion.friction =
            (motion.particle_traction + tau_s * state.areas.surface_surface) / state.loads.total;
        Ok((motion, coarse_traction))
    }

    /// The state at the operating point, the iterations of its separation root, and the
    /// relative residual of the load it was asked to carry.
    fn operate(&self) -> Result<(ContactState, u32, f64), ModelError> {
        let system = self.system;
        let d = &system.diameters;
        let top = match system.asperities {
            Some(a) => d.max.max(12.0 * a.height_std),
            None => d.max,
        };
        let (state, iterations, residual) = match system.operating {
            OperatingPoint::Separation(separation) => (self.state(separation)?, 0, 0.0),
            OperatingPoint::TotalLoad(target) => {
                self.solve_for(target, top, "total_load", |s| s.loads.total)?
            }
            OperatingPoint::ParticleLoad(target) => {
                self.solve_for(target, d.max, "particle_load", |s| {
                    if s.particles_in_contact > 0.0 {
                        s.loads.particles / s.particles_in_contact
                    } else {
                        0.0
                    }
                })?
            }
        };
        // The asperities alone may carry the load (no particle in contact: answered, with a
        // warning); with nothing in contact there is no load, and no friction coefficient.
        if state.loads.total <= 0.0 {
            return Err(ModelError::OutOfModel(format!(
                "nothing is in contact at separation d = {}: no particle (the largest is \
                 x_max = {}) and no asperity touches, so the system carries no load",
                quantity(state.separation, "m"),
                quantity(d.max, "m")
            )));
        }
        if state.max_layer_penetration > system.layer.thickness {
            return Err(ModelError::OutOfModel(format!(
                "the largest particle would penetrate the layer by {}, more than its \
                 thickness H = {}",
                quantity(state.max_layer_penetration, "m"),
                quantity(system.layer.thickness, "m")
            )));
        }
        Ok((state, iterations, residual))
    }

    /// Solves `carried(state(d)) = target` for d ∈ [0, top]; `carried` decreases with d.
    fn solve_for(
        &self,
        target: f64,
        top: f64,
        what: &str,
        carried: impl Fn(&ContactState) -> f64,
    ) -> Result<(ContactState, u32, f64), ModelError> {
        let most = carried(&self.state(0.0)?);
        if most < target {
            return Err(ModelError::OutOfModel(format!(
                "{what} = {} cannot be carried: even at zero separation the system carries \
                 only {}",
                quantity(target, "N"),
                quantity(most, "N")
            )));
        }
        let mut failure = None;
        let mismatch = |d: f64| match self.state(d) {
            Ok(s) => carried(&s) / target - 1.0,
            Err(e) => {
                failure.get_or_insert(e);
                f64::NAN
            }
        };
        let root = brent(
            mismatch,
            (0.0, most / target - 1.0),
            (top, -1.0 + carried(&self.state(top)?) / target),
            1e-15 * top,
            "separation at the operating point",
        );
        if let Some(e) = failure {
            return Err(e);
        }
        let root = root?;
        let state = self.state(root.x)?;
        Ok((
            state,
            root.iterations,
            (carried(&state) / target - 1.0).abs(),
        ))
    }
}
