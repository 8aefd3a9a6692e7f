//! The surface compliance of an elastic layer bonded to a rigid base (docs/model.md §8):
//! ŵ(q) = S(q) p̂(q), S(q) = 2(1 − ν²)/(E q) · C(qH). C → 1 for qH → ∞ (a half-space), and
//! S → H/E_L for qH → 0 (the local law of §2–3, with the same k = E_L/H).

use crate::quadrature::gauss_legendre_16;
use crate::Layer;

/// Beyond s = qH = 24 the layer's correction is below 1e-16 of the half-space's.
const S_MAX: f64 = 24.0;

/// E, the relaxed Young's modulus of a layer whose oedometric (longitudinal) modulus is E_L:
/// E = E_L (1 + ν)(1 − 2ν)/(1 − ν), so that the thin-layer limit is the local law.
pub fn young_modulus(layer: &Layer) -> f64 {
    let nu = layer.poisson_ratio;
    layer.elastic_modulus * (1.0 + nu) * (1.0 - 2.0 * nu) / (1.0 - nu)
}

/// E_L, the oedometric (constrained) modulus of a layer of Young's modulus E and Poisson
/// ratio ν: E_L = E (1 − ν)/((1 + ν)(1 − 2ν)), the inverse of [`young_modulus`] (for a
/// layer given by a lab's E rather than E_L).
pub fn constrained_modulus(youngs_modulus: f64, poisson_ratio: f64) -> f64 {
    let nu = poisson_ratio;
    youngs_modulus * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))
}

/// E* = E/(1 − ν²), the plane-strain modulus of the layer against a rigid sphere.
pub fn contact_modulus(layer: &Layer) -> f64 {
    let nu = layer.poisson_ratio;
    young_modulus(layer) / (1.0 - nu * nu)
}

/// C(s) − 1 at s = qH: the layer's correction to the half-space compliance, written so that
/// nothing cancels (sinh 2s − cosh 2s = −e^{−2s}) or overflows (numerator and denominator
/// divided by cosh 2s); −1 at s = 0, decaying as s² e^{−4s} for large s.
pub fn layer_correction(s: f64, nu: f64) -> f64 {
    let a = 3.0 - 4.0 * nu;
    let b = 5.0 - 12.0 * nu + 8.0 * nu * nu;
    let e2 = (-2.0 * s).exp();
    // sech 2s = 2e^{−2s}/(1 + e^{−4s}).
    let sech = 2.0 * e2 / (1.0 + e2 * e2);
    let numerator = (a * e2 + 2.0 * s + 2.0 * s * s + b) * sech;
    let denominator = a + (2.0 * s * s + b) * sech;
    -numerator / denominator
}

/// The nodes s and weights w·(C(s) − 1) of a rule for ∫₀^∞ (C(s) − 1) g(s) ds, where g
/// oscillates no faster than the Bessel functions of s·r/H for r up to `reach`·H: 16 Gauss
/// nodes on panels short enough to follow two periods, up to where C − 1 is negligible.
pub fn correction_rule(nu: f64, reach: f64) -> Vec<(f64, f64)> {
    let panel = (2.0 / reach.max(1e-300)).min(1.0);
    let panels = (S_MAX / panel).ceil() as usize;
    let (x, w) = gauss_legendre_16();
    let mut nodes = Vec::with_capacity(panels * x.len());
    for m in 0..panels {
        let (lo, hi) = (m as f64 * panel, ((m + 1) as f64 * panel).min(S_MAX));
        for (xk, wk) in x.iter().zip(w) {
            let s = lo + 0.5 * (hi - lo) * (xk + 1.0);
            nodes.push((s, 0.5 * (hi - lo) * wk * layer_correction(s, nu)));
        }
    }
    nodes
}

/// C(s) itself (1 + [`layer_correction`]).
pub fn layer_factor(s: f64, nu: f64) -> f64 {
    1.0 + layer_correction(s, nu)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// C from its definition, where it can be evaluated directly.
    fn direct(s: f64, nu: f64) -> f64 {
        let a = 3.0 - 4.0 * nu;
        let x = 2.0 * s;
        (a * x.sinh() - x) / (a * x.cosh() + 2.0 * s * s + 5.0 - 12.0 * nu + 8.0 * nu * nu)
    }

    #[test]
    fn the_layer_factor_is_its_definition_and_has_both_limits() {
        for nu in [0.0, 0.3, 0.35, 0.45, 0.49] {
            for s in [0.05, 0.3, 1.0, 3.0, 10.0] {
                let (c, d) = (layer_factor(s, nu), direct(s, nu));
                assert!((c / d - 1.0).abs() < 1e-12, "ν = {nu}, s = {s}: {c} vs {d}");
            }
            // Half-space far from the base; no overflow past cosh's range.
            assert!((layer_factor(400.0, nu) - 1.0).abs() < 1e-15);
            assert_eq!(layer_correction(1e4, nu), 0.0);
            // The local law near qH → 0: S = 2(1 − ν²)C(s)/(E q) → H/E_L.
            let layer = Layer {
                poisson_ratio: nu,
                ..Layer::default()
            };
            let s = 1e-4;
            let q = s / layer.thickness;
            let compliance =
                2.0 * (1.0 - nu * nu) * layer_factor(s, nu) / (young_modulus(&layer) * q);
            let local = layer.thickness / layer.elastic_modulus;
            assert!((compliance / local - 1.0).abs() < 1e-3, "ν = {nu}");
        }
    }
}
