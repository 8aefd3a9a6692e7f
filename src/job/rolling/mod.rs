//! The rolling job: one particle rolling over the layer (docs/model.md §3).

pub mod continuum;
mod picture;
pub use picture::RollingPicture;

use std::sync::LazyLock;

use serde::{Deserialize, Serialize};
use serde_json::Value;
use utoipa::ToSchema;

use super::input::{
    self, field, Checker, LayerInput, LayerModel, QuadratureKind, Quantity, UpperSurfaceInput,
};
use super::kind::SMALL_ANSWER;
use super::meta::{Canonical, CONTINUUM_REFERENCES, ROLLING_REFERENCES};
use super::points::{self, PointNotes, PointNotesFields, PointStatus, Row};
use super::validity::{self, PointValidity, Subject, ValidityOutput};
use super::{Control, Cost, JobError, Kind, Limits, Meta, References, Validated, Work};
use crate::model::continuum::ContinuumVerification;
use crate::model::counterface::UpperSurface;
use crate::model::motion::{self, Mode, Motion};
use crate::model::rolling::{BoundaryPoint, PressureGrid, Verification};
use crate::model::tables::{self, Use};
use crate::model::validity::Check;
use crate::model::{
    self, ModelError, Parameter, Rolling, RollingSolution, SolveOption, SolveOptions, Stop,
};
use crate::render::{fields, Column, Field, Fields, Output, Table, UnitTable};
use crate::{described, unit_table};

/// Input of a rolling job; every field optional (docs/model.md §5 defaults).
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"radius": "25 nm", "load": "1 nN", "velocity": "4 nm/s",
    "layer": {"elastic_modulus": "3 GPa", "thickness": "100 nm", "poisson_ratio": 0.35,
              "relaxation_time": "100 ms", "retardation_time": "500 ms"}}))]
pub struct RollingInput {
    /// R, particle radius (m; default 25 nm).
    pub radius: Option<Quantity>,
    /// P, normal load on the particle (N; default 1 nN).
    pub load: Option<Quantity>,
    /// V, rolling speed (m/s, ≥ 0; default 4 nm/s).
    pub velocity: Option<Quantity>,
    /// The viscoelastic layer (default: docs/model.md §5).
    pub layer: Option<LayerInput>,
    /// The counterface the particle rolls against (default steel, 210 GPa, ν = 0.3): with
    /// the layer, it decides whether the particle rolls or slides (docs/model.md §11).
    pub upper_surface: Option<UpperSurfaceInput>,
    /// Quadrature and extra outputs.
    pub options: Option<OptionsInput>,
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

impl OptionsInput {
    fn read(&self, checker: &mut Checker) -> SolveOptions {
        let input = self;
        let strips = checker.count(field!(input.strips), SolveOption::Strips);
        SolveOptions {
            quadrature: QuadratureKind::rule(self.quadrature, strips),
            boundary_points: checker
                .count(field!(input.boundary_points), SolveOption::BoundaryPoints)
                .unwrap_or(SolveOptions::default().boundary_points),
            pressure_grid: checker.count(field!(input.pressure_grid), SolveOption::PressureGrid),
        }
    }

    fn of(options: &SolveOptions) -> OptionsInput {
        let (quadrature, strips) = QuadratureKind::of(options.quadrature);
        OptionsInput {
            quadrature: Some(quadrature),
            strips: Some(strips),
            boundary_points: Some(options.boundary_points),
            pressure_grid: options.pressure_grid,
        }
    }
}

/// A validated rolling job.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RollingJob {
    pub rolling: Rolling,
    /// The counterface: whether the particle rolls (docs/model.md §11).
    pub upper: UpperSurface,
    pub options: SolveOptions,
    /// How the layer gives way.
    pub law: LayerModel,
}

