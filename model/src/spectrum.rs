//! Layers described by material data: a Prony series (generalized Maxwell model)
//! E(t) = E_∞ + Σ_j E_j e^{−t/τ_j}, and the WLF shift of its times with temperature
//! (docs/model.md §9).
//!
//! The paper's Kelvin layer is the one-term series E_∞ = E_L, E₁ = κE_L, τ₁ = T_σ, since
//! (1 + iωT_ε)/(1 + iωT_σ) = 1 + κ iωT_σ/(1 + iωT_σ). A [`Layer`] keeps that term as
//! (T_ε, T_σ); a layer from a series keeps every term of it as [`Layer::arms`], each as its
//! strength κ_j = E_j/E_∞ and its time τ_j (a modulus scale then scales every term, and a
//! time shift every time), and its Kelvin term without strength (T_ε = T_σ).

use std::fmt;

use super::Layer;

/// Most terms a Prony series may have: dynamic mechanical analysis fits give 10 to 20, one
/// or two a decade of time.
pub const MAX_TERMS: usize = 24;
/// Room for a series and the Kelvin term beside it ([`Layer::terms`]).
pub const CAPACITY: usize = MAX_TERMS + 1;

/// Up to [`MAX_TERMS`] + 1 pairs (κ_j, s_j) of a strength and a scale (a time, or a length
/// V τ_j, or one in units of a contact), stored inline so that a [`Layer`] stays `Copy` and
/// its `Debug` form (a memo key) names every term.
#[derive(Clone, Copy, PartialEq)]
pub struct Terms {
    len: usize,
    strength: [f64; CAPACITY],
    scale: [f64; CAPACITY],
}

impl Default for Terms {
    fn default() -> Self {
        Terms {
            len: 0,
            strength: [0.0; CAPACITY],
            scale: [0.0; CAPACITY],
        }
    }
}

impl fmt::Debug for Terms {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl Terms {
    /// The terms of `pairs`, if there are at most [`MAX_TERMS`] (a layer adds its Kelvin
    /// term to them, [`Layer::terms`]).
    pub fn of(pairs: impl IntoIterator<Item = (f64, f64)>) -> Option<Terms> {
        Terms::filled(pairs, MAX_TERMS)
    }

    /// The terms of `pairs`, if there are at most `limit` (≤ [`CAPACITY`]).
    fn filled(pairs: impl IntoIterator<Item = (f64, f64)>, limit: usize) -> Option<Terms> {
        let mut terms = Terms::default();
        for (strength, scale) in pairs {
            if terms.len == limit {
                return None;
            }
            terms.strength[terms.len] = strength;
            terms.scale[terms.len] = scale;
            terms.len += 1;
        }
        Some(terms)
    }

    /// The one term (κ, s), or none if it does nothing (κ = 0 or s = 0).
    pub fn one(strength: f64, scale: f64) -> Terms {
        Terms::of([(strength, scale)])
            .expect("one term fits")
            .scaled(1.0)
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// (κ_j, s_j) in order.
    pub fn iter(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.strength[..self.len]
            .iter()
            .copied()
            .zip(self.scale[..self.len].iter().copied())
    }

    /// Σ κ_j: the instantaneous modulus is (1 + Σκ_j) times the relaxed one.
    pub fn strength(&self) -> f64 {
        self.strength[..self.len].iter().sum()
    }

    /// Σ κ_j s_j: the first-order lag of slow rolling, V Σ κ_j τ_j.
    pub fn lag(&self) -> f64 {
        self.iter().map(|(k, s)| k * s).sum()
    }

    /// The strength-weighted mean scale Σκ_j s_j / Σκ_j (0 without terms): one length that
    /// stands for all where one is needed (a guide, a grid's spacing).
    pub fn mean_scale(&self) -> f64 {
        let strength = self.strength();
        if strength > 0.0 {
            self.lag() / strength
        } else {
            0.0
        }
    }

    /// The shortest scale (0 without terms).
    pub fn shortest(&self) -> f64 {
        self.scale[..self.len]
            .iter()
            .copied()
            .reduce(f64::min)
            .unwrap_or(0.0)
    }

    /// The longest scale (0 without terms).
    pub fn longest(&self) -> f64 {
        self.scale[..self.len].iter().copied().fold(0.0, f64::max)
    }

    /// Every scale times `factor`, without the terms that then do nothing (κ_j = 0 or
    /// s_j = 0: at rest every term is relaxed).
    pub fn scaled(&self, factor: f64) -> Terms {
        let kept = self
            .iter()
            .map(|(k, s)| (k, s * factor))
            .filter(|&(k, s)| k > 0.0 && s > 0.0);
        Terms::filled(kept, CAPACITY).expect("no more terms than before")
    }
}

impl Layer {
    /// The layer of a Prony series: relaxed modulus E_∞, and terms (E_j, τ_j), all kept as
    /// arms; the Kelvin term has no strength (T_ε = T_σ = τ₁). `None` with more than
    /// [`MAX_TERMS`] terms or none.
    pub fn from_prony(
        relaxed_modulus: f64,
        thickness: f64,
        poisson_ratio: f64,
        terms: &[(f64, f64)],
    ) -> Option<Layer> {
        let &(_, first_time) = terms.first()?;
        Some(Layer {
            elastic_modulus: relaxed_modulus,
            thickness,
            poisson_ratio,
            retardation_time: first_time,
            relaxation_time: first_time,
            arms: Terms::of(terms.iter().map(|&(e, t)| (e / relaxed_modulus, t)))?,
        })
    }

