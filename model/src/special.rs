//! Cancellation-free exponential kernels of the strip solution (docs/model.md §3).
//!
//! The exit-edge equation and the pressure of a strip contain differences such as
//! `(sβ + 1) − (β + 1)e^{β(s−1)}` that cancel catastrophically for fast strips (β → 0),
//! which always occur near the lateral tips |y| → √(2Rδ). Writing them through the
//! "relative exponentials" below keeps every digit for every β.

/// Below this |z| the kernels are summed as power series instead of through `expm1`.
/// At the limit the direct formulas lose at most a factor 30 (E₃) to cancellation, so the
/// series are kept longer for E₃ (`EXPREL3_LIMIT`), which only fast strips evaluate.
const SERIES_LIMIT: f64 = 0.5;
const EXPREL3_LIMIT: f64 = 2.0;
/// Beyond this |z| the quotients are divided by z twice rather than by z², which would
/// overflow near |z| = 1e154 (a strip about 1e150 times slower than its relaxation length:
/// V a hundred orders of magnitude below the contact's own scale, still a valid input).
const HUGE: f64 = 1e100;
/// Terms of the series; the remainder is below 2²⁶/28! ≈ 2e-22 of the leading term.
const SERIES_TERMS: usize = 26;

/// 1/(n + m)! for n < SERIES_TERMS, m = 2, 3: the series coefficients, built at compile time.
const fn inverse_factorials<const M: usize>() -> [f64; SERIES_TERMS] {
    let mut c = [0.0; SERIES_TERMS];
    let mut factorial = 1.0;
    let mut k = 1;
    while k <= M {
        factorial *= k as f64;
        k += 1;
    }
    let mut n = 0;
    while n < SERIES_TERMS {
        c[n] = 1.0 / factorial;
        factorial *= (n + M + 1) as f64;
        n += 1;
    }
    c
}

/// Σ zⁿ/(n+2)!.
const EXPREL2: [f64; SERIES_TERMS] = inverse_factorials::<2>();
/// Σ zⁿ/(n+3)!.
const EXPREL3: [f64; SERIES_TERMS] = inverse_factorials::<3>();
/// Σ (n+1) zⁿ/(n+2)!.
const EXPREL_PRIME: [f64; SERIES_TERMS] = {
    let mut c = EXPREL2;
    let mut n = 0;
    while n < SERIES_TERMS {
        c[n] *= (n + 1) as f64;
        n += 1;
    }
    c
};

/// Σ zⁿ/((n+3)!(n+m)): ∫₀¹ s^{m−1} E₃(zs) ds, for m = 4, 5.
const fn exprel3_moment_coefficients(m: usize) -> [f64; SERIES_TERMS] {
    let mut c = EXPREL3;
    let mut n = 0;
    while n < SERIES_TERMS {
        c[n] /= (n + m) as f64;
        n += 1;
    }
    c
}
const EXPREL3_MOMENT_3: [f64; SERIES_TERMS] = exprel3_moment_coefficients(4);
const EXPREL3_MOMENT_4: [f64; SERIES_TERMS] = exprel3_moment_coefficients(5);

/// Σ cₙ zⁿ over the first `terms` coefficients, as E(z²) + z·O(z²) with the even and odd
/// coefficients each summed by Horner's rule: two independent chains of multiply-adds
/// instead of one, which halves the latency (the exit-root Newton steps wait on it).
///
/// `#[inline]`, like the kernels below: inlined at each call, `terms` is a constant and the
/// loops unroll. Left to the compiler, whether that happens depended on how the crate fell
/// into codegen units: changes to other modules (issue 20) once left `series` out of line,
/// a call per kernel with rolled loops, and fast-rolling solves 25 % slower.
#[inline]
fn series(z: f64, coefficients: &[f64; SERIES_TERMS], terms: usize) -> f64 {
    let z2 = z * z;
    let horner = |start: usize| {
        coefficients[..terms]
            .iter()
            .skip(start)
            .step_by(2)
            .rev()
            .fold(0.0, |acc, c| acc * z2 + c)
    };
    horner(0) + z * horner(1)
}

/// Terms enough for |z| < [`SERIES_LIMIT`]: 0.5¹⁶/18! ≈ 2e-21.
const SHORT_SERIES: usize = 16;

/// `(e^z − 1 − z)/z²` = Σ zⁿ/(n+2)!, continuous at `z = 0` where it equals ½.
#[inline]
pub fn exprel2(z: f64) -> f64 {
    if z.abs() < SERIES_LIMIT {
        series(z, &EXPREL2, SHORT_SERIES)
    } else if z.abs() > HUGE {
        (z.exp_m1() / z - 1.0) / z
    } else {
        (z.exp_m1() - z) / (z * z)
    }
}

/// `(e^z − 1 − z − z²/2)/z³` = Σ zⁿ/(n+3)!, continuous at `z = 0` where it equals 1/6.
#[inline]
pub fn exprel3(z: f64) -> f64 {
    // Terms enough for the remainder |z|ⁿ/(n+3)! to stay below 1e-16 of 1/6 on each range
    // (0.5¹⁴/17! ≈ 2e-19, 1/21! ≈ 2e-20, 2²²/25! ≈ 3e-19): fast strips evaluate it at every
    // step of their exit roots and in their shortfalls, mostly at small |z|.
    let a = z.abs();
    if a < EXPREL3_LIMIT {
        let terms = if a < SERIES_LIMIT {
            14
        } else if a < 1.0 {
            18
        } else {
            22
        };
        series(z, &EXPREL3, terms)
    } else {
        (z.exp_m1() - z - 0.5 * z * z) / (z * z * z)
    }
}