impl RollingJob {
    /// Reads `input` under `checker`: fields that are bad are recorded there (and read as
    /// NaN here), so a caller can combine these errors with its own.
    pub fn read(input: &RollingInput, checker: &mut Checker) -> RollingJob {
        let d = Rolling::default();
        let rolling = Rolling {
            radius: checker.quantity(field!(input.radius), Parameter::Radius, d.radius),
            load: checker.quantity(field!(input.load), Parameter::Load, d.load),
            velocity: checker.quantity(field!(input.velocity), Parameter::Velocity, d.velocity),
            layer: checker.nested(field!(input.layer), |c, layer| layer.read(c)),
        };
        let upper = checker.nested(field!(input.upper_surface), |c, u| u.read(c));
        let options = checker.nested(field!(input.options), |c, o| o.read(c));
        checker.parameters(rolling.violations());
        checker.parameters(upper.violations());
        checker.options(options.violations());
        let law = input.layer.as_ref().and_then(|l| l.model);
        RollingJob {
            rolling,
            upper,
            options,
            law: law.unwrap_or_default(),
        }
    }

    /// The contact `point` (this job's, or a sweep's point over it) solved under the job's
    /// law and options: the local law through its similarity table as `method` allows, the
    /// continuum stopped when `stop` says so.
    pub fn solve(&self, point: &Rolling, method: Use, stop: Stop) -> Result<Solved, ModelError> {
        match self.law {
            LayerModel::Local => tables::solve(point, &self.options, method).map(Solved::Local),
            LayerModel::Continuum => {
                model::continuum::solve(point, &self.options, stop).map(Solved::Continuum)
            }
        }
    }

    /// What solving `point` (this job's, or a sweep's point over it) costs: a point on the
    /// local law, what its grids cost on the continuum.
    pub fn cost_of(&self, point: &Rolling) -> Cost {
        match self.law {
            LayerModel::Local => Cost::points(1),
            LayerModel::Continuum => model::continuum::plan(point, model::continuum::PER_RADIUS)
                .map_or(Cost::points(1), |plan| Cost::continuum(&plan)),
        }
    }

    /// The input that gives this job: every field, in SI.
    pub fn input(&self) -> RollingInput {
        let r = &self.rolling;
        RollingInput {
            radius: Quantity::si(r.radius),
            load: Quantity::si(r.load),
            velocity: Quantity::si(r.velocity),
            layer: Some(LayerInput::of(&r.layer, Some(self.law))),
            upper_surface: Some(UpperSurfaceInput::of(&self.upper)),
            options: Some(OptionsInput::of(&self.options)),
        }
    }
}

impl Kind for RollingJob {
    const NAME: &'static str = "rolling";
    type Input = RollingInput;
    type Output = RollingOutput;

