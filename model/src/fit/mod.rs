//! The inverse problem: the layer's parameters that best explain measured friction
//! coefficients or contact areas of rolling particles. [`forward`] gives the model's value at
//! one measured point and its sensitivities to the parameters; [`lm`] is the bounded
//! Levenberg–Marquardt minimiser; [`stats`] turns the minimum into standard errors,
//! intervals and an identifiability verdict.
//!
//! Parameters are fitted in logarithms: every one is positive, they span decades, and the
//! model's own structure is multiplicative in them (docs/model.md §3: A = A₀(k, R, P) · α(ξ, κ)).

pub mod forward;
pub mod lm;
pub mod stats;

pub use forward::{Law, Measured, Point, Sensitivity, Setting};

use nalgebra::{DMatrix, DVector};

use super::{Layer, ModelError, Parameter, Stop};
use lm::{Evaluation, LeastSquares};
use stats::Analysis;

/// A parameter a fit can determine. `Kappa` stands in for `RetardationTime`, and `Stiffness`
/// for `Thickness`: a fit takes at most one of each pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FitParameter {
    /// T_σ (s).
    RelaxationTime,
    /// T_ε (s), ≥ T_σ.
    RetardationTime,
    /// κ = T_ε/T_σ − 1.
    Kappa,
    /// E_L (Pa).
    ElasticModulus,
    /// H (m).
    Thickness,
    /// k = E_L/H (Pa/m).
    Stiffness,
    /// A factor on every modulus of the layer (E_L and a Prony series' E_j), relative to
    /// the fit's base layer.
    ModulusScale,
    /// A factor a on every time of the layer (T_ε, T_σ and a Prony series' τ_j), relative
    /// to the fit's base layer: the shift factor of time–temperature superposition, log₁₀ a
    /// decades.
    ShiftFactor,
}

impl FitParameter {
    /// Every parameter, in the order of the wire's names.
    pub const ALL: [FitParameter; 8] = [
        FitParameter::RelaxationTime,
        FitParameter::RetardationTime,
        FitParameter::Kappa,
        FitParameter::ElasticModulus,
        FitParameter::Thickness,
        FitParameter::Stiffness,
        FitParameter::ModulusScale,
        FitParameter::ShiftFactor,
    ];

    /// The name on the wire.
    pub fn name(self) -> &'static str {
        match self {
            FitParameter::RelaxationTime => "relaxation_time",
            FitParameter::RetardationTime => "retardation_time",
            FitParameter::Kappa => "kappa",
            FitParameter::ElasticModulus => "elastic_modulus",
            FitParameter::Thickness => "thickness",
            FitParameter::Stiffness => "k",
            FitParameter::ModulusScale => "modulus_scale",
            FitParameter::ShiftFactor => "shift_factor",
        }
    }

    /// The model's parameter its values are read and checked as (its unit, its range).
    pub fn parameter(self) -> Parameter {
        match self {
            FitParameter::RelaxationTime => Parameter::RelaxationTime,
            FitParameter::RetardationTime => Parameter::RetardationTime,
            FitParameter::Kappa => Parameter::Kappa,
            FitParameter::ElasticModulus => Parameter::ElasticModulus,
            FitParameter::Thickness => Parameter::Thickness,
            FitParameter::Stiffness => Parameter::Stiffness,
            FitParameter::ModulusScale => Parameter::ModulusScale,
            FitParameter::ShiftFactor => Parameter::ShiftFactor,
        }
    }

    /// Whether it sets a time scale of the layer, which points at rest cannot show.
    pub fn is_time_scale(self) -> bool {
        matches!(
            self,
            FitParameter::RelaxationTime
                | FitParameter::RetardationTime
                | FitParameter::Kappa
                | FitParameter::ShiftFactor
        )
    }

    /// Whether it sets a single Kelvin time or κ: a Prony series of more terms is fitted by
    /// [`FitParameter::ShiftFactor`] instead, which moves all its times.
    pub fn is_kelvin_time(self) -> bool {
        self.is_time_scale() && self != FitParameter::ShiftFactor
    }

    /// The parameter's value in `layer` (the factors: 1, as they are relative to the
    /// layer they act on).
    pub fn of(self, layer: &Layer) -> f64 {
        match self {
            FitParameter::RelaxationTime => layer.relaxation_time,
            FitParameter::RetardationTime => layer.retardation_time,
            FitParameter::Kappa => layer.kappa(),
            FitParameter::ElasticModulus => layer.elastic_modulus,
            FitParameter::Thickness => layer.thickness,
            FitParameter::Stiffness => layer.stiffness(),
            FitParameter::ModulusScale | FitParameter::ShiftFactor => 1.0,
        }
    }
}

