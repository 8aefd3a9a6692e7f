//! Particle diameters: a Gaussian truncated to [x_min, x_max] and renormalised there
//! (docs/model.md eq. 1), and the count of particles in contact (eq. 7) in closed form.

use std::f64::consts::{FRAC_1_SQRT_2, PI};

/// Diameters x ~ N(mean, std²) restricted to [min, max]; `std = 0` puts every particle at
/// `mean` (the single-size limit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diameters {
    /// x_a (m).
    pub mean: f64,
    /// σ_a (m), ≥ 0.
    pub std: f64,
    /// x_min (m), ≥ 0.
    pub min: f64,
    /// x_max (m).
    pub max: f64,
}

impl Diameters {
    /// Bounds x_a ∓ 3σ_a, never below 0 (docs/model.md §4).
    pub fn with_default_bounds(mean: f64, std: f64) -> Self {
        Diameters {
            mean,
            std,
            min: (mean - 3.0 * std).max(0.0),
            max: mean + 3.0 * std,
        }
    }

    /// Whether every particle has the mean diameter: σ_a = 0, or a spread so narrow
    /// (σ_a ≤ 1e-8 x_a) that double precision cannot resolve the distribution across it
    /// (its bounds x_a ∓ 3σ_a lie a few ulps apart at σ_a = 1e-16 x_a, and the sums drifted
    /// by 1.5e-2 there). The spread changes the sums by about (σ_a/ω)², ω the interference:
    /// below 1e-12 here for particles pressed 1e-4 x_a or more.
    pub fn is_single_size(&self) -> bool {
        /// σ_a/x_a below which the spread is treated as none.
        const RESOLVED: f64 = 1e-8;
        self.std <= RESOLVED * self.mean
    }

    /// Probability mass of the untruncated Gaussian on [lo, hi], lo ≤ hi, without
    /// cancellation in either tail.
    fn mass(&self, lo: f64, hi: f64) -> f64 {
        let z = |x: f64| (x - self.mean) / self.std * FRAC_1_SQRT_2;
        let (a, b) = (z(lo), z(hi));
        if a >= 0.0 {
            0.5 * (libm::erfc(a) - libm::erfc(b))
        } else if b <= 0.0 {
            0.5 * (libm::erfc(-b) - libm::erfc(-a))
        } else {
            1.0 - 0.5 * (libm::erfc(-a) + libm::erfc(b))
        }
    }

    /// The renormalising mass of [x_min, x_max]; zero when the bounds hold no probability
    /// representable in double precision.
    pub fn normaliser(&self) -> f64 {
        if self.is_single_size() {
            1.0
        } else {
            self.mass(self.min, self.max)
        }
    }

    /// φ(x), the truncated and renormalised density (0 outside the bounds).
    pub fn density(&self, x: f64) -> f64 {
        if x < self.min || x > self.max {
            return 0.0;
        }
        let u = (x - self.mean) / self.std;
        (-0.5 * u * u).exp() / (self.std * (2.0 * PI).sqrt() * self.normaliser())
    }

    /// ∫_{max(d, x_min)}^{x_max} φ: the fraction of particles larger than the gap d.
    pub fn fraction_above(&self, d: f64) -> f64 {
        if self.is_single_size() {
            return if self.mean > d { 1.0 } else { 0.0 };
        }
        let lo = d.max(self.min);
        if lo >= self.max {
            0.0
        } else {
            self.mass(lo, self.max) / self.normaliser()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_truncated_density_integrates_to_one_and_matches_its_fractions() {
        let dist = Diameters::with_default_bounds(50e-9, 5e-9);
        let rule = crate::quadrature::gauss_legendre(64);
        let (x, w) = &*rule;
        let integral = |lo: f64, hi: f64| -> f64 {
            x.iter()
                .zip(w)
                .map(|(t, w)| {
                    let xm = 0.5 * (lo + hi) + 0.5 * (hi - lo) * t;
                    0.5 * (hi - lo) * w * dist.density(xm)
                })
                .sum()
        };
        assert!((integral(dist.min, dist.max) - 1.0).abs() < 1e-14);
        for d in [30e-9_f64, 40e-9, 52e-9, 64e-9] {
            let lo = d.max(dist.min);
            let expected = integral(lo, dist.max);
            assert!((dist.fraction_above(d) - expected).abs() < 1e-14, "d = {d}");
        }
        assert_eq!(dist.fraction_above(70e-9), 0.0);
        assert_eq!(dist.fraction_above(10e-9), 1.0);
    }

    #[test]
    fn bounds_are_clipped_at_zero_and_far_tails_do_not_cancel() {
        let dist = Diameters::with_default_bounds(10e-9, 5e-9);
        assert_eq!(dist.min, 0.0);
        let far = Diameters {
            mean: 0.0,
            std: 1.0,
            min: 30.0,
            max: 31.0,
        };
        // Φ(31) − Φ(30) ≈ 4.906e-198: computed from erfc, not as a difference of ones.
        assert!((far.normaliser() / 4.906_713_927_148_495e-198 - 1.0).abs() < 1e-12);
    }
}