    /// On the continuum, a job whose answer would pass the grid's cap is refused here.
    fn validate(input: Value, _limits: &Limits) -> Result<Validated<Self>, JobError> {
        input::validate(input, |input, checker| {
            let job = RollingJob::read(input, checker);
            if job.law == LayerModel::Continuum && job.rolling.violations().is_empty() {
                let rolling = job.rolling;
                let problems = |layer: &model::Layer| {
                    vec![Rolling {
                        layer: *layer,
                        ..rolling
                    }]
                };
                continuum::check(&rolling.layer, &problems, checker);
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
        match self.law {
            LayerModel::Local => &ROLLING_REFERENCES,
            LayerModel::Continuum => &CONTINUUM_REFERENCES,
        }
    }

    fn work(&self) -> Work {
        Work::Known(1)
    }

    fn cost(&self) -> Cost {
        self.cost_of(&self.rolling)
    }

    /// A continuum answer costs a hundred times a local one.
    fn cost_class(&self) -> &'static str {
        match self.law {
            LayerModel::Local => Self::NAME,
            LayerModel::Continuum => "rolling on the continuum",
        }
    }

    /// The local law's default rule with a modest boundary and no pressure grid: ≈ 7 µs
    /// through the layer's table, ≈ 50 µs (up to ≈ 150 µs at high speed) by strip sums.
    fn small(&self) -> bool {
        /// Boundary points a small job may ask for (≈ 0.15 µs each).
        const SMALL_BOUNDARY: usize = 401;
        self.law == LayerModel::Local
            && self.options.quadrature == model::Quadrature::default()
            && self.options.pressure_grid.is_none()
            && self.options.boundary_points <= SMALL_BOUNDARY
    }

    /// A boundary point is three numbers (at most 96 bytes of JSON with their keys), a
    /// pressure grid value one (at most 26 bytes).
    fn result_bytes(&self) -> u64 {
        let boundary = self.options.boundary_points as u64 * 96;
        let grid = self.options.pressure_grid.map_or(0, |n| {
            let n = n as u64;
            (n * n + 2 * n) * 26
        });
        SMALL_ANSWER + boundary + grid
    }

    fn run(&self, meta: Meta, control: &Control) -> Result<RollingOutput, JobError> {
        // Strip sums, never a table: a single answer's digits must not depend on which tables
        // earlier jobs of the process built (issue 52).
        let solution = control.solve(|stop| self.solve(&self.rolling, Use::Exact, stop))?;
        RollingOutput::new(&self.rolling, &self.upper, &solution, meta)
    }
}

described! {
    /// The integral quantities of a rolling contact, shared by rolling answers and sweep points.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct ContactOutput {
        /// δ (m).
        pub penetration: f64 => [number "m"],
        /// A (m²).
        pub contact_area: f64 => [number "m²"],
        /// √(2Rδ) (m).
        pub half_width: f64 => [number "m"],
        /// x_c (m), area centroid ahead of the sphere centre.
        pub centroid_shift: f64 => [number "m"],
        /// x_p (m), centre of pressure.
        pub pressure_centre_shift: f64 => [number "m"],
        /// x_p/R (dimensionless).
        pub rolling_resistance_coefficient: f64 => [number ""],
        /// μ = τ_a A/P (eq. 12; dimensionless): the paper's adhesive friction, the most
        /// the layer contact transmits. The particle's own friction, rolling or sliding,
        /// is `motion.friction`.
        pub friction_coefficient: f64 => [number ""],
        /// Whether the particle rolls or slides, and the friction it then transmits
        /// (docs/model.md §11).
        pub motion: MotionOutput => [nested "motion_"],
        /// The same particle at V = 0.
        pub r#static: StaticOutput => [nested "static_"],
    }
}

described! {
    /// Roll or slide (docs/model.md §11): moments about the particle's centre give
    /// 2RT = P(x_p,upper + x_p,layer), so rolling needs the tangential force per load
    /// μ_roll = (μ_r,upper + μ_r,layer)/2; each contact transmits at most τ A/P. The
    /// particle rolls iff both can; otherwise it slides at the weaker.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct MotionOutput {
        /// `rolls`, `slides_at_layer` or `slides_at_upper`.
        pub mode: MotionMode => [],
        /// μ_roll, the tangential force per load that rolling needs (dimensionless).
        pub rolling_need: f64 => [number ""],
        /// τ_u A_u/P, the most the contact with the upper surface transmits
        /// (dimensionless).
        pub upper_capacity: f64 => [number ""],
        /// τ_a A/P, the most the layer contact transmits: eq. 12's μ (dimensionless).
        pub layer_capacity: f64 => [number ""],
        /// T/P, the particle's friction: μ_roll when it rolls, the weaker capacity when it
        /// slides (dimensionless).
        pub friction: f64 => [number ""],
    }
}

/// How a particle moves between the two surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum MotionMode {
    Rolls,
    SlidesAtLayer,
    SlidesAtUpper,
}

