//! The fit's input on the wire: the layer's fixed values, the measured series and the
//! parameters to fit with their starts and bounds; read into a [`Problem`] of the model.

use serde::{Deserialize, Serialize};
use serde_json::json;
use utoipa::ToSchema;

use crate::job::input::{
    field, Checker, Field, LayerInput, LayerModel, Quantity, UpperSurfaceInput,
};
use crate::job::three_body::{OperatingInput, ThreeBodyInput, ThreeBodyJob};
use crate::model::counterface::UpperSurface;
use crate::model::fit::{
    Bounds, Datum, FitParameter, Law, Measured, Parameterization, Point, Problem, Setting,
};
use crate::model::text::quantity;
use crate::model::three_body::{LayerContact, OperatingPoint, ThreeBody, ThreeBodyOptions};
use crate::model::{Layer, Parameter, Rolling};

/// Input of a fit: measured points of one or more series, and the layer's parameters to
/// fit to them (the others fixed at `layer`'s values).
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({
    "layer": {"elastic_modulus": "3 GPa", "thickness": "100 nm", "poisson_ratio": 0.35},
    "series": [{"radius": "25 nm", "load": "1 nN", "quantity": "friction_coefficient",
                "points": [{"velocity": "1 nm/s", "value": 0.1051, "uncertainty": 0.001},
                           {"velocity": "4 nm/s", "value": 0.0947, "uncertainty": 0.001},
                           {"velocity": "10 nm/s", "value": 0.0761, "uncertainty": 0.001}]}],
    "parameters": {"relaxation_time": {"start": "50 ms", "min": "1 ms", "max": "10 s"},
                   "retardation_time": {"start": "200 ms"}}}))]
pub struct FitInput {
    /// The layer's values that are not fitted, and the base of those that are (default:
    /// docs/model.md §5).
    pub layer: Option<LayerInput>,
    /// The measured series (at least one).
    pub series: Option<Vec<SeriesInput>>,
    /// The parameters to fit (at least one).
    pub parameters: Option<ParametersInput>,
}

/// Points measured on one particle size and load (each point may override them), or on one
/// three-body system at total loads.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SeriesInput {
    /// R (m; default 25 nm); not with `system`.
    pub radius: Option<Quantity>,
    /// P (N; default 1 nN); not with `system`.
    pub load: Option<Quantity>,
    /// V (m/s; default 4 nm/s).
    pub velocity: Option<Quantity>,
    /// A three-body system (a `ThreeBodyInput` without `layer`, `velocity` and `operating`,
    /// which the fit sets): the series then measures the system's friction coefficient at
    /// the points' total loads.
    pub system: Option<ThreeBodyInput>,
    /// W (N), the total load on a `system`, for points that do not give theirs.
    pub total_load: Option<Quantity>,
    /// What was measured (default `friction_coefficient`).
    pub quantity: Option<MeasuredQuantity>,
    /// The counterface of a particle series (default steel), which decides with the layer
    /// whether the particle rolls: it matters to `particle_friction` only. A `system` has
    /// its own.
    pub upper_surface: Option<UpperSurfaceInput>,
    /// The points (at least one).
    pub points: Option<Vec<PointInput>>,
}

/// A measured quantity.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum MeasuredQuantity {
    /// μ (eq. 12), a plain number.
    #[default]
    FrictionCoefficient,
    /// A (m²).
    ContactArea,
    /// The friction the particles really transmit (docs/model.md §11), a plain number: a
    /// particle's T/P, rolling or sliding, or a system's (Σ T + τ_s A_s1s2)/W. Measured
    /// rolling only (at rest the particles transmit nothing).
    ParticleFriction,
}

impl MeasuredQuantity {
    /// Each, in the order a residual names them.
    pub const ALL: [MeasuredQuantity; 3] = [
        MeasuredQuantity::FrictionCoefficient,
        MeasuredQuantity::ContactArea,
        MeasuredQuantity::ParticleFriction,
    ];

