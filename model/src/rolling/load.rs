//! The load equation P(δ) = P in units of r₀ (P̂(r̂) = π/4): a guarded secant in t = ln r̂
//! over strip sums, nested from coarse rules to fine so the fine rule needs few passes.

use std::f64::consts::FRAC_PI_4;
use std::sync::Arc;

use super::section::{Integrals, RootGuide, Section};
use crate::quadrature::{Spacing, StripRule};
use crate::spectrum::Terms;
use crate::{ModelError, Quadrature};

/// Iterations allowed for the penetration root P(δ) = P.
const MAX_LOAD_ITERATIONS: u32 = 60;
/// The load equation is solved to this relative residual: δ then carries an error of a
/// quarter of it, far below the 1e-9 of the quadrature.
const LOAD_TOLERANCE: f64 = 1e-14;
/// A residual still accepted when the bracket has shrunk to rounding: the sum over many
/// strips is only that exact.
const LOAD_ROUNDING: f64 = 1e-12;
/// d ln P̂/d ln r̂ at both elastic limits (P ∝ δ² ∝ r̂⁴), the first guess of the load
/// equation's slope.
pub(super) const ELASTIC_SLOPE: f64 = 4.0;

/// The contact in units of r₀ with its load solved: P̂(r̂) = π/4.
pub(super) struct Shape {
    pub(super) rule: Arc<StripRule>,
    /// r̂ = √(2Rδ)/r₀ = √(δ/δ₀).
    pub(super) half_width: f64,
    pub(super) integrals: Integrals,
    /// Exit root ρ of each strip of the rule.
    pub(super) exit_roots: Vec<f64>,
    pub(super) load_residual: f64,
    pub(super) iterations: u32,
    /// The secant's last estimate of d ln P̂/dt.
    slope: f64,
}

/// Where a load-root search starts: t = ln r̂, the slope of ln P̂ in t assumed for the first
/// step, and a guess of each strip's exit root (NaN: none).
struct Start {
    t: f64,
    slope: f64,
    roots: Vec<f64>,
}

impl Start {
    /// From the static answer t = 0 (exact at V = 0), with the slope of both elastic limits.
    fn cold(strips: usize) -> Start {
        Start {
            t: 0.0,
            slope: ELASTIC_SLOPE,
            roots: vec![f64::NAN; strips],
        }
    }
}

impl Shape {
    /// The shape under `quadrature` and, if its companion rule is the coarser one, under
    /// that too. The load root is found on the companion first (recursively, down to
    /// [`NESTED_FROM`] strips): its root, secant slope and exit roots start the finer rule
    /// within the coarse rule's quadrature error of its root, so the finer rule, which costs
    /// twice as much per pass, needs one or two passes instead of five. The iterations
    /// reported count every rule's.
    pub(super) fn nested(
        viscosity: &Terms,
        quadrature: Quadrature,
    ) -> Result<(Shape, Option<Shape>), ModelError> {
        /// Rules of fewer strips start cold.
        const NESTED_FROM: usize = 16;
        let rule = StripRule::shared(quadrature, Spacing::for_speed(viscosity.shortest()))?;
        let companion = quadrature.companion();
        // An elastic contact (at rest, or no viscosity) has its root at t = 0, found in one
        // pass: nothing to start.
        let elastic = viscosity.is_empty();
        if elastic || companion.size() >= rule.len() || rule.len() < NESTED_FROM {
            let cold = Start::cold(rule.len());
            return Ok((Shape::solve(viscosity, rule, cold)?, None));
        }
        let (coarse, _) = Shape::nested(viscosity, companion)?;
        let section = coarse.section(viscosity);
        let start = Start {
            t: coarse.half_width.ln(),
            slope: coarse.slope,
            roots: RootGuide::new(&section, &coarse.rule, &coarse.exit_roots)
                .guesses(&section, &rule),
        };
        let mut fine = Shape::solve(viscosity, rule, start)?;
        fine.iterations += coarse.iterations;
        fine.integrals.exit_root_iterations += coarse.integrals.exit_root_iterations;
        Ok((fine, Some(coarse)))
    }

    /// Solves ln P̂(e^t) = ln(π/4) for t = ln r̂ ([`load_root`]) from `start`; the exit roots
    /// of every strip are warm-started from the previous step.
    fn solve(viscosity: &Terms, rule: Arc<StripRule>, start: Start) -> Result<Shape, ModelError> {
        let target = FRAC_PI_4.ln();
        let mut rho = start.roots;
        let mut exit_root_iterations = 0;
        // The step and roots of the evaluation before the last, for extrapolating each
        // strip's root to the next step; the step of the last evaluation.
        let mut before: Option<(f64, Vec<f64>)> = None;
        let mut last: Option<f64> = None;
        let what = "penetration (load equation P(δ) = P)";
        let bracket = log_bracket(1.0 + viscosity.strength());
        let root = load_root(bracket, start.t, None, start.slope, what, |t| {
            let roots = last.map(|t1| (t1, rho.clone()));
            if let (Some(t1), Some((t0, rho0))) = (last, &before) {
                // Each root is a smooth function of t: linear extrapolation from the last
                // two steps lands within the secant's own (shrinking) error of the new root.
                let ratio = (t - t1) / (t1 - t0);
                for (r, r0) in rho.iter_mut().zip(rho0) {
                    *r += (*r - r0) * ratio;
                }
            }
            (before, last) = (roots, Some(t));
            let integrals = Section::new(t.exp(), *viscosity).integrate(&rule, Some(&mut rho))?;
            exit_root_iterations += integrals.exit_root_iterations;
            Ok((integrals.load.ln() - target, integrals))
        })?;
        let mut integrals = root.at;
        integrals.exit_root_iterations = exit_root_iterations;
        Ok(Shape {
            rule,
            half_width: root.t.exp(),
            integrals,
            exit_roots: rho,
            load_residual: root.value.exp_m1().abs(),
            iterations: root.iterations,
            slope: root.slope,
        })
    }