impl MotionMode {
    /// The mode in a picture's few words.
    pub fn words(self) -> &'static str {
        match self {
            MotionMode::Rolls => "rolls",
            MotionMode::SlidesAtLayer => "slides on layer",
            MotionMode::SlidesAtUpper => "slides on upper",
        }
    }

    /// The mode as the JSON writes it.
    pub fn as_str(self) -> &'static str {
        match self {
            MotionMode::Rolls => "rolls",
            MotionMode::SlidesAtLayer => "slides_at_layer",
            MotionMode::SlidesAtUpper => "slides_at_upper",
        }
    }
}

impl From<&Motion> for MotionOutput {
    fn from(m: &Motion) -> Self {
        MotionOutput {
            mode: m.mode.into(),
            rolling_need: m.rolling_need,
            upper_capacity: m.upper_capacity,
            layer_capacity: m.layer_capacity,
            friction: m.friction,
        }
    }
}

impl From<Mode> for MotionMode {
    fn from(mode: Mode) -> Self {
        match mode {
            Mode::Rolls => MotionMode::Rolls,
            Mode::SlidesAtLayer => MotionMode::SlidesAtLayer,
            Mode::SlidesAtUpper => MotionMode::SlidesAtUpper,
        }
    }
}

described! {
    /// The particle without rolling.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct StaticOutput {
        /// δ at V = 0 (m).
        pub penetration: f64 => [number "m"],
        /// A at V = 0 (m²).
        pub contact_area: f64 => [number "m²"],
        /// μ at V = 0 (dimensionless).
        pub friction_coefficient: f64 => [number ""],
    }
}

described! {
    /// How far the answer can be trusted.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct VerificationOutput {
        /// |P(δ) − P|/P at the returned δ (dimensionless).
        pub relative_load_residual: f64 => [unit ""],
        /// A bound on the relative error of every reported quantity: twice its change when the
        /// quadrature is halved, with the load residual carried through, never below rounding
        /// (dimensionless). For a table answer, add `table_error`.
        pub quadrature_error_estimate: f64 => [unit ""],
        /// Nodes (or strips) of the y-quadrature (count).
        pub quadrature_nodes: usize => [unit ""],
        /// Iterations of the load equation: strip-sum passes under every rule of the solve,
        /// coarsest first, or look-ups in the similarity table (count).
        pub iterations: u32 => [unit ""],
        /// Newton steps of all exit-edge roots, under every rule (count).
        pub exit_root_iterations: u32 => [unit ""],
        /// Whether every root finder converged.
        pub converged: bool => [],
        /// Present when the load equation was solved through the layer's similarity table
        /// (built once per layer from the exact strip solver, then ≈ 1 µs per answer): a bound
        /// on the relative difference of every integral quantity from the exact solve
        /// (dimensionless). Absent for an exact solve.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub table_error: Option<f64> => [unit ""],
    }
}

impl VerificationOutput {
    /// The worse of two answers' errors, field by field (a sweep's, over its points).
    pub fn worst(&self, other: &VerificationOutput) -> VerificationOutput {
        VerificationOutput {
            relative_load_residual: self
                .relative_load_residual
                .max(other.relative_load_residual),
            quadrature_error_estimate: self
                .quadrature_error_estimate
                .max(other.quadrature_error_estimate),
            quadrature_nodes: self.quadrature_nodes.min(other.quadrature_nodes),
            iterations: self.iterations.max(other.iterations),
            exit_root_iterations: self.exit_root_iterations.max(other.exit_root_iterations),
            converged: self.converged && other.converged,
            table_error: match (self.table_error, other.table_error) {
                (Some(a), Some(b)) => Some(a.max(b)),
                (a, b) => a.or(b),
            },
        }
    }
}

