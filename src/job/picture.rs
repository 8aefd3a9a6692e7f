//! What every kind's picture shares. A kind draws its answer from a typed view of the
//! answer's JSON ([`crate::render::Picture`]: the parts of the output it shows, as the
//! output's own types), read back from the JSON, so that an answer solved in another
//! process, or assembled from parts, is drawn exactly as one solved here.

use serde::Deserialize;
use serde_json::Value;

use super::{Kind, Limits};
use crate::model::text::quantity_to;
use crate::render::RenderError;

/// Why an answer cannot be drawn: it is not the answer of the kind asked (a fault of ours).
pub type PictureError = RenderError;

/// An answer's `meta`, for its input: the canonical input of a job of kind `K`.
#[derive(Deserialize)]
pub struct Asked {
    input: Value,
}

impl Asked {
    /// The job the input reads back as (a canonical input always does).
    pub fn job<K: Kind>(self) -> Result<K, PictureError> {
        K::validate(self.input, &Limits::default())
            .map(|validated| validated.job)
            .map_err(|e| RenderError::new(format!("the answer's input does not read back: {e}")))
    }
}

/// `value` (SI) in the unit a person reads, with it: `25 nm`; to four digits, so that the
/// labels of close values in a legend differ.
pub fn shown(value: f64, unit: &str) -> String {
    quantity_to(value, unit, 4)
}

/// The symbol of a condition in a legend (`V = 4 nm/s`) or of a fitted parameter of the
/// layer (`E_L = 2.5 GPa`): the paper's, by its name on the wire.
pub fn symbol(name: &str) -> &str {
    match name {
        "velocity" => "V",
        "load" | "particle_load" => "P",
        "radius" => "R",
        "mean_diameter" => "x_a",
        "total_load" => "W",
        "separation" => "d",
        "elastic_modulus" => "E_L",
        "relaxation_time" => "T_σ",
        "retardation_time" => "T_ε",
        "thickness" => "H",
        other => other,
    }
}
