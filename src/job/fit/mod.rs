//! The fit job: the layer's relaxation time, retardation time (or κ), modulus and thickness
//! (or stiffness) that best explain measured friction coefficients or contact areas, with
//! their uncertainty and what the data leave undetermined ([`crate::model::fit`]).
//!
//! A fit cannot tell its size in advance: it counts the points it evaluates as its work,
//! checks its control before each one (a particle's point takes tens of microseconds, a
//! system's a few milliseconds, so a cancel stops it at once), and reports `Work::Unknown`.

mod picture;
pub use picture::FitPicture;

mod input;
mod output;

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use nalgebra::DVector;
use serde_json::{json, Value};

pub use input::{
    BoundsInput, FitInput, MeasuredQuantity, ParametersInput, PointInput, SeriesInput,
};
pub use output::{
    Comparison, Conditions, Curve, CurvePoint, Estimate, FitMeta, FitOutput, Identifiability,
    Residual, Search, UncertaintySource, Undetermined,
};

use super::input as wire;
use super::kind::SMALL_ANSWER;
use super::meta::{CONTINUUM_REFERENCES, ROLLING_REFERENCES};
use super::three_body::{system_cost, Nodes};
use super::{Control, Cost, FieldError, JobError, Kind, Limits, Meta, References, Validated, Work};
use crate::model::continuum;
use crate::model::fit::stats;
use crate::model::fit::{self, Datum, FitError, Fitted, Law, Point, Problem, Setting};
use crate::model::three_body::{LayerContact, ThreeBody};
use crate::model::{Layer, Rolling, Stop};

/// How long a stopped fit may go on drawing its curves.
const DRAWING_GRACE: Duration = Duration::from_secs(2);

/// What one solve of `point` on `layer` costs under the fit's `law`: a grid's answer for a
/// rolling particle on the continuum, a system's continuum curves, a point otherwise (a
/// particle at rest on the continuum is a table's).
fn solve_cost(point: &Point, layer: &Layer, law: Law) -> Cost {
    match (point.setting, law.at(&point.setting)) {
        (Setting::Particle { radius, load, .. }, Law::Continuum) if point.velocity > 0.0 => {
            let rolling = Rolling {
                radius,
                load,
                velocity: point.velocity,
                layer: *layer,
            };
            continuum::plan(&rolling, continuum::PER_RADIUS)
                .map_or(Cost::points(1), |plan| Cost::continuum(&plan))
        }
        (Setting::System { system, .. }, Law::Continuum) => {
            let system = ThreeBody {
                layer: *layer,
                velocity: point.velocity,
                layer_contact: LayerContact::Continuum,
                ..system
            };
            system_cost(&system, &mut Nodes::default())
        }
        _ => Cost::points(1),
    }
}

/// A validated fit.
#[derive(Clone, Debug, PartialEq)]
pub struct FitJob {
    pub problem: Problem,
    /// The number of points of each series, in order (the data are the series' points).
    pub series: Vec<usize>,
}

impl Kind for FitJob {
    const NAME: &'static str = "fit";
    type Input = FitInput;
    type Output = FitOutput;

    fn validate(value: Value, limits: &Limits) -> Result<Validated<Self>, JobError> {
        let max = limits.max_sweep_points;
        wire::validate(value, |input: &FitInput, checker| {
            let problem = input.read(checker, max);
            let series = input
                .series
                .iter()
                .flatten()
                .map(|s| s.points.as_ref().map_or(0, Vec::len))
                .collect();
            FitJob { problem, series }
        })
    }

    /// Every point explicit, in SI, in its series.
    fn canonical(&self) -> Value {
        wire::canonical(&FitInput::of(&self.problem, &self.series))
    }

