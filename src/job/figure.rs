//! The figure job: the data of one of the paper's Figures 3–9 (MODEL.md §5).

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use utoipa::ToSchema;

use super::fields::{self, Checker};
use super::{format_number, JobError, Meta};
use crate::model::figures::{Figure, Plan, FIGURES};

/// Input of a figure job.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct FigureInput {
    /// The figure's number in the paper, 3 to 9.
    pub number: i64,
}

/// A validated figure job.
#[derive(Clone, Debug)]
pub struct FigureJob {
    pub plan: Plan,
}

impl PartialEq for FigureJob {
    fn eq(&self, other: &Self) -> bool {
        self.plan.number == other.plan.number
    }
}

impl FigureJob {
    /// The job for figure `number`, or the error naming the allowed numbers.
    pub fn new(number: i64) -> Result<FigureJob, JobError> {
        let Some(plan) = u8::try_from(number).ok().and_then(Plan::new) else {
            let mut checker = Checker::new("");
            checker.invalid(
                "number",
                json!(number),
                &format!("{} to {}", FIGURES.start(), FIGURES.end()),
            );
            return Err(checker.into_error());
        };
        Ok(FigureJob { plan })
    }

    /// Validates a figure input given as JSON.
    pub fn from_value(value: Value) -> Result<FigureJob, JobError> {
        let input: FigureInput = fields::deserialize(value, "")?;
        FigureJob::new(input.number)
    }

    /// Rolling solves the figure takes.
    pub fn size(&self) -> usize {
        self.plan.contacts.len()
    }

    pub fn canonical(&self) -> Value {
        json!({ "number": self.plan.number })
    }
}

/// An axis of a figure.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct AxisOutput {
    /// What the axis shows, e.g. `contact_area`.
    pub quantity: &'static str,
    /// SI unit ("" for a plain number).
    pub unit: &'static str,
}

/// One curve.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct SeriesOutput {
    /// The curve's legend, e.g. `V = 4 nm/s`.
    pub label: String,
    /// R of the curve (m), when it is fixed along it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// P of the curve (N), when it is fixed along it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub load: Option<f64>,
    /// V of the curve (m/s).
    pub velocity: f64,
    /// [x, y] pairs in the units of the axes.
    pub points: Vec<[f64; 2]>,
}

/// The answer to a figure job.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct FigureOutput {
    /// The figure's number in the paper, 3 to 9.
    pub figure: u8,
    /// What the figure shows.
    pub title: &'static str,
    /// The horizontal axis: its quantity and SI unit.
    pub x: AxisOutput,
    /// The vertical axis: its quantity and SI unit.
    pub y: AxisOutput,
    /// The curves.
    pub series: Vec<SeriesOutput>,
    pub meta: Meta,
}

impl FigureOutput {
    /// The answer with `meta`, the job's [`Meta`] (see [`super::Job::meta`]).
    pub fn new(figure: Figure, meta: Meta) -> Self {
        let axis = |a: crate::model::figures::Axis| AxisOutput {
            quantity: a.quantity,
            unit: a.unit,
        };
        FigureOutput {
            figure: figure.number,
            title: figure.title,
            x: axis(figure.x),
            y: axis(figure.y),
            series: figure
                .series
                .into_iter()
                .map(|s| SeriesOutput {
                    label: s.label,
                    radius: s.radius,
                    load: s.load,
                    velocity: s.velocity,
                    points: s.points,
                })
                .collect(),
            meta,
        }
    }

    /// CSV: one line per point, `series,label,<x quantity>,<y quantity>`.
    pub fn to_csv(&self) -> String {
        let column = |a: &AxisOutput| {
            if a.unit.is_empty() {
                a.quantity.to_string()
            } else {
                format!("{} ({})", a.quantity, a.unit)
            }
        };
        let mut csv = format!("series,label,{},{}\n", column(&self.x), column(&self.y));
        for (i, s) in self.series.iter().enumerate() {
            for [x, y] in &s.points {
                let (x, y) = (format_number(*x), format_number(*y));
                csv.push_str(&format!("{i},\"{}\",{x},{y}\n", s.label));
            }
        }
        csv
    }
}
