//! The picture of a sweep: the friction coefficient against the longest varied list, one
//! curve per combination of the others; points at rest (V = 0) hollow, rolling ones
//! filled; points without numbers (refused, or not solved) counted in a note.

use std::collections::BTreeMap;

use serde::Deserialize;
use serde_json::Value;

use crate::job::input::LayerModel;
use crate::job::picture::{shown, symbol, PictureError};
use crate::job::points::PointStatus;
use crate::job::rolling::ContactOutput;
use crate::job::three_body::{operating_units, ThreeBodyResult};
use crate::model::text::prefixed;
use crate::model::Parameter;
use crate::render::svg::{Axis, Chart, Layer};
use crate::render::Picture;

/// What the picture shows of a sweep: its rows, and which law of the layer answered them
/// with what error.
#[derive(Deserialize)]
pub struct SweepPicture {
    points: Rows,
    meta: Option<Value>,
}

/// The note naming the layer law of a rolling sweep whose `meta` is `meta` (on the
/// continuum, with its worst error in A); none for a three-body sweep, whose layer names no
/// model (its contact law is a field of its own).
fn law(meta: &Value) -> Option<String> {
    let model = meta.pointer("/input/base/layer/model")?;
    Some(match LayerModel::deserialize(model).ok()? {
        LayerModel::Local => "layer: local law (the paper's)".to_string(),
        LayerModel::Continuum => {
            let verification = meta.get("verification")?;
            match verification
                .get("contact_area_error")
                .and_then(Value::as_f64)
            {
                Some(error) => format!("layer: continuum, A within ±{:.2} %", 100.0 * error),
                None => "layer: continuum".to_string(),
            }
        }
    })
}

/// The rows of either kind, as the output writes them.
#[derive(Deserialize)]
#[serde(untagged)]
enum Rows {
    Rolling(Vec<RollingRow>),
    ThreeBody(Vec<ThreeBodyRow>),
}

#[derive(Deserialize)]
struct RollingRow {
    radius: f64,
    load: f64,
    velocity: f64,
    status: PointStatus,
    #[serde(flatten)]
    contact: Option<ContactOutput>,
}

#[derive(Deserialize)]
struct ThreeBodyRow {
    /// One operating point, by its name.
    operating: BTreeMap<String, f64>,
    velocity: f64,
    mean_diameter: f64,
    status: PointStatus,
    #[serde(flatten)]
    result: Option<ThreeBodyResult>,
}

