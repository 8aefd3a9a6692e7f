//! The three-body job: a population of particles between the upper surface and the layer
//! (MODEL.md §4).

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use utoipa::ToSchema;

use super::fields::{self, Checker, Quantity};
use super::rolling::{si, LayerInput, QuadratureKind};
use super::units::Dimension;
use super::{JobError, Meta};
use crate::model::three_body::{
    Asperities, ContactState, Diameters, LayerContact, OperatingPoint, Particle, ThreeBody,
    ThreeBodyOptions, ThreeBodySolution, UpperContact, UpperSurface, DEFAULT_DIAMETER_NODES,
};

/// Input of a three-body job; every field optional but the operating point.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
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

/// The upper surface (default steel, 210 GPa, ν = 0.3, elastic).
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct UpperSurfaceInput {
    /// E₁ (Pa).
    pub elastic_modulus: Option<Quantity>,
    /// ν₁.
    pub poisson_ratio: Option<Quantity>,
    pub contact: Option<UpperContactKind>,
    /// H₁ (Pa), required for plastic contact.
    pub hardness: Option<Quantity>,
}

/// Elastic (Hertz) or plastic contact of the particles with the upper surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum UpperContactKind {
    Elastic,
    Plastic,
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
    /// The rolling contact of MODEL.md §3 at the job's speed (default).
    KelvinLayer,
    /// Hertz (the paper's eq. 6 reading).
    Hertz,
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

/// A validated three-body job.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThreeBodyJob {
    pub system: ThreeBody,
    pub options: ThreeBodyOptions,
}

impl ThreeBodyJob {
    /// Validates a three-body input given as JSON.
    pub fn from_value(value: Value) -> Result<ThreeBodyJob, JobError> {
        let input: ThreeBodyInput = fields::deserialize(value, "")?;
        let mut checker = Checker::new("");
        let job = ThreeBodyJob::read(&input, &mut checker);
        checker.finish(job)
    }