    /// The name on the wire (as serde writes it).
    pub fn name(self) -> &'static str {
        match self {
            MeasuredQuantity::FrictionCoefficient => "friction_coefficient",
            MeasuredQuantity::ContactArea => "contact_area",
            MeasuredQuantity::ParticleFriction => "particle_friction",
        }
    }

    pub fn model(self) -> Measured {
        match self {
            MeasuredQuantity::FrictionCoefficient => Measured::FrictionCoefficient,
            MeasuredQuantity::ContactArea => Measured::ContactArea,
            MeasuredQuantity::ParticleFriction => Measured::ParticleFriction,
        }
    }

    pub fn of(measured: Measured) -> MeasuredQuantity {
        match measured {
            Measured::FrictionCoefficient => MeasuredQuantity::FrictionCoefficient,
            Measured::ContactArea => MeasuredQuantity::ContactArea,
            Measured::ParticleFriction => MeasuredQuantity::ParticleFriction,
        }
    }

    pub fn parameter(self) -> Parameter {
        match self {
            MeasuredQuantity::FrictionCoefficient | MeasuredQuantity::ParticleFriction => {
                Parameter::FrictionCoefficient
            }
            MeasuredQuantity::ContactArea => Parameter::ContactArea,
        }
    }
}

/// One measured point.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct PointInput {
    /// R (m; default: the series').
    pub radius: Option<Quantity>,
    /// P (N; default: the series').
    pub load: Option<Quantity>,
    /// V (m/s; default: the series').
    pub velocity: Option<Quantity>,
    /// W (N) on the series' `system` (default: the series').
    pub total_load: Option<Quantity>,
    /// The measured value (μ: a plain number; A: m²). Required.
    pub value: Option<Quantity>,
    /// Its standard uncertainty, in the value's unit: given for every point or for none
    /// (then the scatter of the residuals sets it).
    pub uncertainty: Option<Quantity>,
}

/// The parameters to fit; at most one of `retardation_time` and `kappa`, of `thickness`
/// and `k`, of `relaxation_time` and `shift_factor`, and of `elastic_modulus` and
/// `modulus_scale`. A layer given as a Prony series of more than one term is fitted by
/// `shift_factor` and `modulus_scale` (its shape held), not by its single times.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(min_properties = 1)]
pub struct ParametersInput {
    /// T_σ (s).
    pub relaxation_time: Option<BoundsInput>,
    /// T_ε (s), ≥ T_σ.
    pub retardation_time: Option<BoundsInput>,
    /// κ = T_ε/T_σ − 1 (T_ε then follows T_σ).
    pub kappa: Option<BoundsInput>,
    /// E_L (Pa).
    pub elastic_modulus: Option<BoundsInput>,
    /// H (m).
    pub thickness: Option<BoundsInput>,
    /// k = E_L/H (Pa/m; H then follows E_L).
    pub k: Option<BoundsInput>,
    /// A factor on every modulus of the layer (E_L, and each E_j of a Prony series),
    /// relative to `layer` (default start 1).
    pub modulus_scale: Option<BoundsInput>,
    /// The shift factor a: every time of the layer (T_ε, T_σ, each τ_j) times a, relative
    /// to `layer` (default start 1); log₁₀ a is the shift in decades.
    pub shift_factor: Option<BoundsInput>,
}

/// Where a parameter starts and the bounds it stays within.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct BoundsInput {
    /// Default: the layer's value (κ: 4 if the layer is elastic), or, if `min` and `max`
    /// do not hold it, their geometric mean (the bound given, if only one is).
    pub start: Option<Quantity>,
    /// Default: start / 1000.
    pub min: Option<Quantity>,
    /// Default: start × 1000.
    pub max: Option<Quantity>,
}

/// How far the default bounds reach either side of the start.
const DEFAULT_SPAN: f64 = 1e3;

impl ParametersInput {
    /// Each parameter given, in the order of [`FitParameter::ALL`].
    fn given(&self) -> Vec<(FitParameter, Field<'_, BoundsInput>)> {
        let input = self;
        let fields = [
            field!(input.relaxation_time),
            field!(input.retardation_time),
            field!(input.kappa),
            field!(input.elastic_modulus),
            field!(input.thickness),
            field!(input.k),
            field!(input.modulus_scale),
            field!(input.shift_factor),
        ];
        FitParameter::ALL
            .into_iter()
            .zip(fields)
            .filter(|(_, f)| f.value.is_some())
            .collect()
    }

    fn of(problem: &Problem) -> ParametersInput {
        let mut input = ParametersInput::default();
        for (&parameter, b) in problem.parameterization.free.iter().zip(&problem.bounds) {
            let bounds = Some(BoundsInput {
                start: Quantity::si(b.start),
                min: Quantity::si(b.min),
                max: Quantity::si(b.max),
            });
            match parameter {
                FitParameter::RelaxationTime => input.relaxation_time = bounds,
                FitParameter::RetardationTime => input.retardation_time = bounds,
                FitParameter::Kappa => input.kappa = bounds,
                FitParameter::ElasticModulus => input.elastic_modulus = bounds,
                FitParameter::Thickness => input.thickness = bounds,
                FitParameter::Stiffness => input.k = bounds,
                FitParameter::ModulusScale => input.modulus_scale = bounds,
                FitParameter::ShiftFactor => input.shift_factor = bounds,
            }
        }
        input
    }
}

