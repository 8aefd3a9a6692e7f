//! The three-body system (docs/model.md §4): a population of hard particles, Gaussian in diameter,
//! squeezed between a rigid-backed upper surface and the viscoelastic layer, with optional
//! asperity contact; its real contact area, load and friction coefficient with and without
//! rolling, at a given separation, total load or mean particle load.

mod asperities;
mod contact;
mod distribution;

pub use asperities::{Asperities, Zmc};
pub use contact::{squeeze, LayerLaw, Squeeze, UpperLaw};
pub use distribution::Diameters;

use std::sync::Arc;

use super::continuum::ContinuumVerification;
use super::continuum::PenetrationCurve;
use super::quadrature::{gauss_legendre, GaussRule};
use super::roots::brent;
use super::tables;
use super::text::quantity;
use super::{
    Layer, ModelError, OptionError, Parameter, ParameterError, Quadrature, Rolling,
    RollingSolution, SolveOption, Stop,
};

/// Diameter nodes used when a job does not ask for a number: the particle sums then agree
/// with 512 nodes to better than 1e-10 (tested).
pub const DEFAULT_DIAMETER_NODES: usize = 48;
/// Largest number of diameter nodes offered.
pub const MAX_DIAMETER_NODES: usize = 1024;
/// The substitution x = d + (x_max − d)τ⁴ turns the (x − d)^{3/2} edge of the integrands
/// into τ⁶: smooth enough for Gauss–Legendre to converge fast.
const EDGE_POWER: i32 = 4;

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
}

impl Default for UpperSurface {
    /// Steel: 210 GPa, ν = 0.3 (docs/model.md §5).
    fn default() -> Self {
        UpperSurface {
            elastic_modulus: 210e9,
            poisson_ratio: 0.3,
            contact: UpperContact::Elastic,
            hardness: None,
        }
    }
}

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
    /// as in the Kelvin-layer contact: through [`LayerCurves`].
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
        let d = &self.diameters;
        let mut checks = vec![
            (MeanDiameter, d.mean),
            (StdDiameter, d.std),
            (MinDiameter, d.min),
            (MaxDiameter, d.max),
            (ArealDensity, self.areal_density),
            (NominalArea, self.nominal_area),
            (UpperModulus, self.upper.elastic_modulus),
            (UpperPoissonRatio, self.upper.poisson_ratio),
            (ParticlePoissonRatio, self.particle.poisson_ratio),
            (Velocity, self.velocity),
        ];
        checks.extend(self.upper.hardness.map(|h| (UpperHardness, h)));
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
        let mut errors: Vec<ParameterError> = checks
            .into_iter()
            .filter_map(|(p, v)| p.check(v).err())
            .collect();
        errors.extend(self.layer.violations());
        let diameters_valid = !errors.iter().any(|e| {
            matches!(
                e.parameter,
                MeanDiameter | StdDiameter | MinDiameter | MaxDiameter
            )
        });
        let mut add = |parameter, value, allowed: String| {
            errors.push(ParameterError {
                parameter,
                value,
                allowed,
            })
        };
        if !diameters_valid {
            // Bounds derived from an invalid mean or deviation say nothing more.
        } else if d.is_single_size() {
            if !(d.min <= d.mean && d.mean <= d.max) {
                add(
                    MaxDiameter,
                    d.max,
                    format!(
                        "x_min ≤ x_a ≤ x_max when σ_a = 0 (x_a = {})",
                        quantity(d.mean, "m")
                    ),
                );
            }
        } else if d.min >= d.max {
            add(
                MaxDiameter,
                d.max,
                format!("> minimum diameter {}", quantity(d.min, "m")),
            );
        } else if [d.mean, d.std, d.min, d.max].iter().all(|x| x.is_finite())
            && d.normaliser() <= 1e-300
        {
            add(
                MaxDiameter,
                d.max,
                format!(
                    "bounds that hold some of the Gaussian N({}, ({})²)",
                    quantity(d.mean, "m"),
                    quantity(d.std, "m")
                ),
            );
        }
        if self.upper.contact == UpperContact::Plastic && self.upper.hardness.is_none() {
            add(
                UpperHardness,
                f64::NAN,
                "a hardness (Pa) for plastic contact".to_string(),
            );
        }
        errors
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

/// Real contact areas (m²).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Areas {
    /// A_s1s2, asperities of the upper surface on the layer.
    pub surface_surface: f64,
    /// A_s1a, particles on the upper surface.
    pub particle_upper: f64,
    /// A_s2a, particles on the layer.
    pub particle_layer: f64,
    /// A_total = A_s1s2 + A_s1a (eq. 6).
    pub total: f64,
}

