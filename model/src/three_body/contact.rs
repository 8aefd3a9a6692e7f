//! One particle squeezed between the upper surface and the layer (docs/model.md §4): the two
//! contact laws and the split of the interference ω = x − d into ω₁ (upper) and ω₂ (layer)
//! at which both contacts carry the same force.

use std::f64::consts::PI;
use std::sync::Arc;

use crate::continuum::PenetrationCurve;
use crate::counterface::UpperLaw;
use crate::limits::hertz_force;
use crate::roots::brent;
use crate::similarity::SimilarityTable;
use crate::ModelError;

/// How the layer takes a particle of radius R = x/2 (the particle is rigid there).
#[derive(Clone, Debug)]
pub enum LayerLaw {
    /// The rolling contact of docs/model.md §3 at a given penetration δ = ω₂:
    /// F = πkRδ²Φ_P(ξ), A₂ = 2πRδΦ_A(ξ), ξ = V T_σ/√(2Rδ). At rest Φ_P = Φ_A = 1.
    Kelvin {
        /// k = E_L/H.
        stiffness: f64,
        /// λ_σ = V T_σ (0 at rest).
        relaxation_length: f64,
        /// The layer's similarity table; `None` at rest.
        table: Option<Arc<SimilarityTable>>,
    },
    /// Hertz with E_s2a: F = (4/3)E_s2a R^{1/2} δ^{3/2}, A₂ = πRδ.
    Hertz { modulus: f64 },
    /// The layer as a continuum (docs/model.md §8) at one speed, through its curve.
    Continuum { curve: Arc<PenetrationCurve> },
}

impl LayerLaw {
    /// (force, area) at penetration δ.
    pub fn contact(&self, radius: f64, delta: f64) -> (f64, f64) {
        match self {
            LayerLaw::Kelvin {
                stiffness,
                relaxation_length,
                table,
            } => {
                let (phi_p, phi_a) = match table {
                    Some(table) if *relaxation_length > 0.0 => {
                        let half_width = (2.0 * radius * delta).sqrt();
                        let ratios = table.ratios(relaxation_length / half_width);
                        (ratios.load, ratios.area)
                    }
                    _ => (1.0, 1.0),
                };
                (
                    PI * stiffness * radius * delta * delta * phi_p,
                    2.0 * PI * radius * delta * phi_a,
                )
            }
            LayerLaw::Hertz { modulus } => {
                (hertz_force(*modulus, radius, delta), PI * radius * delta)
            }
            LayerLaw::Continuum { curve } => curve.contact(radius, delta),
        }
    }

    /// x_p (m), the layer contact's centre of pressure at penetration δ: its rolling
    /// resistance is x_p/R (docs/model.md §11). Hertz's contact is elastic and symmetric.
    pub fn pressure_centre(&self, radius: f64, delta: f64) -> f64 {
        match self {
            LayerLaw::Kelvin {
                relaxation_length,
                table: Some(table),
                ..
            } if *relaxation_length > 0.0 && delta > 0.0 => {
                let half_width = (2.0 * radius * delta).sqrt();
                half_width * table.ratios(relaxation_length / half_width).pressure_centre
            }
            LayerLaw::Kelvin { .. } | LayerLaw::Hertz { .. } => 0.0,
            LayerLaw::Continuum { curve } => curve.pressure_centre(radius, delta),
        }
    }

    /// A bound on the relative error of [`LayerLaw::pressure_centre`]: the continuum
    /// curve's; the others are the force's and area's (exact, or reported apart).
    pub fn pressure_error(&self, radius: f64, delta: f64) -> f64 {
        match self {
            LayerLaw::Continuum { curve } if delta > 0.0 => curve.pressure_error_at(radius, delta),
            _ => 0.0,
        }
    }

    /// A bound on the relative error of [`LayerLaw::contact`]'s force and area: the
    /// continuum curve's there; the closed forms and the table (whose error the
    /// verification reports apart) count as exact.
    pub fn error(&self, radius: f64, delta: f64) -> f64 {
        match self {
            LayerLaw::Continuum { curve } if delta > 0.0 => curve.error_at(radius, delta),
            _ => 0.0,
        }
    }
}

/// A particle in equilibrium between the two surfaces.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Squeeze {
    /// ω₁, into the upper surface (m).
    pub upper_interference: f64,
    /// ω₂, into the layer (m).
    pub layer_penetration: f64,
    /// F, carried by both contacts (N).
    pub force: f64,
    /// A₁ (m²).
    pub upper_area: f64,
    /// A₂ (m²).
    pub layer_area: f64,
    /// A bound on the relative error of F and A₂ from the layer's law ([`LayerLaw::error`]).
    pub layer_error: f64,
}

/// Splits the interference ω of a particle of diameter x: solves ω₂ + ω₁(F_layer(ω₂)) = ω
/// for ω₂ ∈ (0, ω) (increasing in ω₂, so one root, bracketed), then takes ω₁ from the
/// inverse upper law so that it keeps full relative precision even when ω₁ ≪ ω₂.
pub fn squeeze(
    upper: &UpperLaw,
    layer: &LayerLaw,
    diameter: f64,
    omega: f64,
) -> Result<Squeeze, ModelError> {
    if omega <= 0.0 {
        return Ok(Squeeze::default());
    }
    let radius = 0.5 * diameter;
    let mismatch = |delta: f64| {
        let (force, _) = layer.contact(radius, delta);
        delta + upper.interference(radius, force) - omega
    };
    let root = brent(
        mismatch,
        (0.0, -omega),
        (omega, mismatch(omega)),
        1e-15 * omega,
        "split of the interference between the upper surface and the layer",
    )?;
    let delta = root.x;
    let (force, layer_area) = layer.contact(radius, delta);
    let upper_interference = upper.interference(radius, force);
    Ok(Squeeze {
        upper_interference,
        layer_penetration: delta,
        force,
        upper_area: upper.area(radius, upper_interference),
        layer_area,
        layer_error: layer.error(radius, delta),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_hertz_contacts_split_the_interference_in_closed_form() {
        // Equal forces: ω₁/ω₂ = (E₂/E₁)^{2/3}.
        let (e1, e2) = (2.3e11, 3.3e9);
        let s = squeeze(
            &UpperLaw::Elastic { modulus: e1 },
            &LayerLaw::Hertz { modulus: e2 },
            50e-9,
            2e-9,
        )
        .unwrap();
        let ratio = (e2 / e1).powf(2.0 / 3.0);
        let delta = 2e-9 / (1.0 + ratio);
        assert!((s.layer_penetration / delta - 1.0).abs() < 1e-13);
        assert!((s.upper_interference / (2e-9 - delta) - 1.0).abs() < 1e-13);
        let upper_force = UpperLaw::Elastic { modulus: e1 }.force(25e-9, s.upper_interference);
        assert!((upper_force / s.force - 1.0).abs() < 1e-13);
    }
}