/// Which parameters a fit varies, over a layer that gives the others, and the layer's law
/// the model is solved with.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameterization {
    pub base: Layer,
    pub free: Vec<FitParameter>,
    pub law: Law,
}

impl Parameterization {
    /// Whether κ is held (or fitted) rather than T_ε: then T_ε follows T_σ.
    fn kappa_mode(&self) -> bool {
        self.free.contains(&FitParameter::Kappa)
    }

    /// Whether k is fitted rather than H: then H follows E_L.
    fn stiffness_mode(&self) -> bool {
        self.free.contains(&FitParameter::Stiffness)
    }

    /// The layer at the free parameters' `values` (SI, in the order of `free`).
    pub fn layer(&self, values: &[f64]) -> Layer {
        let mut layer = self.base;
        let (mut kappa, mut stiffness) = (self.base.kappa(), self.base.stiffness());
        let mut shift = 1.0;
        for (&parameter, &value) in self.free.iter().zip(values) {
            match parameter {
                FitParameter::RelaxationTime => layer.relaxation_time = value,
                FitParameter::RetardationTime => layer.retardation_time = value,
                FitParameter::Kappa => kappa = value,
                FitParameter::ElasticModulus => layer.elastic_modulus = value,
                FitParameter::Thickness => layer.thickness = value,
                FitParameter::Stiffness => stiffness = value,
                FitParameter::ModulusScale => {
                    layer.elastic_modulus = self.base.elastic_modulus * value
                }
                FitParameter::ShiftFactor => shift = value,
            }
        }
        if self.kappa_mode() {
            layer.retardation_time = layer.relaxation_time * (1.0 + kappa);
        }
        if self.stiffness_mode() {
            layer.thickness = layer.elastic_modulus / stiffness;
        }
        if shift != 1.0 {
            layer = layer.with_times_scaled(shift);
        }
        layer
    }

    /// ∂ ln y / ∂ ln p for each free parameter p, from the sensitivities of a point at
    /// fixed (T_σ, κ, E_L, H) and the layer's κ (the chain rule of each parameterization).
    pub fn log_derivatives(&self, s: &Sensitivity, kappa: f64) -> Vec<f64> {
        self.free
            .iter()
            .map(|&parameter| match parameter {
                // Every time scaled, κ held: s.relaxation_time by its definition.
                FitParameter::RelaxationTime if self.kappa_mode() => s.relaxation_time,
                FitParameter::ShiftFactor => s.relaxation_time,
                // T_ε held: κ = T_ε/T_σ − 1 falls as T_σ rises.
                FitParameter::RelaxationTime => s.relaxation_time - s.kappa * (1.0 + kappa),
                FitParameter::RetardationTime => s.kappa * (1.0 + kappa),
                FitParameter::Kappa => s.kappa * kappa,
                // k held: H = E_L/k rises with E_L.
                FitParameter::ElasticModulus | FitParameter::ModulusScale
                    if self.stiffness_mode() =>
                {
                    s.elastic_modulus + s.thickness
                }
                FitParameter::ElasticModulus | FitParameter::ModulusScale => s.elastic_modulus,
                FitParameter::Thickness => s.thickness,
                FitParameter::Stiffness => -s.thickness,
            })
            .collect()
    }
}

