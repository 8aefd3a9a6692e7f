//! The counterface a particle rolls against (docs/model.md §4, §11): one input for a single
//! particle's upper surface and a three-body system's.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::units::Dimension;
use super::{field, Checker, Quantity};
use crate::model::counterface::{UpperContact, UpperSurface};
use crate::model::Parameter;

/// The upper surface (default steel, 210 GPa, ν = 0.3, elastic).
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct UpperSurfaceInput {
    /// E₁ (Pa).
    pub elastic_modulus: Option<Quantity>,
    /// ν₁.
    pub poisson_ratio: Option<Quantity>,
    pub contact: Option<UpperContactKind>,
    /// H₁ (Pa), required for plastic contact.
    pub hardness: Option<Quantity>,
    /// τ_u (Pa), the shear strength of a particle's contact with the surface: the most
    /// tangential force per contact area it transmits before the particle slides on it
    /// (docs/model.md §11). Default G₁/1000, as the layer's τ_a = G/1000.
    pub shear_strength: Option<Quantity>,
}

/// Elastic (Hertz) or plastic contact of the particles with the upper surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum UpperContactKind {
    Elastic,
    Plastic,
}

impl UpperSurfaceInput {
    pub fn read(&self, checker: &mut Checker) -> UpperSurface {
        let input = self;
        let u0 = UpperSurface::default();
        let contact = match self.contact {
            Some(UpperContactKind::Plastic) => UpperContact::Plastic,
            _ => UpperContact::Elastic,
        };
        let upper = UpperSurface {
            elastic_modulus: checker.quantity(
                field!(input.elastic_modulus),
                Parameter::UpperModulus,
                u0.elastic_modulus,
            ),
            poisson_ratio: checker.quantity(
                field!(input.poisson_ratio),
                Parameter::UpperPoissonRatio,
                u0.poisson_ratio,
            ),
            contact,
            hardness: checker.optional(field!(input.hardness), Parameter::UpperHardness),
            shear_strength: checker
                .optional(field!(input.shear_strength), Parameter::UpperShearStrength),
        };
        if contact == UpperContact::Plastic && upper.hardness.is_none() {
            checker.missing(
                field!(input.hardness).name,
                &Dimension::PRESSURE.describe(),
                "for plastic contact",
            );
        }
        upper
    }

    pub fn of(upper: &UpperSurface) -> UpperSurfaceInput {
        UpperSurfaceInput {
            elastic_modulus: Quantity::si(upper.elastic_modulus),
            poisson_ratio: Quantity::si(upper.poisson_ratio),
            contact: Some(match upper.contact {
                UpperContact::Elastic => UpperContactKind::Elastic,
                UpperContact::Plastic => UpperContactKind::Plastic,
            }),
            hardness: upper.hardness.and_then(Quantity::si),
            shear_strength: upper.shear_strength.and_then(Quantity::si),
        }
    }
}