/// A condition of a row: its name, unit and value.
type Condition = (String, &'static str, f64);

/// A row as the picture uses it: its conditions, in the order a curve is preferred along
/// (speed first), and its friction coefficient (`None`: not answered).
struct Drawn {
    conditions: Vec<Condition>,
    mu: Option<f64>,
    velocity: f64,
}

impl Rows {
    /// The rows drawn, and the name of the friction coefficient they give.
    fn drawn(self) -> (Vec<Drawn>, &'static str) {
        let answered =
            |status: PointStatus| !matches!(status, PointStatus::Refused | PointStatus::Missing);
        match self {
            Rows::Rolling(rows) => {
                let rows = rows.into_iter().map(|r| Drawn {
                    conditions: vec![
                        condition("velocity", Parameter::Velocity, r.velocity),
                        condition("load", Parameter::Load, r.load),
                        condition("radius", Parameter::Radius, r.radius),
                    ],
                    mu: r
                        .contact
                        .filter(|_| answered(r.status))
                        .map(|c| c.friction_coefficient),
                    velocity: r.velocity,
                });
                (rows.collect(), "friction coefficient")
            }
            Rows::ThreeBody(rows) => {
                let units = operating_units();
                let rows = rows.into_iter().map(|r| {
                    let mut conditions = vec![
                        condition("velocity", Parameter::Velocity, r.velocity),
                        condition("mean_diameter", Parameter::MeanDiameter, r.mean_diameter),
                    ];
                    for (name, value) in r.operating {
                        let unit = units.iter().find(|u| u.0 == name).map_or("", |u| u.1);
                        conditions.push((name, unit, value));
                    }
                    let mu = r.result.filter(|_| answered(r.status));
                    Drawn {
                        conditions,
                        mu: mu.map(|r| r.friction_coefficient.rolling),
                        velocity: r.velocity,
                    }
                });
                (rows.collect(), "rolling friction coefficient")
            }
        }
    }
}

fn condition(name: &str, parameter: Parameter, value: f64) -> Condition {
    (name.to_string(), parameter.unit(), value)
}

/// A condition that varies over the rows: its index, its number of distinct values, and the
/// unit its legend labels are written in (that of its largest value, with its factor from
/// SI), so that one condition reads in one unit: "V = 0 nm/s" beside "V = 4 nm/s", and
/// "P = 0.5 nN" beside "P = 2 nN" (not "500 pN").
struct Varied {
    index: usize,
    values: usize,
    unit: (f64, String),
}

/// The conditions that vary over `rows`.
fn varied(rows: &[Drawn], first: &Drawn) -> Vec<Varied> {
    let values =
        |i: usize| -> Vec<u64> { rows.iter().map(|r| r.conditions[i].2.to_bits()).collect() };
    (0..first.conditions.len())
        .filter_map(|index| {
            let mut seen = values(index);
            seen.sort_unstable();
            seen.dedup();
            let largest = rows
                .iter()
                .map(|r| r.conditions[index].2.abs())
                .fold(0.0, f64::max);
            let unit = prefixed(first.conditions[index].1, largest);
            (seen.len() > 1).then_some(Varied {
                index,
                values: seen.len(),
                unit,
            })
        })
        .collect()
}

/// The label of `row`'s curve: the values of the `varied` conditions other than the one
/// drawn `along`, or `sweep` when there are none.
fn label(row: &Drawn, varied: &[Varied], along: usize) -> String {
    let label: Vec<String> = varied
        .iter()
        .filter(|v| v.index != along)
        .map(|v| {
            let (name, _, value) = &row.conditions[v.index];
            let (factor, unit) = &v.unit;
            let number = shown(value * factor, "");
            format!("{} = {number} {unit}", symbol(name))
                .trim_end()
                .to_string()
        })
        .collect();
    if label.is_empty() {
        "sweep".to_string()
    } else {
        label.join(", ")
    }
}

/// A line for each curve, then the points at rest of them all as hollow markers.
fn layers(curves: Vec<Curve>) -> Vec<Layer> {
    let mut layers = Vec::new();
    let mut rest = Vec::new();
    for (name, line, at_rest) in curves {
        layers.push(Layer::Line {
            group: name.clone(),
            name,
            points: line,
            dashed: false,
        });
        rest.extend(at_rest);
    }
    if !rest.is_empty() {
        layers.push(Layer::Markers {
            name: "at rest, V = 0".to_string(),
            points: rest,
            hollow: true,
        });
    }
    layers
}

impl Picture for SweepPicture {
    fn chart(self) -> Result<Chart, PictureError> {
        let (rows, y_name) = self.points.drawn();
        let first = rows
            .first()
            .ok_or_else(|| PictureError::new("the sweep has no point"))?;
        let varied = varied(&rows, first);
        // The longest list; of equal ones, the first (`max_by_key` keeps the last).
        let along = varied
            .iter()
            .rev()
            .max_by_key(|v| v.values)
            .map_or(0, |v| v.index);
        let (along_name, along_unit, _) = &first.conditions[along];
        // Curves by the values of the other varied lists, in order of first appearance.
        let mut curves: Vec<Curve> = Vec::new();
        let mut unanswered = 0;
        for row in &rows {
            let Some(mu) = row.mu else {
                unanswered += 1;
                continue;
            };
            let label = label(row, &varied, along);
            let point = (row.conditions[along].2, mu);
            let index = match curves.iter().position(|c| c.0 == label) {
                Some(i) => i,
                None => {
                    curves.push((label, Vec::new(), Vec::new()));
                    curves.len() - 1
                }
            };
            curves[index].1.push(point);
            if row.velocity == 0.0 {
                curves[index].2.push(point);
            }
        }
        let layers = layers(curves);
        // Short lines: they stand under the legend.
        let mut notes: Vec<String> = self.meta.as_ref().and_then(law).into_iter().collect();
        if unanswered > 0 {
            notes.push(format!("{unanswered} of {} points not drawn:", rows.len()));
            notes.push("refused, or not solved".to_string());
        }
        Ok(Chart {
            title: format!("Sweep: {y_name} against {}", along_name.replace('_', " ")),
            x: Axis::new(along_name, along_unit),
            y: Axis::new(y_name, ""),
            layers,
            equal_aspect: false,
            notes,
        })
    }
}

/// A sweep's curve: its label, its points, and those of them at rest.
type Curve = (String, Vec<(f64, f64)>, Vec<(f64, f64)>);