    fn references(&self) -> &'static References {
        if self.on_continuum() {
            &CONTINUUM_REFERENCES
        } else {
            &ROLLING_REFERENCES
        }
    }

    /// A fit of rolling points on the continuum takes minutes (three or four grid answers a
    /// point for every evaluation of the model); at rest it is as quick as on the local law.
    fn asynchronous_only(&self) -> Option<JobError> {
        let law = self.problem.parameterization.law;
        let slow = self.problem.data.iter().position(|d| {
            let p = &d.point;
            p.on_continuum(law) && (p.velocity > 0.0 || matches!(p.setting, Setting::System { .. }))
        })?;
        // The field that put it on the continuum: the layer's law, or the system's contact.
        let field = match law {
            Law::Continuum => "layer.model".to_string(),
            Law::Local => {
                let series = self
                    .series
                    .iter()
                    .scan(0, |end, &n| {
                        *end += n;
                        Some(*end)
                    })
                    .position(|end| slow < end)
                    .unwrap_or(0);
                format!("series[{series}].system.layer_contact")
            }
        };
        let message = format!(
            "{field}: a fit of rolling points (or of a system) on the layer as a continuum \
             takes minutes: submit it to POST /v1/jobs as {{\"kind\": \"fit\", \"input\": \
             ...}}, which shows its progress and can be cancelled"
        );
        Some(JobError::Invalid(vec![FieldError {
            field,
            value: "continuum".into(),
            allowed: "the local law for an answer now".to_string(),
            message,
        }]))
    }

    /// A fit on the continuum costs a thousand times one on the local law.
    fn cost_class(&self) -> &'static str {
        if self.on_continuum() {
            "fit on the continuum"
        } else {
            Self::NAME
        }
    }

    fn work(&self) -> Work {
        Work::Unknown
    }

    /// Its expected evaluations of the model ([`fit::expected_evaluations`]) at every datum,
    /// each of so many solves, each what a solve of the datum costs at the start.
    fn cost(&self) -> Cost {
        let problem = &self.problem;
        let (values, with_sensitivities) = fit::expected_evaluations(problem);
        let law = problem.parameterization.law;
        let start: Vec<f64> = problem.bounds.iter().map(|b| b.start).collect();
        let layer = problem.parameterization.layer(&start);
        problem
            .data
            .iter()
            .map(|d| {
                let solves = values + with_sensitivities * d.point.solves_with_sensitivity(law);
                solve_cost(&d.point, &layer, law).times(solves)
            })
            .fold(Cost::default(), Cost::then)
    }

    /// A residual is a row of a dozen numbers in JSON and CSV (at most 1 kB), a fitted curve
    /// `CURVE_POINTS` points of a few numbers each.
    fn result_bytes(&self) -> u64 {
        let points: usize = self.series.iter().sum();
        let curves = self.series.len() * CURVE_POINTS * 256;
        SMALL_ANSWER + (points * 1024 + curves) as u64
    }

    fn run(&self, meta: Meta, control: &Control) -> Result<FitOutput, JobError> {
        let check = || {
            control.check()?;
            control.advance(1);
            Ok(())
        };
        let asked = || control.must_stop();
        let (fitted, stop) =
            fit::fit(&self.problem, &check, Stop::when(&asked)).map_err(|e| self.refused(e))?;
        let layer = self.problem.parameterization.layer(&fitted.values);
        // A stopped fit answers with the minimisations it finished; its curves (a few dozen
        // solves a series) are still drawn, under a control of their own with a short grace
        // of its own: on the continuum they may take minutes, and a job past its deadline
        // or cancelled must end. The curves not drawn by then are left out.
        let drawing = Control::new(Some(Instant::now() + DRAWING_GRACE), 1);
        let curves_control = if stop.is_none() { control } else { &drawing };
        let mut curves = Vec::new();
        for (index, points) in self.series_data().enumerate() {
            let law = self.problem.parameterization.law;
            match curve(index, points, &layer, law, curves_control) {
                Ok(drawn) => curves.push(drawn),
                Err(JobError::DeadlineExceeded) if stop.is_some() => break,
                Err(e) => return Err(e),
            }
        }
        Ok(FitOutput {
            parameter_names: self.names(),
            parameters: self.estimates(&fitted),
            correlation: fitted
                .analysis
                .correlation
                .row_iter()
                .map(|r| r.iter().copied().collect())
                .collect(),
            chi_squared: fitted.chi_squared,
            dof: fitted.dof,
            uncertainties: if fitted.scaled {
                UncertaintySource::FromScatter
            } else {
                UncertaintySource::Given
            },
            residuals: self.residuals(&fitted),
            curves,
            identifiability: self.identifiability(&fitted),
            search: Search {
                candidates: fitted.candidates,
                starts: fitted.starts,
                steps: fitted.steps,
                converged: fitted.converged,
                finished: fitted.finished,
            },
            meta: FitMeta {
                meta,
                complete: stop.is_none(),
                stopped: stop.as_ref().map(ToString::to_string),
            },
            stop,
        })
    }

    fn unfinished(output: &FitOutput) -> Option<JobError> {
        output.stop.clone()
    }
}

