//! The sweep job: the Cartesian product of lists over a base job, one row per point, for
//! rolling jobs (radius, load, speed) and three-body jobs (operating point, speed, mean
//! diameter).

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use utoipa::ToSchema;

use super::fields::{self, Checker, Quantity};
use super::rolling::{si, ContactOutput, RollingInput, RollingJob, VerificationOutput};
use super::three_body::{
    operating_canonical, OperatingInput, ThreeBodyInput, ThreeBodyJob, ThreeBodyResult,
    ThreeBodyVerificationOutput,
};
use super::units::Dimension;
use super::{format_number, JobError, Limits, Meta};
use crate::model::three_body::{Diameters, OperatingPoint, ThreeBody, ThreeBodySolution};
use crate::model::{Parameter, Rolling, RollingSolution, SolveOptions};

/// Input of a sweep: what is swept, a base input of that kind and the lists to vary.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SweepInput {
    /// The kind of the base job: `rolling` (default) or `three_body`.
    pub kind: Option<SweepOf>,
    /// The input every point starts from: a `RollingInput` or a `ThreeBodyInput` (a rolling
    /// base keeps only its quadrature options).
    #[schema(value_type = Option<Object>)]
    pub base: Option<Value>,
    /// The lists to vary (the points are their Cartesian product): a `RollingVary` or a
    /// `ThreeBodyVary`. An absent list keeps the base value.
    #[schema(value_type = Option<Object>)]
    pub vary: Option<Value>,
}

/// The kind of job a sweep repeats.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum SweepOf {
    #[default]
    Rolling,
    ThreeBody,
}

/// The lists of a rolling sweep.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct RollingVary {
    /// R values (m).
    pub radius: Option<Vec<Quantity>>,
    /// P values (N).
    pub load: Option<Vec<Quantity>>,
    /// V values (m/s).
    pub velocity: Option<Vec<Quantity>>,
}

/// The lists of a three-body sweep; at most one operating-point list.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ThreeBodyVary {
    /// d values (m).
    pub separation: Option<Vec<Quantity>>,
    /// W values (N).
    pub total_load: Option<Vec<Quantity>>,
    /// Mean particle loads (N).
    pub particle_load: Option<Vec<Quantity>>,
    /// V values (m/s).
    pub velocity: Option<Vec<Quantity>>,
    /// x_a values (m); default bounds x_a ∓ 3σ_a follow each value.
    pub mean_diameter: Option<Vec<Quantity>>,
}

/// A validated sweep.
#[derive(Clone, Debug, PartialEq)]
pub enum SweepJob {
    Rolling(RollingSweep),
    ThreeBody(ThreeBodySweep),
}

/// A sweep of rolling jobs.
#[derive(Clone, Debug, PartialEq)]
pub struct RollingSweep {
    /// The base job; its options ask for the integral quantities only.
    pub base: RollingJob,
    pub radius: Vec<f64>,
    pub load: Vec<f64>,
    pub velocity: Vec<f64>,
}

/// A sweep of three-body jobs.
#[derive(Clone, Debug, PartialEq)]
pub struct ThreeBodySweep {
    pub base: ThreeBodyJob,
    pub operating: Vec<OperatingPoint>,
    pub velocity: Vec<f64>,
    pub mean_diameter: Vec<f64>,
    /// Whether the base fixed the diameter bounds (else they follow each mean).
    fixed_bounds: (bool, bool),
}

