//! Bounded Levenberg–Marquardt: minimises the sum of squared residuals r(x) over a box
//! lo ≤ x ≤ hi. Each step solves (JᵀJ + λ diag JᵀJ) δ = −Jᵀr over the coordinates not held
//! at a bound by the gradient, and clips the trial to the box. λ falls after a step that
//! lowers the cost and rises after one that does not (Marquardt, 1963; Nocedal & Wright,
//! *Numerical Optimization*, §10.3).

use nalgebra::{DMatrix, DVector};

/// Residuals at a point, and their Jacobian if asked for.
pub struct Evaluation {
    pub residuals: DVector<f64>,
    pub jacobian: DMatrix<f64>,
}

/// A least-squares problem.
pub trait LeastSquares {
    /// Why an evaluation stops the minimisation (a cancelled job, a failed solve).
    type Error;

    /// The residuals at `x` and their Jacobian; `Ok(None)` if `x` is outside the model's
    /// domain (the step to it is refused, as one that raises the cost).
    fn evaluate(&mut self, x: &DVector<f64>) -> Result<Option<Evaluation>, Self::Error>;
}

/// Where a minimisation stopped.
pub struct Minimum {
    pub x: DVector<f64>,
    pub residuals: DVector<f64>,
    pub jacobian: DMatrix<f64>,
    /// Σ r².
    pub cost: f64,
    /// Steps taken (accepted or not).
    pub steps: usize,
    /// Whether it stopped by its tolerances rather than its step limit.
    pub converged: bool,
}

/// Steps at most.
const MAX_STEPS: usize = 200;
/// A step shorter than this (in x, relative) ends the minimisation.
const TOLERANCE: f64 = 1e-10;
/// So does a step that changes the cost by less than this, relative: the model's values are
/// good to ≈ 1e-12, so the cost's rounding is about that.
const COST_TOLERANCE: f64 = 1e-12;

/// Minimises from `start` (clipped to the box); `Ok(None)` if the start is outside the
/// model's domain.
pub fn minimize<P: LeastSquares>(
    problem: &mut P,
    start: &DVector<f64>,
    lower: &DVector<f64>,
    upper: &DVector<f64>,
) -> Result<Option<Minimum>, P::Error> {
    let clip = |x: DVector<f64>| x.zip_zip_map(lower, upper, |x, lo, hi| x.clamp(lo, hi));
    let mut x = clip(start.clone());
    let Some(mut at) = problem.evaluate(&x)? else {
        return Ok(None);
    };
    let mut cost = at.residuals.norm_squared();
    let mut lambda = 1e-3;
    let mut steps = 0;
    let done = |x, at: Evaluation, cost, steps, converged| Minimum {
        x,
        residuals: at.residuals,
        jacobian: at.jacobian,
        cost,
        steps,
        converged,
    };
    while steps < MAX_STEPS {
        let gradient = at.jacobian.tr_mul(&at.residuals);
        let normal = at.jacobian.tr_mul(&at.jacobian);
        // Coordinates at a bound that the descent direction would cross stay there.
        let free: Vec<usize> = (0..x.len())
            .filter(|&i| {
                let held = (x[i] <= lower[i] && gradient[i] > 0.0)
                    || (x[i] >= upper[i] && gradient[i] < 0.0);
                !held
            })
            .collect();
        if free.is_empty() || cost == 0.0 {
            return Ok(Some(done(x, at, cost, steps, true)));
        }
        let scale = normal.diagonal().max().max(f64::MIN_POSITIVE);
        loop {
            steps += 1;
            let step = damped_step(&normal, &gradient, &free, lambda, scale);
            let trial = clip(&x + step);
            if (&trial - &x).norm() <= TOLERANCE * (1.0 + x.norm()) {
                return Ok(Some(done(x, at, cost, steps, true)));
            }
            match problem.evaluate(&trial)? {
                Some(next) if next.residuals.norm_squared() < cost => {
                    let fall = cost - next.residuals.norm_squared();
                    cost -= fall;
                    x = trial;
                    at = next;
                    lambda = (lambda / 10.0).max(1e-12);
                    if fall <= COST_TOLERANCE * cost {
                        return Ok(Some(done(x, at, cost, steps, true)));
                    }
                    break;
                }
                // A step that changes the cost by no more than its rounding: at the minimum.
                Some(next) if next.residuals.norm_squared() - cost <= COST_TOLERANCE * cost => {
                    return Ok(Some(done(x, at, cost, steps, true)));
                }
                _ => lambda *= 10.0,
            }
            if lambda > 1e16 {
                // No step along the gradient lowers the cost: a minimum to rounding.
                return Ok(Some(done(x, at, cost, steps, true)));
            }
            if steps >= MAX_STEPS {
                return Ok(Some(done(x, at, cost, steps, false)));
            }
        }
    }
    Ok(Some(done(x, at, cost, steps, false)))
}