impl FitJob {
    /// Whether any point is solved on the continuum (the fit's `layer.model`, or a system's
    /// `layer_contact`).
    fn on_continuum(&self) -> bool {
        let law = self.problem.parameterization.law;
        self.problem.data.iter().any(|d| d.point.on_continuum(law))
    }

    fn names(&self) -> Vec<&'static str> {
        let free = &self.problem.parameterization.free;
        free.iter().map(|p| p.name()).collect()
    }

    /// The data of each series.
    fn series_data(&self) -> impl Iterator<Item = &[Datum]> {
        let mut rest = &self.problem.data[..];
        self.series.iter().map(move |&n| {
            let (this, next) = rest.split_at(n.min(rest.len()));
            rest = next;
            this
        })
    }

    /// Why the fit has no answer, as a job error.
    fn refused(&self, e: FitError<JobError>) -> JobError {
        match e {
            FitError::Stopped(e) => e,
            FitError::Model(e) => e.into(),
            FitError::NoEffect(indices) => JobError::Invalid(
                indices
                    .into_iter()
                    .map(|i| {
                        let parameter = self.problem.parameterization.free[i];
                        let name = parameter.name();
                        let field = format!("parameters.{name}");
                        let allowed = "a parameter some measured point depends on".to_string();
                        let hint = if parameter.is_time_scale() {
                            " (a time has no effect when every point is at rest, V = 0)"
                        } else {
                            ""
                        };
                        let message = format!(
                            "{field}: no measured point depends on {name}{hint}: it cannot \
                             be fitted; give its value in `layer` instead"
                        );
                        FieldError {
                            field,
                            value: json!({}),
                            allowed,
                            message,
                        }
                    })
                    .collect(),
            ),
        }
    }

    fn estimates(&self, fitted: &Fitted) -> BTreeMap<&'static str, Estimate> {
        let a = &fitted.analysis;
        let free = &self.problem.parameterization.free;
        free.iter()
            .zip(&self.problem.bounds)
            .enumerate()
            .map(|(j, (parameter, bounds))| {
                let value = fitted.values[j];
                let se = a.standard_errors[j];
                let half = se.map(|se| a.coverage_factor * se);
                let on = |bound: f64| (value / bound).ln().abs() < 1e-9;
                let estimate = Estimate {
                    value,
                    standard_error: se.map(|se| se * value),
                    interval_95: half.map(|h| [value * (-h).exp(), value * h.exp()]),
                    determined: se.is_some(),
                    bounds: [bounds.min, bounds.max],
                    at_bound: on(bounds.min) || on(bounds.max),
                };
                (parameter.name(), estimate)
            })
            .collect()
    }

    fn residuals(&self, fitted: &Fitted) -> Vec<Residual> {
        // Without uncertainties, residuals are normalised by the scatter √(χ²/dof).
        let scatter = (fitted.chi_squared / fitted.dof.max(1) as f64).sqrt();
        let mut rows = Vec::new();
        let mut i = 0;
        for (series, data) in self.series_data().enumerate() {
            for (point, d) in data.iter().enumerate() {
                let fit = fitted.fitted[i];
                i += 1;
                let residual = fit - d.value;
                let sigma = d.uncertainty.unwrap_or(scatter);
                let comparison = Comparison {
                    measured: d.value,
                    fitted: fit,
                    residual,
                    uncertainty: d.uncertainty,
                };
                let (friction_coefficient, contact_area, particle_friction) =
                    by_quantity(d.point.measured, comparison);
                rows.push(Residual {
                    series,
                    point,
                    at: where_measured(&d.point),
                    friction_coefficient,
                    contact_area,
                    particle_friction,
                    normalized_residual: if residual == 0.0 {
                        0.0
                    } else {
                        residual / sigma
                    },
                });
            }
        }
        rows
    }

    fn identifiability(&self, fitted: &Fitted) -> Identifiability {
        let names = self.names();
        let a = &fitted.analysis;
        let determined: Vec<&str> = (0..names.len())
            .filter(|&j| a.standard_errors[j].is_some())
            .map(|j| names[j])
            .collect();
        let undetermined: Vec<Undetermined> = a
            .null_directions
            .iter()
            .map(|v| undetermined(&names, v))
            .collect();
        let identifiable = determined.len() == names.len();
        let message = if identifiable {
            format!(
                "The data determine every fitted parameter: {}.",
                names.join(", ")
            )
        } else {
            let alone = if determined.is_empty() {
                "no parameter alone".to_string()
            } else {
                determined.join(", ") + " alone"
            };
            let mut sentences: Vec<String> =
                undetermined.iter().map(|u| u.message.clone()).collect();
            let weak: Vec<&str> = names
                .iter()
                .filter(|n| !determined.contains(n))
                .filter(|n| !undetermined.iter().any(|u| u.parameters.contains(n)))
                .copied()
                .collect();
            if !weak.is_empty() {
                sentences.push(format!(
                    "{} is determined so weakly that no interval can be given.",
                    weak.join(" and ")
                ));
            }
            format!("The data determine {alone}. {}", sentences.join(" "))
        };
        Identifiability {
            identifiable,
            determined,
            undetermined,
            message,
        }
    }
}