impl SweepJob {
    /// Validates a sweep input given as JSON.
    pub fn from_value(value: Value, limits: &Limits) -> Result<SweepJob, JobError> {
        let input: SweepInput = fields::deserialize(value, "")?;
        let base = input.base.unwrap_or_else(|| json!({}));
        let vary = input.vary.unwrap_or_else(|| json!({}));
        let mut checker = Checker::new("");
        let job = match input.kind.unwrap_or_default() {
            SweepOf::Rolling => SweepJob::Rolling(RollingSweep::read(base, vary, &mut checker)?),
            SweepOf::ThreeBody => {
                SweepJob::ThreeBody(ThreeBodySweep::read(base, vary, &mut checker)?)
            }
        };
        if job.len() > limits.max_sweep_points {
            checker.invalid(
                "vary",
                json!(job.len()),
                &format!(
                    "at most {} points (the product of the list lengths)",
                    limits.max_sweep_points
                ),
            );
        }
        checker.finish(job)
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        match self {
            SweepJob::Rolling(s) => s.radius.len() * s.load.len() * s.velocity.len(),
            SweepJob::ThreeBody(s) => s.operating.len() * s.velocity.len() * s.mean_diameter.len(),
        }
    }

    /// Whether the sweep has no points (never, once validated).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The canonical input: the base in canonical form and every list explicit.
    pub fn canonical(&self) -> Value {
        let list = |values: &[f64]| values.iter().map(|&x| si(x)).collect::<Vec<_>>();
        match self {
            SweepJob::Rolling(s) => json!({
                "kind": "rolling",
                "base": s.base.canonical(),
                "vary": {
                    "radius": list(&s.radius),
                    "load": list(&s.load),
                    "velocity": list(&s.velocity),
                },
            }),
            SweepJob::ThreeBody(s) => {
                let operating: Vec<Value> = s
                    .operating
                    .iter()
                    .map(|&o| operating_canonical(o))
                    .collect();
                json!({
                    "kind": "three_body",
                    "base": s.base.canonical(),
                    "vary": {
                        "operating": operating,
                        "velocity": list(&s.velocity),
                        "mean_diameter": list(&s.mean_diameter),
                    },
                })
            }
        }
    }
}

impl RollingSweep {
    fn read(base: Value, vary: Value, checker: &mut Checker) -> Result<RollingSweep, JobError> {
        let base: RollingInput = fields::deserialize(base, "base")?;
        let vary: RollingVary = fields::deserialize(vary, "vary")?;
        let mut base_checker = Checker::new("base");
        let mut base = RollingJob::read(&base, &mut base_checker);
        checker.absorb(base_checker);
        base.options = SolveOptions::integrals_only(base.options.quadrature);
        let r = base.rolling;
        Ok(RollingSweep {
            radius: read_list(
                checker,
                "vary.radius",
                vary.radius.as_deref(),
                Parameter::Radius,
                Dimension::LENGTH,
                r.radius,
            ),
            load: read_list(
                checker,
                "vary.load",
                vary.load.as_deref(),
                Parameter::Load,
                Dimension::FORCE,
                r.load,
            ),
            velocity: read_list(
                checker,
                "vary.velocity",
                vary.velocity.as_deref(),
                Parameter::Velocity,
                Dimension::SPEED,
                r.velocity,
            ),
            base,
        })
    }

