//! The three-body job: a population of particles between the upper surface and the layer
//! (docs/model.md §4).

mod picture;
pub use picture::ThreeBodyPicture;

use std::collections::HashSet;
use std::sync::LazyLock;

use serde::{Deserialize, Serialize};
use serde_json::Value;
use utoipa::ToSchema;

use super::input::{
    self, field, Checker, LayerInput, LayerModel, QuadratureKind, Quantity, UpperSurfaceInput,
};
use super::meta::{Canonical, REFERENCES, THREE_BODY_CONTINUUM_REFERENCES};
use super::points::{self, PointNotes, PointNotesFields, PointStatus, Row};
use super::rolling::{MotionMode, MotionOutput, RollingJob};
use super::validity::{self, PointValidity, Subject, ValidityOutput};
use super::{rolling, Control, Cost, JobError, Kind, Limits, Meta, References, Validated, Work};
use crate::model::continuum::{self, ContinuumVerification, PenetrationCurve};
use crate::model::three_body::{
    self, Asperities, ContactState, Diameters, LayerContact, LayerCurves, OperatingPoint, Particle,
    SystemMotion, ThreeBody, ThreeBodyOptions, ThreeBodySolution, DEFAULT_DIAMETER_NODES,
};
use crate::model::{
    Layer, ModelError, Parameter, Rolling, RollingSolution, SolveOption, SolveOptions, Stop,
    MODEL_VERSION,
};
use crate::render::{fields, Column, Output, Table, UnitTable};
use crate::{described, unit_table};

/// Input of a three-body job; every field optional but the operating point.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"distribution": {"mean_diameter": "50 nm", "std_diameter": "5 nm",
    "areal_density": "1e12 1/m^2"}, "operating": {"total_load": "1 mN"}, "velocity": "4 nm/s"}))]
pub struct ThreeBodyInput {
    pub distribution: Option<DistributionInput>,
    /// A_n (m²).
    pub nominal_area: Option<Quantity>,
    pub upper_surface: Option<UpperSurfaceInput>,
    pub particle: Option<ParticleInput>,
    pub layer: Option<LayerInput>,
    pub layer_contact: Option<LayerContactKind>,
    /// Asperity contact (Zhao–Maietta–Chang); none unless given, then all four fields.
    pub asperities: Option<AsperitiesInput>,
    /// V, rolling speed of the particles (m/s).
    pub velocity: Option<Quantity>,
    /// Exactly one of `separation`, `total_load`, `particle_load`.
    pub operating: Option<OperatingInput>,
    pub options: Option<ThreeBodyOptionsInput>,
}

/// Particle diameters: a truncated Gaussian, and how many particles per unit area.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct DistributionInput {
    /// x_a (m), default 50 nm.
    pub mean_diameter: Option<Quantity>,
    /// σ_a (m), default 5 nm; 0 for particles of one size.
    pub std_diameter: Option<Quantity>,
    /// x_min (m), default max(x_a − 3σ_a, 0).
    pub min_diameter: Option<Quantity>,
    /// x_max (m), default x_a + 3σ_a.
    pub max_diameter: Option<Quantity>,
    /// η_a (m⁻²), default 1e12.
    pub areal_density: Option<Quantity>,
}

/// The particles' material: rigid unless `elastic_modulus` is given.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ParticleInput {
    /// E_a (Pa); absent for rigid particles.
    pub elastic_modulus: Option<Quantity>,
    /// ν_a, default 0.3.
    pub poisson_ratio: Option<Quantity>,
}

/// The layer contact law.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum LayerContactKind {
    /// The rolling contact of docs/model.md §3 at the job's speed (default).
    KelvinLayer,
    /// Hertz (the paper's eq. 6 reading).
    Hertz,
    /// The layer as a continuum (docs/model.md §8) at the job's speed: each particle's
    /// contact is the single-particle continuum answer, through a curve over the contact's
    /// size built once per layer and speed (about a second).
    Continuum,
}

/// Asperities of the rough pair.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct AsperitiesInput {
    /// η_s (m⁻²).
    pub density: Option<Quantity>,
    /// β_s (m).
    pub tip_radius: Option<Quantity>,
    /// σ_s (m).
    pub height_std: Option<Quantity>,
    /// H_s of the softer surface (Pa).
    pub hardness: Option<Quantity>,
}