/// The combination of `names` that the null direction `v` (in their logarithms) leaves free.
fn undetermined(names: &[&'static str], v: &DVector<f64>) -> Undetermined {
    let largest = v.amax();
    let involved = stats::involved(v);
    let round = |x: f64| (x / largest * 1e4).round() / 1e4;
    let direction: BTreeMap<&'static str, f64> =
        involved.iter().map(|&j| (names[j], round(v[j]))).collect();
    let parameters: Vec<&'static str> = involved.iter().map(|&j| names[j]).collect();
    let moves: Vec<String> = involved
        .iter()
        .map(|&j| format!("ln {} by {:+}", names[j], round(v[j])))
        .collect();
    let mut message = format!(
        "The data do not determine {} apart: changing {} together leaves every fitted value \
         unchanged, so the values given are one of many that fit equally.",
        parameters.join(" and "),
        moves.join(", ")
    );
    if let [a, b] = involved[..] {
        // The product a^x b^y with (x, y) ⟂ (v_a, v_b) is what the data fix.
        let (x, y) = (v[b], -v[a]);
        let scale = if x.abs() >= y.abs() { x } else { y };
        let term = |name: &str, e: f64| {
            let e = (e * 1e4).round() / 1e4;
            if e == 1.0 {
                name.to_string()
            } else {
                format!("{name}^{e}")
            }
        };
        message += &format!(
            " Only {} · {} is determined.",
            term(names[a], x / scale),
            term(names[b], y / scale)
        );
    }
    Undetermined {
        parameters,
        direction,
        message,
    }
}

/// A condition of a point: its name, how to read it (`None`: the point has none), how to
/// set it.
type Condition = (&'static str, fn(&Point) -> Option<f64>, fn(&mut Point, f64));

/// Where `point` was measured, as the answer says it.
fn where_measured(point: &Point) -> Conditions {
    let (radius, load, total_load) = match point.setting {
        Setting::Particle { radius, load, .. } => (Some(radius), Some(load), None),
        Setting::System { total_load, .. } => (None, None, Some(total_load)),
    };
    Conditions {
        radius,
        load,
        total_load,
        velocity: point.velocity,
    }
}

/// `x` as eq. 12's friction coefficient, the contact area or the particles' own friction,
/// as `measured` says.
fn by_quantity<T>(measured: fit::Measured, x: T) -> (Option<T>, Option<T>, Option<T>) {
    match measured {
        fit::Measured::FrictionCoefficient => (Some(x), None, None),
        fit::Measured::ContactArea => (None, Some(x), None),
        fit::Measured::ParticleFriction => (None, None, Some(x)),
    }
}

/// Points along a curve.
const CURVE_POINTS: usize = 41;

/// The conditions a series may vary, in the order a curve is drawn along the first varied.
const CONDITIONS: [Condition; 4] = [
    ("velocity", |p| Some(p.velocity), |p, x| p.velocity = x),
    (
        "load",
        |p| where_measured(p).load,
        |p, x| {
            if let Setting::Particle { load, .. } = &mut p.setting {
                *load = x;
            }
        },
    ),
    (
        "radius",
        |p| where_measured(p).radius,
        |p, x| {
            if let Setting::Particle { radius, .. } = &mut p.setting {
                *radius = x;
            }
        },
    ),
    (
        "total_load",
        |p| where_measured(p).total_load,
        |p, x| {
            if let Setting::System { total_load, .. } = &mut p.setting {
                *total_load = x;
            }
        },
    ),
];

/// Where a series' curve is evaluated: dense over the one condition its points vary (on a
/// log scale when it spans more than a factor of 20), else at the points themselves, sorted
/// along the first condition they vary.
fn grid(points: &[Datum], first: Point, varied: &[&Condition]) -> Vec<Point> {
    let mut grid: Vec<Point> = points.iter().map(|d| d.point).collect();
    if let [(_, of, set)] = varied[..] {
        let (lo, hi) = grid
            .iter()
            .filter_map(of)
            .fold((f64::INFINITY, 0.0_f64), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            });
        let logarithmic = lo > 0.0 && hi / lo > 20.0;
        grid = (0..CURVE_POINTS)
            .map(|i| {
                let f = i as f64 / (CURVE_POINTS - 1) as f64;
                let mut p = first;
                set(
                    &mut p,
                    if logarithmic {
                        lo * (hi / lo).powf(f)
                    } else {
                        lo + f * (hi - lo)
                    },
                );
                p
            })
            .collect();
    } else if let Some((_, of, _)) = varied.first() {
        grid.sort_by(|a, b| {
            of(a)
                .partial_cmp(&of(b))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
    }
    grid
}

/// The fitted model along the series `points`: dense over the one condition they vary,
/// through the points themselves when they vary several or none.
fn curve(
    series: usize,
    points: &[Datum],
    layer: &Layer,
    law: Law,
    control: &Control,
) -> Result<Curve, JobError> {
    let first = points.first().map_or_else(
        || Err(JobError::Internal("a series without points".to_string())),
        |d| Ok(d.point),
    )?;
    let varied: Vec<&Condition> = CONDITIONS
        .iter()
        .filter(|(_, of, _)| points.iter().any(|d| of(&d.point) != of(&first)))
        .collect();
    let along = varied.first().map_or("velocity", |c| c.0);
    let grid = grid(points, first, &varied);
    let mut curve_points = Vec::with_capacity(grid.len());
    for p in grid {
        let y = control.solve(|stop| p.value(layer, law, stop))?;
        let (friction_coefficient, contact_area, particle_friction) = by_quantity(p.measured, y);
        curve_points.push(CurvePoint {
            at: where_measured(&p),
            friction_coefficient,
            contact_area,
            particle_friction,
        });
    }
    Ok(Curve {
        series,
        quantity: MeasuredQuantity::of(first.measured),
        along: along.into(),
        points: curve_points,
    })
}