    /// Every term of the series as (κ_j = E_j/E_∞, τ_j): the Kelvin term first.
    pub fn terms(&self) -> Terms {
        let kelvin = std::iter::once((self.kappa(), self.relaxation_time));
        Terms::filled(kelvin.chain(self.arms.iter()), CAPACITY).expect("arms are at most MAX_TERMS")
    }

    /// The Prony series (E_j, τ_j) of the layer, the Kelvin term first if it has strength.
    pub fn prony(&self) -> Vec<(f64, f64)> {
        self.terms()
            .iter()
            .filter(|(k, _)| *k > 0.0)
            .map(|(k, t)| (k * self.elastic_modulus, t))
            .collect()
    }

    /// The viscous terms at speed V, as (κ_j, V τ_j) (none at rest).
    pub fn viscosity(&self, velocity: f64) -> Terms {
        self.terms().scaled(velocity)
    }

    /// E_0/E_∞ = 1 + Σ κ_j, the instantaneous stiffening (1 + κ for the Kelvin layer).
    pub fn stiffening(&self) -> f64 {
        1.0 + self.kappa() + self.arms.strength()
    }

    /// The layer at V → ∞: every term stiff, its modulus E_0 = E_∞(1 + Σκ_j).
    pub fn instantaneous(&self) -> Layer {
        Layer {
            elastic_modulus: self.elastic_modulus * self.stiffening(),
            ..*self
        }
    }

    /// Σ κ_j τ_j: slow rolling lags by V times this (T_ε − T_σ for the Kelvin layer,
    /// taken as that difference so that it is exact).
    pub fn lag_time(&self) -> f64 {
        (self.retardation_time - self.relaxation_time) + self.arms.lag()
    }

    /// The same material with every time multiplied by `factor` (a WLF shift, or a fit's
    /// time shift): 10^Δ shifts by Δ decades.
    pub fn with_times_scaled(&self, factor: f64) -> Layer {
        Layer {
            retardation_time: self.retardation_time * factor,
            relaxation_time: self.relaxation_time * factor,
            arms: self.arms.scaled(factor),
            ..*self
        }
    }