impl FitInput {
    /// Reads the fit under `checker`; `max_points` bounds the number of points.
    pub fn read(&self, checker: &mut Checker, max_points: usize) -> Problem {
        let input = self;
        let base = checker.nested(field!(input.layer), |c, layer| layer.read(c));
        let law = match input.layer.as_ref().and_then(|l| l.model) {
            Some(LayerModel::Continuum) => Law::Continuum,
            _ => Law::Local,
        };
        checker.parameters(base.violations());
        let (free, bounds) = checker.nested(field!(input.parameters), |c, p| {
            read_parameters(p, &base, c)
        });
        if free.is_empty() {
            let allowed = "at least one parameter to fit";
            if input.parameters.is_some() {
                checker.invalid("parameters", json!({}), allowed);
            } else {
                checker.missing("parameters", allowed, "");
            }
        }
        let data = read_series(input.series.as_deref(), max_points, checker);
        let problem = Problem {
            parameterization: Parameterization { base, free, law },
            bounds,
            data,
        };
        check_counts(&problem, input, checker);
        problem
    }

    /// The input that gives `problem`, whose series have `sizes` points: every point
    /// explicit, in SI.
    pub fn of(problem: &Problem, sizes: &[usize]) -> FitInput {
        let mut data = problem.data.iter();
        let series = sizes
            .iter()
            .map(|&n| {
                let points: Vec<&Datum> = data.by_ref().take(n).collect();
                let first = points.first().map(|d| d.point);
                SeriesInput {
                    quantity: first.map(|p| MeasuredQuantity::of(p.measured)),
                    system: first.and_then(|p| system_input(&p.setting)),
                    upper_surface: first.and_then(upper_input),
                    points: Some(points.into_iter().map(PointInput::of).collect()),
                    ..SeriesInput::default()
                }
            })
            .collect();
        FitInput {
            // The local law unnamed, as before the continuum was offered (the canonical
            // form, and so the cache key, of a local fit is unchanged).
            layer: Some(LayerInput::of(
                &problem.parameterization.base,
                (problem.parameterization.law == Law::Continuum).then_some(LayerModel::Continuum),
            )),
            series: Some(series),
            parameters: Some(ParametersInput::of(problem)),
        }
    }
}

impl PointInput {
    /// The point of `datum`, every field explicit.
    fn of(datum: &Datum) -> PointInput {
        let p = &datum.point;
        let mut input = PointInput {
            velocity: Quantity::si(p.velocity),
            value: Quantity::si(datum.value),
            uncertainty: datum.uncertainty.and_then(Quantity::si),
            ..PointInput::default()
        };
        match p.setting {
            Setting::Particle { radius, load, .. } => {
                input.radius = Quantity::si(radius);
                input.load = Quantity::si(load);
            }
            Setting::System { total_load, .. } => input.total_load = Quantity::si(total_load),
        }
        input
    }
}

/// The counterface of a particle's point, where it matters (its own friction measured).
fn upper_input(point: Point) -> Option<UpperSurfaceInput> {
    match point.setting {
        Setting::Particle { upper, .. } if point.measured == Measured::ParticleFriction => {
            Some(UpperSurfaceInput::of(&upper))
        }
        _ => None,
    }
}

/// The system of a three-body setting as a series gives it: without what the fit sets.
fn system_input(setting: &Setting) -> Option<ThreeBodyInput> {
    let Setting::System {
        system, options, ..
    } = *setting
    else {
        return None;
    };
    let mut input = ThreeBodyJob { system, options }.input();
    input.layer = None;
    input.velocity = None;
    input.operating = None;
    Some(input)
}

