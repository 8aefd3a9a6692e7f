//! The continuum law's limits as a field's range. A continuum answer whose grid would pass
//! the model's cap ([`continuum::plan`]) is refused when its job is validated, in
//! microseconds, naming the field that makes it so and the range of that field that is
//! answered with the other inputs as given, rather than failing after seconds of coarse
//! marches (or, before the plan, overflowing its pixel count). A job may stand on several
//! continuum answers (a three-body system's layer curves): the range is where all of them
//! are answered.

use serde_json::Value;

use super::super::input::Checker;
use crate::model::continuum::{self, Fineness, PER_RADIUS, THIN_POISSON};
use crate::model::text::{count, quantity};
use crate::model::{Layer, ModelError, Parameter, ParameterError, Rolling};

/// The continuum answers a job on a layer stands on.
pub type Problems<'a> = &'a dyn Fn(&Layer) -> Vec<Rolling>;

/// Records in `checker` why a continuum answer of `problems` on `layer` is refused before
/// it starts, if one is (`layer` and the problems within the model's ranges).
pub fn check(layer: &Layer, problems: Problems, checker: &mut Checker) {
    let Some(refused) = problems(layer)
        .iter()
        .find_map(|p| continuum::plan(p, PER_RADIUS).err())
    else {
        return;
    };
    let grid = format!(
        "the layer as a continuum would need a grid of {} by {} here, at most {} in all",
        count(refused.nx, "pixel", "pixels"),
        count(refused.ny, "pixel", "pixels"),
        count(continuum::MAX_PIXELS as f64, "pixel", "pixels"),
    );
    let field = match refused.cause {
        Fineness::Thickness => thicker(layer, problems).map(|h| ParameterError {
            parameter: Parameter::Thickness,
            value: layer.thickness,
            allowed: format!(
                "at least {} with the other inputs as given, or ν at most {THIN_POISSON} (the \
                 thin-layer path): {grid}, its pixels finer than this thin, nearly \
                 incompressible layer",
                quantity(h, "m")
            ),
        }),
        Fineness::Stiffening if layer.arms.is_empty() => slower(layer, problems),
        Fineness::Stiffening => None,
    };
    match field {
        Some(e) => checker.parameters(vec![e]),
        None => checker.invalid(
            "layer",
            Value::Null,
            &format!("{}", ModelError::from(refused)),
        ),
    }
}

/// The range of the Kelvin layer's time furthest from its default (T_σ at least, or T_ε at
/// most) that is answered: the layer stiffens T_ε/T_σ times at speed, and the grid must
/// resolve the contact at high speed, that much smaller than at rest.
fn slower(layer: &Layer, problems: Problems) -> Option<ParameterError> {
    let default = Layer::default();
    let off = |value: f64, default: f64| (value / default).ln().abs();
    type Set = fn(&mut Layer, f64);
    let (parameter, value, good, side, set): (_, _, _, _, Set) =
        if off(layer.relaxation_time, default.relaxation_time)
            >= off(layer.retardation_time, default.retardation_time)
        {
            let set: Set = |l, t| l.relaxation_time = t;
            let (value, good) = (layer.relaxation_time, layer.retardation_time);
            (Parameter::RelaxationTime, value, good, "at least", set)
        } else {
            let set: Set = |l, t| l.retardation_time = t;
            let (value, good) = (layer.retardation_time, layer.relaxation_time);
            (Parameter::RetardationTime, value, good, "at most", set)
        };
    let bound = boundary(layer, problems, value, good, set)?;
    let mut answered = *layer;
    set(&mut answered, bound);
    Some(ParameterError {
        parameter,
        value,
        allowed: format!(
            "{side} {} with the other inputs as given (T_ε/T_σ at most {}): beyond it the \
             layer as a continuum would need a grid of more than {} to resolve the contact \
             at high speed, which is that many times stiffer than at rest",
            quantity(bound, "s"),
            quantity(answered.retardation_time / answered.relaxation_time, ""),
            count(continuum::MAX_PIXELS as f64, "pixel", "pixels"),
        ),
    })
}

/// The least thickness answered, doubling from the layer's own up to a million times it.
fn thicker(layer: &Layer, problems: Problems) -> Option<f64> {
    let set = |l: &mut Layer, h: f64| l.thickness = h;
    let good = (1..=20)
        .map(|k| layer.thickness * 2f64.powi(k))
        .find(|&h| answered(layer, problems, h, set))?;
    boundary(layer, problems, layer.thickness, good, set)
}

/// Whether every problem on `layer` with one of its inputs set to `value` (by `set`) is
/// answered.
fn answered(layer: &Layer, problems: Problems, value: f64, set: impl Fn(&mut Layer, f64)) -> bool {
    let mut changed = *layer;
    set(&mut changed, value);
    changed.violations().is_empty()
        && problems(&changed)
            .iter()
            .all(|p| p.violations().is_empty() && continuum::plan(p, PER_RADIUS).is_ok())
}

/// The value of one input of `layer` (set by `set`) where answers begin, between `refused`
/// and `good` (answered), to a thousandth in its logarithm, on the answered side; `None` if
/// `good` is not answered.
fn boundary(
    layer: &Layer,
    problems: Problems,
    refused: f64,
    good: f64,
    set: impl Fn(&mut Layer, f64) + Copy,
) -> Option<f64> {
    if !answered(layer, problems, good, set) {
        return None;
    }
    let (mut bad, mut good) = (refused.ln(), good.ln());
    while (good - bad).abs() > 1e-3 {
        let middle = 0.5 * (bad + good);
        if answered(layer, problems, middle.exp(), set) {
            good = middle;
        } else {
            bad = middle;
        }
    }
    Some(good.exp())
}
