//! The fit's answer: estimates with their uncertainty, the residuals and fitted curves, and
//! what the data determine.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::sync::LazyLock;

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::input::MeasuredQuantity;
use super::FitPicture;
use crate::job::{JobError, Meta};
use crate::model::fit::FitParameter;
use crate::render::{fields, Column, Output, Table, UnitTable};
use crate::{described, unit_table};

described! {
    /// The answer to a fit.
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct FitOutput {
        /// The fitted parameters, in the order of `correlation`'s rows.
        pub parameter_names: Vec<&'static str> => [],
        /// Each fitted parameter, by name (SI).
        pub parameters: BTreeMap<&'static str, Estimate> => [by parameter_units()],
        /// Correlations of the estimates (rows and columns in the order of `parameter_names`).
        /// For a parameter the data do not determine alone, they describe the combination that
        /// is determined.
        pub correlation: Vec<Vec<f64>> => [grid ""],
        /// Σ ((fitted − measured)/uncertainty)², with uncertainty 1 when none was given.
        pub chi_squared: f64 => [unit ""],
        /// Degrees of freedom: points − parameters.
        pub dof: usize => [unit ""],
        /// `given` (the points' uncertainties), or `from_scatter`: none was given, so the
        /// covariance is scaled by χ²/dof and intervals use Student's t.
        pub uncertainties: UncertaintySource => [],
        /// One row per measured point, in the order of the series and their points.
        pub residuals: Vec<Residual> => [each],
        /// The fitted model along each series.
        pub curves: Vec<Curve> => [each],
        pub identifiability: Identifiability => [nested],
        /// How the minimum was found.
        pub search: Search => [nested],
        pub meta: FitMeta => [],
        /// Why the fit stopped before its end, if it did (`meta.stopped` in words).
        #[serde(skip)]
        pub stop: Option<JobError> => [],
    }
}

/// The path and unit of each number of a fitted parameter's estimate, by parameter: the
/// estimate's numbers are in the parameter's unit.
fn parameter_units() -> Vec<(String, &'static str)> {
    let numbers = fields::units::<Estimate>();
    FitParameter::ALL
        .iter()
        .flat_map(|p| {
            let unit = p.parameter().unit();
            let paths = numbers
                .keys()
                .map(move |path| (format!("{}.{path}", p.name()), unit));
            paths.collect::<Vec<_>>()
        })
        .collect()
}

/// The path and unit of each component of a direction, by parameter.
fn direction_units() -> Vec<(String, &'static str)> {
    let names = FitParameter::ALL.iter().map(|p| p.name().to_string());
    names.map(|name| (name, "")).collect()
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

described! {
    /// A fitted parameter (SI).
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct Estimate {
        /// The best value; for a parameter not determined alone, one of many that fit equally.
        pub value: f64 => [unit ""],
        /// Its standard error (from the covariance of its logarithm); absent if the data do not
        /// determine it alone.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub standard_error: Option<f64> => [unit ""],
        /// The 95 % interval, value × exp(∓ t · standard error of ln value); absent if the data
        /// do not determine it alone.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub interval_95: Option<[f64; 2]> => [list ""],
        /// Whether the data determine it alone.
        pub determined: bool => [],
        /// The bounds it was kept within.
        pub bounds: [f64; 2] => [list ""],
        /// Whether it ended on a bound (the interval then means little).
        pub at_bound: bool => [],
    }
}

described! {
    /// The model against one measured point: `radius` and `load` on one particle, `total_load`
    /// on a three-body system; the comparison under the name of the quantity measured.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct Residual {
        /// Index of the series, and of the point in it.
        pub series: usize => [unit ""],
        pub point: usize => [unit ""],
        #[serde(flatten)]
        pub at: Conditions => [flatten],
        /// μ measured and fitted, if μ was measured.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub friction_coefficient: Option<Comparison> => [optional in ""],
        /// A (m²) measured and fitted, if A was measured.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub contact_area: Option<Comparison> => [optional in "m^2"],
        /// The particles' own friction (docs/model.md §11) measured and fitted, if it was
        /// measured.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub particle_friction: Option<Comparison> => [optional in ""],
        /// (fitted − measured)/uncertainty; from the scatter when no uncertainty was given.
        pub normalized_residual: f64 => [unit ""],
    }
}

impl CurvePoint {
    /// The model's value of `quantity`, if the curve gives it.
    pub fn value(&self, quantity: MeasuredQuantity) -> Option<f64> {
        match quantity {
            MeasuredQuantity::FrictionCoefficient => self.friction_coefficient,
            MeasuredQuantity::ContactArea => self.contact_area,
            MeasuredQuantity::ParticleFriction => self.particle_friction,
        }
    }
}

impl Residual {
    /// The comparison of `quantity`, if the point measured it.
    pub fn comparison(&self, quantity: MeasuredQuantity) -> Option<&Comparison> {
        match quantity {
            MeasuredQuantity::FrictionCoefficient => self.friction_coefficient.as_ref(),
            MeasuredQuantity::ContactArea => self.contact_area.as_ref(),
            MeasuredQuantity::ParticleFriction => self.particle_friction.as_ref(),
        }
    }

