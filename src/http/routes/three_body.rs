//! `POST /v1/three-body`: a population of particles between the upper surface and the
//! layer, solved now.

use super::solve_endpoint;
use crate::job::three_body::{ThreeBodyInput, ThreeBodyJob, ThreeBodyOutput};

solve_endpoint!(
    /// Solve one three-body system.
    ///
    /// The body is a three-body input: every field is optional and defaults to the paper's
    /// system (1 mm², 1e12 particles/m² of 50 ± 5 nm, steel on the default Kelvin layer,
    /// V = 4 nm/s) except the operating point, exactly one of `separation`, `total_load` or
    /// `particle_load`. Quantities are SI numbers or strings with units (`"1 mN"`). With
    /// `Accept: text/csv` the answer is one CSV row, as a sweep's.
    "/v1/three-body",
    "solve_three_body",
    ThreeBodyJob,
    ThreeBodyInput,
    ThreeBodyOutput,
    "The system at its operating point: separation, particles in contact, areas, loads, \
     friction with and without rolling, per-particle means; meta"
);