    /// The contacts to solve: radius outermost, then load, then speed.
    pub fn points(&self) -> Vec<Rolling> {
        let mut points = Vec::new();
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
}

impl ThreeBodySweep {
    fn read(base: Value, vary: Value, checker: &mut Checker) -> Result<ThreeBodySweep, JobError> {
        let mut base: ThreeBodyInput = fields::deserialize(base, "base")?;
        let vary: ThreeBodyVary = fields::deserialize(vary, "vary")?;
        let lists = [
            (
                "separation",
                &vary.separation,
                Parameter::Separation,
                Dimension::LENGTH,
            ),
            (
                "total_load",
                &vary.total_load,
                Parameter::TotalLoad,
                Dimension::FORCE,
            ),
            (
                "particle_load",
                &vary.particle_load,
                Parameter::ParticleLoad,
                Dimension::FORCE,
            ),
        ];
        let varied: Vec<_> = lists.iter().filter(|l| l.1.is_some()).collect();
        if varied.len() > 1 {
            checker.invalid(
                "vary",
                json!(varied.iter().map(|l| l.0).collect::<Vec<_>>()),
                "at most one operating-point list (separation, total_load or particle_load)",
            );
        }
        // A varied operating point replaces the base's; the base needs one to be read.
        if let Some((name, Some(values), ..)) = varied.first().map(|l| **l) {
            if let Some(first) = values.first() {
                let mut operating = OperatingInput::default();
                match name {
                    "separation" => operating.separation = Some(first.clone()),
                    "total_load" => operating.total_load = Some(first.clone()),
                    _ => operating.particle_load = Some(first.clone()),
                }
                base.operating = Some(operating);
            }
        }
        let bounds = base.distribution.as_ref().map_or((false, false), |d| {
            (d.min_diameter.is_some(), d.max_diameter.is_some())
        });
        let mut base_checker = Checker::new("base");
        let job = ThreeBodyJob::read(&base, &mut base_checker);
        checker.absorb(base_checker);
        let s = job.system;
        let operating = match varied.first() {
            Some(&&(name, values, parameter, dimension)) => {
                let values = read_list(
                    checker,
                    &format!("vary.{name}"),
                    values.as_deref(),
                    parameter,
                    dimension,
                    f64::NAN,
                );
                values
                    .into_iter()
                    .map(|x| match name {
                        "separation" => OperatingPoint::Separation(x),
                        "total_load" => OperatingPoint::TotalLoad(x),
                        _ => OperatingPoint::ParticleLoad(x),
                    })
                    .collect()
            }
            None => vec![s.operating],
        };
        let sweep = ThreeBodySweep {
            velocity: read_list(
                checker,
                "vary.velocity",
                vary.velocity.as_deref(),
                Parameter::Velocity,
                Dimension::SPEED,
                s.velocity,
            ),
            mean_diameter: read_list(
                checker,
                "vary.mean_diameter",
                vary.mean_diameter.as_deref(),
                Parameter::MeanDiameter,
                Dimension::LENGTH,
                s.diameters.mean,
            ),
            operating,
            base: job,
            fixed_bounds: bounds,
        };
        // Each mean diameter must make a valid distribution with the base's bounds.
        for (i, &mean) in sweep.mean_diameter.iter().enumerate() {
            let system = sweep.system(mean, s.velocity, s.operating);
            for e in system.violations() {
                if matches!(e.parameter, Parameter::MinDiameter | Parameter::MaxDiameter) {
                    checker.out_of_range(
                        &format!("vary.mean_diameter[{i}]"),
                        mean,
                        "m",
                        &e.allowed,
                    );
                }
            }
        }
        Ok(sweep)
    }

    /// The base system at one point of the sweep.
    fn system(&self, mean: f64, velocity: f64, operating: OperatingPoint) -> ThreeBody {
        let base = self.base.system;
        let defaults = Diameters::with_default_bounds(mean, base.diameters.std);
        ThreeBody {
            diameters: Diameters {
                mean,
                min: if self.fixed_bounds.0 {
                    base.diameters.min
                } else {
                    defaults.min
                },
                max: if self.fixed_bounds.1 {
                    base.diameters.max
                } else {
                    defaults.max
                },
                ..base.diameters
            },
            velocity,
            operating,
            ..base
        }
    }

    /// The systems to solve: operating point outermost, then speed, then mean diameter.
    pub fn points(&self) -> Vec<ThreeBody> {
        let mut points = Vec::new();
        for &operating in &self.operating {
            for &velocity in &self.velocity {
                for &mean in &self.mean_diameter {
                    points.push(self.system(mean, velocity, operating));
                }
            }
        }
        points
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

/// One row of a rolling sweep.
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
    pub verification: VerificationOutput,
}

/// One row of a three-body sweep.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct ThreeBodySweepPoint {
    /// The operating point as asked: `{"separation": d}`, `{"total_load": W}` or
    /// `{"particle_load": P}` (SI).
    #[schema(value_type = Object)]
    pub operating: Value,
    /// V (m/s).
    pub velocity: f64,
    /// x_a (m).
    pub mean_diameter: f64,
    #[serde(flatten)]
    pub result: ThreeBodyResult,
    pub verification: ThreeBodyVerificationOutput,
}

/// The rows of a sweep.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
#[serde(untagged)]
pub enum SweepPoints {
    Rolling(Vec<SweepPoint>),
    ThreeBody(Vec<ThreeBodySweepPoint>),
}

/// The answer to a sweep.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct SweepOutput {
    /// One row per point; rolling: radius outermost, then load, then speed; three-body:
    /// operating point, then speed, then mean diameter.
    pub points: SweepPoints,
    pub meta: Meta,
}

