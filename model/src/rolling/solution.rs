//! What a rolling solve answers, in SI units, and how far the answer can be trusted: kept apart
//! from the solver so the service's outputs and the continuum solver share one vocabulary.

use crate::limits::ElasticContact;

/// One point of the contact boundary: at lateral position y, material leaves the contact at
/// x = exit (trailing edge a(y)) and enters it at x = entry (leading edge b(y)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundaryPoint {
    pub y: f64,
    pub exit: f64,
    pub entry: f64,
}

/// Contact pressure p(x, y) (Pa) on a grid: `values[j][i]` is p(x[i], y[j]).
#[derive(Clone, Debug, PartialEq)]
pub struct PressureGrid {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub values: Vec<Vec<f64>>,
}

/// How far the answer can be trusted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Verification {
    /// |P(δ) − P|/P, with P(δ) recomputed from the returned penetration.
    pub load_residual: f64,
    /// A bound on the relative error of every quantity returned (δ, A, the half-width, x_c,
    /// x_p, μ, μ_r and the static companion) against the exact solution of docs/model.md §3:
    /// twice their largest relative change against a companion rule of half (for rules of
    /// fewer than 8 strips, twice) the strips, with the load residual, propagated through
    /// the load equation (`quadrature_error` in `rolling/section.rs`). Never below rounding
    /// (16 ε). A table answer reports the exact solver's bound near its ξ here, and
    /// `table_error` beside it: the two add up.
    pub quadrature_error_estimate: f64,
    /// Strips (quadrature nodes) in the half-width.
    pub quadrature_nodes: usize,
    /// Iterations of the load equation P(δ) = P: strip-sum passes under every rule of the
    /// nested solve (coarsest first), or table look-ups.
    pub iterations: u32,
    /// Newton steps of all exit-edge roots together (every rule's).
    pub exit_root_iterations: u32,
    /// Whether every root converged (a solution is only returned when it did).
    pub converged: bool,
    /// When the load equation was solved through the layer's similarity table rather than
    /// by strip sums: the table's certified bound on the relative difference from the exact
    /// solve ([`crate::similarity::SimilarityTable::error`]); the answer's error is then
    /// bounded by `quadrature_error_estimate + table_error`.
    pub table_error: Option<f64>,
}

/// The rolling contact (docs/model.md §3), in SI units, with how far it can be trusted:
/// [`Verification`] for the local law's exact solution, the grid's error for the layer as a
/// continuum ([`crate::continuum::GridVerification`]).
#[derive(Clone, Debug, PartialEq)]
pub struct RollingSolution<V = Verification> {
    /// δ (m).
    pub penetration: f64,
    /// A (m²).
    pub contact_area: f64,
    /// √(2Rδ) (m): lateral half-width of the contact, at every speed.
    pub half_width: f64,
    /// x_c (m), area centroid, positive in the rolling direction.
    pub centroid_shift: f64,
    /// x_p (m), centre of pressure.
    pub pressure_centre_shift: f64,
    /// μ_r = x_p/R, the hysteresis (rolling-resistance) coefficient; not part of eq. 12.
    pub rolling_resistance_coefficient: f64,
    /// μ = τ_a A / P (eq. 12).
    pub friction_coefficient: f64,
    /// The same sphere at V = 0 (closed form for the local law).
    pub static_contact: ElasticContact,
    pub boundary: Vec<BoundaryPoint>,
    pub pressure: Option<PressureGrid>,
    pub verification: V,
}

impl<V> RollingSolution<V> {
    /// The integral quantities an answer reports, in the order of the struct: δ, A,
    /// half-width, x_c, x_p, μ_r, μ, and the static companion's δ, A, μ.
    pub fn quantities(&self) -> [f64; 10] {
        [
            self.penetration,
            self.contact_area,
            self.half_width,
            self.centroid_shift,
            self.pressure_centre_shift,
            self.rolling_resistance_coefficient,
            self.friction_coefficient,
            self.static_contact.penetration,
            self.static_contact.contact_area,
            self.static_contact.friction_coefficient,
        ]
    }
}
