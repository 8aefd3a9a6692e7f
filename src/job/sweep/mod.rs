//! The sweep job: the Cartesian product of lists over a base job, one row per point, for
//! rolling jobs (radius, load, speed) and three-body jobs (operating point, speed, mean
//! diameter).

mod picture;
mod rows;
pub use picture::SweepPicture;
pub use rows::{PointCounts, SweepSummary, SweepVerification};

use std::collections::BTreeMap;
use std::ops::Range;

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use utoipa::ToSchema;

use super::input::LayerModel;
use super::input::{self, field, Checker, Field, Quantity};
use super::kind::SMALL_ANSWER;
use super::rolling::{RollingInput, RollingJob, Solved};
use super::three_body::{
    operating_fields, references as three_body_references, slot, solve_kept, system_cost, Nodes,
    ThreeBodyInput, ThreeBodyJob,
};
use super::validity::Subject;
use super::{
    Control, Cost, JobError, Kind, Limits, Meta, OnRefusal, References, Swept, Validated, Work,
};
use crate::model::tables::Use;
use crate::model::text::quantity;
use crate::model::three_body::{
    Diameters, LayerContact, OperatingPoint, ThreeBody, ThreeBodySolution,
};
use crate::model::{Parameter, Rolling, SolveOptions, Stop, MODEL_VERSION};
use crate::render::{self, Fields, Output, Table, UnitTable};
use crate::{described, unit_table};

pub use super::rolling::SweepPoint;
pub use super::three_body::ThreeBodySweepPoint;

/// Input of a sweep: what is swept, a base input of that kind and the lists to vary.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"kind": "rolling", "base": {"radius": "25 nm"},
    "vary": {"load": ["0.5 nN", "1 nN", "2 nN"], "velocity": ["0 nm/s", "4 nm/s", "8 nm/s"]}}))]
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
    /// What a point the model refuses does: `continue` (default: its row says why, and the
    /// other points are answered) or `fail` (the sweep fails with it).
    pub on_refusal: Option<OnRefusal>,
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
pub struct SweepJob {
    pub points: SweepOfPoints,
    pub on_refusal: OnRefusal,
}

/// The points of a validated sweep, by kind.
#[derive(Clone, Debug, PartialEq)]
pub enum SweepOfPoints {
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
    /// Whether `vary` gave the operating points (else the base did).
    varies_operating: bool,
    /// Whether the base fixed the diameter bounds (else they follow each mean).
    fixed_bounds: (bool, bool),
}

impl SweepJob {
    /// Number of points: the product of the list lengths; `None` past `usize`.
    pub fn size(&self) -> Option<usize> {
        let lengths = match &self.points {
            SweepOfPoints::Rolling(s) => [s.radius.len(), s.load.len(), s.velocity.len()],
            SweepOfPoints::ThreeBody(s) => {
                [s.operating.len(), s.velocity.len(), s.mean_diameter.len()]
            }
        };
        lengths.into_iter().try_fold(1_usize, usize::checked_mul)
    }
}

impl Kind for SweepJob {
    const NAME: &'static str = "sweep";
    type Input = SweepInput;
    type Output = SweepOutput;

    fn validate(value: Value, limits: &Limits) -> Result<Validated<Self>, JobError> {
        let input: SweepInput = input::deserialize(value, "")?;
        let mut checker = Checker::new();
        let (base, vary) = (field!(input.base), field!(input.vary));
        let points = match input.kind.unwrap_or_default() {
            SweepOf::Rolling => {
                SweepOfPoints::Rolling(RollingSweep::read(base, vary, limits, &mut checker)?)
            }
            SweepOf::ThreeBody => {
                SweepOfPoints::ThreeBody(ThreeBodySweep::read(base, vary, limits, &mut checker)?)
            }
        };
        let job = SweepJob {
            points,
            on_refusal: input.on_refusal.unwrap_or_default(),
        };
        let max = limits.max_sweep_points;
        if job.size().is_none_or(|n| n > max) {
            let points = job
                .size()
                .map_or_else(|| Value::from("more than 2^64"), Value::from);
            let allowed = format!("at most {max} points (the product of the list lengths)");
            checker.invalid(vary.name, points, &allowed);
        }
        checker.finish(job)
    }