/// A measured value at a point, with its standard uncertainty if known.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Datum {
    pub point: Point,
    pub value: f64,
    pub uncertainty: Option<f64>,
}

impl Datum {
    /// The residual's scale: the uncertainty, or 1 when none is known (the scatter of the
    /// residuals then sets the scale, [`stats::analyse`]).
    fn sigma(&self) -> f64 {
        self.uncertainty.unwrap_or(1.0)
    }
}

/// Where a free parameter starts and the box it stays in (SI, all positive).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub start: f64,
    pub min: f64,
    pub max: f64,
}

/// A fit: the data, the parameters free and their bounds (in the order of `free`).
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    pub parameterization: Parameterization,
    pub bounds: Vec<Bounds>,
    /// Every datum has an uncertainty, or none has.
    pub data: Vec<Datum>,
}

impl Problem {
    /// Why the model fails at the start (no minimisation could begin there), stopped when
    /// `stop` says so.
    fn failure_at_start(&self, stop: Stop) -> ModelError {
        let start: Vec<f64> = self.bounds.iter().map(|b| b.start).collect();
        let layer = self.parameterization.layer(&start);
        if let Some(e) = layer.violations().into_iter().next() {
            return ModelError::InvalidParameter(e);
        }
        self.data
            .iter()
            .find_map(|d| {
                d.point
                    .value_and_sensitivity(&layer, self.parameterization.law, stop)
                    .err()
            })
            .unwrap_or_else(|| {
                ModelError::OutOfModel(
                    "the weighted residuals overflow at every start: a measured value or an \
                     uncertainty is beyond the scale of double precision"
                        .to_string(),
                )
            })
    }
}

/// The best fit.
#[derive(Clone, Debug, PartialEq)]
pub struct Fitted {
    /// The free parameters' values (SI).
    pub values: Vec<f64>,
    /// Uncertainty of their logarithms.
    pub analysis: Analysis,
    pub chi_squared: f64,
    pub dof: usize,
    /// No datum had an uncertainty: the covariance was scaled by χ²/dof.
    pub scaled: bool,
    /// The model's value at each datum.
    pub fitted: Vec<f64>,
    /// Points tried as starts, and the minimisations run from the best of them.
    pub candidates: usize,
    pub starts: usize,
    /// Levenberg–Marquardt steps over all starts.
    pub steps: usize,
    /// Whether the best minimisation stopped by its tolerances.
    pub converged: bool,
    /// Minimisations run to their end: fewer than `starts` when the caller's check stopped
    /// the fit after the first (the answer is then the best of those run).
    pub finished: usize,
}

/// Why a fit has no answer.
#[derive(Debug, PartialEq)]
pub enum FitError<E> {
    /// The caller's check stopped it (cancelled, past its deadline).
    Stopped(E),
    /// The model failed at the start.
    Model(ModelError),
    /// The free parameters (indices into `free`) change no residual at the best fit.
    NoEffect(Vec<usize>),
}

/// Minimisations run: from the given start and from the best other candidate.
const STARTS: usize = 2;

/// Steps a minimisation is expected to take ([`expected_evaluations`]); at most
/// [`lm`]'s 200.
const EXPECTED_STEPS: u64 = 20;

/// How often a fit of `problem` is expected to evaluate its model at every datum, before it
/// runs: its value alone at each candidate start (the start and the corners of the box's
/// middle half), and with its sensitivities at each step of each minimisation. An estimate
/// of its work for a quota, which charges what the fit really took after it.
pub fn expected_evaluations(problem: &Problem) -> (u64, u64) {
    let candidates = 1 + (1u64 << problem.bounds.len().min(32));
    (candidates, STARTS as u64 * EXPECTED_STEPS)
}