    /// Reads `input` under `checker` (bad fields are recorded there and read as NaN).
    pub fn read(input: &ThreeBodyInput, checker: &mut Checker) -> ThreeBodyJob {
        use Dimension as D;
        let defaults = ThreeBody::with_defaults(OperatingPoint::Separation(0.0));
        let dist = input.distribution.clone().unwrap_or_default();
        let d0 = defaults.diameters;
        let mean = checker.quantity(
            "distribution.mean_diameter",
            dist.mean_diameter.as_ref(),
            D::LENGTH,
            d0.mean,
        );
        let std = checker.quantity(
            "distribution.std_diameter",
            dist.std_diameter.as_ref(),
            D::LENGTH,
            d0.std,
        );
        let bounds = Diameters::with_default_bounds(mean, std);
        let diameters = Diameters {
            mean,
            std,
            min: checker.quantity(
                "distribution.min_diameter",
                dist.min_diameter.as_ref(),
                D::LENGTH,
                bounds.min,
            ),
            max: checker.quantity(
                "distribution.max_diameter",
                dist.max_diameter.as_ref(),
                D::LENGTH,
                bounds.max,
            ),
        };
        let areal_density = checker.quantity(
            "distribution.areal_density",
            dist.areal_density.as_ref(),
            D::PER_AREA,
            defaults.areal_density,
        );
        let nominal_area = checker.quantity(
            "nominal_area",
            input.nominal_area.as_ref(),
            D::AREA,
            defaults.nominal_area,
        );

        let up = input.upper_surface.clone().unwrap_or_default();
        let u0 = UpperSurface::default();
        let contact = match up.contact {
            Some(UpperContactKind::Plastic) => UpperContact::Plastic,
            _ => UpperContact::Elastic,
        };
        let upper = UpperSurface {
            elastic_modulus: checker.quantity(
                "upper_surface.elastic_modulus",
                up.elastic_modulus.as_ref(),
                D::PRESSURE,
                u0.elastic_modulus,
            ),
            poisson_ratio: checker.quantity(
                "upper_surface.poisson_ratio",
                up.poisson_ratio.as_ref(),
                D::NONE,
                u0.poisson_ratio,
            ),
            contact,
            hardness: optional(
                checker,
                "upper_surface.hardness",
                up.hardness.as_ref(),
                D::PRESSURE,
            ),
        };
        if contact == UpperContact::Plastic && upper.hardness.is_none() {
            checker.invalid(
                "upper_surface.hardness",
                Value::Null,
                "a hardness (Pa): required for plastic contact",
            );
        }
        let pa = input.particle.clone().unwrap_or_default();
        let particle = Particle {
            elastic_modulus: optional(
                checker,
                "particle.elastic_modulus",
                pa.elastic_modulus.as_ref(),
                D::PRESSURE,
            ),
            poisson_ratio: checker.quantity(
                "particle.poisson_ratio",
                pa.poisson_ratio.as_ref(),
                D::NONE,
                Particle::default().poisson_ratio,
            ),
        };
        let asperities = input.asperities.as_ref().map(|a| {
            let mut required = |field: &str, value: &Option<Quantity>, dimension| {
                let path = format!("asperities.{field}");
                optional(checker, &path, value.as_ref(), dimension).unwrap_or_else(|| {
                    checker.invalid(
                        &path,
                        Value::Null,
                        &format!("{}: required with asperities", dimension.describe()),
                    );
                    f64::NAN
                })
            };
            Asperities {
                density: required("density", &a.density, D::PER_AREA),
                tip_radius: required("tip_radius", &a.tip_radius, D::LENGTH),
                height_std: required("height_std", &a.height_std, D::LENGTH),
                hardness: required("hardness", &a.hardness, D::PRESSURE),
            }
        });
        let velocity = checker.quantity(
            "velocity",
            input.velocity.as_ref(),
            D::SPEED,
            defaults.velocity,
        );
        let operating = read_operating(input.operating.as_ref(), checker);
        let layer = LayerInput::read(input.layer.as_ref(), checker, "layer");
        let o = input.options.clone().unwrap_or_default();
        let quadrature = QuadratureKind::rule(o.quadrature, o.strips);
        let options = ThreeBodyOptions {
            diameter_nodes: o.diameter_nodes.unwrap_or(DEFAULT_DIAMETER_NODES),
            quadrature,
        };
        let system = ThreeBody {
            diameters,
            areal_density,
            nominal_area,
            upper,
            particle,
            layer,
            layer_contact: match input.layer_contact {
                Some(LayerContactKind::Hertz) => LayerContact::Hertz,
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

    /// The canonical input (a valid input itself).
    pub fn canonical(&self) -> Value {
        let s = &self.system;
        let d = &s.diameters;
        let mut upper = json!({
            "elastic_modulus": si(s.upper.elastic_modulus),
            "poisson_ratio": si(s.upper.poisson_ratio),
            "contact": match s.upper.contact {
                UpperContact::Elastic => "elastic",
                UpperContact::Plastic => "plastic",
            },
        });
        if let Some(h) = s.upper.hardness {
            upper["hardness"] = json!(si(h));
        }
        let mut particle = json!({ "poisson_ratio": si(s.particle.poisson_ratio) });
        if let Some(e) = s.particle.elastic_modulus {
            particle["elastic_modulus"] = json!(si(e));
        }
        let (quadrature, strips) = QuadratureKind::canonical(self.options.quadrature);
        let mut canonical = json!({
            "distribution": {
                "mean_diameter": si(d.mean),
                "std_diameter": si(d.std),
                "min_diameter": si(d.min),
                "max_diameter": si(d.max),
                "areal_density": si(s.areal_density),
            },
            "nominal_area": si(s.nominal_area),
            "upper_surface": upper,
            "particle": particle,
            "layer": LayerInput::canonical(&s.layer),
            "layer_contact": match s.layer_contact {
                LayerContact::KelvinLayer => "kelvin_layer",
                LayerContact::Hertz => "hertz",
            },
            "velocity": si(s.velocity),
            "operating": operating_canonical(s.operating),
            "options": {
                "diameter_nodes": self.options.diameter_nodes,
                "quadrature": quadrature,
                "strips": strips,
            },
        });
        if let Some(a) = &s.asperities {
            canonical["asperities"] = json!({
                "density": si(a.density),
                "tip_radius": si(a.tip_radius),
                "height_std": si(a.height_std),
                "hardness": si(a.hardness),
            });
        }
        canonical
    }
}

/// A quantity that may be absent: `None` if it is, NaN (error recorded) if unreadable.
fn optional(
    checker: &mut Checker,
    field: &str,
    value: Option<&Quantity>,
    dimension: Dimension,
) -> Option<f64> {
    value.map(|v| checker.quantity(field, Some(v), dimension, f64::NAN))
}

/// The operating point: exactly one of its three fields.
fn read_operating(input: Option<&OperatingInput>, checker: &mut Checker) -> OperatingPoint {
    let op = input.cloned().unwrap_or_default();
    let mut given = Vec::new();
    if let Some(v) = &op.separation {
        given.push(OperatingPoint::Separation(checker.quantity(
            "operating.separation",
            Some(v),
            Dimension::LENGTH,
            f64::NAN,
        )));
    }
    if let Some(v) = &op.total_load {
        given.push(OperatingPoint::TotalLoad(checker.quantity(
            "operating.total_load",
            Some(v),
            Dimension::FORCE,
            f64::NAN,
        )));
    }
    if let Some(v) = &op.particle_load {
        given.push(OperatingPoint::ParticleLoad(checker.quantity(
            "operating.particle_load",
            Some(v),
            Dimension::FORCE,
            f64::NAN,
        )));
    }
    match given.as_slice() {
        [one] => *one,
        _ => {
            let sent = serde_json::to_value(&op).unwrap_or(Value::Null);
            checker.invalid(
                "operating",
                sent,
                "exactly one of separation (m), total_load (N), particle_load (N)",
            );
            OperatingPoint::Separation(f64::NAN)
        }
    }
}

/// `{"separation": d}`, `{"total_load": W}` or `{"particle_load": P}`.
pub fn operating_canonical(operating: OperatingPoint) -> Value {
    match operating {
        OperatingPoint::Separation(d) => json!({ "separation": si(d) }),
        OperatingPoint::TotalLoad(w) => json!({ "total_load": si(w) }),
        OperatingPoint::ParticleLoad(p) => json!({ "particle_load": si(p) }),
    }
}

/// Real contact areas (m²).
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct AreasOutput {
    /// A_s1s2, asperity contact of the two surfaces.
    pub surface_surface: f64,
    /// A_s1a, particles on the upper surface.
    pub particle_upper: f64,
    /// A_s2a, particles on the layer.
    pub particle_layer: f64,
    /// A_total = A_s1s2 + A_s1a (eq. 6).
    pub total: f64,
}

/// Loads (N).
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct LoadsOutput {
    pub asperities: f64,
    pub particles: f64,
    pub total: f64,
}

/// The system at one separation.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct StateOutput {
    /// d (m).
    pub separation: f64,
    /// n_a (eq. 7).
    pub particles_in_contact: f64,
    pub areas: AreasOutput,
    pub loads: LoadsOutput,
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

/// μ = (τ_a A_s2a + τ_s A_s1s2)/W without and with rolling.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct FrictionOutput {
    /// V = 0 (the job's separation, or its load re-solved at V = 0).
    #[serde(rename = "static")]
    pub static_: f64,
    /// At the job's V.
    pub rolling: f64,
}

/// Per particle in contact.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct PerParticleOutput {
    /// A_total/n_a (m², eq. 8).
    pub mean_area: f64,
    /// W/n_a (N).
    pub mean_load: f64,
}

/// How far the answer can be trusted.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct ThreeBodyVerificationOutput {
    pub diameter_nodes: usize,
    pub separation_iterations: u32,
    /// Relative residual of the operating load at the returned separation.
    pub relative_load_residual: f64,
    /// Largest relative change of areas and loads with half the diameter nodes.
    pub quadrature_error_estimate: f64,
    /// Relative error of the kelvin_layer table against direct solves (when used).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub layer_table_error: Option<f64>,
    pub converged: bool,
}

