//! The rolling contact at a given penetration, tabulated once per layer: the forward map
//! penetration → (load, area) that the three-body model evaluates for every diameter at
//! every trial separation (docs/model.md §4, `kelvin_layer`).
//!
//! By the similarity law (docs/model.md §3) the ratios Φ_P = P/(πkRδ²) and Φ_A = A/(2πRδ) depend
//! only on ξ = V T_σ/√(2Rδ) and κ, so one table in ξ serves every diameter and every load.
//! It is a Chebyshev interpolant in v = (u − 1)/(u + 1), u = √((1 + κ)ξ), which maps
//! ξ ∈ [0, ∞] onto [−1, 1], centres the viscous transition (it starts where V T_ε ≈ r) and
//! keeps both ends smooth (expansions in √ξ near 0 and in 1/√ξ near ∞); the ends themselves
//! are exact (the static and the instantaneous elastic contact).

use super::quadrature::StripRule;
use super::rolling::penetration_ratios;
use super::ModelError;

/// Chebyshev points of the table for viscosity strength κ. The transition of Φ spans ξ from
/// about 1/(1+κ) to 1, wider as κ grows; these sizes keep the interpolation error below
/// 1e-13 over all ξ for κ up to 1e4 (tested), and larger κ get the largest table.
pub fn table_points(kappa: f64) -> usize {
    if kappa <= 100.0 {
        128
    } else if kappa <= 1e4 {
        256
    } else {
        512
    }
}

/// Points between the table's own at which [`KelvinMap::check`] compares with direct solves.
const CHECK_POINTS: usize = 8;

/// Φ_P(ξ) and Φ_A(ξ) for one κ, by barycentric interpolation on Chebyshev points.
#[derive(Clone, Debug)]
pub struct KelvinMap {
    kappa: f64,
    /// v_j = cos(πj/N), j = 0…N.
    nodes: Vec<f64>,
    load: Vec<f64>,
    area: Vec<f64>,
}

impl KelvinMap {
    /// Tabulates the ratios for viscosity strength κ, each point solved with `rule`.
    pub fn new(kappa: f64, rule: &StripRule) -> Result<KelvinMap, ModelError> {
        let n = table_points(kappa);
        let nodes: Vec<f64> = (0..=n)
            .map(|j| (std::f64::consts::PI * j as f64 / n as f64).cos())
            .collect();
        let (mut load, mut area) = (Vec::with_capacity(n + 1), Vec::with_capacity(n + 1));
        for &v in &nodes {
            let (p, a) = if v >= 1.0 {
                (1.0 + kappa, 1.0) // ξ = ∞: instantaneous elastic layer
            } else if v <= -1.0 {
                (1.0, 1.0) // ξ = 0: relaxed elastic layer
            } else {
                let u = (1.0 + v) / (1.0 - v);
                penetration_ratios(u * u / (1.0 + kappa), kappa, rule)?
            };
            load.push(p);
            area.push(a);
        }
        Ok(KelvinMap {
            kappa,
            nodes,
            load,
            area,
        })
    }

    /// κ the table was built for.
    pub fn kappa(&self) -> f64 {
        self.kappa
    }

    /// (Φ_P, Φ_A) at ξ ≥ 0 (ξ = ∞ allowed).
    pub fn ratios(&self, xi: f64) -> (f64, f64) {
        let v = if xi.is_infinite() {
            1.0
        } else {
            let u = (xi * (1.0 + self.kappa)).sqrt();
            (u - 1.0) / (u + 1.0)
        };
        self.interpolate(v)
    }

    /// ξ at table coordinate v ∈ (−1, 1): ξ = u²/(1 + κ), u = (1 + v)/(1 − v).
    fn xi_at(&self, v: f64) -> f64 {
        let u = (1.0 + v) / (1.0 - v);
        u * u / (1.0 + self.kappa)
    }

    /// The largest relative difference between the table and direct solves with `rule`,
    /// halfway between table points spread over the whole range: the table's own error,
    /// reported with every answer that uses it.
    pub fn check(&self, rule: &StripRule) -> Result<f64, ModelError> {
        let n = self.nodes.len() - 1;
        let mut worst: f64 = 0.0;
        for k in 0..CHECK_POINTS {
            let j = (2 * k + 1) * n / (2 * CHECK_POINTS);
            let v = 0.5 * (self.nodes[j] + self.nodes[j + 1]);
            let (p, a) = self.interpolate(v);
            let (p_direct, a_direct) = penetration_ratios(self.xi_at(v), self.kappa, rule)?;
            worst = worst
                .max((p / p_direct - 1.0).abs())
                .max((a / a_direct - 1.0).abs());
        }
        Ok(worst)
    }

    /// Barycentric interpolation at v ∈ [−1, 1] (Chebyshev points of the second kind).
    fn interpolate(&self, v: f64) -> (f64, f64) {
        let (mut num_p, mut num_a, mut den) = (0.0, 0.0, 0.0);
        let last = self.nodes.len() - 1;
        for (j, &node) in self.nodes.iter().enumerate() {
            let diff = v - node;
            if diff == 0.0 {
                return (self.load[j], self.area[j]);
            }
            let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
            let weight = if j == 0 || j == last {
                0.5 * sign
            } else {
                sign
            } / diff;
            num_p += weight * self.load[j];
            num_a += weight * self.area[j];
            den += weight;
        }
        (num_p / den, num_a / den)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Quadrature;

    #[test]
    fn the_table_matches_direct_solves_between_its_points_to_1e_12_for_kappa_up_to_1e4() {
        let rule = StripRule::shared(Quadrature::default()).unwrap();
        for kappa in [0.01, 1.0, 4.0, 100.0, 1e3, 1e4] {
            let map = KelvinMap::new(kappa, &rule).unwrap();
            assert!(map.check(&rule).unwrap() < 1e-13, "κ = {kappa}");
            let mut worst: f64 = 0.0;
            for i in 0..=200 {
                let xi = 10f64.powf(-10.0 + 20.0 * f64::from(i) / 200.0 + 0.0123);
                let (p, a) = map.ratios(xi);
                let (p_direct, a_direct) = penetration_ratios(xi, kappa, &rule).unwrap();
                worst = worst
                    .max((p / p_direct - 1.0).abs())
                    .max((a / a_direct - 1.0).abs());
            }
            assert!(worst < 1e-12, "κ = {kappa}: worst relative error {worst:e}");
        }
    }

    #[test]
    fn the_ends_are_the_static_and_instantaneous_contacts() {
        let rule = StripRule::shared(Quadrature::default()).unwrap();
        let map = KelvinMap::new(4.0, &rule).unwrap();
        assert_eq!(map.ratios(0.0), (1.0, 1.0));
        assert_eq!(map.ratios(f64::INFINITY), (5.0, 1.0));
    }
}
