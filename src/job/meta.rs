//! What every answer says about itself: the model version, the canonical input and its hash,
//! and the papers behind the numbers.

use serde::{Deserialize, Serialize};

use serde_json::value::RawValue;
use serde_json::Value;
use sha2::{Digest, Sha256};
use utoipa::ToSchema;

use crate::model::MODEL_VERSION;
use crate::render::{Fixed, UnitTable};

/// A source of the model.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, ToSchema)]
pub struct Reference {
    /// What the service takes from it.
    pub role: &'static str,
    /// Authors, title, journal and year.
    pub citation: &'static str,
    /// The DOI, where the work has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub doi: Option<&'static str>,
}

/// Papers behind the numbers, a fixed part of answers.
pub type References = Fixed<&'static [Reference]>;

/// The papers behind the numbers: all of them behind three-body jobs.
pub static REFERENCES: References =
    Fixed::new(&[PAPER, STRIPS, SHEAR_STRENGTH, THREE_BODY, ASPERITIES]);

/// The papers behind one particle rolling over the layer under the local law: the model, the
/// strip method and the shear strength.
pub static ROLLING_REFERENCES: References = Fixed::new(&[PAPER, STRIPS, SHEAR_STRENGTH]);

/// The papers behind one particle rolling over the layer as a continuum (docs/model.md §8):
/// the model's layer and shear strength, the layer's compliance, the pixels' influence and
/// the solver.
pub static CONTINUUM_REFERENCES: References =
    Fixed::new(&[PAPER, SHEAR_STRENGTH, LAYER, PIXELS, SOLVER]);

/// The papers behind a three-body answer on the continuum layer contact: the model's and the
/// continuum's.
pub static THREE_BODY_CONTINUUM_REFERENCES: References = Fixed::new(&[
    PAPER,
    SHEAR_STRENGTH,
    THREE_BODY,
    ASPERITIES,
    LAYER,
    PIXELS,
    SOLVER,
]);

const PAPER: Reference = Reference {
    role: "model: three-body contact with particles rolling over a Kelvin layer (eqs. 1–13)",
    citation: "Contact problem of a system of particles rolling over a viscoelastic layer \
               bonded to the rigid half-space. Advances in Mechanical Engineering, 2019",
    doi: Some("10.1177/1687814019872303"),
};

const STRIPS: Reference = Reference {
    role: "strip method for rolling contact (eq. 10)",
    citation: "D. J. Haines and E. Ollerton, Contact stress distributions on elliptical \
               contact surfaces subjected to radial and tangential forces. Proceedings of \
               the Institution of Mechanical Engineers 177 (1963)",
    doi: None,
};

const SHEAR_STRENGTH: Reference = Reference {
    role: "interfacial shear strength τ_a = G/1000 (eq. 12)",
    citation: "G. G. Adams, S. Müftü and N. Mohd Azhar, A scale-dependent model for \
               multi-asperity contact and friction. Journal of Tribology 125 (2003)",
    doi: None,
};

const THREE_BODY: Reference = Reference {
    role: "three-body microcontact model: particles between rough surfaces (eqs. 6–8)",
    citation: "J. H. Horng's three-body microcontact model for rough surfaces, reference 16 \
               of the model paper",
    doi: None,
};

const ASPERITIES: Reference = Reference {
    role: "asperity contact: elastic, elastic-plastic and plastic regimes",
    citation: "Y. Zhao, D. M. Maietta and L. Chang, An asperity microcontact model \
               incorporating the transition from elastic deformation to fully plastic \
               flow. Journal of Tribology 122 (2000)",
    doi: None,
};

const LAYER: Reference = Reference {
    role: "the layer as a continuum: surface compliance of an elastic layer bonded to a rigid \
           base (eq. A.30)",
    citation: "G. Carbone and L. Mangialardi, Analysis of the adhesive contact of confined \
               layers by using a Green's function approach. Journal of the Mechanics and \
               Physics of Solids 56 (2008)",
    doi: None,
};

const PIXELS: Reference = Reference {
    role: "the half-space's deflection under a uniformly loaded rectangle (the grid's pixel)",
    citation: "A. E. H. Love, The stress produced in a semi-infinite solid by pressure on part \
               of the boundary. Philosophical Transactions of the Royal Society A 228 (1929)",
    doi: Some("10.1098/rsta.1929.0009"),
};

const SOLVER: Reference = Reference {
    role: "the contact pressure on the grid: constrained conjugate gradients with the load",
    citation: "I. A. Polonsky and L. M. Keer, A numerical method for solving rough contact \
               problems based on the multi-level multi-summation and conjugate gradient \
               techniques. Wear 231 (1999)",
    doi: Some("10.1016/S0043-1648(99)00113-1"),
};

/// The version of this software (the crate's).
pub const SOFTWARE_VERSION: &str = env!("CARGO_PKG_VERSION");
/// The git commit this binary was built from (`build.rs`), or `unknown`.
pub const GIT_COMMIT: &str = env!("THIRDBODY_GIT_COMMIT");