/// The moments ∫₀¹ s³ E₃(zs) ds and ∫₀¹ s⁴ E₃(zs) ds of [`exprel3`], for |z| ≤ 2: what a
/// fast strip's moment integrates (its viscous correction is a cubic times E₃ along the
/// strip), as two series, where 16-point quadrature summed E₃ at 16 points.
/// Terms as [`exprel3`] takes them, so the remainders are below 1e-19 of the leading terms.
#[inline]
pub fn exprel3_moments(z: f64) -> [f64; 2] {
    debug_assert!(
        z.abs() <= EXPREL3_LIMIT,
        "z = {z} is beyond the series' range"
    );
    let a = z.abs();
    let terms = if a < SERIES_LIMIT {
        14
    } else if a < 1.0 {
        18
    } else {
        22
    };
    [
        series(z, &EXPREL3_MOMENT_3, terms),
        series(z, &EXPREL3_MOMENT_4, terms),
    ]
}

/// The three kernels a Newton step on the exit edge needs, sharing one exponential:
/// (`exprel` = (e^z − 1)/z, [`exprel2`], d/dz exprel = `(e^z (z − 1) + 1)/z²` = Σ (n+1) zⁿ/(n+2)!,
/// which is positive for every z).
#[inline]
pub fn exprel_kernels(z: f64) -> (f64, f64, f64) {
    if z.abs() < SERIES_LIMIT {
        let e2 = series(z, &EXPREL2, SHORT_SERIES);
        let prime = series(z, &EXPREL_PRIME, SHORT_SERIES);
        (1.0 + z * e2, e2, prime)
    } else if z.abs() > HUGE {
        let em1 = z.exp_m1();
        let e1 = em1 / z;
        (
            e1,
            (e1 - 1.0) / z,
            ((em1 + 1.0) * (z - 1.0) / z + 1.0 / z) / z,
        )
    } else {
        // One division instead of three: the Newton step waits on this.
        let em1 = z.exp_m1();
        let w = 1.0 / z;
        let w2 = w * w;
        (
            em1 * w,
            (em1 - z) * w2,
            ((em1 + 1.0) * (z - 1.0) + 1.0) * w2,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference values from the definitions evaluated where they do not cancel.
    #[test]
    fn kernels_match_their_definitions_on_both_sides_of_the_series_limit() {
        for z in [
            -30.0_f64, -5.0, -2.0000001, -1.9999999, -0.7, -0.5000001, -0.4999999, 0.3,
        ] {
            let direct1 = z.exp_m1() / z;
            let direct2 = (z.exp_m1() - z) / (z * z);
            let direct3 = (z.exp_m1() - z - 0.5 * z * z) / (z * z * z);
            let direct_prime = (z.exp() * (z - 1.0) + 1.0) / (z * z);
            let (e1, e2, prime) = exprel_kernels(z);
            assert!((e1 / direct1 - 1.0).abs() < 1e-14, "exprel({z})");
            assert!((e2 / direct2 - 1.0).abs() < 1e-13, "exprel2({z})");
            assert!((exprel2(z) / direct2 - 1.0).abs() < 1e-13, "exprel2({z})");
            assert!((exprel3(z) / direct3 - 1.0).abs() < 1e-12, "exprel3({z})");
            assert!((prime / direct_prime - 1.0).abs() < 1e-13, "exprel'({z})");
        }
    }

    #[test]
    fn kernels_stay_finite_and_right_where_z_squared_overflows() {
        // For z → −∞: exprel → −1/z, exprel2 → −1/z − 1/z², exprel' → 1/z² (here 0).
        for z in [-1e120_f64, -1e200, -f64::MAX] {
            let (e1, e2, prime) = exprel_kernels(z);
            assert!((e1 * -z - 1.0).abs() < 1e-15, "exprel({z})");
            assert!((e2 * -z - 1.0).abs() < 1e-15, "exprel2({z})");
            assert!((exprel2(z) * -z - 1.0).abs() < 1e-15, "exprel2({z})");
            assert!((0.0..=1e-239).contains(&prime), "exprel'({z}) = {prime}");
        }
    }

    #[test]
    fn kernels_take_their_limits_at_zero() {
        assert_eq!(exprel_kernels(0.0), (1.0, 0.5, 0.5));
        assert_eq!(exprel2(0.0), 0.5);
        assert!((exprel3(0.0) - 1.0 / 6.0).abs() < 1e-17);
        // First-order terms: exprel2 ≈ ½ + z/6, exprel' ≈ ½ + z/3, exprel3 ≈ 1/6 + z/24.
        let z = 1e-6;
        let (_, e2, prime) = exprel_kernels(z);
        assert!((e2 - (0.5 + z / 6.0)).abs() < 1e-13);
        assert!((prime - (0.5 + z / 3.0)).abs() < 1e-12);
        assert!((exprel3(z) - (1.0 / 6.0 + z / 24.0)).abs() < 1e-13);
    }

    #[test]
    fn the_derivative_kernel_is_the_derivative_of_exprel() {
        for z in [-40.0_f64, -3.0, -0.5, -1e-3] {
            let h = 1e-5 * z.abs().max(1.0);
            let numeric = (z + h).exp_m1() / (z + h) - (z - h).exp_m1() / (z - h);
            let numeric = numeric / (2.0 * h);
            assert!(
                (numeric / exprel_kernels(z).2 - 1.0).abs() < 1e-7,
                "z = {z}"
            );
        }
    }
}
