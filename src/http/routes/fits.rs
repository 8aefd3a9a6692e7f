//! `POST /v1/fits`: the layer's parameters fitted to measured points, solved now.

use super::solve_endpoint;
use crate::job::fit::{FitInput, FitJob, FitOutput};

solve_endpoint!(
    /// Fit the layer to measurements.
    ///
    /// Measured friction coefficients or contact areas (series of points, each an operating
    /// condition and a value, with an optional standard uncertainty) and the layer's
    /// parameters to fit (`relaxation_time`, `retardation_time` or `kappa`,
    /// `elastic_modulus`, `thickness` or `k`, `modulus_scale`, `shift_factor`, each with a
    /// start and bounds). The answer gives
    /// the best values with standard errors, 95 % intervals and correlations, χ², the
    /// residuals, the fitted curves, and which parameters the data determine. Answered
    /// within the solve deadline; a larger fit belongs in `POST /v1/jobs` (kind `fit`), which
    /// reports progress and can be cancelled; a fit of rolling points on the layer as a
    /// continuum (`layer.model`), which takes minutes, is refused here with 422 and runs
    /// there. With `Accept: text/csv`: one row per point.
    "/v1/fits",
    "solve_fit",
    FitJob,
    FitInput,
    FitOutput,
    "The fitted parameters, their uncertainty, residuals, curves and identifiability"
);