described! {
    /// How far an answer on the layer as a continuum can be trusted (docs/model.md §8), per
    /// quantity. On the grid: the changes from a coarse grid (pixels half as large again) and
    /// to a domain reaching twice as far behind the contact. On the thin-layer path: the
    /// local law's difference from the continuum at rest.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct ContinuumVerificationOutput {
        /// `grid` (solved on a grid of pixels) or `thin_layer` (a contact many layer
        /// thicknesses wide on a compressible layer: the local law's exact answer, which the
        /// continuum tends to there).
        pub method: ContinuumMethod => [],
        /// A bound on δ's relative error (dimensionless).
        pub penetration_error: f64 => [unit ""],
        /// A bound on A's (and μ's) relative error (dimensionless).
        pub contact_area_error: f64 => [unit ""],
        /// A bound on x_c's error (m).
        pub centroid_shift_error: f64 => [unit "m"],
        /// A bound on x_p's (and R μ_r's) error (m).
        pub pressure_centre_shift_error: f64 => [unit "m"],
        /// A bound on the static companion's δ's relative error (dimensionless).
        pub static_penetration_error: f64 => [unit ""],
        /// A bound on the static companion's A's relative error (dimensionless).
        pub static_contact_area_error: f64 => [unit ""],
        /// The part of the errors of δ and A that is the domain's: their largest relative
        /// change when the grid reaches twice as far behind (dimensionless).
        pub domain_error: f64 => [unit ""],
        /// Whether the reported bounds of δ's and A's errors (rolling and at rest) are within
        /// §8's tolerances, 0.5 % and 1 %: a statement about the bounds, which exceed the
        /// true error (by 2 to 5 times, measured). False: the answer is given, and is not
        /// known to be that exact; the `numerical` validity row then warns, with the number.
        pub within_tolerance: bool => [],
        /// The fine grid (absent on the thin-layer path).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub grid: Option<GridOutput> => [optional nested],
        /// Whether the solve reached its steady state (an answer is given only then).
        pub converged: bool => [],
    }
}

/// How an answer on the layer as a continuum was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum ContinuumMethod {
    Grid,
    ThinLayer,
}

described! {
    /// The fine grid of an answer on the layer as a continuum.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct GridOutput {
        /// Pixels along the rolling direction (count).
        pub length: usize => [unit ""],
        /// Pixels across it (count).
        pub width: usize => [unit ""],
        /// The pixel's side (m).
        pub pixel: f64 => [unit "m"],
        /// Pixels across the rolling contact, 2√(A/π)/h (count).
        pub pixels_across: f64 => [unit ""],
        /// Steps of the march to the steady state (count).
        pub march_steps: usize => [unit ""],
    }
}

impl From<&ContinuumVerification> for ContinuumVerificationOutput {
    fn from(v: &ContinuumVerification) -> Self {
        let e = &v.errors;
        let (rolling, at_rest) = e.tolerance_shares();
        ContinuumVerificationOutput {
            method: match v.grid {
                Some(_) => ContinuumMethod::Grid,
                None => ContinuumMethod::ThinLayer,
            },
            penetration_error: e.penetration,
            contact_area_error: e.contact_area,
            centroid_shift_error: e.centroid_shift,
            pressure_centre_shift_error: e.pressure_centre_shift,
            static_penetration_error: e.static_penetration,
            static_contact_area_error: e.static_contact_area,
            domain_error: v.domain_error,
            within_tolerance: rolling.max(at_rest) <= 1.0,
            grid: v.grid.map(|g| GridOutput {
                length: g.nx,
                width: g.ny,
                pixel: g.pixel,
                pixels_across: g.across,
                march_steps: g.steps,
            }),
            converged: true,
        }
    }
}