/// Loads carried (N).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Loads {
    /// W_s1s2.
    pub asperities: f64,
    /// W_a.
    pub particles: f64,
    /// W = W_s1s2 + W_a.
    pub total: f64,
}

/// The system at one separation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactState {
    /// d (m).
    pub separation: f64,
    /// n_a (eq. 7).
    pub particles_in_contact: f64,
    pub areas: Areas,
    pub loads: Loads,
    /// ω₂ of the largest particle (m): must stay below the layer thickness.
    pub max_layer_penetration: f64,
    /// μ = (τ_a A_s2a + τ_s A_s1s2)/W (eq. 12 summed).
    pub friction_coefficient: f64,
    /// A bound on the relative error of A_s2a and W_a from the layer contacts' law at this
    /// separation: their errors ([`Squeeze::layer_error`]) weighted by what each contact
    /// adds to the sums (0 for the closed-form laws).
    pub layer_error: f64,
    /// The same for W_a alone.
    pub layer_load_error: f64,
}

impl ContactState {
    /// A_total/n_a (eq. 8); `None` when no particle is in contact (the asperities carry
    /// the load alone).
    pub fn mean_area(&self) -> Option<f64> {
        self.per_particle(self.areas.total)
    }

    /// W/n_a; `None` when no particle is in contact.
    pub fn mean_load(&self) -> Option<f64> {
        self.per_particle(self.loads.total)
    }

    fn per_particle(&self, total: f64) -> Option<f64> {
        (self.particles_in_contact > 0.0).then(|| total / self.particles_in_contact)
    }
}

/// How far the answer can be trusted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThreeBodyVerification {
    pub diameter_nodes: usize,
    /// Iterations of the separation root (0 for a given separation).
    pub separation_iterations: u32,
    /// |W(d) − W|/W (or the same for the mean particle load) at the returned d.
    pub load_residual: f64,
    /// Largest relative change of the areas and loads when the diameter nodes are halved.
    pub quadrature_error_estimate: f64,
    /// Relative error of the `kelvin_layer` table against direct solves, when one is used.
    pub layer_table_error: Option<f64>,
    /// For the `continuum` layer contact: a bound on the relative error of A_s2a and W_a
    /// from the continuum contacts (their curves' errors, weighted over the sizes; at a
    /// given load, the load's error added, which moves the separation), with and without
    /// rolling, the worse.
    pub layer_contact_error: Option<f64>,
    pub converged: bool,
}

/// The three-body system with rolling (at the job's V) and without (V = 0).
#[derive(Clone, Debug, PartialEq)]
pub struct ThreeBodySolution {
    pub rolling: ContactState,
    pub static_state: ContactState,
    pub verification: ThreeBodyVerification,
}

/// The continuum layer's contacts a system with the `continuum` layer contact needs: at its
/// speed and at rest (one curve when it is at rest), each up to the largest c = √(Rδ) a
/// particle can reach, √((x_max/2)·max(H, x_max)): δ ≤ ω ≤ x_max for every separation
/// the operating point's root may try, and H keeps a layer thicker than the particles
/// covered to its thickness.
#[derive(Clone, Debug)]
pub struct LayerCurves {
    pub rolling: Arc<PenetrationCurve>,
    pub resting: Arc<PenetrationCurve>,
}

impl LayerCurves {
    /// The continuum problems whose answers make the curves of `system`, the rolling
    /// curve's first ([`PenetrationCurve::problems`]).
    pub fn problems(system: &ThreeBody) -> Vec<Rolling> {
        let (layer, reach) = (&system.layer, Self::reach(system));
        let mut problems = PenetrationCurve::problems(layer, system.velocity, reach);
        if system.velocity > 0.0 {
            problems.extend(PenetrationCurve::problems(layer, 0.0, reach));
        }
        problems
    }

    /// The curves of `system` from `solve_all`, which answers [`LayerCurves::problems`] in
    /// their order (in parallel, from a memo, or one after another, as the caller has it).
    pub fn solved_by<E>(
        system: &ThreeBody,
        solve_all: impl FnOnce(&[Rolling]) -> Result<Vec<RollingSolution<ContinuumVerification>>, E>,
    ) -> Result<LayerCurves, E> {
        let problems = Self::problems(system);
        let answers = solve_all(&problems)?;
        Ok(Self::from_answers(system, &problems, &answers))
    }

