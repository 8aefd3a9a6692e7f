//! The rolling job: one particle rolling over the layer (MODEL.md §3).

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use utoipa::ToSchema;

use super::fields::{self, Checker, Quantity};
use super::units::Dimension;
use super::{JobError, Meta};
use crate::model::quadrature::{DEFAULT_GAUSS_NODES, DEFAULT_MIDPOINT_STRIPS};
use crate::model::rolling::{BoundaryPoint, PressureGrid, Verification};
use crate::model::{Layer, Quadrature, Rolling, RollingSolution, SolveOptions};

/// Input of a rolling job; every field optional (MODEL.md §5 defaults).
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct RollingInput {
    /// R, particle radius (m; default 25 nm).
    pub radius: Option<Quantity>,
    /// P, normal load on the particle (N; default 1 nN).
    pub load: Option<Quantity>,
    /// V, rolling speed (m/s, ≥ 0; default 4 nm/s).
    pub velocity: Option<Quantity>,
    /// The viscoelastic layer (default: MODEL.md §5).
    pub layer: Option<LayerInput>,
    /// Quadrature and extra outputs.
    pub options: Option<OptionsInput>,
}

/// The Kelvin layer.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct LayerInput {
    /// E_L, relaxed longitudinal modulus (Pa; default 3 GPa).
    pub elastic_modulus: Option<Quantity>,
    /// H, layer thickness (m; default 100 nm).
    pub thickness: Option<Quantity>,
    /// ν, Poisson ratio (dimensionless; default 0.35).
    pub poisson_ratio: Option<Quantity>,
    /// T_ε, retardation time (s, ≥ T_σ; default 0.5 s).
    pub retardation_time: Option<Quantity>,
    /// T_σ, relaxation time (s; default 0.1 s).
    pub relaxation_time: Option<Quantity>,
}

/// How to integrate across the contact and what to return besides the integrals.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct OptionsInput {
    /// The y-quadrature (default `gauss`).
    pub quadrature: Option<QuadratureKind>,
    /// Gauss nodes (default 64) or midpoint strips (default 40) in the half-width (count).
    pub strips: Option<usize>,
    /// Points of the contact boundary (default 41; 0 for none).
    pub boundary_points: Option<usize>,
    /// Return the pressure on an n × n grid (points per side; default none).
    pub pressure_grid: Option<usize>,
}

/// The y-quadrature: exact to 1e-9 (`gauss`) or the paper's uniform strips (`midpoint`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum QuadratureKind {
    #[default]
    Gauss,
    Midpoint,
}

impl QuadratureKind {
    /// The rule a job asks for: its kind (default Gauss) with `strips` nodes or strips
    /// (default 64 Gauss nodes, or the paper's 40 midpoint strips).
    pub fn rule(kind: Option<QuadratureKind>, strips: Option<usize>) -> Quadrature {
        match kind.unwrap_or_default() {
            QuadratureKind::Gauss => Quadrature::Gauss {
                nodes: strips.unwrap_or(DEFAULT_GAUSS_NODES),
            },
            QuadratureKind::Midpoint => Quadrature::Midpoint {
                strips: strips.unwrap_or(DEFAULT_MIDPOINT_STRIPS),
            },
        }
    }

    /// The canonical `quadrature` and `strips` of a rule.
    pub fn canonical(rule: Quadrature) -> (&'static str, usize) {
        match rule {
            Quadrature::Gauss { nodes } => ("gauss", nodes),
            Quadrature::Midpoint { strips } => ("midpoint", strips),
        }
    }
}

impl LayerInput {
    /// Reads the layer under `checker`, its fields at `prefix.*`.
    pub fn read(input: Option<&LayerInput>, checker: &mut Checker, prefix: &str) -> Layer {
        let d = Layer::default();
        let layer = input.cloned().unwrap_or_default();
        let mut q = |field: &str, value: &Option<Quantity>, dim, default| {
            checker.quantity(&format!("{prefix}.{field}"), value.as_ref(), dim, default)
        };
        Layer {
            elastic_modulus: q(
                "elastic_modulus",
                &layer.elastic_modulus,
                Dimension::PRESSURE,
                d.elastic_modulus,
            ),
            thickness: q(
                "thickness",
                &layer.thickness,
                Dimension::LENGTH,
                d.thickness,
            ),
            poisson_ratio: q(
                "poisson_ratio",
                &layer.poisson_ratio,
                Dimension::NONE,
                d.poisson_ratio,
            ),
            retardation_time: q(
                "retardation_time",
                &layer.retardation_time,
                Dimension::TIME,
                d.retardation_time,
            ),
            relaxation_time: q(
                "relaxation_time",
                &layer.relaxation_time,
                Dimension::TIME,
                d.relaxation_time,
            ),
        }
    }