impl ContinuumVerificationOutput {
    /// The worse of two answers' errors, field by field (a sweep's, over its points): its
    /// method and grid are those of the worse answer in A.
    pub fn worst(&self, other: &ContinuumVerificationOutput) -> ContinuumVerificationOutput {
        let (a, b) = (self, other);
        let worse = if b.contact_area_error > a.contact_area_error {
            b
        } else {
            a
        };
        ContinuumVerificationOutput {
            method: worse.method,
            penetration_error: a.penetration_error.max(b.penetration_error),
            contact_area_error: a.contact_area_error.max(b.contact_area_error),
            centroid_shift_error: a.centroid_shift_error.max(b.centroid_shift_error),
            pressure_centre_shift_error: a
                .pressure_centre_shift_error
                .max(b.pressure_centre_shift_error),
            static_penetration_error: a.static_penetration_error.max(b.static_penetration_error),
            static_contact_area_error: a.static_contact_area_error.max(b.static_contact_area_error),
            domain_error: a.domain_error.max(b.domain_error),
            within_tolerance: a.within_tolerance && b.within_tolerance,
            grid: worse.grid.clone(),
            converged: a.converged && b.converged,
        }
    }
}

/// The numerical error of a rolling answer: the local law's quadrature, or the continuum's
/// grid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(untagged)]
pub enum ContactVerification {
    Local(VerificationOutput),
    Continuum(ContinuumVerificationOutput),
}

/// The fields of either law's verification (the union: an answer's is one of them).
impl Fields for ContactVerification {
    fn fields() -> Vec<Field<Self>> {
        let mut fields = Field::nested::<VerificationOutput>("", None, |_| None);
        fields.extend(Field::nested::<ContinuumVerificationOutput>(
            "",
            None,
            |_| None,
        ));
        fields
    }
}

impl ContactVerification {
    /// The worse of the two, field by field (a sweep's points are all of one law).
    pub fn worst(&self, other: &ContactVerification) -> ContactVerification {
        match (self, other) {
            (ContactVerification::Local(a), ContactVerification::Local(b)) => {
                ContactVerification::Local(a.worst(b))
            }
            (ContactVerification::Continuum(a), ContactVerification::Continuum(b)) => {
                ContactVerification::Continuum(a.worst(b))
            }
            (a, _) => a.clone(),
        }
    }
}

/// A rolling contact solved under one of the layer's laws.
#[derive(Clone, Debug, PartialEq)]
pub enum Solved {
    Local(RollingSolution),
    Continuum(RollingSolution<ContinuumVerification>),
}

impl Solved {
    /// Its contact, with how the particle moves against `upper` (§11), and the assumptions
    /// measured on it (§7, §8, and whether it rolls): the particle's motion found once.
    fn contact_and_checks(
        &self,
        rolling: &Rolling,
        upper: &UpperSurface,
    ) -> (ContactOutput, Vec<Check>) {
        let motion = self.motion(rolling, upper);
        let (contact, mut checks) = match self {
            Solved::Local(s) => (
                ContactOutput::new(s, (&motion).into()),
                model::validity::rolling(rolling, s),
            ),
            Solved::Continuum(s) => (
                ContactOutput::new(s, (&motion).into()),
                model::validity::continuum(rolling, s),
            ),
        };
        checks.push(Check::pure_rolling(&motion));
        (contact, checks)
    }

    /// Whether the particle rolls or slides between `upper` and the layer (§11).
    fn motion(&self, rolling: &Rolling, upper: &UpperSurface) -> Motion {
        let (resistance, area) = match self {
            Solved::Local(s) => (s.rolling_resistance_coefficient, s.contact_area),
            Solved::Continuum(s) => (s.rolling_resistance_coefficient, s.contact_area),
        };
        let tau = rolling.layer.interfacial_shear_strength();
        motion::particle(rolling.radius, rolling.load, resistance, area, tau, upper)
    }

    fn verification(&self) -> ContactVerification {
        match self {
            Solved::Local(s) => ContactVerification::Local((&s.verification).into()),
            Solved::Continuum(s) => ContactVerification::Continuum((&s.verification).into()),
        }
    }

    fn boundary(&self) -> &[BoundaryPoint] {
        match self {
            Solved::Local(s) => &s.boundary,
            Solved::Continuum(s) => &s.boundary,
        }
    }