/// The operating point: exactly one field.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct OperatingInput {
    /// d (m).
    pub separation: Option<Quantity>,
    /// W (N).
    pub total_load: Option<Quantity>,
    /// Mean load per particle in contact (N).
    pub particle_load: Option<Quantity>,
}

/// Discretisation.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ThreeBodyOptionsInput {
    /// Gauss nodes over the diameters (default 48).
    pub diameter_nodes: Option<usize>,
    /// The strip rule of the rolling contacts (as for rolling jobs).
    pub quadrature: Option<QuadratureKind>,
    pub strips: Option<usize>,
}

impl DistributionInput {
    /// The diameters and the areal density; bounds default to x_a ∓ 3σ_a (never below 0).
    fn read(&self, checker: &mut Checker, defaults: &ThreeBody) -> (Diameters, f64) {
        let input = self;
        let d0 = defaults.diameters;
        let mean = checker.quantity(
            field!(input.mean_diameter),
            Parameter::MeanDiameter,
            d0.mean,
        );
        let std = checker.quantity(field!(input.std_diameter), Parameter::StdDiameter, d0.std);
        let bounds = Diameters::with_default_bounds(mean, std);
        let diameters = Diameters {
            mean,
            std,
            min: checker.quantity(
                field!(input.min_diameter),
                Parameter::MinDiameter,
                bounds.min,
            ),
            max: checker.quantity(
                field!(input.max_diameter),
                Parameter::MaxDiameter,
                bounds.max,
            ),
        };
        let areal_density = checker.quantity(
            field!(input.areal_density),
            Parameter::ArealDensity,
            defaults.areal_density,
        );
        (diameters, areal_density)
    }
}

impl ParticleInput {
    fn read(&self, checker: &mut Checker) -> Particle {
        let input = self;
        Particle {
            elastic_modulus: checker
                .optional(field!(input.elastic_modulus), Parameter::ParticleModulus),
            poisson_ratio: checker.quantity(
                field!(input.poisson_ratio),
                Parameter::ParticlePoissonRatio,
                Particle::default().poisson_ratio,
            ),
        }
    }

    fn of(particle: &Particle) -> ParticleInput {
        ParticleInput {
            elastic_modulus: particle.elastic_modulus.and_then(Quantity::si),
            poisson_ratio: Quantity::si(particle.poisson_ratio),
        }
    }
}

impl AsperitiesInput {
    /// Every field is required once asperities are given.
    fn read(&self, checker: &mut Checker) -> Asperities {
        let input = self;
        let why = "with asperities";
        Asperities {
            density: checker.required(field!(input.density), Parameter::AsperityDensity, why),
            tip_radius: checker.required(field!(input.tip_radius), Parameter::TipRadius, why),
            height_std: checker.required(field!(input.height_std), Parameter::HeightStd, why),
            hardness: checker.required(field!(input.hardness), Parameter::AsperityHardness, why),
        }
    }

    fn of(a: &Asperities) -> AsperitiesInput {
        AsperitiesInput {
            density: Quantity::si(a.density),
            tip_radius: Quantity::si(a.tip_radius),
            height_std: Quantity::si(a.height_std),
            hardness: Quantity::si(a.hardness),
        }
    }
}

/// The operating-point fields of `$input`, an input or a sweep's lists (which name them
/// alike), in the order of [`OperatingPoint::KINDS`], each as `$field!` makes it
/// ([`field!`] to read, [`slot!`] to write): the one place naming them.
macro_rules! operating_fields {
    ($field:ident!($input:ident)) => {
        [
            $field!($input.separation),
            $field!($input.total_load),
            $field!($input.particle_load),
        ]
    };
}
pub(crate) use operating_fields;

/// A field of `$input` to write.
macro_rules! slot {
    ($input:ident . $name:ident) => {
        &mut $input.$name
    };
}
pub(crate) use slot;

impl OperatingInput {
    /// Every operating point given (a valid input gives exactly one).
    fn read(&self, checker: &mut Checker) -> Vec<OperatingPoint> {
        let input = self;
        operating_fields!(field!(input))
            .into_iter()
            .zip(OperatingPoint::KINDS)
            .filter_map(|(field, (parameter, point))| checker.optional(field, parameter).map(point))
            .collect()
    }

