//! `POST /v1/rolling`: one particle rolling over the layer, solved now.

use super::solve_endpoint;
use crate::job::rolling::{RollingInput, RollingJob, RollingOutput};

solve_endpoint!(
    /// Solve one rolling contact.
    ///
    /// The body is a rolling input: every field is optional and defaults to the paper's
    /// particle (R = 25 nm, P = 1 nN, V = 4 nm/s on a 100 nm, 3 GPa Kelvin layer), so `{}` is a
    /// valid job. Quantities are SI numbers or strings with units (`"25 nm"`). With
    /// `Accept: text/csv` the answer is one CSV row of the contact's integrals.
    "/v1/rolling",
    "solve_rolling",
    RollingJob,
    RollingInput,
    RollingOutput,
    "The contact: penetration, area, shifts, friction; the same at V = 0; the boundary; meta"
);