    /// The canonical form of a layer.
    pub fn canonical(layer: &Layer) -> Value {
        json!({
            "elastic_modulus": si(layer.elastic_modulus),
            "thickness": si(layer.thickness),
            "poisson_ratio": si(layer.poisson_ratio),
            "retardation_time": si(layer.retardation_time),
            "relaxation_time": si(layer.relaxation_time),
        })
    }
}

/// -0.0 and 0.0 are the same input: one canonical form, one cache key.
pub(crate) fn si(x: f64) -> f64 {
    if x == 0.0 {
        0.0
    } else {
        x
    }
}

/// A validated rolling job.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RollingJob {
    pub rolling: Rolling,
    pub options: SolveOptions,
}

impl RollingJob {
    /// Validates a rolling input given as JSON.
    pub fn from_value(value: Value) -> Result<RollingJob, JobError> {
        let input: RollingInput = fields::deserialize(value, "")?;
        let mut checker = Checker::new("");
        let job = RollingJob::read(&input, &mut checker);
        checker.finish(job)
    }

    /// Reads `input` under `checker`: fields that are bad are recorded there (and read as
    /// NaN here), so a caller can combine these errors with its own.
    pub fn read(input: &RollingInput, checker: &mut Checker) -> RollingJob {
        let d = Rolling::default();
        let rolling = Rolling {
            radius: checker.quantity("radius", input.radius.as_ref(), Dimension::LENGTH, d.radius),
            load: checker.quantity("load", input.load.as_ref(), Dimension::FORCE, d.load),
            velocity: checker.quantity(
                "velocity",
                input.velocity.as_ref(),
                Dimension::SPEED,
                d.velocity,
            ),
            layer: LayerInput::read(input.layer.as_ref(), checker, "layer"),
        };
        let o = input.options.clone().unwrap_or_default();
        let quadrature = QuadratureKind::rule(o.quadrature, o.strips);
        let options = SolveOptions {
            quadrature,
            boundary_points: o
                .boundary_points
                .unwrap_or(SolveOptions::default().boundary_points),
            pressure_grid: o.pressure_grid,
        };
        checker.parameters(rolling.violations());
        checker.options(options.violations());
        RollingJob { rolling, options }
    }

    /// The canonical input (a valid input itself).
    pub fn canonical(&self) -> Value {
        let r = &self.rolling;
        let (quadrature, strips) = QuadratureKind::canonical(self.options.quadrature);
        let mut options = json!({
            "quadrature": quadrature,
            "strips": strips,
            "boundary_points": self.options.boundary_points,
        });
        if let Some(n) = self.options.pressure_grid {
            options["pressure_grid"] = json!(n);
        }
        json!({
            "radius": si(r.radius),
            "load": si(r.load),
            "velocity": si(r.velocity),
            "layer": LayerInput::canonical(&r.layer),
            "options": options,
        })
    }
}

/// The integral quantities of a rolling contact, shared by rolling answers and sweep points.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct ContactOutput {
    /// δ (m).
    pub penetration: f64,
    /// A (m²).
    pub contact_area: f64,
    /// √(2Rδ) (m).
    pub half_width: f64,
    /// x_c (m), area centroid ahead of the sphere centre.
    pub centroid_shift: f64,
    /// x_p (m), centre of pressure.
    pub pressure_centre_shift: f64,
    /// x_p/R (dimensionless).
    pub rolling_resistance_coefficient: f64,
    /// μ = τ_a A/P (eq. 12; dimensionless).
    pub friction_coefficient: f64,
    /// The same particle at V = 0.
    #[serde(rename = "static")]
    pub static_contact: StaticOutput,
}