/// The results of a three-body solve, shared by answers and sweep points.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct ThreeBodyResult {
    #[serde(flatten)]
    pub state: StateOutput,
    pub friction_coefficient: FrictionOutput,
    pub per_particle: PerParticleOutput,
    /// The same system at V = 0.
    pub static_operating_point: StateOutput,
}

impl From<&ThreeBodySolution> for ThreeBodyResult {
    fn from(s: &ThreeBodySolution) -> Self {
        ThreeBodyResult {
            state: (&s.rolling).into(),
            friction_coefficient: FrictionOutput {
                static_: s.static_state.friction_coefficient,
                rolling: s.rolling.friction_coefficient,
            },
            per_particle: PerParticleOutput {
                mean_area: s.rolling.mean_area(),
                mean_load: s.rolling.mean_load(),
            },
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
            converged: v.converged,
        }
    }
}

/// The `meta` block of a three-body answer.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct ThreeBodyMeta {
    #[serde(flatten)]
    pub meta: Meta,
    pub verification: ThreeBodyVerificationOutput,
}

/// The answer to a three-body job.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct ThreeBodyOutput {
    #[serde(flatten)]
    pub result: ThreeBodyResult,
    pub meta: ThreeBodyMeta,
}

impl ThreeBodyOutput {
    /// The answer with `meta`, the job's [`Meta`] (see [`super::Job::meta`]).
    pub fn new(solution: &ThreeBodySolution, meta: Meta) -> Self {
        ThreeBodyOutput {
            result: solution.into(),
            meta: ThreeBodyMeta {
                meta,
                verification: solution.into(),
            },
        }
    }
}