/// The software that computed an answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, ToSchema)]
pub struct Software {
    /// The crate's version (semver).
    pub version: &'static str,
    /// The git commit it was built from (`unknown` when built without one).
    pub commit: &'static str,
}

/// This software.
pub const SOFTWARE: Software = Software {
    version: SOFTWARE_VERSION,
    commit: GIT_COMMIT,
};

/// A valid value that is implausible as sent: a bare number far from its field's scale.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct InputWarning {
    /// Path of the field in the input.
    pub field: String,
    /// The value as sent.
    #[schema(value_type = serde_json::Value)]
    pub value: Value,
    /// What the value means, and the form the sender may have meant.
    pub message: String,
}

/// The `meta` block of an answer.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct Meta {
    /// Version of the model's numbers (semver): a new version may change results.
    pub model_version: &'static str,
    /// The software that computed the answer.
    pub software: Software,
    /// SHA-256 of the model version, the job kind and the canonical input (hex): the cache
    /// key, and the HTTP `ETag`.
    pub input_hash: String,
    /// The input as understood: defaults filled in, SI numbers.
    #[schema(value_type = Object)]
    pub input: Canonical,
    /// The papers behind the numbers.
    #[schema(value_type = Vec<Reference>)]
    pub references: &'static References,
    /// Values of the input that are valid but implausible as sent.
    pub warnings: Vec<InputWarning>,
    /// The unit of every numeric field of the answer, by its path (`boundary[].exit`);
    /// those of `meta.input` are the SI units of the input's fields.
    #[schema(value_type = std::collections::BTreeMap<String, String>)]
    pub units: &'static UnitTable,
}

/// A canonical input as its JSON text (keys sorted, no `null`), the text its hash is taken
/// of. Kept as text rather than as a [`Value`]: an answer then writes its input by copying,
/// and a cached answer holds one string rather than a tree of maps and keys, which cost more
/// to free when the answer is pushed out than the rest of the answer (BENCHMARKS.md,
/// issue 12).
#[derive(Clone, Debug, Serialize)]
#[serde(transparent)]
pub struct Canonical(Box<RawValue>);

impl Canonical {
    /// The canonical text of `input`, a canonical tree.
    pub fn new(input: &Value) -> Canonical {
        Canonical(serde_json::value::to_raw_value(input).expect("a JSON value writes as JSON"))
    }

    /// A canonical text written directly ([`crate::job::input::canonical_text`]), checked to
    /// be JSON once more (its cost is in BENCHMARKS.md's figures, issue 25).
    pub fn from_text(text: String) -> Canonical {
        Canonical(RawValue::from_string(text).expect("a canonical text is JSON"))
    }

    /// The JSON text.
    pub fn get(&self) -> &str {
        self.0.get()
    }
}

/// Equal texts, equal inputs: the form is canonical.
impl PartialEq for Canonical {
    fn eq(&self, other: &Canonical) -> bool {
        self.get() == other.get()
    }
}

impl Meta {
    /// The meta block of a job of `kind` whose canonical input is `input`, with the
    /// `warnings` its input raised and the `units` of its answer.
    pub fn new(
        kind: &str,
        input: Canonical,
        references: &'static References,
        warnings: Vec<InputWarning>,
        units: &'static UnitTable,
    ) -> Self {
        Meta {
            model_version: MODEL_VERSION,
            software: SOFTWARE,
            input_hash: input_hash(kind, input.get(), &warnings),
            input,
            references,
            warnings,
            units,
        }
    }

    /// One line saying where the answer comes from, for files that travel without their
    /// `meta` (CSV, SVG; [`crate::render::Format::with_provenance`] puts it in each):
    /// `thirdbody 0.1.0 (commit …), model 1.0.0, input sha256 …`.
    pub fn provenance(&self) -> String {
        provenance(&self.input_hash)
    }
}

/// The provenance line of the answer whose cache key is `input_hash` (see
/// [`Meta::provenance`]).
pub fn provenance(input_hash: &str) -> String {
    format!(
        "thirdbody {SOFTWARE_VERSION} (commit {GIT_COMMIT}), model {MODEL_VERSION}, \
         input sha256 {input_hash}"
    )
}

/// Hex SHA-256 of `model version \n kind \n canonical JSON` (keys sorted, shortest floats),
/// followed by the input's warnings if it raised any: an answer that carries warnings is
/// another answer than the same input's without them.
pub fn input_hash(kind: &str, canonical: &str, warnings: &[InputWarning]) -> String {
    let mut hasher = Sha256::new();
    hasher.update(MODEL_VERSION.as_bytes());
    hasher.update(b"\n");
    hasher.update(kind.as_bytes());
    hasher.update(b"\n");
    hasher.update(canonical.as_bytes());
    for warning in warnings {
        hasher.update(b"\n");
        hasher.update(warning.message.as_bytes());
    }
    // Hex by table: one allocation rather than one per byte (this runs on every request).
    const HEX: &[u8; 16] = b"0123456789abcdef";
    let mut hex = String::with_capacity(64);
    for byte in hasher.finalize() {
        hex.push(char::from(HEX[usize::from(byte >> 4)]));
        hex.push(char::from(HEX[usize::from(byte & 15)]));
    }
    hex
}