    fn pressure(&self) -> Option<&PressureGrid> {
        match self {
            Solved::Local(s) => s.pressure.as_ref(),
            Solved::Continuum(s) => s.pressure.as_ref(),
        }
    }
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
            table_error: v.table_error,
        }
    }
}

impl ContactOutput {
    /// The integrals of `s`, with how the particle moves.
    fn new<V>(s: &RollingSolution<V>, motion: MotionOutput) -> Self {
        ContactOutput {
            penetration: s.penetration,
            contact_area: s.contact_area,
            half_width: s.half_width,
            centroid_shift: s.centroid_shift,
            pressure_centre_shift: s.pressure_centre_shift,
            rolling_resistance_coefficient: s.rolling_resistance_coefficient,
            friction_coefficient: s.friction_coefficient,
            motion,
            r#static: StaticOutput {
                penetration: s.static_contact.penetration,
                contact_area: s.static_contact.contact_area,
                friction_coefficient: s.static_contact.friction_coefficient,
            },
        }
    }
}

described! {
    /// One row of a rolling sweep: the point's conditions, its status, and (answered) its numbers
    /// and the ratios of the model's assumptions, or (refused) the reason.
    // Also the CSV row of a rolling answer: one declaration of the columns of rolling contacts.
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct SweepPoint {
        /// R (m).
        pub radius: f64 => [number "m"],
        /// P (N).
        pub load: f64 => [number "N"],
        /// V (m/s).
        pub velocity: f64 => [number "m/s"],
        pub status: PointStatus => [],
        /// The contact, when answered.
        #[serde(flatten)]
        pub contact: Option<ContactOutput> => [optional flatten],
        /// On the layer as a continuum, a bound on the relative error of this point's A and μ
        /// (dimensionless; each point's own, where `meta.verification` has the worst). The
        /// local law's quadrature error, orders smaller, bounds every point's alike.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub contact_area_error: Option<f64> => [optional ""],
        #[serde(flatten)]
        #[schema(inline, value_type = PointNotesFields)]
        pub notes: PointNotes => [flatten by PointNotes::units()],
        /// The numerical error of an answered point (in the sweep's `meta.verification`, the
        /// worst over its points).
        #[serde(skip)]
        pub verification: Option<ContactVerification> => [],
    }
}

impl SweepPoint {
    /// The row of `rolling` against `upper`, solved as `solution`, unless the model's domain
    /// excludes it.
    pub fn new(
        rolling: &Rolling,
        upper: &UpperSurface,
        solution: &Solved,
    ) -> Result<Self, JobError> {
        let (contact, checks) = solution.contact_and_checks(rolling, upper);
        let validity = PointValidity::assess(checks, Subject::Particle)?;
        Ok(SweepPoint::answered(
            rolling,
            contact,
            solution.verification(),
            validity,
        ))
    }

    fn answered(
        rolling: &Rolling,
        contact: ContactOutput,
        verification: ContactVerification,
        validity: PointValidity,
    ) -> SweepPoint {
        let mut row = SweepPoint::unanswered(rolling, PointNotes::Answered(validity));
        row.contact = Some(contact);
        row.contact_area_error = match &verification {
            ContactVerification::Continuum(v) => Some(v.contact_area_error),
            ContactVerification::Local(_) => None,
        };
        row.verification = Some(verification);
        row
    }

    /// The CSV columns of rolling contacts: the fields', the particle's motion, then the
    /// status and the note.
    pub fn columns() -> &'static [Column<SweepPoint>] {
        static COLUMNS: LazyLock<Vec<Column<SweepPoint>>> = LazyLock::new(|| {
            let mut columns = fields::columns::<SweepPoint>();
            columns.push(Column::text("motion_mode", |row: &SweepPoint, text| {
                if let Some(contact) = &row.contact {
                    text.push_str(contact.motion.mode.as_str());
                }
            }));
            points::columns(columns)
        });
        &COLUMNS
    }
}

impl Row for SweepPoint {
    type Point = Rolling;
    type Verification = ContactVerification;