impl SweepOutput {
    /// A rolling sweep's answer; `solutions` are those of [`RollingSweep::points`], in order.
    pub fn rolling(sweep: &RollingSweep, solutions: &[RollingSolution], meta: Meta) -> Self {
        let points = sweep
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
            points: SweepPoints::Rolling(points),
            meta,
        }
    }

    /// A three-body sweep's answer; `solutions` follow [`ThreeBodySweep::points`].
    pub fn three_body(sweep: &ThreeBodySweep, solutions: &[ThreeBodySolution], meta: Meta) -> Self {
        let points = sweep
            .points()
            .iter()
            .zip(solutions)
            .map(|(p, s)| ThreeBodySweepPoint {
                operating: operating_canonical(p.operating),
                velocity: p.velocity,
                mean_diameter: p.diameters.mean,
                result: s.into(),
                verification: s.into(),
            })
            .collect();
        SweepOutput {
            points: SweepPoints::ThreeBody(points),
            meta,
        }
    }

    /// One header line and one line per point, SI units, shortest round-trip numbers.
    pub fn to_csv(&self) -> String {
        let (header, rows): (String, Vec<Vec<f64>>) = match &self.points {
            SweepPoints::Rolling(points) => (
                "radius,load,velocity,penetration,contact_area,half_width,centroid_shift,\
                 pressure_centre_shift,rolling_resistance_coefficient,friction_coefficient,\
                 static_penetration,static_contact_area,static_friction_coefficient"
                    .to_string(),
                points
                    .iter()
                    .map(|p| {
                        let c = &p.contact;
                        vec![
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
                        ]
                    })
                    .collect(),
            ),
            SweepPoints::ThreeBody(points) => (
                format!(
                    "{},velocity,mean_diameter,separation,particles_in_contact,\
                     area_surface_surface,area_particle_upper,area_particle_layer,area_total,\
                     load_asperities,load_particles,load_total,friction_static,\
                     friction_rolling,mean_area,mean_load",
                    // Every point of a sweep has the same kind of operating point.
                    points
                        .first()
                        .and_then(|p| p.operating.as_object())
                        .and_then(|o| o.keys().next().cloned())
                        .unwrap_or_else(|| "operating".to_string())
                ),
                points
                    .iter()
                    .map(|p| {
                        let r = &p.result;
                        let s = &r.state;
                        let operating = p
                            .operating
                            .as_object()
                            .and_then(|o| o.values().next())
                            .and_then(Value::as_f64)
                            .unwrap_or(f64::NAN);
                        vec![
                            operating,
                            p.velocity,
                            p.mean_diameter,
                            s.separation,
                            s.particles_in_contact,
                            s.areas.surface_surface,
                            s.areas.particle_upper,
                            s.areas.particle_layer,
                            s.areas.total,
                            s.loads.asperities,
                            s.loads.particles,
                            s.loads.total,
                            r.friction_coefficient.static_,
                            r.friction_coefficient.rolling,
                            r.per_particle.mean_area,
                            r.per_particle.mean_load,
                        ]
                    })
                    .collect(),
            ),
        };
        let mut csv = format!("{header}\n");
        for row in rows {
            let cells: Vec<String> = row.into_iter().map(format_number).collect();
            csv.push_str(&cells.join(","));
            csv.push('\n');
        }
        csv
    }
}