fn read_parameters(
    input: &ParametersInput,
    base: &Layer,
    checker: &mut Checker,
) -> (Vec<FitParameter>, Vec<Bounds>) {
    let given = input.given();
    refuse_conflicts(&given, base, checker);
    let mut free = Vec::new();
    let mut all = Vec::new();
    for (parameter, field) in given {
        let model = parameter.parameter();
        let layer_value = match parameter.of(base) {
            k if parameter == FitParameter::Kappa && k <= 0.0 => 4.0,
            x => x,
        };
        let b = checker.nested(field, |c, bounds| {
            let given_min = c.optional(field!(bounds.min), model);
            let given_max = c.optional(field!(bounds.max), model);
            // Without a start, the layer's value if the bounds given hold it; their middle
            // (in logarithm) if both are given; the nearer one otherwise.
            let default = match (given_min, given_max) {
                (Some(lo), Some(hi)) if !(lo..=hi).contains(&layer_value) => (lo * hi).sqrt(),
                (lo, hi) => layer_value
                    .max(lo.unwrap_or(f64::NEG_INFINITY))
                    .min(hi.unwrap_or(f64::INFINITY)),
            };
            let start = c.quantity(field!(bounds.start), model, default);
            let min = given_min.unwrap_or(start / DEFAULT_SPAN);
            let max = given_max.unwrap_or(start * DEFAULT_SPAN);
            for (name, value) in [("start", start), ("min", min), ("max", max)] {
                if let Err(e) = model.check(value) {
                    c.out_of_range(name, value, model.unit(), &e.allowed);
                }
            }
            if min > max {
                c.out_of_range(
                    "min",
                    min,
                    model.unit(),
                    &format!("≤ max = {}", quantity(max, model.unit())),
                );
            } else if !(min..=max).contains(&start) {
                let allowed = format!(
                    "within [min, max] = [{}, {}]",
                    quantity(min, model.unit()),
                    quantity(max, model.unit())
                );
                c.out_of_range("start", start, model.unit(), &allowed);
            }
            Bounds { start, min, max }
        });
        free.push(parameter);
        all.push(b);
    }
    check_starts(base, &free, &all, checker);
    (free, all)
}

/// Parameters that name one quantity twice (a time and the factor over it), and Kelvin
/// times for a layer of several Prony terms: each refused, naming the parameter.
fn refuse_conflicts<F>(given: &[(FitParameter, F)], base: &Layer, checker: &mut Checker) {
    let named = |p: FitParameter| given.iter().any(|(q, _)| *q == p);
    for (a, b) in [
        (FitParameter::RetardationTime, FitParameter::Kappa),
        (FitParameter::Thickness, FitParameter::Stiffness),
        (FitParameter::RelaxationTime, FitParameter::ShiftFactor),
        (FitParameter::ElasticModulus, FitParameter::ModulusScale),
    ] {
        if named(a) && named(b) {
            let allowed = format!("at most one of {} and {}", a.name(), b.name());
            checker.invalid(b.name(), json!({}), &allowed);
        }
    }
    if !base.arms.is_empty() {
        for (parameter, _) in given.iter().filter(|(p, _)| p.is_kelvin_time()) {
            let allowed = "absent for a layer given as a Prony series of more than one term: \
                           fit shift_factor (all its times) and modulus_scale (all its moduli)";
            checker.invalid(parameter.name(), json!({}), allowed);
        }
    }
}

/// The starts must make a valid layer (T_ε ≥ T_σ above all): each violation is refused,
/// showing the starts.
fn check_starts(base: &Layer, free: &[FitParameter], all: &[Bounds], checker: &mut Checker) {
    let starts: Vec<f64> = all.iter().map(|b| b.start).collect();
    // Only its layers are read here, which the law does not change.
    let parameterization = Parameterization {
        base: *base,
        free: free.to_vec(),
        law: Law::Local,
    };
    if starts.iter().all(|x| x.is_finite()) && base.violations().is_empty() {
        // The starts as a person reads them: each parameter's name and value with its unit.
        let shown: serde_json::Map<String, serde_json::Value> = free
            .iter()
            .zip(&starts)
            .map(|(p, &x)| {
                (
                    p.name().to_string(),
                    quantity(x, p.parameter().unit()).into(),
                )
            })
            .collect();
        for e in parameterization.layer(&starts).violations() {
            let allowed = format!("starts that make a valid layer, but at them {e}");
            checker.invalid("", serde_json::Value::Object(shown.clone()), &allowed);
        }
    }
}

