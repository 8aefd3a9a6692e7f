//! Surface-to-surface contact of the asperities: the Zhao–Maietta–Chang model (docs/model.md §4),
//! elastic, then elastic-plastic, then fully plastic as the interference grows, summed over
//! Gaussian asperity heights.

use std::f64::consts::{FRAC_1_SQRT_2, PI};

use crate::limits::hertz_force;
use crate::quadrature::gauss_legendre;

/// Heights are integrated to this many standard deviations above the separation.
const HEIGHT_RANGE: f64 = 12.0;
/// Gauss–Legendre nodes per regime of the height integral.
const NODES_PER_REGIME: usize = 48;

/// The asperities of the rough pair (Greenwood–Williamson statistics).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Asperities {
    /// η_s, asperities per unit area (m⁻²).
    pub density: f64,
    /// β_s, tip radius (m).
    pub tip_radius: f64,
    /// σ_s, standard deviation of the asperity heights (m).
    pub height_std: f64,
    /// H_s, hardness of the softer surface (Pa).
    pub hardness: f64,
}

/// The ZMC law of one asperity for a given pair of surfaces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Zmc {
    pub asperities: Asperities,
    /// E′, composite modulus of the pair.
    pub modulus: f64,
    /// K = 0.454 + 0.41ν of the softer surface.
    pub k: f64,
    /// ω_c1 = (3πK H_s/(4E′))² β_s: end of elastic contact.
    pub critical_elastic: f64,
    /// ω_c2 = 54 ω_c1: start of fully plastic contact.
    pub critical_plastic: f64,
}

impl Zmc {
    /// The law for `asperities` on surfaces of composite modulus E′, the softer of which has
    /// Poisson ratio ν.
    pub fn new(asperities: Asperities, modulus: f64, poisson_ratio: f64) -> Self {
        let k = 0.454 + 0.41 * poisson_ratio;
        let critical_elastic =
            (3.0 * PI * k * asperities.hardness / (4.0 * modulus)).powi(2) * asperities.tip_radius;
        Zmc {
            asperities,
            modulus,
            k,
            critical_elastic,
            critical_plastic: 54.0 * critical_elastic,
        }
    }

    /// (area, load) of one asperity at interference w ≥ 0.
    pub fn asperity(&self, w: f64) -> (f64, f64) {
        let beta = self.asperities.tip_radius;
        let h = self.asperities.hardness;
        let (w1, w2) = (self.critical_elastic, self.critical_plastic);
        if w <= 0.0 {
            (0.0, 0.0)
        } else if w < w1 {
            (PI * beta * w, hertz_force(self.modulus, beta, w))
        } else if w < w2 {
            let t = (w - w1) / (w2 - w1);
            let area = PI * beta * w * (1.0 - 2.0 * t * t * t + 3.0 * t * t);
            let pressure = h - h * (1.0 - self.k) * (w2 / w).ln() / (w2 / w1).ln();
            (area, pressure * area)
        } else {
            let area = 2.0 * PI * beta * w;
            (area, h * area)
        }
    }

    /// (A_s1s2, W_s1s2) over the nominal area at separation d:
    /// η_s A_n ∫_d^{d+12σ_s} (area, load)(z − d) φ_s(z) dz, one Gauss rule per regime (the
    /// regimes meet with kinks), the first one in w = ω_c1·t² to absorb the w^{3/2} edge.
    pub fn totals(&self, separation: f64, nominal_area: f64) -> (f64, f64) {
        let sigma = self.asperities.height_std;
        let top = HEIGHT_RANGE * sigma;
        let breaks = [0.0, self.critical_elastic, self.critical_plastic, top];
        let rule = gauss_legendre(NODES_PER_REGIME);
        let (x, w) = &*rule;
        let heights = |z: f64| {
            let u = z / sigma;
            (-0.5 * u * u).exp() * FRAC_1_SQRT_2 / (sigma * PI.sqrt())
        };
        let (mut area, mut load) = (0.0, 0.0);
        for (i, pair) in breaks.windows(2).enumerate() {
            let (lo, hi) = (pair[0], pair[1].min(top));
            if hi <= lo {
                continue;
            }
            for (t, wt) in x.iter().zip(w) {
                // First regime: w = hi·τ², τ ∈ (0, 1); others: linear.
                let (interference, jacobian) = if i == 0 {
                    let tau = 0.5 * (t + 1.0);
                    (hi * tau * tau, hi * tau)
                } else {
                    (0.5 * (lo + hi) + 0.5 * (hi - lo) * t, 0.5 * (hi - lo))
                };
                let (a, l) = self.asperity(interference);
                let weight = wt * jacobian * heights(separation + interference);
                area += weight * a;
                load += weight * l;
            }
        }
        let scale = self.asperities.density * nominal_area;
        (scale * area, scale * load)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn zmc() -> Zmc {
        Zmc::new(
            Asperities {
                density: 1e10,
                tip_radius: 1e-6,
                height_std: 20e-9,
                hardness: 1e9,
            },
            3e9,
            0.35,
        )
    }

    #[test]
    fn the_three_regimes_join_continuously() {
        let z = zmc();
        for w in [z.critical_elastic, z.critical_plastic] {
            let (below, above) = (z.asperity(w * (1.0 - 1e-12)), z.asperity(w * (1.0 + 1e-12)));
            assert!((below.0 / above.0 - 1.0).abs() < 1e-10, "area at {w}");
            assert!((below.1 / above.1 - 1.0).abs() < 1e-10, "load at {w}");
        }
        // Mean pressure K·H_s at ω_c1 and H_s at ω_c2.
        let (a, l) = z.asperity(z.critical_elastic);
        assert!((l / a / (z.k * 1e9) - 1.0).abs() < 1e-12);
        let (a, l) = z.asperity(z.critical_plastic);
        assert!((l / a / 1e9 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn height_integrals_match_a_fine_composite_rule() {
        let z = zmc();
        for d in [0.0, 10e-9, 40e-9] {
            let (area, load) = z.totals(d, 1e-6);
            // Composite midpoint rule with 2e6 cells over [d, d + 12σ].
            let n = 2_000_000;
            let h = 12.0 * 20e-9 / n as f64;
            let (mut a_ref, mut l_ref) = (0.0, 0.0);
            for i in 0..n {
                let w = (i as f64 + 0.5) * h;
                let u = (d + w) / 20e-9;
                let phi = (-0.5 * u * u).exp() / (20e-9 * (2.0 * PI).sqrt());
                let (a, l) = z.asperity(w);
                a_ref += a * phi * h;
                l_ref += l * phi * h;
            }
            let scale = 1e10 * 1e-6;
            assert!((area / (scale * a_ref) - 1.0).abs() < 1e-8, "d = {d}: area");
            assert!((load / (scale * l_ref) - 1.0).abs() < 1e-8, "d = {d}: load");
        }
    }
}