    fn unanswered(rolling: &Rolling, notes: PointNotes) -> Self {
        SweepPoint {
            radius: rolling.radius,
            load: rolling.load,
            velocity: rolling.velocity,
            status: notes.status(),
            contact: None,
            contact_area_error: None,
            notes,
            verification: None,
        }
    }

    fn notes(&self) -> &PointNotes {
        &self.notes
    }

    fn verification(&self) -> Option<ContactVerification> {
        self.verification.clone()
    }
}

described! {
    /// A point of the contact boundary (m).
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct BoundaryOutput {
        /// Lateral coordinate y (m).
        pub y: f64 => [unit "m"],
        /// Trailing edge a(y) (m).
        pub exit: f64 => [unit "m"],
        /// Leading edge b(y) (m).
        pub entry: f64 => [unit "m"],
    }
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

described! {
    /// p(x, y) (Pa) on a grid: `values[j][i]` = p(x[i], y[j]) (m).
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct PressureOutput {
        /// Grid abscissae in the rolling direction (m).
        pub x: Vec<f64> => [list "m"],
        /// Grid ordinates across it (m).
        pub y: Vec<f64> => [list "m"],
        /// p(x[i], y[j]) as `values[j][i]` (Pa).
        pub values: Vec<Vec<f64>> => [grid "Pa"],
    }
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

described! {
    /// The `meta` block of a rolling answer.
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct RollingMeta {
        #[serde(flatten)]
        pub meta: Meta => [],
        /// How far the numbers can be trusted: the local law's quadrature error, or the
        /// continuum's grid error.
        pub verification: ContactVerification => [nested],
        /// How far the model can be trusted here (docs/model.md §7).
        pub validity: ValidityOutput => [nested],
    }
}

described! {
    /// The answer to a rolling job.
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct RollingOutput {
        #[serde(flatten)]
        pub contact: ContactOutput => [flatten],
        /// The contact boundary, `options.boundary_points` points over y.
        pub boundary: Vec<BoundaryOutput> => [each],
        /// The pressure grid, when `options.pressure_grid` asked for one.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub pressure: Option<PressureOutput> => [optional nested],
        /// Model version, cache key, the input as understood, references, verification.
        pub meta: RollingMeta => [nested],
        /// The contact solved (its R, P, V are in `meta.input` on the wire; the CSV row needs
        /// them).
        #[serde(skip)]
        rolling: Rolling => [],
        /// The validity's checks, for the CSV row.
        #[serde(skip)]
        checks: PointValidity => [],
    }
}

impl RollingOutput {
    /// The answer for `rolling` against `upper`, solved as `solution`, with `meta`, the
    /// job's [`Meta`]; refused where the model's domain excludes it.
    pub fn new(
        rolling: &Rolling,
        upper: &UpperSurface,
        solution: &Solved,
        meta: Meta,
    ) -> Result<Self, JobError> {
        let (contact, checks) = solution.contact_and_checks(rolling, upper);
        Ok(RollingOutput {
            contact,
            boundary: solution.boundary().iter().map(Into::into).collect(),
            pressure: solution.pressure().map(Into::into),
            meta: RollingMeta {
                meta,
                verification: solution.verification(),
                validity: validity::assess(&checks, Subject::Particle)?,
            },
            rolling: *rolling,
            checks: PointValidity::assess(checks, Subject::Particle)?,
        })
    }
}

impl Output for RollingOutput {
    const UNITS: &'static UnitTable = unit_table!(RollingOutput);
    type Picture = RollingPicture;

    /// One row: the contact's conditions and integrals, as a sweep's row.
    fn table(&self) -> Table {
        let point = SweepPoint::answered(
            &self.rolling,
            self.contact.clone(),
            self.meta.verification.clone(),
            self.checks.clone(),
        );
        Table::new(SweepPoint::columns(), [&point])
    }
}
