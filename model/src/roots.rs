//! A bracketed root finder for the one-dimensional equations of the model: Brent's method
//! (inverse quadratic interpolation and secant steps, guarded by bisection). It never leaves
//! its bracket, is bounded in iterations, and reports failure instead of a wrong number.

use super::ModelError;

/// Iterations allowed; Brent's method needs at most about (log₂ of the bracket / tolerance)²
/// and in practice a dozen.
const MAX_ITERATIONS: u32 = 200;

/// A root and the iterations it took.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Root {
    pub x: f64,
    pub iterations: u32,
}

/// The root of `f` in [a, b], given f(a) and f(b) of opposite signs (or one of them zero).
/// Converges when the bracket is narrower than `x_tolerance` (absolute) or f is exactly 0.
/// `what` names the equation in the error if the bracket is invalid or iterations run out.
pub fn brent(
    mut f: impl FnMut(f64) -> f64,
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    x_tolerance: f64,
    what: &'static str,
) -> Result<Root, ModelError> {
    if fa == 0.0 {
        return Ok(Root {
            x: a,
            iterations: 0,
        });
    }
    if fb == 0.0 {
        return Ok(Root {
            x: b,
            iterations: 0,
        });
    }
    if !(fa.is_finite() && fb.is_finite()) || fa.signum() == fb.signum() {
        return Err(ModelError::NoConvergence {
            what,
            iterations: 0,
        });
    }
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for iterations in 1..=MAX_ITERATIONS {
        if fb.signum() == fc.signum() {
            (c, fc) = (a, fa);
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            (a, fa) = (b, fb);
            (b, fb) = (c, fc);
            (c, fc) = (a, fa);
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 0.5 * x_tolerance;
        let m = 0.5 * (c - b);
        if m.abs() <= tol || fb == 0.0 {
            return Ok(Root { x: b, iterations });
        }
        (d, e) = next_step((a, fa), (b, fb), (c, fc), (m, tol), (d, e));
        (a, fa) = (b, fb);
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        fb = f(b);
        if !fb.is_finite() {
            break;
        }
    }
    Err(ModelError::NoConvergence {
        what,
        iterations: MAX_ITERATIONS,
    })
}

/// Brent's next step from b, and the step before it, as (d, e): inverse quadratic
/// interpolation through a, b and c (a secant when a = c) while the steps shrink fast enough
/// and it lands well inside the bracket, else bisection by m, half the bracket; `tol` is the
/// smallest step that counts. Apart from [`brent`] so the bracket's bookkeeping reads alone.
fn next_step(
    (a, fa): (f64, f64),
    (b, fb): (f64, f64),
    (c, fc): (f64, f64),
    (m, tol): (f64, f64),
    (d, e): (f64, f64),
) -> (f64, f64) {
    if e.abs() >= tol && fa.abs() > fb.abs() {
        // Inverse quadratic interpolation, or secant when only two points differ.
        let s = fb / fa;
        let (mut p, mut q) = if a == c {
            (2.0 * m * s, 1.0 - s)
        } else {
            let q = fa / fc;
            let r = fb / fc;
            (
                s * (2.0 * m * q * (q - r) - (b - a) * (r - 1.0)),
                (q - 1.0) * (r - 1.0) * (s - 1.0),
            )
        };
        if p > 0.0 {
            q = -q;
        } else {
            p = -p;
        }
        if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
            (p / q, d)
        } else {
            (m, m)
        }
    } else {
        (m, m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_roots_to_the_tolerance_within_the_bracket() {
        let f = |x: f64| x.powi(3) - 2.0;
        let root = brent(f, (0.0, f(0.0)), (2.0, f(2.0)), 1e-15, "cube root").unwrap();
        assert!((root.x - 2f64.cbrt()).abs() < 1e-14);
        assert!(root.iterations < 20);
        // A function that is flat over most of the bracket.
        let g = |x: f64| (x - 1e-3).signum() * (x - 1e-3).abs().powf(0.1);
        let root = brent(g, (0.0, g(0.0)), (10.0, g(10.0)), 1e-14, "flat").unwrap();
        assert!((root.x - 1e-3).abs() < 1e-13);
    }

    #[test]
    fn refuses_a_bracket_without_a_sign_change() {
        let f = |x: f64| x * x + 1.0;
        assert!(brent(f, (-1.0, f(-1.0)), (1.0, f(1.0)), 1e-12, "no root").is_err());
    }
}