/// The step over the `free` coordinates (the others 0) for damping `lambda`; the damping
/// uses diag JᵀJ, floored at 1e-12 of its largest entry `scale` so that a parameter without
/// effect cannot make the system singular.
fn damped_step(
    normal: &DMatrix<f64>,
    gradient: &DVector<f64>,
    free: &[usize],
    lambda: f64,
    scale: f64,
) -> DVector<f64> {
    let m = free.len();
    let mut a = DMatrix::from_fn(m, m, |i, j| normal[(free[i], free[j])]);
    for i in 0..m {
        a[(i, i)] += lambda * a[(i, i)].max(1e-12 * scale);
    }
    let b = DVector::from_fn(m, |i, _| -gradient[free[i]]);
    let reduced = match a.clone().cholesky() {
        Some(c) => c.solve(&b),
        None => a
            .svd(true, true)
            .solve(&b, 0.0)
            .unwrap_or_else(|_| DVector::zeros(m)),
    };
    let mut step = DVector::zeros(gradient.len());
    for (i, &k) in free.iter().enumerate() {
        step[k] = reduced[i];
    }
    step
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rosenbrock's valley as residuals (10(y − x²), 1 − x): minimum 0 at (1, 1).
    struct Rosenbrock;

    impl LeastSquares for Rosenbrock {
        type Error = ();
        fn evaluate(&mut self, x: &DVector<f64>) -> Result<Option<Evaluation>, ()> {
            Ok(Some(Evaluation {
                residuals: DVector::from_vec(vec![10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0]]),
                jacobian: DMatrix::from_row_slice(2, 2, &[-20.0 * x[0], 10.0, -1.0, 0.0]),
            }))
        }
    }

    #[test]
    fn it_finds_the_minimum_of_a_curved_valley() {
        let (lo, hi) = (
            DVector::from_element(2, -5.0),
            DVector::from_element(2, 5.0),
        );
        let start = DVector::from_vec(vec![-1.2, 1.0]);
        let m = minimize(&mut Rosenbrock, &start, &lo, &hi)
            .unwrap()
            .unwrap();
        assert!(m.converged);
        assert!(
            (m.x[0] - 1.0).abs() < 1e-9 && (m.x[1] - 1.0).abs() < 1e-9,
            "{}",
            m.x
        );
    }

    #[test]
    fn a_bound_holds_and_the_minimum_on_it_is_found() {
        // With x ≤ 0.5 the minimum is on the bound, at y = x² = 0.25.
        let lo = DVector::from_element(2, -5.0);
        let hi = DVector::from_vec(vec![0.5, 5.0]);
        let start = DVector::from_vec(vec![-1.2, 1.0]);
        let m = minimize(&mut Rosenbrock, &start, &lo, &hi)
            .unwrap()
            .unwrap();
        assert_eq!(m.x[0], 0.5);
        assert!((m.x[1] - 0.25).abs() < 1e-9, "{}", m.x);
    }
}