    /// The input of one operating point.
    pub fn of(operating: OperatingPoint) -> OperatingInput {
        let mut input = OperatingInput::default();
        let slots = operating_fields!(slot!(input));
        *slots[operating.kind()] = Quantity::si(operating.value());
        input
    }
}

impl ThreeBodyOptionsInput {
    fn read(&self, checker: &mut Checker) -> ThreeBodyOptions {
        let input = self;
        let strips = checker.count(field!(input.strips), SolveOption::Strips);
        ThreeBodyOptions {
            diameter_nodes: checker
                .count(field!(input.diameter_nodes), SolveOption::DiameterNodes)
                .unwrap_or(DEFAULT_DIAMETER_NODES),
            quadrature: QuadratureKind::rule(self.quadrature, strips),
        }
    }
}

/// A validated three-body job.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThreeBodyJob {
    pub system: ThreeBody,
    pub options: ThreeBodyOptions,
}

impl ThreeBodyJob {
    /// Reads `input` under `checker` (bad fields are recorded there and read as NaN).
    pub fn read(input: &ThreeBodyInput, checker: &mut Checker) -> ThreeBodyJob {
        let defaults = ThreeBody::with_defaults(OperatingPoint::Separation(0.0));
        let (diameters, areal_density) =
            checker.nested(field!(input.distribution), |c, d| d.read(c, &defaults));
        let nominal_area = checker.quantity(
            field!(input.nominal_area),
            Parameter::NominalArea,
            defaults.nominal_area,
        );
        let upper = checker.nested(field!(input.upper_surface), |c, u| u.read(c));
        let particle = checker.nested(field!(input.particle), |c, p| p.read(c));
        let asperities = input
            .asperities
            .is_some()
            .then(|| checker.nested(field!(input.asperities), |c, a| a.read(c)));
        let velocity = checker.quantity(
            field!(input.velocity),
            Parameter::Velocity,
            defaults.velocity,
        );
        let given = checker.nested(field!(input.operating), |c, o| o.read(c));
        let operating = match given.as_slice() {
            [one] => *one,
            _ => {
                let name = field!(input.operating).name;
                let allowed = "exactly one of separation (m), total_load (N), particle_load (N)";
                match &input.operating {
                    Some(sent) => checker.invalid(name, input::canonical(sent), allowed),
                    None => checker.missing(name, allowed, ""),
                }
                OperatingPoint::Separation(f64::NAN)
            }
        };
        let layer = checker.nested(field!(input.layer), |c, l| {
            l.read_local(
                c,
                "a three-body system takes the layer as a continuum through \"layer_contact\": \
                 \"continuum\"",
            )
        });
        let options = checker.nested(field!(input.options), |c, o| o.read(c));
        let system = ThreeBody {
            diameters,
            areal_density,
            nominal_area,
            upper,
            particle,
            layer,
            layer_contact: match input.layer_contact {
                Some(LayerContactKind::Hertz) => LayerContact::Hertz,
                Some(LayerContactKind::Continuum) => LayerContact::Continuum,
                _ => LayerContact::KelvinLayer,
            },
            asperities,
            velocity,
            operating,
        };
        checker.parameters(system.violations());
        checker.options(options.violations());
        ThreeBodyJob { system, options }
    }

    /// The input that gives this job: every field, in SI.
    pub fn input(&self) -> ThreeBodyInput {
        let s = &self.system;
        let d = &s.diameters;
        let (quadrature, strips) = QuadratureKind::of(self.options.quadrature);
        ThreeBodyInput {
            distribution: Some(DistributionInput {
                mean_diameter: Quantity::si(d.mean),
                std_diameter: Quantity::si(d.std),
                min_diameter: Quantity::si(d.min),
                max_diameter: Quantity::si(d.max),
                areal_density: Quantity::si(s.areal_density),
            }),
            nominal_area: Quantity::si(s.nominal_area),
            upper_surface: Some(UpperSurfaceInput::of(&s.upper)),
            particle: Some(ParticleInput::of(&s.particle)),
            layer: Some(LayerInput::of(&s.layer, None)),
            layer_contact: Some(match s.layer_contact {
                LayerContact::KelvinLayer => LayerContactKind::KelvinLayer,
                LayerContact::Hertz => LayerContactKind::Hertz,
                LayerContact::Continuum => LayerContactKind::Continuum,
            }),
            asperities: s.asperities.as_ref().map(AsperitiesInput::of),
            velocity: Quantity::si(s.velocity),
            operating: Some(OperatingInput::of(s.operating)),
            options: Some(ThreeBodyOptionsInput {
                diameter_nodes: Some(self.options.diameter_nodes),
                quadrature: Some(quadrature),
                strips: Some(strips),
            }),
        }
    }
}