/// Fits `problem`. `check` is called before each point is evaluated (one to five solves);
/// an error from it stops the fit.
/// The fit of `problem`, checking `check` between evaluations of the model. Stopped by it
/// after a first minimisation ran to its end, the fit answers with the best minimisation run
/// so far, and the check's error: a stopped fit keeps what it finished.
pub fn fit<E>(
    problem: &Problem,
    check: &(dyn Fn() -> Result<(), E> + Sync),
    stop: Stop,
) -> Result<(Fitted, Option<E>), FitError<E>> {
    let ln = |f: fn(&Bounds) -> f64| {
        DVector::from_iterator(
            problem.bounds.len(),
            problem.bounds.iter().map(|b| f(b).ln()),
        )
    };
    let (start, lower, upper) = (ln(|b| b.start), ln(|b| b.min), ln(|b| b.max));
    let mut residuals = Residuals {
        problem,
        check,
        stop,
    };
    // Screen the start and the corners of the box's middle half by their cost alone.
    let candidates = candidates(&start, &lower, &upper);
    let starts = residuals.screen(&candidates).map_err(FitError::Stopped)?;
    let mut best: Option<lm::Minimum> = None;
    let (mut steps, mut finished, mut stopped) = (0, 0, None);
    for &i in &starts {
        let found = match lm::minimize(&mut residuals, &candidates[i], &lower, &upper) {
            Ok(found) => found,
            Err(e) if best.is_some() => {
                stopped = Some(e);
                break;
            }
            Err(e) => return Err(FitError::Stopped(e)),
        };
        finished += 1;
        if let Some(m) = found {
            steps += m.steps;
            if best.as_ref().map_or(true, |b| m.cost < b.cost) {
                best = Some(m);
            }
        }
    }
    let Some(best) = best else {
        let failure = problem.failure_at_start(stop);
        return Err(match check() {
            Err(e) if failure == ModelError::Stopped => FitError::Stopped(e),
            _ => FitError::Model(failure),
        });
    };
    let n = problem.data.len();
    let dof = n.saturating_sub(start.len());
    let scaled = problem.data.iter().all(|d| d.uncertainty.is_none());
    let analysis = stats::analyse(&best.jacobian, best.cost, dof, scaled);
    if !analysis.no_effect.is_empty() {
        return Err(FitError::NoEffect(analysis.no_effect));
    }
    let fitted = problem
        .data
        .iter()
        .zip(best.residuals.iter())
        .map(|(d, r)| d.value + r * d.sigma())
        .collect();
    let fitted = Fitted {
        values: best.x.iter().map(|x| x.exp()).collect(),
        analysis,
        chi_squared: best.cost,
        dof,
        scaled,
        fitted,
        candidates: candidates.len(),
        starts: starts.len(),
        steps,
        converged: best.converged,
        finished,
    };
    Ok((fitted, stopped))
}

/// The candidate starts, in the logarithms of the free parameters: `start` first, then the
/// corners of the middle half of the box [`lower`, `upper`], so that a fit whose start lies
/// in the wrong basin has another to try.
fn candidates(
    start: &DVector<f64>,
    lower: &DVector<f64>,
    upper: &DVector<f64>,
) -> Vec<DVector<f64>> {
    let mut candidates = vec![start.clone()];
    for corner in 0..1usize << start.len() {
        candidates.push(DVector::from_fn(start.len(), |i, _| {
            let quarter = if corner >> i & 1 == 0 { 0.25 } else { 0.75 };
            lower[i] + quarter * (upper[i] - lower[i])
        }));
    }
    candidates
}

/// The weighted residuals of a problem in the logarithms of its free parameters.
struct Residuals<'a, E> {
    problem: &'a Problem,
    check: &'a (dyn Fn() -> Result<(), E> + Sync),
    /// Asked inside each solve (a continuum answer takes up to half a minute); `check`,
    /// which may count its calls, is asked between them.
    stop: Stop<'a>,
}