    /// A valid sweep input itself: the base in canonical form and every list explicit.
    fn canonical(&self) -> Value {
        let (kind, base, vary) = match &self.points {
            SweepOfPoints::Rolling(s) => (SweepOf::Rolling, s.base.canonical(), s.vary()),
            SweepOfPoints::ThreeBody(s) => (SweepOf::ThreeBody, s.base_input(), s.vary()),
        };
        input::canonical(&SweepInput {
            kind: Some(kind),
            base: Some(base),
            vary: Some(vary),
            on_refusal: Some(self.on_refusal),
        })
    }

    fn references(&self) -> &'static References {
        match &self.points {
            SweepOfPoints::Rolling(s) => s.base.references(),
            SweepOfPoints::ThreeBody(s) => three_body_references(&s.base.system),
        }
    }

    fn work(&self) -> Work {
        self.size().map_or(Work::Unknown, Work::Known)
    }

    /// Each point's, its continuum nodes shared with the points before it as the memo
    /// shares them.
    fn cost(&self) -> Cost {
        match &self.points {
            SweepOfPoints::Rolling(s) => s
                .points()
                .iter()
                .map(|p| s.base.cost_of(p))
                .fold(Cost::default(), Cost::then),
            SweepOfPoints::ThreeBody(s) => {
                let mut counted = Nodes::default();
                s.points()
                    .iter()
                    .map(|p| system_cost(p, &mut counted))
                    .fold(Cost::default(), Cost::then)
            }
        }
    }

    fn answer_units(&self) -> &'static UnitTable {
        match &self.points {
            SweepOfPoints::Rolling(_) => &ROLLING_UNITS,
            SweepOfPoints::ThreeBody(_) => &THREE_BODY_UNITS,
        }
    }

    /// A three-body point costs a hundred rolling points, a continuum point more.
    fn cost_class(&self) -> &'static str {
        match &self.points {
            SweepOfPoints::Rolling(s) if s.base.law == LayerModel::Continuum => {
                "sweep of rolling on the continuum"
            }
            SweepOfPoints::Rolling(_) => "sweep of rolling",
            SweepOfPoints::ThreeBody(s)
                if s.base.system.layer_contact == LayerContact::Continuum =>
            {
                "sweep of three_body on the continuum"
            }
            SweepOfPoints::ThreeBody(_) => "sweep of three_body",
        }
    }

    fn run(&self, meta: Meta, control: &Control) -> Result<SweepOutput, JobError> {
        let all = 0..self.size().unwrap_or(0);
        self.run_points(meta, all, control)
    }

    fn points(&self) -> Option<usize> {
        self.size()
    }

    /// A row's numbers are at most 26 bytes each in JSON (with its key) and CSV; a refused
    /// row carries its reason (a few hundred bytes) in both instead.
    fn result_bytes(&self) -> u64 {
        let per_point: u64 = match self.points {
            SweepOfPoints::Rolling(_) => 1536,
            SweepOfPoints::ThreeBody(_) => 3072,
        };
        let points = self.size().unwrap_or(usize::MAX) as u64;
        SMALL_ANSWER.saturating_add(points.saturating_mul(per_point))
    }

    fn run_points(
        &self,
        meta: Meta,
        range: Range<usize>,
        control: &Control,
    ) -> Result<SweepOutput, JobError> {
        let first = range.start;
        let on_refusal = self.on_refusal;
        let (points, summary, stop) = match &self.points {
            SweepOfPoints::Rolling(s) => {
                let all = s.points();
                let base = &s.base;
                let (options, law) = (&base.options, base.law);
                let method = Use::for_solves(all.len(), options.quadrature);
                let contacts = part(all, range)?;
                let asked = || control.must_stop();
                let solve = |p: &Rolling| base.solve(p, method, Stop::when(&asked));
                let swept = if method == Use::Build && law == LayerModel::Local {
                    // A point costs a microsecond: cheaper to solve again than to keep.
                    control.map_each(&contacts, on_refusal, |p| {
                        SweepPoint::new(p, &base.upper, &solve(p)?)
                    })
                } else {
                    let kept = control.kept(
                        |p| {
                            point_key(&RollingJob {
                                rolling: *p,
                                ..*base
                            })
                        },
                        |_| std::mem::size_of::<Solved>(),
                        solve,
                    );
                    control.map_each(&contacts, on_refusal, |p| {
                        SweepPoint::new(p, &base.upper, &kept(p)?)
                    })
                };
                let swept = refused_at(swept, first, on_refusal, |i| contact_name(&contacts[i]));
                let stop = swept.stopped.clone();
                let (rows, summary) = rows::rows(&contacts, swept, first, Subject::Particle);
                (SweepPoints::Rolling(rows), summary, stop)
            }
            SweepOfPoints::ThreeBody(s) => {
                let systems = part(s.points(), range)?;
                let base = &s.base;
                let options = &base.options;
                let kept = control.kept(
                    |p| {
                        point_key(&ThreeBodyJob {
                            system: *p,
                            ..*base
                        })
                    },
                    |_| std::mem::size_of::<ThreeBodySolution>(),
                    |p| solve_kept(p, options, control),
                );
                let swept = control.map_each(&systems, on_refusal, |p| {
                    ThreeBodySweepPoint::new(p, &kept(p)?)
                });
                let swept = refused_at(swept, first, on_refusal, |i| system_name(&systems[i]));
                let stop = swept.stopped.clone();
                let (rows, summary) = rows::rows(&systems, swept, first, Subject::System);
                (SweepPoints::ThreeBody(rows), summary, stop)
            }
        };
        Ok(SweepOutput {
            points,
            meta: SweepMeta { meta, summary },
            stop,
        })
    }

    fn unfinished(output: &SweepOutput) -> Option<JobError> {
        output.stop.clone()
    }
}