    /// The curves of `system`, solved here one problem after another, stopped when `stop`
    /// says so.
    pub fn build(system: &ThreeBody, stop: Stop) -> Result<LayerCurves, ModelError> {
        Self::solved_by(system, |problems| {
            problems
                .iter()
                .map(|p| PenetrationCurve::solve(p, stop))
                .collect()
        })
    }

    /// The curves from the answers to [`LayerCurves::problems`], in their order.
    fn from_answers(
        system: &ThreeBody,
        problems: &[Rolling],
        answers: &[RollingSolution<ContinuumVerification>],
    ) -> LayerCurves {
        let layer = &system.layer;
        let split = problems
            .iter()
            .position(|p| p.velocity != system.velocity)
            .unwrap_or(problems.len());
        let curve = |range: std::ops::Range<usize>, velocity: f64| {
            Arc::new(PenetrationCurve::from_answers(
                layer,
                velocity,
                &problems[range.clone()],
                &answers[range],
            ))
        };
        let rolling = curve(0..split, system.velocity);
        let resting = if split < problems.len() {
            curve(split..problems.len(), 0.0)
        } else {
            rolling.clone()
        };
        LayerCurves { rolling, resting }
    }

    fn reach(system: &ThreeBody) -> f64 {
        let x_max = system.diameters.max;
        (0.5 * x_max * system.layer.thickness.max(x_max)).sqrt()
    }
}

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
    if let Some(e) = system.violations().into_iter().next() {
        return Err(e.into());
    }
    if let Some(e) = options.violations().into_iter().next() {
        return Err(ModelError::InvalidOption(e));
    }
    let kappa = system.layer.kappa();
    let table = match system.layer_contact {
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
    };
    let layer_table_error = table.as_ref().map(|t| t.error());
    let layer = &system.layer;
    let (rolling_law, resting_law) = match (system.layer_contact, curves) {
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
    };
    let rolling = Model::new(system, rolling_law, options.diameter_nodes);
    let fixed = Model::new(system, resting_law, options.diameter_nodes);
    let (state, iterations, residual) = rolling.operate()?;
    let (static_state, ..) = if system.velocity > 0.0 && system.layer_contact != LayerContact::Hertz
    {
        fixed.operate()?
    } else {
        (state, iterations, residual)
    };
    let coarse = Model {
        nodes: gauss_legendre((options.diameter_nodes / 2).max(2)),
        ..rolling.clone()
    };
    let check = coarse.state(state.separation)?;
    let change = |a: f64, b: f64| if b == 0.0 { 0.0 } else { (a / b - 1.0).abs() };
    let quadrature_error_estimate = [
        change(check.areas.particle_upper, state.areas.particle_upper),
        change(check.areas.particle_layer, state.areas.particle_layer),
        change(check.loads.particles, state.loads.particles),
    ]
    .into_iter()
    .fold(0.0, f64::max);
    let solution = ThreeBodySolution {
        rolling: state,
        static_state,
        verification: ThreeBodyVerification {
            diameter_nodes: options.diameter_nodes,
            separation_iterations: iterations,
            load_residual: residual,
            quadrature_error_estimate,
            layer_table_error,
            layer_contact_error: (system.layer_contact == LayerContact::Continuum).then(|| {
                // At a given load the force's error moves the separation, and the areas
                // follow the load (A_s2a grows about as W does): the two errors add.
                let bound = |s: &ContactState| match system.operating {
                    OperatingPoint::Separation(_) => s.layer_error,
                    _ => s.layer_error + s.layer_load_error,
                };
                bound(&state).max(bound(&static_state))
            }),
            converged: true,
        },
    };
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
        .chain([residual, quadrature_error_estimate])
        .all(f64::is_finite)
    {
        Ok(solution)
    } else {
        Err(ModelError::NotRepresentable {
            what: "a result of this three-body job".to_string(),
        })
    }
}

/// (1 − ν²)/E.
fn compliance(modulus: f64, poisson_ratio: f64) -> f64 {
    (1.0 - poisson_ratio * poisson_ratio) / modulus
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
        let upper_modulus = 1.0
            / (compliance(upper.elastic_modulus, upper.poisson_ratio)
                + Self::particle_compliance(system));
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
            upper: match (upper.contact, upper.hardness) {
                (UpperContact::Plastic, Some(hardness)) => UpperLaw::Plastic { hardness },
                _ => UpperLaw::Elastic {
                    modulus: upper_modulus,
                },
            },
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