fn read_series(
    series: Option<&[SeriesInput]>,
    max_points: usize,
    checker: &mut Checker,
) -> Vec<Datum> {
    let Some(series) = series else {
        checker.missing("series", "a list of measured series", "");
        return Vec::new();
    };
    if series.is_empty() {
        checker.invalid("series", json!([]), "a list of at least one series");
    }
    let total: usize = series
        .iter()
        .map(|s| s.points.as_ref().map_or(0, Vec::len))
        .sum();
    if total > max_points {
        let allowed = format!("at most {max_points} points over all series");
        checker.invalid("series", json!(total), &allowed);
        return Vec::new();
    }
    let mut data = Vec::new();
    for (i, s) in series.iter().enumerate() {
        checker.item("series", i, s, |c, s| read_one(s, c, &mut data));
    }
    data
}

/// Reads one series into `data`.
fn read_one(s: &SeriesInput, c: &mut Checker, data: &mut Vec<Datum>) {
    let d = Rolling::default();
    let quantity = s.quantity.unwrap_or_default();
    let velocity = condition(c, field!(s.velocity), Parameter::Velocity, d.velocity);
    let series = match &s.system {
        Some(system) => {
            for field in [field!(s.radius), field!(s.load)] {
                refuse(
                    c,
                    field,
                    "none: a three-body series gives `total_load` instead",
                );
            }
            if quantity == MeasuredQuantity::ContactArea {
                let allowed = "friction_coefficient or particle_friction: a three-body series \
                               measures the system's friction";
                c.invalid("quantity", json!(quantity), allowed);
            }
            refuse(
                c,
                field!(s.upper_surface),
                "none: a three-body series' `system` has its own `upper_surface`",
            );
            let (system, options) = read_system(system, c);
            if quantity == MeasuredQuantity::ParticleFriction
                && system.layer_contact == LayerContact::Hertz
            {
                let allowed = "friction_coefficient: on the hertz layer contact a particle \
                               has no rolling resistance and transmits no tangential force, \
                               whatever the layer's times (docs/model.md §11)";
                c.invalid("quantity", json!(quantity), allowed);
            }
            let total_load = c.optional(field!(s.total_load), Parameter::TotalLoad);
            check_range(c, field!(s.total_load), Parameter::TotalLoad, total_load);
            Series::System(system, options, total_load)
        }
        None => {
            refuse(
                c,
                field!(s.total_load),
                "none: only a three-body series (one with a `system`) has a total load",
            );
            let upper = c.nested(field!(s.upper_surface), |c, u| u.read(c));
            c.parameters(upper.violations());
            Series::Particle {
                radius: condition(c, field!(s.radius), Parameter::Radius, d.radius),
                load: condition(c, field!(s.load), Parameter::Load, d.load),
                upper,
            }
        }
    };
    let points = s.points.as_deref().unwrap_or_default();
    if points.is_empty() {
        let allowed = "a list of at least one measured point";
        c.invalid("points", json!(points), allowed);
    }
    for (j, p) in points.iter().enumerate() {
        data.push(c.item("points", j, p, |c, p| {
            let point = Point {
                setting: series.of_point(p, c),
                velocity: condition(c, field!(p.velocity), Parameter::Velocity, velocity),
                measured: quantity.model(),
            };
            if quantity == MeasuredQuantity::ParticleFriction && point.velocity == 0.0 {
                let allowed = "> 0 m/s for particle_friction: at rest a particle needs no \
                               tangential force to roll and transmits none (a system's \
                               friction is then its asperities' alone)";
                c.invalid("velocity", json!(0.0), allowed);
            }
            let why = "at each measured point";
            let value = c.required(field!(p.value), quantity.parameter(), why);
            check_range(c, field!(p.value), quantity.parameter(), Some(value));
            let uncertainty = c.optional(field!(p.uncertainty), quantity.parameter());
            check_range(c, field!(p.uncertainty), quantity.parameter(), uncertainty);
            Datum {
                point,
                value,
                uncertainty,
            }
        }));
    }
}

/// What a series fixes for its points (one per series: its size does not matter).
#[allow(clippy::large_enum_variant)]
enum Series {
    Particle {
        radius: f64,
        load: f64,
        upper: UpperSurface,
    },
    System(ThreeBody, ThreeBodyOptions, Option<f64>),
}