/// The memo key of a sweep's point: the model's version, its kind, and its canonical text
/// as a job of its own, so that equal points share one solve (a retry, a sweep that
/// overlaps another).
fn point_key<K: Kind>(point: &K) -> String {
    format!(
        "{MODEL_VERSION} {} {}",
        K::NAME,
        point.canonical_text().get()
    )
}

/// A sweep asked to stop at a refusal (`on_refusal: fail`) fails with it, the point named by
/// its index in the whole sweep and its inputs (`name`, by index in this part); it keeps the
/// points before it, as a cancel keeps what it finished, and those from it on are missing.
fn refused_at<R>(
    mut swept: Swept<R, JobError>,
    first: usize,
    on_refusal: OnRefusal,
    name: impl Fn(usize) -> String,
) -> Swept<R, JobError> {
    if on_refusal == OnRefusal::Fail && swept.stopped.is_none() {
        if let Some((i, e)) = swept.take_first_refusal() {
            swept.outcomes[i..].iter_mut().for_each(|o| *o = None);
            swept.stopped = Some(at_point(first + i, &name(i), e));
        }
    }
    swept
}

/// The points `range` of `points`.
fn part<T>(mut points: Vec<T>, range: Range<usize>) -> Result<Vec<T>, JobError> {
    if range.start > range.end || range.end > points.len() {
        return Err(JobError::Internal(format!(
            "points {range:?} of a sweep of {} points",
            points.len()
        )));
    }
    points.truncate(range.end);
    Ok(points.split_off(range.start))
}

/// A rolling point by its inputs, for messages: `R = 25 nm, P = 1 mN, V = 4 nm/s`.
fn contact_name(p: &Rolling) -> String {
    let (r, load, v) = (p.radius, p.load, p.velocity);
    let [r, load, v] = [(r, "m"), (load, "N"), (v, "m/s")].map(|(x, unit)| quantity(x, unit));
    format!("R = {r}, P = {load}, V = {v}")
}

/// A three-body point by its operating point and speed, for messages: `W = 1 mN, V = 4 nm/s`.
fn system_name(system: &ThreeBody) -> String {
    let operating = match system.operating {
        OperatingPoint::Separation(d) => format!("d = {}", quantity(d, "m")),
        OperatingPoint::TotalLoad(w) => format!("W = {}", quantity(w, "N")),
        OperatingPoint::ParticleLoad(p) => format!("P = {}", quantity(p, "N")),
    };
    format!("{operating}, V = {}", quantity(system.velocity, "m/s"))
}

/// The error of point `index` of a sweep, whose inputs are `name`, said so.
fn at_point(index: usize, name: &str, e: JobError) -> JobError {
    let at = |m: String| format!("points[{index}] ({name}): {m}");
    match e {
        JobError::OutOfDomain(m) => JobError::OutOfDomain(at(m)),
        JobError::Unsolvable(m) => JobError::Unsolvable(at(m)),
        other => other,
    }
}

/// A list of SI values as an input gives it.
fn quantities(values: &[f64]) -> Option<Vec<Quantity>> {
    Some(values.iter().filter_map(|&x| Quantity::si(x)).collect())
}

