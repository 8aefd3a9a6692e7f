//! What a least-squares minimum says about its parameters: the covariance from the
//! Jacobian's singular value decomposition, scaled by χ²/dof when the data carry no
//! uncertainties (then intervals use Student's t on dof degrees of freedom), correlations,
//! and the directions of parameter space the data leave undetermined.

use nalgebra::{DMatrix, DVector};

/// A singular value below this fraction of the largest is a direction the data do not
/// determine: the model's finite differences are good to ≈ 1e-7, so a true null direction
/// shows ≈ 1e-7 of the largest and a weak but real one far more.
const NULL: f64 = 1e-5;
/// A parameter whose Jacobian column is below this fraction of the largest has no effect.
const NO_EFFECT: f64 = 1e-9;
/// A parameter with a component above this in a (unit) null direction is not determined
/// alone.
const INVOLVED: f64 = 1e-3;
/// The largest half-width of an interval in ln value: e^300 is near the end of double
/// precision, so a parameter known less well than that is not determined either.
const MAX_LN_HALF_WIDTH: f64 = 300.0;

/// The uncertainty of the parameters at a minimum (in the coordinates of the Jacobian).
#[derive(Clone, Debug, PartialEq)]
pub struct Analysis {
    /// Standard errors; `None` for a parameter the data do not determine alone, or so weakly
    /// that its interval would overflow.
    pub standard_errors: Vec<Option<f64>>,
    /// Correlations of the determined part (1 on the diagonal).
    pub correlation: DMatrix<f64>,
    /// Unit directions along which the residuals do not change, largest component positive.
    pub null_directions: Vec<DVector<f64>>,
    /// Parameters with no effect on any residual.
    pub no_effect: Vec<usize>,
    /// The half-width of a 95 % interval, in standard errors.
    pub coverage_factor: f64,
}

/// Analyses the minimum with Jacobian `jacobian` (of residuals weighted by their standard
/// uncertainties), `chi_squared` and `dof` degrees of freedom; `scaled`: the data had no
/// uncertainties, so the weights are 1 and the scatter of the residuals sets the scale.
pub fn analyse(jacobian: &DMatrix<f64>, chi_squared: f64, dof: usize, scaled: bool) -> Analysis {
    let m = jacobian.ncols();
    let columns: Vec<f64> = jacobian.column_iter().map(|c| c.norm()).collect();
    let largest = columns.iter().copied().fold(0.0, f64::max);
    let no_effect = (0..m)
        .filter(|&j| columns[j] <= NO_EFFECT * largest || largest == 0.0)
        .collect();
    let svd = jacobian.clone().svd(false, true);
    let v_t = svd.v_t.expect("asked for V");
    let top = svd.singular_values.max();
    let mut covariance = DMatrix::zeros(m, m);
    let mut null_directions = Vec::new();
    for (k, &sigma) in svd.singular_values.iter().enumerate() {
        let v = v_t.row(k).transpose();
        if sigma <= NULL * top || top == 0.0 {
            let sign = if v.max() >= -v.min() { 1.0 } else { -1.0 };
            null_directions.push(v * sign);
        } else {
            covariance += &v * v.transpose() / (sigma * sigma);
        }
    }
    // Fewer residuals than parameters leave directions the SVD does not list.
    if jacobian.nrows() < m {
        null_directions.extend(missing_directions(&v_t, m));
    }
    let scale = if scaled && dof > 0 {
        chi_squared / dof as f64
    } else {
        1.0
    };
    covariance *= scale;
    let coverage_factor = if scaled {
        t_quantile_975(dof.max(1))
    } else {
        Z_975
    };
    let in_null_space = |j: usize| null_directions.iter().any(|v| involved(v).contains(&j));
    let standard_errors = (0..m)
        .map(|j| {
            let se = covariance[(j, j)].max(0.0).sqrt();
            (!in_null_space(j) && coverage_factor * se < MAX_LN_HALF_WIDTH).then_some(se)
        })
        .collect();
    let correlation = DMatrix::from_fn(m, m, |i, j| {
        let d = (covariance[(i, i)] * covariance[(j, j)]).sqrt();
        if i == j {
            1.0
        } else if d > 0.0 {
            (covariance[(i, j)] / d).clamp(-1.0, 1.0)
        } else {
            0.0
        }
    });
    Analysis {
        standard_errors,
        correlation,
        null_directions,
        no_effect,
        coverage_factor,
    }
}

/// The parameters a null direction moves (the indices of its components above [`INVOLVED`]).
pub fn involved(direction: &DVector<f64>) -> Vec<usize> {
    (0..direction.len())
        .filter(|&j| direction[j].abs() > INVOLVED)
        .collect()
}

