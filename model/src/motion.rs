//! Roll or slide (docs/model.md §11): whether a particle's two contacts can supply the
//! tangential force that rolling needs, and the friction the particle then transmits.
//!
//! The paper assumes every particle rolls and reports eq. 12's μ = τ_a A/P, a sliding law.
//! Moments about the particle's centre give 2RT = P(x_p,u + x_p,l): rolling needs the
//! tangential force per load μ_roll = (μ_r,u + μ_r,l)/2, and contact i can transmit at most
//! μ_cap,i = τ_i A_i/P. The particle rolls iff μ_roll ≤ both capacities; otherwise it slides
//! at the weaker contact, whose capacity is then its friction. Either way the friction is
//! min(μ_roll, μ_cap,u, μ_cap,l): continuous where the mode changes.

use crate::counterface::UpperSurface;

/// How a particle moves between the two surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Mode {
    /// Both contacts hold the tangential force rolling needs.
    Rolls,
    /// The layer contact gives way first: the particle slides on the layer.
    SlidesAtLayer,
    /// The upper contact gives way first: the particle slides against the upper surface.
    SlidesAtUpper,
}

/// The tangential balance of one particle, per unit of its normal load.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    pub mode: Mode,
    /// μ_roll = (μ_r,u + μ_r,l)/2: the tangential force per load that rolling needs.
    pub rolling_need: f64,
    /// μ_cap,u = τ_u A_u/P: the most the upper contact can transmit, per load.
    pub upper_capacity: f64,
    /// μ_cap,l = τ_a A_l/P: the most the layer contact can transmit, per load (eq. 12's μ).
    pub layer_capacity: f64,
    /// T/P, the particle's friction: μ_roll when it rolls, the weaker capacity when it
    /// slides.
    pub friction: f64,
}

impl Motion {
    /// The balance of a particle whose contacts have rolling-resistance coefficients
    /// μ_r,u and μ_r,l (x_p/R at each) and capacities μ_cap,u and μ_cap,l. At a tie
    /// between the capacities the layer is named (the paper's sliding contact).
    pub fn new(
        upper_resistance: f64,
        layer_resistance: f64,
        upper_capacity: f64,
        layer_capacity: f64,
    ) -> Motion {
        let rolling_need = 0.5 * (upper_resistance + layer_resistance);
        let weaker = upper_capacity.min(layer_capacity);
        let mode = if rolling_need <= weaker {
            Mode::Rolls
        } else if layer_capacity <= upper_capacity {
            Mode::SlidesAtLayer
        } else {
            Mode::SlidesAtUpper
        };
        Motion {
            mode,
            rolling_need,
            upper_capacity,
            layer_capacity,
            friction: rolling_need.min(weaker),
        }
    }

    /// The weaker contact's capacity over what rolling needs: at least 1 when the particle
    /// rolls (infinite when rolling needs nothing).
    pub fn margin(&self) -> f64 {
        self.upper_capacity.min(self.layer_capacity) / self.rolling_need
    }
}

/// The balance of a single rigid particle of radius `radius` under `load` between `upper`
/// (its contact solved here: Hertz, or plastic) and a layer contact of area `layer_area`
/// and rolling-resistance coefficient `layer_resistance`, on a layer of interfacial shear
/// strength `layer_shear_strength` (τ_a). The upper contact is elastic, or plastic without
/// hysteresis: μ_r,u = 0.
pub fn particle(
    radius: f64,
    load: f64,
    layer_resistance: f64,
    layer_area: f64,
    layer_shear_strength: f64,
    upper: &UpperSurface,
) -> Motion {
    let law = upper.law(0.0);
    let upper_area = law.area(radius, law.interference(radius, load));
    Motion::new(
        0.0,
        layer_resistance,
        upper.shear_strength() * upper_area / load,
        layer_shear_strength * layer_area / load,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_weaker_contact_gives_way_and_the_friction_is_continuous() {
        let rolls = Motion::new(0.0, 0.04, 0.05, 0.09);
        assert_eq!(rolls.mode, Mode::Rolls);
        assert_eq!(rolls.friction, 0.02);
        assert_eq!(rolls.margin(), 2.5);
        let at_layer = Motion::new(0.0, 0.04, 0.05, 0.01);
        assert_eq!(at_layer.mode, Mode::SlidesAtLayer);
        assert_eq!(at_layer.friction, 0.01);
        let at_upper = Motion::new(0.0, 0.04, 0.01, 0.05);
        assert_eq!(at_upper.mode, Mode::SlidesAtUpper);
        assert_eq!(at_upper.friction, 0.01);
        // At the changeover both modes give the same friction.
        let edge = Motion::new(0.0, 0.04, 0.05, 0.02);
        assert_eq!(edge.mode, Mode::Rolls);
        assert_eq!(
            edge.friction,
            Motion::new(0.0, 0.04 + 1e-15, 0.05, 0.02).friction
        );
        // At rest rolling needs nothing: it always rolls.
        let at_rest = Motion::new(0.0, 0.0, 0.05, 0.02);
        assert_eq!((at_rest.mode, at_rest.friction), (Mode::Rolls, 0.0));
        assert!(at_rest.margin().is_infinite());
    }
}
