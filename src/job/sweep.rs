//! The sweep job: the Cartesian product of lists of radius, load and speed over a base
//! rolling job, one row per point.

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use utoipa::ToSchema;

use super::fields::{self, Checker, Quantity};
use super::rolling::{si, ContactOutput, RollingInput, RollingJob, VerificationOutput};
use super::units::Dimension;
use super::{format_number, JobError, JobKind, Limits, Meta};
use crate::model::{Parameter, Rolling, RollingSolution, SolveOptions};

/// Input of a sweep: a base rolling input and the lists to vary over it.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SweepInput {
    /// The rolling input every point starts from (its options keep the quadrature only).
    pub base: Option<RollingInput>,
    /// The lists to vary; the points are their Cartesian product.
    pub vary: Option<VaryInput>,
}

/// The values to sweep; an absent list keeps the base value.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct VaryInput {
    /// R values (m).
    pub radius: Option<Vec<Quantity>>,
    /// P values (N).
    pub load: Option<Vec<Quantity>>,
    /// V values (m/s).
    pub velocity: Option<Vec<Quantity>>,
}

/// A validated sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepJob {
    /// The base job; its options ask for the integral quantities only.
    pub base: RollingJob,
    pub radius: Vec<f64>,
    pub load: Vec<f64>,
    pub velocity: Vec<f64>,
}

impl SweepJob {
    /// Validates a sweep input given as JSON.
    pub fn from_value(value: Value, limits: &Limits) -> Result<SweepJob, JobError> {
        let input: SweepInput = fields::deserialize(value, "")?;
        let mut base_checker = Checker::new("base");
        let mut base = RollingJob::read(&input.base.unwrap_or_default(), &mut base_checker);
        base.options = SolveOptions::integrals_only(base.options.quadrature);
        let mut checker = Checker::new("");
        checker.absorb(base_checker);
        let vary = input.vary.unwrap_or_default();
        let mut list =
            |name: &str, values: &Option<Vec<Quantity>>, parameter: Parameter, dim, base: f64| {
                read_list(&mut checker, name, values.as_deref(), parameter, dim, base)
            };
        let radius = list(
            "vary.radius",
            &vary.radius,
            Parameter::Radius,
            Dimension::LENGTH,
            base.rolling.radius,
        );
        let load = list(
            "vary.load",
            &vary.load,
            Parameter::Load,
            Dimension::FORCE,
            base.rolling.load,
        );
        let velocity = list(
            "vary.velocity",
            &vary.velocity,
            Parameter::Velocity,
            Dimension::SPEED,
            base.rolling.velocity,
        );
        let points = radius.len() * load.len() * velocity.len();
        if points > limits.max_sweep_points {
            checker.invalid(
                "vary",
                json!(points),
                &format!(
                    "at most {} points (the product of the list lengths)",
                    limits.max_sweep_points
                ),
            );
        }
        checker.finish(SweepJob {
            base,
            radius,
            load,
            velocity,
        })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.radius.len() * self.load.len() * self.velocity.len()
    }

    /// Whether the sweep has no points (never, once validated).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The contacts to solve: radius outermost, then load, then speed.
    pub fn points(&self) -> Vec<Rolling> {
        let mut points = Vec::with_capacity(self.len());
        for &radius in &self.radius {
            for &load in &self.load {
                for &velocity in &self.velocity {
                    points.push(Rolling {
                        radius,
                        load,
                        velocity,
                        ..self.base.rolling
                    });
                }
            }
        }
        points
    }

    /// The canonical input: the base in canonical form and every list explicit.
    pub fn canonical(&self) -> Value {
        let list = |values: &[f64]| values.iter().map(|&x| si(x)).collect::<Vec<_>>();
        json!({
            "base": self.base.canonical(),
            "vary": {
                "radius": list(&self.radius),
                "load": list(&self.load),
                "velocity": list(&self.velocity),
            },
        })
    }
}

/// Reads one list of the sweep; absent, it is the base value alone.
fn read_list(
    checker: &mut Checker,
    name: &str,
    values: Option<&[Quantity]>,
    parameter: Parameter,
    dimension: Dimension,
    base: f64,
) -> Vec<f64> {
    let Some(values) = values else {
        return vec![base];
    };
    if values.is_empty() {
        checker.invalid(name, json!([]), "a list of at least one value");
    }
    values
        .iter()
        .enumerate()
        .map(|(i, q)| {
            let field = format!("{name}[{i}]");
            let x = checker.quantity(&field, Some(q), dimension, base);
            if let Err(e) = parameter.check(x) {
                checker.out_of_range(&field, x, parameter.unit(), &e.allowed);
            }
            x
        })
        .collect()
}

/// One row of a sweep.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct SweepPoint {
    /// R (m).
    pub radius: f64,
    /// P (N).
    pub load: f64,
    /// V (m/s).
    pub velocity: f64,
    #[serde(flatten)]
    pub contact: ContactOutput,
    /// How far this point's numbers can be trusted.
    pub verification: VerificationOutput,
}

/// The answer to a sweep.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct SweepOutput {
    /// One row per point: radius outermost, then load, then speed.
    pub points: Vec<SweepPoint>,
    pub meta: Meta,
}

/// Columns of the CSV form of a sweep, all SI.
const CSV_HEADER: &str = "radius,load,velocity,penetration,contact_area,half_width,\
centroid_shift,pressure_centre_shift,rolling_resistance_coefficient,friction_coefficient,\
static_penetration,static_contact_area,static_friction_coefficient";

impl SweepOutput {
    /// `solutions` are those of [`SweepJob::points`], in order.
    pub fn new(job: &SweepJob, solutions: &[RollingSolution]) -> Self {
        let points = job
            .points()
            .iter()
            .zip(solutions)
            .map(|(p, s)| SweepPoint {
                radius: p.radius,
                load: p.load,
                velocity: p.velocity,
                contact: s.into(),
                verification: (&s.verification).into(),
            })
            .collect();
        SweepOutput {
            points,
            meta: Meta::new(JobKind::Sweep, job.canonical()),
        }
    }

    /// One header line and one line per point, SI units, shortest round-trip numbers.
    pub fn to_csv(&self) -> String {
        let mut csv = format!("{CSV_HEADER}\n");
        for p in &self.points {
            let c = &p.contact;
            let row = [
                p.radius,
                p.load,
                p.velocity,
                c.penetration,
                c.contact_area,
                c.half_width,
                c.centroid_shift,
                c.pressure_centre_shift,
                c.rolling_resistance_coefficient,
                c.friction_coefficient,
                c.static_contact.penetration,
                c.static_contact.contact_area,
                c.static_contact.friction_coefficient,
            ];
            let cells: Vec<String> = row.iter().map(|&x| format_number(x)).collect();
            csv.push_str(&cells.join(","));
            csv.push('\n');
        }
        csv
    }
}