impl Kind for ThreeBodyJob {
    const NAME: &'static str = "three_body";
    type Input = ThreeBodyInput;
    type Output = ThreeBodyOutput;

    /// On the continuum, a system one of whose layer curves' nodes would pass the grid's
    /// cap is refused here.
    fn validate(input: Value, _limits: &Limits) -> Result<Validated<Self>, JobError> {
        input::validate(input, |input, checker| {
            let job = ThreeBodyJob::read(input, checker);
            let system = job.system;
            if system.layer_contact == LayerContact::Continuum && system.violations().is_empty() {
                let problems = |layer: &Layer| {
                    LayerCurves::problems(&ThreeBody {
                        layer: *layer,
                        ..system
                    })
                };
                rolling::continuum::check(&system.layer, &problems, checker);
            }
            job
        })
    }

    /// A valid input itself.
    fn canonical(&self) -> Value {
        input::canonical(&self.input())
    }

    fn canonical_text(&self) -> Canonical {
        input::canonical_text(&self.input())
    }

    fn references(&self) -> &'static References {
        references(&self.system)
    }

    /// The system, and on the continuum each node of its layer's curves.
    fn work(&self) -> Work {
        Work::Known(1 + self.continuum_problems().len())
    }

    fn cost(&self) -> Cost {
        system_cost(&self.system, &mut Nodes::default())
    }

    /// A system on the continuum costs a second, a thousand times one on the local law.
    fn cost_class(&self) -> &'static str {
        match self.system.layer_contact {
            LayerContact::Continuum => "three_body on the continuum",
            _ => Self::NAME,
        }
    }

    fn run(&self, meta: Meta, control: &Control) -> Result<ThreeBodyOutput, JobError> {
        let curves = match self.system.layer_contact {
            LayerContact::Continuum => Some(LayerCurves::solved_by(&self.system, |problems| {
                control.map(problems, kept_node(control))
            })?),
            _ => None,
        };
        let solution = control
            .solve(|_| three_body::solve_with(&self.system, &self.options, curves.as_ref()))?;
        ThreeBodyOutput::new(&self.system, &solution, meta)
    }
}

impl ThreeBodyJob {
    /// The continuum problems of the system's layer curves (none off the continuum).
    fn continuum_problems(&self) -> Vec<Rolling> {
        match self.system.layer_contact {
            LayerContact::Continuum => LayerCurves::problems(&self.system),
            _ => Vec::new(),
        }
    }
}

/// The papers behind `system`'s answer: the continuum's besides the model's when its layer
/// contact is the continuum.
pub fn references(system: &ThreeBody) -> &'static References {
    match system.layer_contact {
        LayerContact::Continuum => &THREE_BODY_CONTINUUM_REFERENCES,
        _ => &REFERENCES,
    }
}

/// The nodes of continuum layer curves counted already (as a job's memo shares them):
/// their sphere, load and speed, and their layer's modulus, thickness and times.
pub type Nodes = HashSet<[u64; 7]>;

/// What solving `system` costs: a point, and on the continuum each node of its layer's
/// curves not in `counted` (which it joins) as the continuum answer it is.
pub fn system_cost(system: &ThreeBody, counted: &mut Nodes) -> Cost {
    let nodes = match system.layer_contact {
        LayerContact::Continuum => LayerCurves::problems(system),
        _ => Vec::new(),
    };
    nodes
        .iter()
        .filter(|p| {
            let l = &p.layer;
            counted.insert(
                [
                    p.radius,
                    p.load,
                    p.velocity,
                    l.elastic_modulus,
                    l.thickness,
                    l.relaxation_time,
                    l.retardation_time,
                ]
                .map(f64::to_bits),
            )
        })
        .map(|p| {
            continuum::plan(p, continuum::PER_RADIUS)
                .map_or(Cost::points(1), |plan| Cost::continuum(&plan))
        })
        .fold(Cost::points(1), Cost::then)
}