/// The particle without rolling.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct StaticOutput {
    /// δ at V = 0 (m).
    pub penetration: f64,
    /// A at V = 0 (m²).
    pub contact_area: f64,
    /// μ at V = 0 (dimensionless).
    pub friction_coefficient: f64,
}

/// How far the answer can be trusted.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct VerificationOutput {
    /// |P(δ) − P|/P at the returned δ (dimensionless).
    pub relative_load_residual: f64,
    /// Relative change of A when the quadrature is halved (an estimate of its error;
    /// dimensionless).
    pub quadrature_error_estimate: f64,
    /// Nodes (or strips) of the y-quadrature (count).
    pub quadrature_nodes: usize,
    /// Iterations of the load equation (count).
    pub iterations: u32,
    /// Newton steps of all exit-edge roots (count).
    pub exit_root_iterations: u32,
    /// Whether every root finder converged.
    pub converged: bool,
}

impl From<&Verification> for VerificationOutput {
    fn from(v: &Verification) -> Self {
        VerificationOutput {
            relative_load_residual: v.load_residual,
            quadrature_error_estimate: v.quadrature_error_estimate,
            quadrature_nodes: v.quadrature_nodes,
            iterations: v.iterations,
            exit_root_iterations: v.exit_root_iterations,
            converged: v.converged,
        }
    }
}

impl From<&RollingSolution> for ContactOutput {
    fn from(s: &RollingSolution) -> Self {
        ContactOutput {
            penetration: s.penetration,
            contact_area: s.contact_area,
            half_width: s.half_width,
            centroid_shift: s.centroid_shift,
            pressure_centre_shift: s.pressure_centre_shift,
            rolling_resistance_coefficient: s.rolling_resistance_coefficient,
            friction_coefficient: s.friction_coefficient,
            static_contact: StaticOutput {
                penetration: s.static_contact.penetration,
                contact_area: s.static_contact.contact_area,
                friction_coefficient: s.static_contact.friction_coefficient,
            },
        }
    }
}

/// A point of the contact boundary (m).
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct BoundaryOutput {
    /// Lateral coordinate y (m).
    pub y: f64,
    /// Trailing edge a(y) (m).
    pub exit: f64,
    /// Leading edge b(y) (m).
    pub entry: f64,
}

impl From<&BoundaryPoint> for BoundaryOutput {
    fn from(p: &BoundaryPoint) -> Self {
        BoundaryOutput {
            y: p.y,
            exit: p.exit,
            entry: p.entry,
        }
    }
}

/// p(x, y) (Pa) on a grid: `values[j][i]` = p(x[i], y[j]) (m).
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct PressureOutput {
    /// Grid abscissae in the rolling direction (m).
    pub x: Vec<f64>,
    /// Grid ordinates across it (m).
    pub y: Vec<f64>,
    /// p(x[i], y[j]) as `values[j][i]` (Pa).
    pub values: Vec<Vec<f64>>,
}

impl From<&PressureGrid> for PressureOutput {
    fn from(g: &PressureGrid) -> Self {
        PressureOutput {
            x: g.x.clone(),
            y: g.y.clone(),
            values: g.values.clone(),
        }
    }
}

/// The `meta` block of a rolling answer.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct RollingMeta {
    #[serde(flatten)]
    pub meta: Meta,
    /// How far the numbers can be trusted.
    pub verification: VerificationOutput,
}

/// The answer to a rolling job.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct RollingOutput {
    #[serde(flatten)]
    pub contact: ContactOutput,
    /// The contact boundary, `options.boundary_points` points over y.
    pub boundary: Vec<BoundaryOutput>,
    /// The pressure grid, when `options.pressure_grid` asked for one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pressure: Option<PressureOutput>,
    /// Model version, cache key, the input as understood, references, verification.
    pub meta: RollingMeta,
}

impl RollingOutput {
    /// The answer with `meta`, the job's [`Meta`] (see [`super::Job::meta`]).
    pub fn new(solution: &RollingSolution, meta: Meta) -> Self {
        RollingOutput {
            contact: solution.into(),
            boundary: solution.boundary.iter().map(Into::into).collect(),
            pressure: solution.pressure.as_ref().map(Into::into),
            meta: RollingMeta {
                meta,
                verification: (&solution.verification).into(),
            },
        }
    }
}
