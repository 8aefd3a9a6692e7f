//! The Kelvin layer, as rolling and three-body inputs give it.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::{field, Checker, Quantity};
use crate::model::{Layer, Parameter};

/// How the layer gives way under the sphere (docs/model.md §8).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum LayerModel {
    /// The paper's local (Winkler) law: each point of the layer a spring, k = E_L/H. Exact
    /// for contacts much wider than the layer; the paper's model and its figures.
    #[default]
    Local,
    /// The layer as a viscoelastic solid bonded to a rigid base, solved on a grid: right at
    /// any width, and the answer for contacts a few thicknesses wide or narrower, where the
    /// local law overstates the area (the `local_layer` validity row says by how much).
    /// Rolling jobs and their sweeps; milliseconds to a second per answer.
    Continuum,
}

/// The Kelvin layer.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct LayerInput {
    /// How the layer gives way: `local` (default, the paper's law) or `continuum`.
    pub model: Option<LayerModel>,
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

    /// [`LayerInput::read`] where the layer's law is chosen elsewhere (a three-body
    /// system's `layer_contact`, named by `instead`): `model: "continuum"` is an error
    /// naming the field and saying where to ask.
    pub fn read_local(&self, checker: &mut Checker, instead: &str) -> Layer {
        if self.model == Some(LayerModel::Continuum) {
            checker.invalid(
                "model",
                "continuum".into(),
                &format!("\"local\" or absent: {instead}"),
            );
        }
        self.read(checker)
    }

    /// The input that gives `layer` under `model`: every field, in SI (`model` absent
    /// where only the local law is offered).
    pub fn of(layer: &Layer, model: Option<LayerModel>) -> LayerInput {
        LayerInput {
            model,
            elastic_modulus: Quantity::si(layer.elastic_modulus),
            thickness: Quantity::si(layer.thickness),
            poisson_ratio: Quantity::si(layer.poisson_ratio),
            retardation_time: Quantity::si(layer.retardation_time),
            relaxation_time: Quantity::si(layer.relaxation_time),
        }
    }
}
