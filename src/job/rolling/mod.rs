//! The rolling job: one particle rolling over the layer (docs/model.md §3).

mod picture;
pub use picture::RollingPicture;

use std::sync::LazyLock;

use serde::{Deserialize, Serialize};
use serde_json::Value;
use utoipa::ToSchema;

use super::input::{self, field, Checker, LayerInput, QuadratureKind, Quantity};
use super::kind::SMALL_ANSWER;
use super::meta::ROLLING_REFERENCES;
use super::points::{self, PointNotes, PointNotesFields, PointStatus, Row, SweepVerification};
use super::validity::{self, PointValidity, Subject, ValidityOutput};
use super::{Control, JobError, Kind, Limits, Meta, References, Validated, Work};
use crate::model::rolling::{BoundaryPoint, PressureGrid, Verification};
use crate::model::tables::{self, Use};
use crate::model::{self, Parameter, Rolling, RollingSolution, SolveOption, SolveOptions};
use crate::render::{fields, Column, Output, Table, UnitTable};
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
    pub options: SolveOptions,
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
        let options = checker.nested(field!(input.options), |c, o| o.read(c));
        checker.parameters(rolling.violations());
        checker.options(options.violations());
        RollingJob { rolling, options }
    }

    /// The input that gives this job: every field, in SI.
    pub fn input(&self) -> RollingInput {
        let r = &self.rolling;
        RollingInput {
            radius: Quantity::si(r.radius),
            load: Quantity::si(r.load),
            velocity: Quantity::si(r.velocity),
            layer: Some(LayerInput::of(&r.layer)),
            options: Some(OptionsInput::of(&self.options)),
        }
    }
}

impl Kind for RollingJob {
    const NAME: &'static str = "rolling";
    type Input = RollingInput;
    type Picture = RollingPicture;
    type Output = RollingOutput;

    fn validate(input: Value, _limits: &Limits) -> Result<Validated<Self>, JobError> {
        input::validate(input, RollingJob::read)
    }

    /// A valid input itself.
    fn canonical(&self) -> Value {
        input::canonical(&self.input())
    }

    fn references(&self) -> &'static References {
        &ROLLING_REFERENCES
    }

    fn work(&self) -> Work {
        Work::Known(1)
    }

    /// The default rule with a modest boundary and no pressure grid: ≈ 7 µs through the
    /// layer's table, ≈ 50 µs (up to ≈ 150 µs at high speed) by strip sums.
    fn small(&self) -> bool {
        /// Boundary points a small job may ask for (≈ 0.15 µs each).
        const SMALL_BOUNDARY: usize = 401;
        self.options.quadrature == model::Quadrature::default()
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
        let solution =
            control.solve(|| tables::solve(&self.rolling, &self.options, Use::IfBuilt))?;
        // Solved exactly, as the first answer on a layer is: the table for the answers after
        // it is built off this request's path.
        if let Some(kappa) = tables::wanted(&self.rolling, &self.options) {
            let quadrature = self.options.quadrature;
            control.later(format!("similarity table κ = {kappa:e}"), move || {
                let _ = tables::get_or_build(kappa, quadrature);
            });
        }
        RollingOutput::new(&self.rolling, &solution, meta)
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
        /// μ = τ_a A/P (eq. 12; dimensionless).
        pub friction_coefficient: f64 => [number ""],
        /// The same particle at V = 0.
        pub r#static: StaticOutput => [nested "static_"],
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
        #[serde(flatten)]
        #[schema(inline, value_type = PointNotesFields)]
        pub notes: PointNotes => [flatten by PointNotes::units()],
        /// The numerical error of an answered point (in the sweep's `meta.verification`, the
        /// worst over its points).
        #[serde(skip)]
        pub verification: Option<VerificationOutput> => [],
    }
}

impl SweepPoint {
    /// The row of `rolling`, solved as `solution`, unless the model's domain excludes it.
    pub fn new(rolling: &Rolling, solution: &RollingSolution) -> Result<Self, JobError> {
        let validity = PointValidity::assess(
            model::validity::rolling(rolling, solution),
            Subject::Particle,
        )?;
        Ok(SweepPoint::answered(
            rolling,
            solution.into(),
            (&solution.verification).into(),
            validity,
        ))
    }

    fn answered(
        rolling: &Rolling,
        contact: ContactOutput,
        verification: VerificationOutput,
        validity: PointValidity,
    ) -> SweepPoint {
        let mut row = SweepPoint::unanswered(rolling, PointNotes::Answered(validity));
        row.contact = Some(contact);
        row.verification = Some(verification);
        row
    }

    /// The CSV columns of rolling contacts: the fields', then the status and the note.
    pub fn columns() -> &'static [Column<SweepPoint>] {
        static COLUMNS: LazyLock<Vec<Column<SweepPoint>>> =
            LazyLock::new(|| points::columns(fields::columns::<SweepPoint>()));
        &COLUMNS
    }
}

impl Row for SweepPoint {
    type Point = Rolling;

    fn unanswered(rolling: &Rolling, notes: PointNotes) -> Self {
        SweepPoint {
            radius: rolling.radius,
            load: rolling.load,
            velocity: rolling.velocity,
            status: notes.status(),
            contact: None,
            notes,
            verification: None,
        }
    }

    fn notes(&self) -> &PointNotes {
        &self.notes
    }

    fn verification(&self) -> Option<SweepVerification> {
        self.verification.clone().map(SweepVerification::Rolling)
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
        /// How far the numbers can be trusted.
        pub verification: VerificationOutput => [nested],
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
    /// The answer for `rolling`, solved as `solution`, with `meta`, the job's [`Meta`];
    /// refused where the model's domain excludes it.
    pub fn new(
        rolling: &Rolling,
        solution: &RollingSolution,
        meta: Meta,
    ) -> Result<Self, JobError> {
        let checks = model::validity::rolling(rolling, solution);
        Ok(RollingOutput {
            contact: solution.into(),
            boundary: solution.boundary.iter().map(Into::into).collect(),
            pressure: solution.pressure.as_ref().map(Into::into),
            meta: RollingMeta {
                meta,
                verification: (&solution.verification).into(),
                validity: validity::assess(&checks, Subject::Particle)?,
            },
            rolling: *rolling,
            checks: PointValidity::assess(checks, Subject::Particle)?,
        })
    }
}

impl Output for RollingOutput {
    const UNITS: &'static UnitTable = unit_table!(RollingOutput);

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