/// Solves one node of a continuum layer curve, kept in `control`'s memo: every system on
/// the same layer at the same speed shares its nodes (a sweep's points, a retry).
pub fn kept_node(
    control: &Control,
) -> impl Fn(&Rolling) -> Result<RollingSolution<ContinuumVerification>, ModelError> + Sync + '_ {
    control.kept(
        |p: &Rolling| {
            // The node as a rolling contact on the continuum: its canonical text.
            let node = RollingJob {
                rolling: *p,
                upper: Default::default(),
                options: SolveOptions::default(),
                law: LayerModel::Continuum,
            };
            let text = Kind::canonical_text(&node);
            format!("{MODEL_VERSION} continuum curve node {}", text.get())
        },
        |_| std::mem::size_of::<RollingSolution<ContinuumVerification>>(),
        move |p: &Rolling| {
            let asked = || control.must_stop();
            PenetrationCurve::solve(p, Stop::when(&asked))
        },
    )
}

/// `system` solved, its continuum curves (if any) built here from nodes kept in `control`'s
/// memo, one after another (a sweep's points are solved in parallel already).
pub fn solve_kept(
    system: &ThreeBody,
    options: &ThreeBodyOptions,
    control: &Control,
) -> Result<ThreeBodySolution, ModelError> {
    let curves = match system.layer_contact {
        LayerContact::Continuum => Some(LayerCurves::solved_by(system, |problems| {
            problems.iter().map(kept_node(control)).collect()
        })?),
        _ => None,
    };
    three_body::solve_with(system, options, curves.as_ref())
}

/// `{"separation": d}`, `{"total_load": W}` or `{"particle_load": P}`.
pub fn operating_canonical(operating: OperatingPoint) -> Value {
    input::canonical(&OperatingInput::of(operating))
}

described! {
    /// Real contact areas (m²).
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct AreasOutput {
        /// A_s1s2, asperity contact of the two surfaces.
        pub surface_surface: f64 => [number "m²"],
        /// A_s1a, particles on the upper surface.
        pub particle_upper: f64 => [number "m²"],
        /// A_s2a, particles on the layer.
        pub particle_layer: f64 => [number "m²"],
        /// A_total = A_s1s2 + A_s1a (eq. 6).
        pub total: f64 => [number "m²"],
    }
}

described! {
    /// Loads (N).
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct LoadsOutput {
        pub asperities: f64 => [number "N"],
        pub particles: f64 => [number "N"],
        pub total: f64 => [number "N"],
    }
}

described! {
    /// The system at one separation.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct StateOutput {
        /// d (m).
        pub separation: f64 => [number "m"],
        /// n_a (eq. 7).
        pub particles_in_contact: f64 => [number ""],
        pub areas: AreasOutput => [nested "area_"],
        pub loads: LoadsOutput => [nested "load_"],
    }
}

impl From<&ContactState> for StateOutput {
    fn from(s: &ContactState) -> Self {
        StateOutput {
            separation: s.separation,
            particles_in_contact: s.particles_in_contact,
            areas: AreasOutput {
                surface_surface: s.areas.surface_surface,
                particle_upper: s.areas.particle_upper,
                particle_layer: s.areas.particle_layer,
                total: s.areas.total,
            },
            loads: LoadsOutput {
                asperities: s.loads.asperities,
                particles: s.loads.particles,
                total: s.loads.total,
            },
        }
    }
}

described! {
    /// μ = (τ_a A_s2a + τ_s A_s1s2)/W without and with rolling: eq. 12 summed, the paper's
    /// adhesive law (every particle's layer contact transmitting all it can). The system's
    /// friction with each particle's own motion is `motion.friction` (docs/model.md §11).
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct FrictionOutput {
        /// V = 0 (the job's separation, or its load re-solved at V = 0).
        pub r#static: f64 => [number ""],
        /// At the job's V.
        pub rolling: f64 => [number ""],
    }
}

