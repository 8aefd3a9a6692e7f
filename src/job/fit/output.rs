//! The fit's answer: estimates with their uncertainty, the residuals and fitted curves, and
//! what the data determine.

use std::collections::BTreeMap;

use serde::Serialize;
use utoipa::ToSchema;

use super::input::MeasuredQuantity;
use crate::job::{JobError, Meta};
use crate::render::{Column, Output, Table, UnitTable};
use crate::unit_table;

/// The answer to a fit.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct FitOutput {
    /// The fitted parameters, in the order of `correlation`'s rows.
    pub parameter_names: Vec<&'static str>,
    /// Each fitted parameter, by name (SI).
    pub parameters: BTreeMap<&'static str, Estimate>,
    /// Correlations of the estimates (rows and columns in the order of `parameter_names`).
    /// For a parameter the data do not determine alone, they describe the combination that
    /// is determined.
    pub correlation: Vec<Vec<f64>>,
    /// Σ ((fitted − measured)/uncertainty)², with uncertainty 1 when none was given.
    pub chi_squared: f64,
    /// Degrees of freedom: points − parameters.
    pub dof: usize,
    /// `given` (the points' uncertainties), or `from_scatter`: none was given, so the
    /// covariance is scaled by χ²/dof and intervals use Student's t.
    pub uncertainties: UncertaintySource,
    /// One row per measured point, in the order of the series and their points.
    pub residuals: Vec<Residual>,
    /// The fitted model along each series.
    pub curves: Vec<Curve>,
    pub identifiability: Identifiability,
    /// How the minimum was found.
    pub search: Search,
    pub meta: FitMeta,
    /// Why the fit stopped before its end, if it did (`meta.stopped` in words).
    #[serde(skip)]
    pub stop: Option<JobError>,
}

/// The `meta` block of a fit.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct FitMeta {
    #[serde(flatten)]
    pub meta: Meta,
    /// Whether the fit ran every minimisation it planned. False: it was stopped (a cancel,
    /// its deadline) after `search.finished` of `search.starts`; the answer is the best of
    /// those, with its intervals and curves.
    pub complete: bool,
    /// Why it stopped, when it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped: Option<String>,
}

/// Where the uncertainties came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum UncertaintySource {
    Given,
    FromScatter,
}

/// A fitted parameter (SI).
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct Estimate {
    /// The best value; for a parameter not determined alone, one of many that fit equally.
    pub value: f64,
    /// Its standard error (from the covariance of its logarithm); absent if the data do not
    /// determine it alone.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub standard_error: Option<f64>,
    /// The 95 % interval, value × exp(∓ t · standard error of ln value); absent if the data
    /// do not determine it alone.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interval_95: Option<[f64; 2]>,
    /// Whether the data determine it alone.
    pub determined: bool,
    /// The bounds it was kept within.
    pub bounds: [f64; 2],
    /// Whether it ended on a bound (the interval then means little).
    pub at_bound: bool,
}

/// The model against one measured point: `radius` and `load` on one particle, `total_load`
/// on a three-body system; the comparison under the name of the quantity measured.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct Residual {
    /// Index of the series, and of the point in it.
    pub series: usize,
    pub point: usize,
    #[serde(flatten)]
    pub at: Conditions,
    /// μ measured and fitted, if μ was measured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction_coefficient: Option<Comparison>,
    /// A (m²) measured and fitted, if A was measured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_area: Option<Comparison>,
    /// (fitted − measured)/uncertainty; from the scatter when no uncertainty was given.
    pub normalized_residual: f64,
}

impl Residual {
    /// The comparison with the name and unit of its quantity.
    fn compared(&self) -> Option<(&'static str, &'static str, &Comparison)> {
        let mu = self.friction_coefficient.as_ref();
        let area = self.contact_area.as_ref();
        mu.map(|c| ("friction_coefficient", "", c))
            .or(area.map(|c| ("contact_area", "m^2", c)))
    }
}

/// Where a point was measured: `radius` and `load` on one particle, `total_load` on a
/// three-body system; `velocity` always.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, ToSchema)]
pub struct Conditions {
    /// R (m), on one particle.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// P (N), on one particle.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub load: Option<f64>,
    /// W (N), on a three-body system.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub total_load: Option<f64>,
    /// V (m/s).
    pub velocity: f64,
}

/// A measured value beside the model's.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct Comparison {
    pub measured: f64,
    pub fitted: f64,
    /// fitted − measured.
    pub residual: f64,
    /// The standard uncertainty given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uncertainty: Option<f64>,
}

/// The fitted model along a series: over the range of the condition its points vary (dense),
/// or through its points when they vary more than one.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct Curve {
    pub series: usize,
    pub quantity: MeasuredQuantity,
    /// The condition along the curve: `velocity`, `load`, `radius` or `total_load`.
    pub along: &'static str,
    pub points: Vec<CurvePoint>,
}

/// A point of a fitted curve: its conditions as a residual gives them, and the model's value
/// under the name of the quantity.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct CurvePoint {
    #[serde(flatten)]
    pub at: Conditions,
    /// μ, if the series measured μ.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub friction_coefficient: Option<f64>,
    /// A (m²), if the series measured A.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_area: Option<f64>,
}

/// What the data determine.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct Identifiability {
    /// Whether every fitted parameter is determined alone.
    pub identifiable: bool,
    /// The parameters determined alone.
    pub determined: Vec<&'static str>,
    /// Each combination of parameters the data leave free.
    pub undetermined: Vec<Undetermined>,
    /// All of it, in a sentence or two.
    pub message: String,
}