impl RollingSweep {
    fn read(
        base: Field<Value>,
        vary: Field<Value>,
        limits: &Limits,
        checker: &mut Checker,
    ) -> Result<RollingSweep, JobError> {
        let max = limits.max_sweep_points;
        let base_input: RollingInput = read_object(base)?;
        let vary_input: RollingVary = read_object(vary)?;
        let base_field = Field {
            name: base.name,
            value: Some(&base_input),
        };
        let mut base = checker.nested(base_field, |c, b| RollingJob::read(b, c));
        base.options = SolveOptions::integrals_only(base.options.quadrature);
        let r = base.rolling;
        let vary_field = Field {
            name: vary.name,
            value: Some(&vary_input),
        };
        Ok(checker.nested(vary_field, |c, vary| RollingSweep {
            radius: c.list(field!(vary.radius), Parameter::Radius, r.radius, max),
            load: c.list(field!(vary.load), Parameter::Load, r.load, max),
            velocity: c.list(field!(vary.velocity), Parameter::Velocity, r.velocity, max),
            base,
        }))
    }

    /// Every list, explicit.
    fn vary(&self) -> Value {
        input::canonical(&RollingVary {
            radius: quantities(&self.radius),
            load: quantities(&self.load),
            velocity: quantities(&self.velocity),
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
    fn read(
        base: Field<Value>,
        vary: Field<Value>,
        limits: &Limits,
        checker: &mut Checker,
    ) -> Result<ThreeBodySweep, JobError> {
        let max = limits.max_sweep_points;
        let mut base_input: ThreeBodyInput = read_object(base)?;
        let vary_input: ThreeBodyVary = read_object(vary)?;
        let v = &vary_input;
        let lists = operating_fields!(field!(v))
            .into_iter()
            .zip(OperatingPoint::KINDS);
        let varied: Vec<_> = lists.filter(|(list, _)| list.value.is_some()).collect();
        // A varied operating point replaces the base's, which then only has to be readable.
        if !varied.is_empty() {
            let placeholder = OperatingPoint::Separation(0.0);
            base_input.operating = Some(super::three_body::OperatingInput::of(placeholder));
        }
        let fixed_bounds = base_input
            .distribution
            .as_ref()
            .map_or((false, false), |d| {
                (d.min_diameter.is_some(), d.max_diameter.is_some())
            });
        let base_field = Field {
            name: base.name,
            value: Some(&base_input),
        };
        let job = checker.nested(base_field, |c, b| ThreeBodyJob::read(b, c));
        let s = job.system;
        let vary_field = Field {
            name: vary.name,
            value: Some(&vary_input),
        };
        let sweep = checker.nested(vary_field, |c, vary| {
            if varied.len() > 1 {
                let names: Vec<&str> = varied.iter().map(|(list, _)| list.name).collect();
                c.invalid(
                    "",
                    json!(names),
                    "at most one operating-point list (separation, total_load or particle_load)",
                );
            }
            let operating = match varied.first() {
                Some(&(list, (parameter, point))) => c
                    .list(list, parameter, f64::NAN, max)
                    .into_iter()
                    .map(point)
                    .collect(),
                None => vec![s.operating],
            };
            let sweep = ThreeBodySweep {
                velocity: c.list(field!(vary.velocity), Parameter::Velocity, s.velocity, max),
                mean_diameter: c.list(
                    field!(vary.mean_diameter),
                    Parameter::MeanDiameter,
                    s.diameters.mean,
                    max,
                ),
                operating,
                base: job,
                varies_operating: !varied.is_empty(),
                fixed_bounds,
            };
            // Each mean diameter must make a valid distribution with the base's bounds.
            let means = field!(vary.mean_diameter).name;
            for (i, &mean) in sweep.mean_diameter.iter().enumerate() {
                let system = sweep.system(mean, s.velocity, s.operating);
                for e in system.violations() {
                    if matches!(e.parameter, Parameter::MinDiameter | Parameter::MaxDiameter) {
                        c.out_of_range(&format!("{means}[{i}]"), mean, "m", &e.allowed);
                    }
                }
            }
            sweep
        });
        Ok(sweep)
    }

    /// The base as an input: bounds that follow each mean and a varied operating point
    /// are left out, so that the canonical sweep reads back as the same sweep.
    fn base_input(&self) -> Value {
        let mut base = self.base.input();
        if let Some(d) = &mut base.distribution {
            if !self.fixed_bounds.0 {
                d.min_diameter = None;
            }
            if !self.fixed_bounds.1 {
                d.max_diameter = None;
            }
        }
        if self.varies_operating {
            base.operating = None;
        }
        input::canonical(&base)
    }

    /// Every list, explicit; the operating points only if the sweep varies them.
    fn vary(&self) -> Value {
        let mut vary = ThreeBodyVary {
            velocity: quantities(&self.velocity),
            mean_diameter: quantities(&self.mean_diameter),
            ..ThreeBodyVary::default()
        };
        if self.varies_operating {
            let values: Vec<f64> = self.operating.iter().map(|o| o.value()).collect();
            if let Some(first) = self.operating.first() {
                let slots = operating_fields!(slot!(vary));
                *slots[first.kind()] = quantities(&values);
            }
        }
        input::canonical(&vary)
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

/// Reads the object `field` (absent: `{}`) as `T`, shape errors under its name.
fn read_object<T: serde::de::DeserializeOwned>(field: Field<Value>) -> Result<T, JobError> {
    let value = field.value.cloned().unwrap_or_else(|| json!({}));
    input::deserialize(value, field.name)
}

/// The rows of a sweep.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
#[serde(untagged)]
pub enum SweepPoints {
    Rolling(Vec<SweepPoint>),
    ThreeBody(Vec<ThreeBodySweepPoint>),
}

/// The rows of either kind (the union: a sweep's are of one).
impl Fields for SweepPoints {
    fn fields() -> Vec<render::Field<Self>> {
        let mut fields = render::Field::each::<SweepPoint>("");
        fields.extend(render::Field::each::<ThreeBodySweepPoint>(""));
        fields
    }
}

described! {
    /// The answer to a sweep.
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct SweepOutput {
        /// One row per point; rolling: radius outermost, then load, then speed; three-body:
        /// operating point, then speed, then mean diameter.
        pub points: SweepPoints => [nested],
        pub meta: SweepMeta => [nested],
        /// Why the sweep stopped before its end, if it did (`meta.stopped` in words).
        #[serde(skip)]
        pub stop: Option<JobError> => [],
    }
}

described! {
    /// The `meta` block of a sweep: the job's, and what it says of the rows.
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct SweepMeta {
        #[serde(flatten)]
        pub meta: Meta => [],
        #[serde(flatten)]
        pub summary: SweepSummary => [flatten],
    }
}

/// The unit table of a sweep of one kind of point: a sweep's, without the fields of the other
/// kind's rows (`rows` and `other` are the two kinds' fields, by path within a row).
fn units_of(
    rows: BTreeMap<String, &'static str>,
    other: BTreeMap<String, &'static str>,
) -> BTreeMap<String, &'static str> {
    let mut units = render::fields::units::<SweepOutput>();
    units.retain(|path, _| match path.strip_prefix("points[].") {
        Some(field) => rows.contains_key(field) || !other.contains_key(field),
        None => true,
    });
    units
}

/// The unit tables of a rolling sweep's answer and of a three-body sweep's.
static ROLLING_UNITS: UnitTable = render::Fixed::new(render::UnitGroups::new(|| {
    units_of(
        render::fields::units::<SweepPoint>(),
        render::fields::units::<ThreeBodySweepPoint>(),
    )
}));
static THREE_BODY_UNITS: UnitTable = render::Fixed::new(render::UnitGroups::new(|| {
    units_of(
        render::fields::units::<ThreeBodySweepPoint>(),
        render::fields::units::<SweepPoint>(),
    )
}));

impl Output for SweepOutput {
    /// The points of a rolling sweep or of a three-body sweep (a sweep's own answer lists
    /// its kind's alone: [`Kind::answer_units`]).
    const UNITS: &'static UnitTable = unit_table!(SweepOutput);
    type Picture = SweepPicture;

    /// How many points the model refused, and how to fail the sweep instead.
    fn notice(&self) -> Option<String> {
        let counts = self.meta.summary.counts;
        (counts.refused > 0).then(|| {
            format!(
                "the model refused {} of {} points; their rows say why \
                 (\"on_refusal\": \"fail\" fails the sweep instead)",
                counts.refused, counts.total
            )
        })
    }

    /// One row per point.
    fn table(&self) -> Table {
        match &self.points {
            SweepPoints::Rolling(points) => Table::new(SweepPoint::columns(), points),
            SweepPoints::ThreeBody(points) => ThreeBodySweepPoint::table(points),
        }
    }

    /// A rolling sweep's rows written straight from its points (10,000 of them by
    /// default at most).
    fn csv(&self) -> Option<String> {
        match &self.points {
            SweepPoints::Rolling(points) => render::csv(SweepPoint::columns(), points),
            SweepPoints::ThreeBody(_) => self.table().to_csv(),
        }
    }
}