    /// The comparison with the name and unit of its quantity.
    fn compared(&self) -> Option<(&'static str, &'static str, &Comparison)> {
        MeasuredQuantity::ALL.into_iter().find_map(|q| {
            let compared = self.comparison(q)?;
            Some((q.name(), q.parameter().unit(), compared))
        })
    }
}

described! {
    /// Where a point was measured: `radius` and `load` on one particle, `total_load` on a
    /// three-body system; `velocity` always.
    #[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct Conditions {
        /// R (m), on one particle.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub radius: Option<f64> => [optional "m"],
        /// P (N), on one particle.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub load: Option<f64> => [optional "N"],
        /// W (N), on a three-body system.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub total_load: Option<f64> => [optional "N"],
        /// V (m/s).
        pub velocity: f64 => [number "m/s"],
    }
}

impl Conditions {
    /// Each condition it gives: its name, unit and value (R, P, W, V in that order).
    pub fn given(&self) -> Vec<(String, &'static str, f64)> {
        static COLUMNS: LazyLock<Vec<Column<Conditions>>> =
            LazyLock::new(fields::columns::<Conditions>);
        let given = COLUMNS.iter().filter_map(|c| {
            let value = c.value(self)?;
            Some((c.name.to_string(), c.unit, value))
        });
        given.collect()
    }
}

described! {
    /// A measured value beside the model's (all in the unit of the quantity measured).
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct Comparison {
        pub measured: f64 => [unit ""],
        pub fitted: f64 => [unit ""],
        /// fitted − measured.
        pub residual: f64 => [unit ""],
        /// The standard uncertainty given.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub uncertainty: Option<f64> => [unit ""],
    }
}

described! {
    /// The fitted model along a series: over the range of the condition its points vary (dense),
    /// or through its points when they vary more than one.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct Curve {
        pub series: usize => [unit ""],
        pub quantity: MeasuredQuantity => [],
        /// The condition along the curve: `velocity`, `load`, `radius` or `total_load`.
        #[schema(value_type = String)]
        pub along: Cow<'static, str> => [],
        pub points: Vec<CurvePoint> => [each],
    }
}

described! {
    /// A point of a fitted curve: its conditions as a residual gives them, and the model's value
    /// under the name of the quantity.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct CurvePoint {
        #[serde(flatten)]
        pub at: Conditions => [flatten],
        /// μ, if the series measured μ.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub friction_coefficient: Option<f64> => [unit ""],
        /// A (m²), if the series measured A.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub contact_area: Option<f64> => [unit "m^2"],
        /// The particles' own friction, if the series measured it.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub particle_friction: Option<f64> => [unit ""],
    }
}

described! {
    /// What the data determine.
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct Identifiability {
        /// Whether every fitted parameter is determined alone.
        pub identifiable: bool => [],
        /// The parameters determined alone.
        pub determined: Vec<&'static str> => [],
        /// Each combination of parameters the data leave free.
        pub undetermined: Vec<Undetermined> => [each],
        /// All of it, in a sentence or two.
        pub message: String => [],
    }
}

described! {
    /// A direction of parameter space along which the fit does not change.
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct Undetermined {
        /// The parameters it moves.
        pub parameters: Vec<&'static str> => [],
        /// Its components in the logarithms of the parameters (the largest 1).
        pub direction: BTreeMap<&'static str, f64> => [by direction_units()],
        pub message: String => [],
    }
}

described! {
    /// How the minimum was found.
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct Search {
        /// Points screened as starts (the given start and the corners of the bounds' middle half).
        pub candidates: usize => [unit ""],
        /// Levenberg–Marquardt runs, from the given start and the best other candidate.
        pub starts: usize => [unit ""],
        /// Steps over all runs.
        pub steps: usize => [unit ""],
        /// Whether the best run stopped by its tolerances (not its step limit).
        pub converged: bool => [],
        /// Runs finished: `starts`, unless the fit was stopped.
        pub finished: usize => [unit ""],
    }
}

impl Output for FitOutput {
    /// `radius` and `load` for a particle's points, `total_load` for a system's.
    const UNITS: &'static UnitTable = unit_table!(FitOutput);
    type Picture = FitPicture;

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
            Column::text("quantity", |r, text| {
                text.push_str(r.compared().map_or("", |c| c.0))
            }),
            Column::optional("measured", "", |r| r.compared().map(|c| c.2.measured)),
            Column::optional("fitted", "", |r| r.compared().map(|c| c.2.fitted)),
            Column::optional("residual", "", |r| r.compared().map(|c| c.2.residual)),
            Column::text("unit", |r, text| {
                text.push_str(r.compared().map_or("", |c| c.1))
            }),
            Column::number("normalized_residual", "", |r| r.normalized_residual),
        ];
        // Each fitted parameter and its standard error beside every residual: a CSV alone
        // says what was fitted.
        let fitted = self.parameter_names.iter().filter_map(|&name| {
            let unit = FitParameter::ALL
                .iter()
                .find(|p| p.name() == name)
                .map_or("", |p| p.parameter().unit());
            Some((name, unit, self.parameters.get(name)?))
        });
        fitted.fold(
            Table::new(&COLUMNS, &self.residuals),
            |table, (name, unit, e)| {
                table
                    .with_constant(&format!("fitted_{name}"), unit, Some(e.value))
                    .with_constant(
                        &format!("fitted_{name}_standard_error"),
                        unit,
                        e.standard_error,
                    )
            },
        )
    }
}
