//! The Kelvin layer, as rolling and three-body inputs give it.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::{field, Checker, Quantity};
use crate::model::{Layer, Parameter};

/// The Kelvin layer.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct LayerInput {
    /// E_L, relaxed longitudinal modulus (Pa; default 3 GPa).
    pub elastic_modulus: Option<Quantity>,
    /// H, layer thickness (m; default 100 nm).
    pub thickness: Option<Quantity>,
    /// ν, Poisson ratio (dimensionless; default 0.35).
    pub poisson_ratio: Option<Quantity>,
    /// T_ε, retardation time (s, ≥ T_σ; default 0.5 s).
    pub retardation_time: Option<Quantity>,
    /// T_σ, relaxation time (s; default 0.1 s).
    pub relaxation_time: Option<Quantity>,
}

impl LayerInput {
    /// Reads the layer under `checker` (inside its `nested` object).
    pub fn read(&self, checker: &mut Checker) -> Layer {
        let input = self;
        let d = Layer::default();
        Layer {
            elastic_modulus: checker.quantity(
                field!(input.elastic_modulus),
                Parameter::ElasticModulus,
                d.elastic_modulus,
            ),
            thickness: checker.quantity(field!(input.thickness), Parameter::Thickness, d.thickness),
            poisson_ratio: checker.quantity(
                field!(input.poisson_ratio),
                Parameter::PoissonRatio,
                d.poisson_ratio,
            ),
            retardation_time: checker.quantity(
                field!(input.retardation_time),
                Parameter::RetardationTime,
                d.retardation_time,
            ),
            relaxation_time: checker.quantity(
                field!(input.relaxation_time),
                Parameter::RelaxationTime,
                d.relaxation_time,
            ),
        }
    }

    /// The input that gives `layer`: every field, in SI.
    pub fn of(layer: &Layer) -> LayerInput {
        LayerInput {
            elastic_modulus: Quantity::si(layer.elastic_modulus),
            thickness: Quantity::si(layer.thickness),
            poisson_ratio: Quantity::si(layer.poisson_ratio),
            retardation_time: Quantity::si(layer.retardation_time),
            relaxation_time: Quantity::si(layer.relaxation_time),
        }
    }
}