    /// The layer's creep (retardation) spectrum, for the continuum law's memory.
    pub fn creep(&self) -> Creep {
        Creep::of(&self.terms())
    }
}

/// The compliance of a Prony series in partial fractions:
/// E_∞/E(s) = c₀ + Σ_k c_k/(1 + sθ_k), with E(s) = E_∞[1 + Σκ_j sτ_j/(1 + sτ_j)].
///
/// c₀ = E_∞/E_0 is the share of the response that is instantaneous, θ_k the retardation
/// times: the roots of 1 − Σκ_jτ_j/(θ − τ_j), one above the longest τ_j and one between
/// each pair of neighbouring τ_j (the left side increases from −∞ to +∞ between poles), and
/// c_k = 1/(θ_k Σκ_jτ_j/(θ_k − τ_j)²) > 0 their residues. For one term θ = T_ε and
/// c = 1 − T_σ/T_ε: docs/model.md §8's remembered pressure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Creep {
    /// c₀ = E_∞/E_0.
    pub instant: f64,
    /// (c_k, θ_k), θ_k ascending.
    pub terms: Terms,
}

impl Creep {
    fn of(series: &Terms) -> Creep {
        // Equal times act as one term.
        let mut merged: Vec<(f64, f64)> = Vec::new();
        let mut sorted: Vec<(f64, f64)> = series.iter().filter(|(k, _)| *k > 0.0).collect();
        sorted.sort_by(|a, b| a.1.total_cmp(&b.1));
        for (k, t) in sorted {
            match merged.last_mut() {
                Some(last) if last.1 == t => last.0 += k,
                _ => merged.push((k, t)),
            }
        }
        let instant = 1.0 / (1.0 + merged.iter().map(|(k, _)| k).sum::<f64>());
        let lag: f64 = merged.iter().map(|(k, t)| k * t).sum();
        let roots = (0..merged.len()).map(|i| {
            // θ = τ_i + d: the sum in terms of d keeps θ − τ_i exact near its pole.
            let tau = merged[i].1;
            let gaps = |d: f64| merged.iter().map(move |(k, t)| (k * t, (tau - t) + d));
            let f = |d: f64| 1.0 - gaps(d).map(|(kt, gap)| kt / gap).sum::<f64>();
            // f rises from −∞ at d = 0 to +∞ at the next time, or above 0 once
            // d ≥ Σκ_jτ_j (every gap is then at least that).
            let (mut lo, mut hi) = (0.0, merged.get(i + 1).map_or(2.0 * lag, |n| n.1 - tau));
            while hi - lo > 2.0 * f64::EPSILON * hi {
                let mid = 0.5 * (lo + hi);
                if f(mid) < 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let d = 0.5 * (lo + hi);
            let slope: f64 = gaps(d).map(|(kt, gap)| kt / (gap * gap)).sum();
            let theta = tau + d;
            (1.0 / (theta * slope), theta)
        });
        Creep {
            instant,
            terms: Terms::filled(roots, CAPACITY).expect("no more roots than terms"),
        }
    }
}

/// The WLF shift of the times at temperature T from the reference temperature T_ref, in
/// decades: log₁₀ a_T = −C₁(T − T_ref)/(C₂ + T − T_ref). `None` where C₂ + T − T_ref ≤ 0
/// (the law's pole: below it WLF says nothing).
pub fn wlf_decades(c1: f64, c2: f64, reference: f64, temperature: f64) -> Option<f64> {
    let above = temperature - reference;
    let denominator = c2 + above;
    (denominator > 0.0).then(|| -c1 * above / denominator)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// E_∞/E(iω) from the series directly, as a complex number (re, im).
    fn compliance(series: &Terms, omega: f64) -> (f64, f64) {
        let (mut re, mut im) = (1.0, 0.0);
        for (k, t) in series.iter() {
            let wt = omega * t;
            let d = 1.0 + wt * wt;
            re += k * wt * wt / d;
            im += k * wt / d;
        }
        let n = re * re + im * im;
        (re / n, -im / n)
    }

    #[test]
    fn the_creep_spectrum_reproduces_the_compliance_at_every_frequency() {
        let series = Terms::of([(2.0, 1e-3), (0.5, 0.1), (3.0, 10.0), (0.01, 1e4)]).unwrap();
        let creep = Creep::of(&series);
        let total: f64 = creep.terms.iter().map(|(c, _)| c).sum();
        assert!((creep.instant + total - 1.0).abs() < 1e-13);
        for e in -8..=8 {
            let omega = 10f64.powi(e);
            let (re, im) = compliance(&series, omega);
            let (mut fre, mut fim) = (creep.instant, 0.0);
            for (c, theta) in creep.terms.iter() {
                let wt = omega * theta;
                fre += c / (1.0 + wt * wt);
                fim -= c * wt / (1.0 + wt * wt);
            }
            assert!((fre - re).abs() < 1e-12, "ω = {omega}: {fre} vs {re}");
            assert!((fim - im).abs() < 1e-12, "ω = {omega}: {fim} vs {im}");
        }
    }

    #[test]
    fn one_term_creeps_at_the_retardation_time() {
        let layer = Layer::default();
        let creep = layer.creep();
        let (c, theta) = creep.terms.iter().next().unwrap();
        assert!((theta / layer.retardation_time - 1.0).abs() < 1e-14);
        assert!((c - (1.0 - layer.relaxation_time / layer.retardation_time)).abs() < 1e-14);
        assert!((creep.instant - layer.relaxation_time / layer.retardation_time).abs() < 1e-15);
    }

    #[test]
    fn a_one_term_series_has_the_kelvin_layers_limits() {
        let d = Layer::default();
        let prony = Layer::from_prony(3e9, 100e-9, 0.35, &[(12e9, 0.1)]).unwrap();
        assert_eq!(prony.kappa(), 0.0);
        assert_eq!(prony.prony(), vec![(12e9, 0.1)]);
        assert!((prony.stiffening() / d.stiffening() - 1.0).abs() < 1e-15);
        assert!((prony.lag_time() / d.lag_time() - 1.0).abs() < 1e-15);
        let (c, theta) = prony.creep().terms.iter().next().unwrap();
        assert!((theta / d.retardation_time - 1.0).abs() < 1e-14);
        assert!((c / (1.0 - d.relaxation_time / d.retardation_time) - 1.0).abs() < 1e-14);
        assert_eq!(
            Layer::from_prony(3e9, 1e-7, 0.35, &[(1e9, 1.0); MAX_TERMS + 1]),
            None
        );
    }

    #[test]
    fn wlf_shifts_by_the_law_and_has_a_pole() {
        let d = wlf_decades(17.44, 51.6, 300.0, 310.0).unwrap();
        assert!((d + 17.44 * 10.0 / 61.6).abs() < 1e-14);
        assert_eq!(wlf_decades(17.44, 51.6, 300.0, 300.0), Some(0.0));
        assert_eq!(wlf_decades(17.44, 51.6, 300.0, 240.0), None);
    }
}