described! {
    /// Roll or slide, particle by particle (docs/model.md §11): each size, at the load it
    /// carries, rolls if both its contacts transmit the tangential force rolling needs, and
    /// slides at the weaker otherwise.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct SystemMotionOutput {
        /// (Σ T + τ_s A_s1s2)/W: the system's friction, each particle transmitting the
        /// tangential force T of its own motion (dimensionless).
        pub friction: f64 => [number ""],
        /// Σ T, the particles' tangential forces (N).
        pub particle_traction: f64 => [number "N"],
        /// Particles in contact that roll (count).
        pub rolling: f64 => [number ""],
        /// Particles that slide on the layer (count).
        pub sliding_at_layer: f64 => [number ""],
        /// Particles that slide against the upper surface (count).
        pub sliding_at_upper: f64 => [number ""],
        /// Where the mode changes, in ascending diameter.
        pub changes: Vec<ModeChangeOutput> => [each],
        /// The balance of the particle in contact furthest from rolling (the largest need
        /// over its weaker capacity): its mode, need, capacities and friction. Absent with
        /// no particle in contact.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub furthest: Option<MotionOutput> => [optional nested],
    }
}

described! {
    /// A diameter where the particles' mode changes.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct ModeChangeOutput {
        /// x (m).
        pub diameter: f64 => [unit "m"],
        /// The mode of the particles just smaller.
        pub below: MotionMode => [],
        /// The mode of the particles just larger.
        pub above: MotionMode => [],
    }
}

impl From<&SystemMotion> for SystemMotionOutput {
    fn from(m: &SystemMotion) -> Self {
        SystemMotionOutput {
            friction: m.friction,
            particle_traction: m.particle_traction,
            rolling: m.rolling,
            sliding_at_layer: m.sliding_at_layer,
            sliding_at_upper: m.sliding_at_upper,
            changes: m
                .changes
                .iter()
                .map(|change| ModeChangeOutput {
                    diameter: change.diameter,
                    below: change.below.into(),
                    above: change.above.into(),
                })
                .collect(),
            furthest: m.furthest.as_ref().map(MotionOutput::from),
        }
    }
}

described! {
    /// Per particle in contact.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct PerParticleOutput {
        /// A_total/n_a (m², eq. 8).
        pub mean_area: f64 => [number "m²"],
        /// W/n_a (N).
        pub mean_load: f64 => [number "N"],
    }
}

described! {
    /// How far the answer can be trusted.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct ThreeBodyVerificationOutput {
        pub diameter_nodes: usize => [unit ""],
        pub separation_iterations: u32 => [unit ""],
        /// Relative residual of the operating load at the returned separation.
        pub relative_load_residual: f64 => [unit ""],
        /// Largest relative change of areas, loads and the particles' Σ T with half the
        /// diameter nodes.
        pub quadrature_error_estimate: f64 => [unit ""],
        /// Relative error of the kelvin_layer table against direct solves (when used).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub layer_table_error: Option<f64> => [unit ""],
        /// On the continuum layer contact: a bound on the relative error of the particles'
        /// layer areas and loads, and of their tangential forces (`motion`), from the
        /// continuum contacts (each contact's discretisation error and its curve's
        /// interpolation, weighted over the sizes; at a given load the load's error added,
        /// as it moves the separation), with and without rolling, the worse.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub layer_contact_error: Option<f64> => [unit ""],
        pub converged: bool => [],
    }
}

impl ThreeBodyVerificationOutput {
    /// The worse of two answers' errors, field by field (a sweep's, over its points).
    pub fn worst(&self, other: &ThreeBodyVerificationOutput) -> ThreeBodyVerificationOutput {
        ThreeBodyVerificationOutput {
            diameter_nodes: self.diameter_nodes.min(other.diameter_nodes),
            separation_iterations: self.separation_iterations.max(other.separation_iterations),
            relative_load_residual: self
                .relative_load_residual
                .max(other.relative_load_residual),
            quadrature_error_estimate: self
                .quadrature_error_estimate
                .max(other.quadrature_error_estimate),
            layer_table_error: worse(self.layer_table_error, other.layer_table_error),
            layer_contact_error: worse(self.layer_contact_error, other.layer_contact_error),
            converged: self.converged && other.converged,
        }
    }
}

/// The larger of two optional errors; the one given when only one is.
fn worse(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    }
}

