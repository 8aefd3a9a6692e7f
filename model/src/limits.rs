//! Closed-form limits of the rolling contact (docs/model.md §3): the exact answers at V = 0 and
//! V → ∞, and the first-order small-V asymptotics. They are the oracles the solver is tested
//! against, and the V = 0 one is the "static" (the paper's "without rolling") result.

use std::f64::consts::PI;

use super::Layer;

/// A symmetric (elastic) contact of a sphere on the layer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElasticContact {
    /// δ (m).
    pub penetration: f64,
    /// r = √(2Rδ) (m): half-width, and radius of the circular contact.
    pub half_width: f64,
    /// A = π r² (m²).
    pub contact_area: f64,
    /// μ = τ_a A / P (eq. 12).
    pub friction_coefficient: f64,
}

impl ElasticContact {
    /// A sphere of radius `radius` pressed with `load` on a foundation of stiffness `stiffness`:
    /// P = π k R δ².
    fn new(radius: f64, load: f64, stiffness: f64, layer: &Layer) -> Self {
        let penetration = (load / (PI * stiffness * radius)).sqrt();
        let half_width = (2.0 * radius * penetration).sqrt();
        let contact_area = PI * half_width * half_width;
        ElasticContact {
            penetration,
            half_width,
            contact_area,
            friction_coefficient: layer.interfacial_shear_strength() * contact_area / load,
        }
    }
}

/// Hertz's force (4/3)E*√R d^{3/2} of a rigid sphere of radius `radius` pressed to depth
/// `depth` into a half-space of plane-strain modulus `modulus` (Johnson eq. 4.23): the
/// three-body contacts' and the continuum curve's scale.
pub fn hertz_force(modulus: f64, radius: f64, depth: f64) -> f64 {
    4.0 / 3.0 * modulus * radius.sqrt() * depth * depth.sqrt()
}

/// V = 0 on the relaxed layer: δ₀ = √(P/(πkR)), A₀ = 2√(πRP/k),
/// μ₀ = √(πRHE_L/P)/(1000(1+ν)).
pub fn relaxed(radius: f64, load: f64, layer: &Layer) -> ElasticContact {
    ElasticContact::new(radius, load, layer.stiffness(), layer)
}

/// V → ∞ on the instantaneous layer of stiffness k(1 + κ) (k(1 + Σκ_j) for a Prony series):
/// δ_∞ = δ₀√(T_σ/T_ε), A_∞ = A₀√(T_σ/T_ε).
pub fn instantaneous(radius: f64, load: f64, layer: &Layer) -> ElasticContact {
    ElasticContact::new(radius, load, layer.instantaneous().stiffness(), layer)
}

/// The first-order effect of slow rolling (V T_ε ≪ r₀).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlowRolling {
    /// A = A₀ − 2V(T_ε − T_σ) r₀.
    pub contact_area: f64,
    /// x_c = V(T_ε − T_σ)/2.
    pub centroid_shift: f64,
    /// μ_r = V(T_ε − T_σ)/R.
    pub rolling_resistance_coefficient: f64,
}

/// Small-V asymptotics: the exit edge moves to a = −b + V(T_ε − T_σ) on every strip
/// (a = −b + VΣκ_jτ_j for a Prony series, [`Layer::lag_time`]).
pub fn slow_rolling(radius: f64, load: f64, velocity: f64, layer: &Layer) -> SlowRolling {
    let r0 = relaxed(radius, load, layer);
    let lag = velocity * layer.lag_time();
    SlowRolling {
        contact_area: r0.contact_area - 2.0 * lag * r0.half_width,
        centroid_shift: lag / 2.0,
        rolling_resistance_coefficient: lag / radius,
    }
}