impl<E> Residuals<'_, E> {
    /// The candidates to minimise from, by index: the given start (the first), then the
    /// [`STARTS`] − 1 others of least cost, among those the model answers. A cost is cheap
    /// beside a minimisation, so screening saves minimising from a poor start.
    fn screen(&mut self, candidates: &[DVector<f64>]) -> Result<Vec<usize>, E> {
        let mut costs = Vec::new();
        for (i, x) in candidates.iter().enumerate() {
            if let Some(cost) = self.cost(x)? {
                costs.push((cost, i));
            }
        }
        costs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut starts = vec![0];
        starts.extend(
            costs
                .iter()
                .map(|&(_, i)| i)
                .filter(|&i| i != 0)
                .take(STARTS - 1),
        );
        Ok(starts)
    }

    /// The layer at `x`, if inside the model's ranges (T_ε ≥ T_σ among them).
    fn layer(&self, x: &DVector<f64>) -> Option<Layer> {
        let values: Vec<f64> = x.iter().map(|x| x.exp()).collect();
        let layer = self.problem.parameterization.layer(&values);
        layer.violations().is_empty().then_some(layer)
    }

    /// Σ r² at `x`, without the Jacobian; `None` outside the model's domain.
    fn cost(&mut self, x: &DVector<f64>) -> Result<Option<f64>, E> {
        let Some(layer) = self.layer(x) else {
            return Ok(None);
        };
        let mut cost = 0.0;
        for d in &self.problem.data {
            (self.check)()?;
            let law = self.problem.parameterization.law;
            let Ok(y) = d.point.value(&layer, law, self.stop) else {
                // A solve the check stopped is the check's error, not a point outside.
                (self.check)()?;
                return Ok(None);
            };
            cost += ((y - d.value) / d.sigma()).powi(2);
        }
        Ok(cost.is_finite().then_some(cost))
    }
}