described! {
    /// The results of a three-body solve, shared by answers and sweep points.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct ThreeBodyResult {
        #[serde(flatten)]
        pub state: StateOutput => [flatten],
        pub friction_coefficient: FrictionOutput => [nested "friction_"],
        /// How the particles move with rolling, and the friction they then transmit.
        pub motion: SystemMotionOutput => [nested "motion_"],
        /// Means per particle in contact; absent when no particle is in contact (the
        /// asperities carry the load alone).
        #[serde(skip_serializing_if = "Option::is_none")]
        pub per_particle: Option<PerParticleOutput> => [optional nested ""],
        /// The same system at V = 0.
        pub static_operating_point: StateOutput => [nested],
    }
}

impl From<&ThreeBodySolution> for ThreeBodyResult {
    fn from(s: &ThreeBodySolution) -> Self {
        ThreeBodyResult {
            state: (&s.rolling).into(),
            friction_coefficient: FrictionOutput {
                r#static: s.static_state.friction_coefficient,
                rolling: s.rolling.friction_coefficient,
            },
            motion: (&s.motion).into(),
            per_particle: s.rolling.mean_area().zip(s.rolling.mean_load()).map(
                |(mean_area, mean_load)| PerParticleOutput {
                    mean_area,
                    mean_load,
                },
            ),
            static_operating_point: (&s.static_state).into(),
        }
    }
}

impl From<&ThreeBodySolution> for ThreeBodyVerificationOutput {
    fn from(s: &ThreeBodySolution) -> Self {
        let v = &s.verification;
        ThreeBodyVerificationOutput {
            diameter_nodes: v.diameter_nodes,
            separation_iterations: v.separation_iterations,
            relative_load_residual: v.load_residual,
            quadrature_error_estimate: v.quadrature_error_estimate,
            layer_table_error: v.layer_table_error,
            layer_contact_error: v.layer_contact_error,
            converged: v.converged,
        }
    }
}

described! {
    /// The `meta` block of a three-body answer.
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct ThreeBodyMeta {
        #[serde(flatten)]
        pub meta: Meta => [],
        pub verification: ThreeBodyVerificationOutput => [nested],
        /// How far the model can be trusted here (docs/model.md §7).
        pub validity: ValidityOutput => [nested],
    }
}

described! {
    /// The answer to a three-body job.
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct ThreeBodyOutput {
        #[serde(flatten)]
        pub result: ThreeBodyResult => [flatten],
        pub meta: ThreeBodyMeta => [nested],
        /// The system solved (its operating point, speed and mean diameter are in
        /// `meta.input` on the wire; the CSV row needs them).
        #[serde(skip)]
        system: ThreeBody => [],
        /// The validity's checks, for the CSV row.
        #[serde(skip)]
        checks: PointValidity => [],
    }
}

impl ThreeBodyOutput {
    /// The answer for `system`, solved as `solution`, with `meta`, the job's [`Meta`];
    /// refused where the model's domain excludes it.
    pub fn new(
        system: &ThreeBody,
        solution: &ThreeBodySolution,
        meta: Meta,
    ) -> Result<Self, JobError> {
        let checks = crate::model::validity::three_body(system, solution);
        Ok(ThreeBodyOutput {
            result: solution.into(),
            meta: ThreeBodyMeta {
                meta,
                verification: solution.into(),
                validity: validity::assess(&checks, Subject::System)?,
            },
            system: *system,
            checks: PointValidity::assess(checks, Subject::System)?,
        })
    }
}

impl Output for ThreeBodyOutput {
    const UNITS: &'static UnitTable = unit_table!(ThreeBodyOutput);
    type Picture = ThreeBodyPicture;

    /// One row: the system's operating point, speed and mean diameter and its results, as a
    /// sweep's row.
    fn table(&self) -> Table {
        let point = ThreeBodySweepPoint::answered(
            &self.system,
            self.result.clone(),
            self.meta.verification.clone(),
            self.checks.clone(),
        );
        ThreeBodySweepPoint::table(&[point])
    }
}