    /// The contact region at the solved half-width.
    pub(super) fn section(&self, viscosity: &Terms) -> Section {
        Section::new(self.half_width, *viscosity)
    }
}

/// The root of a load equation and what was computed there.
pub(super) struct LoadRoot<T> {
    pub(super) t: f64,
    pub(super) at: T,
    /// The equation's value at the root.
    pub(super) value: f64,
    pub(super) iterations: u32,
    /// The last slope estimate (the assumed one if the start was the root).
    slope: f64,
}

/// The bracket δ ∈ [0.9 δ_∞, 1.05 δ₀] of docs/model.md §3, in t = ln r̂ (r̂ = √(δ/δ₀)),
/// for a layer whose instantaneous modulus is `stiffening` times its relaxed one.
pub(super) fn log_bracket(stiffening: f64) -> (f64, f64) {
    (
        0.5 * 0.9_f64.ln() - 0.25 * stiffening.ln(),
        0.5 * 1.05_f64.ln(),
    )
}

/// Solves a load equation `f` (returning f(t) and what it computed at t; f is a relative
/// residual of the load, increasing in t) by the secant method from `start` (and from a
/// point `known` = (t, f(t)) already computed, if any), guarded by `bracket`.
/// The equations in use are ln P̂/(π/4) in t = ln r̂, nearly linear with slope 4 at both
/// elastic limits ([`ELASTIC_SLOPE`]), so the secant converges in a handful of steps;
/// without a known point its first step assumes the slope `slope`.
pub(super) fn load_root<T>(
    bracket: (f64, f64),
    start: f64,
    known: Option<(f64, f64)>,
    slope: f64,
    what: &'static str,
    mut f: impl FnMut(f64) -> Result<(f64, T), ModelError>,
) -> Result<LoadRoot<T>, ModelError> {
    let (mut lo, mut hi) = bracket;
    let (mut t_prev, mut f_prev) = known.unwrap_or((f64::NAN, f64::NAN));
    let mut t = start.clamp(lo, hi);
    let (assumed, mut slope) = (slope, slope);
    let mut iterations = 0;
    loop {
        iterations += 1;
        let (value, at) = f(t)?;
        if value > 0.0 {
            hi = hi.min(t);
        } else {
            lo = lo.max(t);
        }
        let collapsed = hi - lo <= 4.0 * f64::EPSILON * t.abs().max(1.0);
        if value.abs() <= LOAD_TOLERANCE || collapsed && value.abs() <= LOAD_ROUNDING {
            return Ok(LoadRoot {
                t,
                at,
                value,
                iterations,
                slope,
            });
        }
        slope = if f_prev.is_nan() || value == f_prev || t == t_prev {
            assumed
        } else {
            (value - f_prev) / (t - t_prev)
        };
        let mut next = t - value / slope;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if collapsed || iterations >= MAX_LOAD_ITERATIONS {
            // Out of iterations, or the bracket collapsed onto a point that does not
            // carry the load.
            return Err(ModelError::NoConvergence { what, iterations });
        }
        (t_prev, f_prev, t) = (t, value, next);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nested solve is only a faster path to the same root: it must agree with the fine
    /// rule solved alone, and be cheaper in exit-root Newton steps, across the range of ξ.
    #[test]
    fn nested_solves_agree_with_the_fine_rule_alone_in_fewer_exit_root_steps() {
        let quadrature = Quadrature::default();
        for kappa in [0.5, 4.0, 100.0] {
            for xi in [1e-5, 1e-3, 0.07, 0.5, 3.0, 100.0] {
                let viscosity = Terms::one(kappa, xi);
                let rule = StripRule::shared(quadrature, Spacing::for_speed(xi)).unwrap();
                let cold = Shape::solve(&viscosity, rule.clone(), Start::cold(rule.len())).unwrap();
                let (nested, coarse) = Shape::nested(&viscosity, quadrature).unwrap();
                let coarse = coarse.expect("the default rule's companion is coarser");
                assert!(coarse.rule.len() < rule.len());
                let relative = (nested.half_width / cold.half_width - 1.0).abs();
                assert!(relative < 1e-14, "ξ = {xi}, κ = {kappa}: {relative:e}");
                for (a, b) in nested.exit_roots.iter().zip(&cold.exit_roots) {
                    assert!((a - b).abs() <= 1e-12 * b.abs().max(1e-300), "{a} vs {b}");
                }
                assert!(
                    nested.integrals.exit_root_iterations < cold.integrals.exit_root_iterations,
                    "ξ = {xi}, κ = {kappa}: {} vs {}",
                    nested.integrals.exit_root_iterations,
                    cold.integrals.exit_root_iterations
                );
            }
        }
    }
}