impl<E> LeastSquares for Residuals<'_, E> {
    type Error = E;

    fn evaluate(&mut self, x: &DVector<f64>) -> Result<Option<Evaluation>, E> {
        let Some(layer) = self.layer(x) else {
            return Ok(None);
        };
        let (n, m) = (self.problem.data.len(), x.len());
        let mut residuals = DVector::zeros(n);
        let mut jacobian = DMatrix::zeros(n, m);
        for (i, d) in self.problem.data.iter().enumerate() {
            (self.check)()?;
            let law = self.problem.parameterization.law;
            let Ok((y, s)) = d.point.value_and_sensitivity(&layer, law, self.stop) else {
                // A solve the check stopped is the check's error, not a point outside.
                (self.check)()?;
                return Ok(None);
            };
            let weight = 1.0 / d.sigma();
            residuals[i] = (y - d.value) * weight;
            let derivatives = self
                .problem
                .parameterization
                .log_derivatives(&s, layer.kappa());
            for (j, dj) in derivatives.into_iter().enumerate() {
                jacobian[(i, j)] = y * dj * weight;
            }
        }
        // Values beyond double precision (a modulus at 1e300) count as outside the domain.
        let finite = residuals.norm_squared().is_finite() && jacobian.iter().all(|x| x.is_finite());
        Ok(finite.then_some(Evaluation {
            residuals,
            jacobian,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_parameterization_gives_the_layer_it_names() {
        let base = Layer::default();
        let p = Parameterization {
            base,
            free: vec![FitParameter::RelaxationTime, FitParameter::Kappa],
            law: Law::Local,
        };
        let layer = p.layer(&[0.2, 3.0]);
        assert_eq!(layer.relaxation_time, 0.2);
        assert!((layer.retardation_time - 0.8).abs() < 1e-15);
        let p = Parameterization {
            base,
            free: vec![FitParameter::ElasticModulus, FitParameter::Stiffness],
            law: Law::Local,
        };
        let layer = p.layer(&[6e9, 3e16]);
        assert!((layer.thickness - 2e-7).abs() < 1e-22);
        for parameter in FitParameter::ALL {
            let p = Parameterization {
                base,
                free: vec![parameter],
                law: Law::Local,
            };
            let value = parameter.of(&base) * 1.5;
            let layer = p.layer(&[value]);
            // The factors act on the layer's moduli and times, and read 1 on any layer.
            let (got, expected) = match parameter {
                FitParameter::ModulusScale => (layer.elastic_modulus, 1.5 * base.elastic_modulus),
                FitParameter::ShiftFactor => (layer.retardation_time, 1.5 * base.retardation_time),
                _ => (parameter.of(&layer), value),
            };
            assert!((got / expected - 1.0).abs() < 1e-15, "{parameter:?}");
        }
    }

    fn friction_at(speeds_nm_s: &[f64], layer: &Layer) -> Vec<Datum> {
        speeds_nm_s
            .iter()
            .map(|&v| {
                let point = Point {
                    setting: Setting::Particle {
                        radius: 25e-9,
                        load: 1e-9,
                        upper: Default::default(),
                    },
                    velocity: v * 1e-9,
                    measured: Measured::FrictionCoefficient,
                };
                Datum {
                    point,
                    value: point.value(layer, Law::Local, Stop::NEVER).unwrap(),
                    uncertainty: Some(1e-3),
                }
            })
            .collect()
    }

    /// Both times free, from a start off the truth, on `truth`'s friction against speed.
    fn two_times(truth: &Layer) -> Problem {
        Problem {
            parameterization: Parameterization {
                base: Layer {
                    relaxation_time: 0.05,
                    retardation_time: 0.2,
                    ..*truth
                },
                free: vec![FitParameter::RelaxationTime, FitParameter::RetardationTime],
                law: Law::Local,
            },
            bounds: vec![
                Bounds {
                    start: 0.05,
                    min: 1e-3,
                    max: 10.0,
                },
                Bounds {
                    start: 0.2,
                    min: 1e-3,
                    max: 100.0,
                },
            ],
            data: friction_at(&[0.0, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0], truth),
        }
    }

    #[test]
    fn a_fit_stopped_after_its_first_minimisation_answers_with_the_best_it_finished() {
        let problem = two_times(&Layer::default());
        let calls = std::sync::atomic::AtomicUsize::new(0);
        let counting = || {
            calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            Ok::<(), ()>(())
        };
        let (whole, stop) = fit(&problem, &counting, Stop::NEVER).unwrap();
        assert!(stop.is_none() && whole.finished == whole.starts && whole.starts >= 2);
        // Stopped at its last evaluation: every run but the last finished.
        let last = calls.load(std::sync::atomic::Ordering::Relaxed);
        let seen = std::sync::atomic::AtomicUsize::new(0);
        let stopping = || {
            let n = seen.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            if n >= last {
                Err("stopped")
            } else {
                Ok(())
            }
        };
        let (partial, stop) = fit(&problem, &stopping, Stop::NEVER).unwrap();
        assert_eq!(stop, Some("stopped"));
        assert_eq!(partial.finished, whole.starts - 1);
        assert!(partial.chi_squared.is_finite() && partial.values.len() == 2);
        // Stopped before any run finished, it has nothing to answer with.
        assert!(matches!(
            fit(&problem, &|| Err::<(), _>("at once"), Stop::NEVER),
            Err(FitError::Stopped("at once"))
        ));
    }

    #[test]
    fn noiseless_data_give_back_the_layer_they_came_from() {
        let truth = Layer::default();
        let problem = two_times(&truth);
        let (fitted, _) = fit(&problem, &|| Ok::<(), ()>(()), Stop::NEVER).unwrap();
        assert!(
            (fitted.values[0] / 0.1 - 1.0).abs() < 1e-6,
            "{:?}",
            fitted.values
        );
        assert!(
            (fitted.values[1] / 0.5 - 1.0).abs() < 1e-6,
            "{:?}",
            fitted.values
        );
        assert!(fitted.chi_squared < 1e-12);
        assert!(fitted.analysis.null_directions.is_empty());
    }
}