described! {
    /// One row of a three-body sweep: the point's conditions, its status, and (answered) its
    /// results and the ratios of the model's assumptions, or (refused) the reason.
    // Also the CSV row of a three-body answer: one declaration of the columns of systems.
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct ThreeBodySweepPoint {
        /// The operating point as asked: `{"separation": d}`, `{"total_load": W}` or
        /// `{"particle_load": P}` (SI).
        #[schema(value_type = BTreeMap<String, f64>)]
        pub operating: Value => [by operating_units().to_vec()],
        /// V (m/s).
        pub velocity: f64 => [number "m/s"],
        /// x_a (m).
        pub mean_diameter: f64 => [number "m"],
        pub status: PointStatus => [],
        /// The system's results, when answered.
        #[serde(flatten)]
        pub result: Option<ThreeBodyResult> => [optional flatten],
        #[serde(flatten)]
        #[schema(inline, value_type = PointNotesFields)]
        pub notes: PointNotes => [flatten by PointNotes::units()],
        /// The numerical error of an answered point (in the sweep's `meta.verification`, the
        /// worst over its points).
        #[serde(skip)]
        pub verification: Option<ThreeBodyVerificationOutput> => [],
        /// `operating`, typed (for the CSV).
        #[serde(skip)]
        operating_point: OperatingPoint => [],
    }
}

/// The name and unit of each kind of operating point, in the order of
/// [`OperatingPoint::KINDS`].
pub(crate) fn operating_units() -> &'static [(String, &'static str)] {
    static UNITS: LazyLock<Vec<(String, &'static str)>> = LazyLock::new(|| {
        let input = OperatingInput::default();
        let names = operating_fields!(field!(input)).map(|f| f.name.to_string());
        let units = OperatingPoint::KINDS.map(|(parameter, _)| parameter.unit());
        names.into_iter().zip(units).collect()
    });
    &UNITS
}

impl ThreeBodySweepPoint {
    /// The row of `system`, solved as `solution`, unless the model's domain excludes it.
    pub fn new(system: &ThreeBody, solution: &ThreeBodySolution) -> Result<Self, JobError> {
        let checks = crate::model::validity::three_body(system, solution);
        let validity = PointValidity::assess(checks, Subject::System)?;
        Ok(ThreeBodySweepPoint::answered(
            system,
            solution.into(),
            solution.into(),
            validity,
        ))
    }

    fn answered(
        system: &ThreeBody,
        result: ThreeBodyResult,
        verification: ThreeBodyVerificationOutput,
        validity: PointValidity,
    ) -> ThreeBodySweepPoint {
        let mut row = Self::unanswered(system, PointNotes::Answered(validity));
        row.result = Some(result);
        row.verification = Some(verification);
        row
    }

    /// The table of `points`, whose operating points are all of one kind: the first column
    /// is named after it (`separation`, `total_load` or `particle_load`) and takes its unit.
    pub fn table(points: &[ThreeBodySweepPoint]) -> Table {
        let mut table = Table::new(Self::columns(), points);
        if let Some(point) = points.first() {
            let (name, unit) = &operating_units()[point.operating_point.kind()];
            table.rename(0, name, unit);
        }
        table
    }

    /// The CSV columns of three-body systems: the operating point (named by
    /// [`ThreeBodySweepPoint::table`]), then the fields', the status and the note.
    fn columns() -> &'static [Column<ThreeBodySweepPoint>] {
        static COLUMNS: LazyLock<Vec<Column<ThreeBodySweepPoint>>> = LazyLock::new(|| {
            let operating = Column::number("operating", "", |p: &ThreeBodySweepPoint| {
                p.operating_point.value()
            });
            let numbers = fields::columns::<ThreeBodySweepPoint>();
            points::columns([operating].into_iter().chain(numbers).collect())
        });
        &COLUMNS
    }
}

impl Row for ThreeBodySweepPoint {
    type Point = ThreeBody;
    type Verification = ThreeBodyVerificationOutput;

    fn unanswered(system: &ThreeBody, notes: PointNotes) -> Self {
        ThreeBodySweepPoint {
            operating: operating_canonical(system.operating),
            velocity: system.velocity,
            mean_diameter: system.diameters.mean,
            status: notes.status(),
            result: None,
            notes,
            verification: None,
            operating_point: system.operating,
        }
    }

    fn notes(&self) -> &PointNotes {
        &self.notes
    }

    fn verification(&self) -> Option<ThreeBodyVerificationOutput> {
        self.verification.clone()
    }
}