/// The directions orthogonal to the rows of `v_t` (a thin SVD of a wide matrix).
fn missing_directions(v_t: &DMatrix<f64>, m: usize) -> Vec<DVector<f64>> {
    let mut basis: Vec<DVector<f64>> = v_t.row_iter().map(|r| r.transpose()).collect();
    let mut missing = Vec::new();
    for j in 0..m {
        let mut e = DVector::zeros(m);
        e[j] = 1.0;
        for b in &basis {
            e -= b * b.dot(&e);
        }
        if e.norm() > 1e-6 {
            let e = e.normalize();
            basis.push(e.clone());
            missing.push(e);
        }
    }
    missing
}

/// The 97.5 % quantile of the standard normal distribution.
const Z_975: f64 = 1.959_963_984_540_054;

/// The 97.5 % quantile of Student's t with `dof` degrees of freedom, by bisection of its
/// distribution function (exact finite series for integer dof, Abramowitz & Stegun
/// 26.7.3–4); the normal quantile beyond 10,000.
pub fn t_quantile_975(dof: usize) -> f64 {
    if dof > 10_000 {
        return Z_975;
    }
    let (mut lo, mut hi) = (Z_975, 13.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if central_probability(mid, dof) < 0.95 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// P(|T| ≤ t) for Student's t with `dof` degrees of freedom (A&S 26.7.3–4).
fn central_probability(t: f64, dof: usize) -> f64 {
    let theta = (t / (dof as f64).sqrt()).atan();
    let (s, c2) = (theta.sin(), theta.cos().powi(2));
    // Σ of the terms ∏ (k − 1)/k · cos² θ, over k = 2, 4, ... (even) or 3, 5, ... (odd).
    let series = |first: usize| {
        let (mut term, mut sum, mut k) = (1.0, 1.0, first);
        while k + 2 <= dof {
            term *= (k - 1) as f64 / k as f64 * c2;
            sum += term;
            k += 2;
        }
        sum
    };
    if dof % 2 == 0 {
        s * series(2)
    } else if dof == 1 {
        2.0 * theta / std::f64::consts::PI
    } else {
        2.0 / std::f64::consts::PI * (theta + s * theta.cos() * series(3))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_quantiles_match_the_tables() {
        // Abramowitz & Stegun, Table 26.10 (two-sided 5 %).
        for (dof, t) in [
            (1, 12.706_204_736),
            (2, 4.302_652_730),
            (3, 3.182_446_305),
            (5, 2.570_581_836),
            (10, 2.228_138_852),
            (27, 2.051_830_516),
            (120, 1.979_930_405),
        ] {
            assert!((t_quantile_975(dof) / t - 1.0).abs() < 1e-9, "{dof}");
        }
    }

    #[test]
    fn a_direction_the_data_cannot_see_is_reported_and_the_rest_has_errors() {
        // Residuals depend on x0 + x1 and on x2 only.
        let j = DMatrix::from_row_slice(3, 3, &[1.0, 1.0, 0.0, 2.0, 2.0, 1.0, 0.0, 0.0, 3.0]);
        let a = analyse(&j, 0.0, 0, false);
        assert_eq!(a.null_directions.len(), 1);
        let v = &a.null_directions[0];
        assert!((v[0] - v[1].abs()).abs() < 1e-12 && v[0] * v[1] < 0.0 && v[2].abs() < 1e-12);
        assert_eq!(a.standard_errors[0], None);
        assert_eq!(a.standard_errors[1], None);
        let direct = (j.tr_mul(&j)).try_inverse();
        assert!(direct.is_none() || a.standard_errors[2].is_some());
        assert!(a.no_effect.is_empty());
    }

    #[test]
    fn a_full_rank_jacobian_gives_the_inverse_of_its_normal_matrix() {
        let j = DMatrix::from_row_slice(4, 2, &[1.0, 0.5, 2.0, -1.0, 0.3, 0.7, 1.5, 1.0]);
        let a = analyse(&j, 8.0, 2, true);
        let covariance = j.tr_mul(&j).try_inverse().unwrap() * 4.0;
        for i in 0..2 {
            let se = a.standard_errors[i].unwrap();
            assert!((se / covariance[(i, i)].sqrt() - 1.0).abs() < 1e-12);
        }
        let rho = covariance[(0, 1)] / (covariance[(0, 0)] * covariance[(1, 1)]).sqrt();
        assert!((a.correlation[(0, 1)] - rho).abs() < 1e-12);
        assert!((a.coverage_factor - 4.302_652_730).abs() < 1e-8);
    }

    #[test]
    fn a_column_of_zeros_has_no_effect() {
        let j = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 2.0, 0.0, 3.0, 0.0]);
        let a = analyse(&j, 1.0, 1, true);
        assert_eq!(a.no_effect, vec![1]);
        assert_eq!(a.standard_errors[1], None);
    }
}
