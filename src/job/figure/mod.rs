//! The figure job: the data of one of the paper's Figures 3–9 (docs/model.md §5).

mod picture;
pub use picture::FigurePicture;

use std::borrow::Cow;

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use utoipa::ToSchema;

use super::input::{self, Checker};
use super::kind::SMALL_ANSWER;
use super::meta::ROLLING_REFERENCES;
use super::{Control, JobError, Kind, Limits, Meta, References, Validated, Work};
use crate::model::figures::{Axis, Figure, Plan, FIGURES};
use crate::model::tables::{self, Use};
use crate::render::{Column, Output, Table, UnitTable};
use crate::{described, unit_table};

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
            let mut checker = Checker::new();
            let allowed = format!("{} to {}", FIGURES.start(), FIGURES.end());
            checker.invalid("number", json!(number), &allowed);
            return Err(checker.into_error());
        };
        Ok(FigureJob { plan })
    }
}

impl Kind for FigureJob {
    const NAME: &'static str = "figure";
    type Input = FigureInput;
    type Output = FigureOutput;

    fn validate(input: Value, _limits: &Limits) -> Result<Validated<Self>, JobError> {
        let number = input::deserialize::<FigureInput>(input, "")?.number;
        FigureJob::new(number).map(Validated::from)
    }

    fn canonical(&self) -> Value {
        input::canonical(&FigureInput {
            number: i64::from(self.plan.number),
        })
    }

    fn references(&self) -> &'static References {
        &ROLLING_REFERENCES
    }

    fn work(&self) -> Work {
        Work::Known(self.plan.contacts.len())
    }

    /// A plotted point is at most two numbers and its legend in JSON, a row in CSV.
    fn result_bytes(&self) -> u64 {
        SMALL_ANSWER + self.plan.contacts.len() as u64 * 512
    }

    fn run(&self, meta: Meta, control: &Control) -> Result<FigureOutput, JobError> {
        let plan = &self.plan;
        // Every figure is on the default layer: its table serves them all.
        let solutions = control.map(&plan.contacts, |p| {
            tables::solve(p, &plan.options, Use::Build)
        })?;
        Ok(FigureOutput::new(plan.assemble(&solutions), meta))
    }
}

/// An axis of a figure.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct AxisOutput {
    /// What the axis shows, e.g. `contact_area`.
    #[schema(value_type = String)]
    pub quantity: Cow<'static, str>,
    /// SI unit ("" for a plain number).
    #[schema(value_type = String)]
    pub unit: Cow<'static, str>,
}

impl From<Axis> for AxisOutput {
    fn from(a: Axis) -> Self {
        AxisOutput {
            quantity: Cow::Borrowed(a.quantity),
            unit: Cow::Borrowed(a.unit),
        }
    }
}

described! {
    /// One curve.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
    pub struct SeriesOutput {
        /// The curve's legend, e.g. `V = 4 nm/s`.
        pub label: String => [],
        /// R of the curve (m), when it is fixed along it.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub radius: Option<f64> => [unit "m"],
        /// P of the curve (N), when it is fixed along it.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub load: Option<f64> => [unit "N"],
        /// V of the curve (m/s).
        pub velocity: f64 => [unit "m/s"],
        /// [x, y] pairs in the units of the axes.
        pub points: Vec<[f64; 2]> => [grid "x.unit, y.unit"],
    }
}

described! {
    /// The answer to a figure job.
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct FigureOutput {
        /// The figure's number in the paper, 3 to 9.
        pub figure: u8 => [unit ""],
        /// What the figure shows.
        pub title: &'static str => [],
        /// The horizontal axis: its quantity and SI unit.
        pub x: AxisOutput => [],
        /// The vertical axis: its quantity and SI unit.
        pub y: AxisOutput => [],
        /// The curves.
        pub series: Vec<SeriesOutput> => [each],
        pub meta: Meta => [],
    }
}

impl FigureOutput {
    /// The answer with `meta`, the job's [`Meta`] (see [`super::Job::meta`]).
    pub fn new(figure: Figure, meta: Meta) -> Self {
        FigureOutput {
            figure: figure.number,
            title: figure.title,
            x: figure.x.into(),
            y: figure.y.into(),
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
}

/// One point of a figure, as a CSV row.
struct FigureRow<'a> {
    series: usize,
    of: &'a SeriesOutput,
    point: [f64; 2],
}

impl Output for FigureOutput {
    /// The points are in the units of the axes, which the answer names.
    const UNITS: &'static UnitTable = unit_table!(FigureOutput);
    type Picture = FigurePicture;

    /// One row per point: the series' index and legend, then x and y in the axes' units, then
    /// the conditions its series holds fixed (R, P, V) as columns of their own.
    fn table(&self) -> Table {
        fn columns<'a>() -> [Column<FigureRow<'a>>; 4] {
            [
                Column::count("series", |r| r.series),
                Column::text("label", |r, text| text.push_str(&r.of.label)),
                Column::number("x", "", |r| r.point[0]),
                Column::number("y", "", |r| r.point[1]),
            ]
        }
        /// What a curve holds fixed, but for the x axis's quantity, which varies along it.
        fn conditions<'a>() -> [Column<FigureRow<'a>>; 3] {
            [
                Column::optional("radius", "m", |r| r.of.radius),
                Column::optional("load", "N", |r| r.of.load),
                Column::number("velocity", "m/s", |r| r.of.velocity),
            ]
        }
        let rows: Vec<FigureRow> = self
            .series
            .iter()
            .enumerate()
            .flat_map(|(series, s)| {
                s.points.iter().map(move |&point| FigureRow {
                    series,
                    of: s,
                    point,
                })
            })
            .collect();
        let conditions = conditions().into_iter();
        let columns: Vec<Column<FigureRow>> = columns()
            .into_iter()
            .chain(conditions.filter(|c| c.name != self.x.quantity))
            .collect();
        let mut table = Table::new(&columns, &rows);
        table.rename(2, &self.x.quantity, &self.x.unit);
        table.rename(3, &self.y.quantity, &self.y.unit);
        table
    }
}