impl Series {
    /// The setting of the point `p` of the series.
    fn of_point(&self, p: &PointInput, c: &mut Checker) -> Setting {
        match *self {
            Series::Particle {
                radius,
                load,
                upper,
            } => {
                refuse(
                    c,
                    field!(p.total_load),
                    "none: only a three-body series (one with a `system`) has a total load",
                );
                Setting::Particle {
                    radius: condition(c, field!(p.radius), Parameter::Radius, radius),
                    load: condition(c, field!(p.load), Parameter::Load, load),
                    upper,
                }
            }
            Series::System(system, options, total_load) => {
                for field in [field!(p.radius), field!(p.load)] {
                    refuse(
                        c,
                        field,
                        "none: a three-body series gives `total_load` instead",
                    );
                }
                let why = "for each point of a three-body series, or for the series";
                let total_load = match total_load {
                    Some(w) => c.quantity(field!(p.total_load), Parameter::TotalLoad, w),
                    None => c.required(field!(p.total_load), Parameter::TotalLoad, why),
                };
                check_range(
                    c,
                    field!(p.total_load),
                    Parameter::TotalLoad,
                    Some(total_load),
                );
                Setting::System {
                    system,
                    options,
                    total_load,
                }
            }
        }
    }
}

/// The system of a three-body series; what the fit sets refused if given.
fn read_system(input: &ThreeBodyInput, c: &mut Checker) -> (ThreeBody, ThreeBodyOptions) {
    let set = [
        (
            "layer",
            input.layer.is_some(),
            "none: the fit's own `layer` is the system's layer",
        ),
        (
            "velocity",
            input.velocity.is_some(),
            "none: each point gives its own `velocity`",
        ),
        (
            "operating",
            input.operating.is_some(),
            "none: each point gives its own `total_load`",
        ),
    ];
    for (name, given, allowed) in set {
        if given {
            c.invalid(&format!("system.{name}"), json!({}), allowed);
        }
    }
    let mut input = input.clone();
    input.layer = None;
    input.velocity = None;
    // A placeholder: each point solves at its own total load.
    input.operating = Some(OperatingInput::of(OperatingPoint::TotalLoad(1e-3)));
    let field = Field {
        name: "system",
        value: Some(&input),
    };
    let job = c.nested(field, |c, s| ThreeBodyJob::read(s, c));
    (job.system, job.options)
}

/// The quantity `field` as `parameter`, its range checked if given; `default` if absent.
fn condition(c: &mut Checker, field: Field<Quantity>, parameter: Parameter, default: f64) -> f64 {
    let x = c.quantity(field, parameter, default);
    check_range(c, field, parameter, Some(x));
    x
}

/// Checks `value`, read from `field` as `parameter`, against its range if the field was given.
fn check_range(c: &mut Checker, field: Field<Quantity>, parameter: Parameter, value: Option<f64>) {
    if let (Some(_), Some(x)) = (field.value, value) {
        if let Err(e) = parameter.check(x) {
            c.out_of_range(field.name, x, parameter.unit(), &e.allowed);
        }
    }
}

/// Refuses `field` if given: `allowed` says why it may not be.
fn refuse<T: Serialize>(c: &mut Checker, field: Field<T>, allowed: &str) {
    if let Some(q) = field.value {
        c.invalid(field.name, json!(q), allowed);
    }
}

/// Enough data for the parameters, and uncertainties for all points or none.
fn check_counts(problem: &Problem, input: &FitInput, checker: &mut Checker) {
    let with = problem
        .data
        .iter()
        .filter(|d| d.uncertainty.is_some())
        .count();
    if with > 0 && with < problem.data.len() {
        let allowed = format!(
            "an uncertainty for every point or for none ({with} of {} have one)",
            problem.data.len()
        );
        checker.invalid("series", json!(with), &allowed);
    }
    let m = problem.parameterization.free.len();
    let mut conditions: Vec<String> = problem
        .data
        .iter()
        .map(|d| format!("{:?}", d.point))
        .collect();
    conditions.sort_unstable();
    conditions.dedup();
    if input.series.as_ref().is_some_and(|s| !s.is_empty()) && m > 0 {
        // Without uncertainties the scatter needs one point more than the parameters.
        let needed = if with == 0 { m + 1 } else { m };
        if problem.data.len() < needed {
            let without = if with == 0 {
                " without uncertainties"
            } else {
                ""
            };
            let allowed = format!(
                "at least {needed} points to fit {m} parameter{}{without}, but {} given",
                if m == 1 { "" } else { "s" },
                problem.data.len()
            );
            checker.invalid("series", json!(problem.data.len()), &allowed);
        } else if conditions.len() < m {
            let allowed = format!(
                "points at {m} or more distinct conditions (radius, load or total load, \
                 velocity, quantity) to fit {m} parameters, but all are at {}",
                conditions.len()
            );
            checker.invalid("series", json!(conditions.len()), &allowed);
        }
    }
}