/// A direction of parameter space along which the fit does not change.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct Undetermined {
    /// The parameters it moves.
    pub parameters: Vec<&'static str>,
    /// Its components in the logarithms of the parameters (the largest 1).
    pub direction: BTreeMap<&'static str, f64>,
    pub message: String,
}

/// How the minimum was found.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct Search {
    /// Points screened as starts (the given start and the corners of the bounds' middle half).
    pub candidates: usize,
    /// Levenberg–Marquardt runs, from the given start and the best other candidate.
    pub starts: usize,
    /// Steps over all runs.
    pub steps: usize,
    /// Whether the best run stopped by its tolerances (not its step limit).
    pub converged: bool,
    /// Runs finished: `starts`, unless the fit was stopped.
    pub finished: usize,
}

impl Output for FitOutput {
    /// `radius` and `load` for a particle's points, `total_load` for a system's.
    const UNITS: &'static UnitTable = unit_table![&[
        ("parameters.relaxation_time.value", "s"),
        ("parameters.relaxation_time.standard_error", "s"),
        ("parameters.relaxation_time.interval_95[]", "s"),
        ("parameters.relaxation_time.bounds[]", "s"),
        ("parameters.retardation_time.value", "s"),
        ("parameters.retardation_time.standard_error", "s"),
        ("parameters.retardation_time.interval_95[]", "s"),
        ("parameters.retardation_time.bounds[]", "s"),
        ("parameters.kappa.value", ""),
        ("parameters.kappa.standard_error", ""),
        ("parameters.kappa.interval_95[]", ""),
        ("parameters.kappa.bounds[]", ""),
        ("parameters.elastic_modulus.value", "Pa"),
        ("parameters.elastic_modulus.standard_error", "Pa"),
        ("parameters.elastic_modulus.interval_95[]", "Pa"),
        ("parameters.elastic_modulus.bounds[]", "Pa"),
        ("parameters.thickness.value", "m"),
        ("parameters.thickness.standard_error", "m"),
        ("parameters.thickness.interval_95[]", "m"),
        ("parameters.thickness.bounds[]", "m"),
        ("parameters.k.value", "Pa/m"),
        ("parameters.k.standard_error", "Pa/m"),
        ("parameters.k.interval_95[]", "Pa/m"),
        ("parameters.k.bounds[]", "Pa/m"),
        ("correlation[][]", ""),
        ("chi_squared", ""),
        ("dof", ""),
        ("residuals[].series", ""),
        ("residuals[].point", ""),
        ("residuals[].radius", "m"),
        ("residuals[].load", "N"),
        ("residuals[].total_load", "N"),
        ("residuals[].velocity", "m/s"),
        ("residuals[].friction_coefficient.measured", ""),
        ("residuals[].friction_coefficient.fitted", ""),
        ("residuals[].friction_coefficient.residual", ""),
        ("residuals[].friction_coefficient.uncertainty", ""),
        ("residuals[].contact_area.measured", "m^2"),
        ("residuals[].contact_area.fitted", "m^2"),
        ("residuals[].contact_area.residual", "m^2"),
        ("residuals[].contact_area.uncertainty", "m^2"),
        ("residuals[].normalized_residual", ""),
        ("curves[].series", ""),
        ("curves[].points[].radius", "m"),
        ("curves[].points[].load", "N"),
        ("curves[].points[].total_load", "N"),
        ("curves[].points[].velocity", "m/s"),
        ("curves[].points[].friction_coefficient", ""),
        ("curves[].points[].contact_area", "m^2"),
        (
            "identifiability.undetermined[].direction.relaxation_time",
            "",
        ),
        (
            "identifiability.undetermined[].direction.retardation_time",
            "",
        ),
        ("identifiability.undetermined[].direction.kappa", ""),
        (
            "identifiability.undetermined[].direction.elastic_modulus",
            "",
        ),
        ("identifiability.undetermined[].direction.thickness", ""),
        ("identifiability.undetermined[].direction.k", ""),
        ("search.candidates", ""),
        ("search.starts", ""),
        ("search.steps", ""),
        ("search.finished", ""),
    ]];

    /// One row per measured point: measured, fitted and residual in the unit of `quantity`
    /// (`m^2` for contact_area, a plain number for friction_coefficient).
    fn table(&self) -> Table {
        const COLUMNS: [Column<Residual>; 12] = [
            Column::count("series", |r| r.series),
            Column::count("point", |r| r.point),
            Column::optional("radius", "m", |r| r.at.radius),
            Column::optional("load", "N", |r| r.at.load),
            Column::optional("total_load", "N", |r| r.at.total_load),
            Column::number("velocity", "m/s", |r| r.at.velocity),
            Column::text("quantity", |r| r.compared().map_or("", |c| c.0).to_string()),
            Column::optional("measured", "", |r| r.compared().map(|c| c.2.measured)),
            Column::optional("fitted", "", |r| r.compared().map(|c| c.2.fitted)),
            Column::optional("residual", "", |r| r.compared().map(|c| c.2.residual)),
            Column::text("unit", |r| r.compared().map_or("", |c| c.1).to_string()),
            Column::number("normalized_residual", "", |r| r.normalized_residual),
        ];
        Table::new(&COLUMNS, &self.residuals)
    }
}
