//! The y-quadrature of a rolling contact, as rolling and three-body inputs choose it.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::model::quadrature::{DEFAULT_GAUSS_NODES, DEFAULT_MIDPOINT_STRIPS};
use crate::model::Quadrature;

/// The y-quadrature: exact to 1e-9 (`gauss`) or the paper's uniform strips (`midpoint`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum QuadratureKind {
    #[default]
    Gauss,
    Midpoint,
}

impl QuadratureKind {
    /// The rule a job asks for: its kind (default Gauss) with `strips` nodes or strips
    /// (default 64 Gauss nodes, or the paper's 40 midpoint strips).
    pub fn rule(kind: Option<QuadratureKind>, strips: Option<usize>) -> Quadrature {
        match kind.unwrap_or_default() {
            QuadratureKind::Gauss => Quadrature::Gauss {
                nodes: strips.unwrap_or(DEFAULT_GAUSS_NODES),
            },
            QuadratureKind::Midpoint => Quadrature::Midpoint {
                strips: strips.unwrap_or(DEFAULT_MIDPOINT_STRIPS),
            },
        }
    }

    /// The kind and size of a rule, as an input names them (`quadrature`, `strips`).
    pub fn of(rule: Quadrature) -> (QuadratureKind, usize) {
        match rule {
            Quadrature::Gauss { nodes } => (QuadratureKind::Gauss, nodes),
            Quadrature::Midpoint { strips } => (QuadratureKind::Midpoint, strips),
        }
    }
}
