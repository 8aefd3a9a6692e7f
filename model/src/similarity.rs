//! The similarity law as a table: the rolling contact at a given penetration, for one κ, as
//! four smooth functions of one variable (docs/model.md §3).
//!
//! At a penetration δ, with r = √(2Rδ), the ratios Φ_P = P/(πkRδ²), Φ_A = A/(2πRδ),
//! x_c/r and x_p/r depend only on ξ = V T_σ/r and κ. The strip solver computes them exactly
//! (≈ 10 µs for the four); this table evaluates them in well under a microsecond, so that a
//! rolling answer at a given load ([`super::rolling`]) and every diameter of a three-body
//! system ([`super::three_body`]) cost a few table look-ups instead of strip sums.
//!
//! The variable is v = (u − 1)/(u + 1), u = √((1 + κ)ξ), which maps ξ ∈ [0, ∞] onto [−1, 1],
//! centres the viscous transition (it starts where V T_ε ≈ r) and keeps both ends smooth
//! (expansions in √ξ near 0 and in 1/√ξ near ∞). The two shifts vanish at both ends like ξ and
//! 1/ξ, so they are tabulated divided by w(v) = (1 − v²)²: then their *relative* error stays
//! as small as the others' right up to the ends.
//!
//! Building: the exact ratios at N Chebyshev points of the first kind, one global Chebyshev
//! series through them, then that series re-expanded on [`PANELS`] panels (equal in
//! s = (√u − 1)/(√u + 1)) as short local
//! series (truncated where their coefficients fall below rounding), which is what an
//! evaluation sums. The table is then certified against exact solves at points between its
//! own ([`SimilarityTable::error`]).

use std::f64::consts::PI;

use nalgebra::DMatrix;

use super::ModelError;

/// The four ratios of the contact at a given penetration (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ratios {
    /// Φ_P = P/(πkRδ²): 1 at ξ = 0, 1 + κ at ξ = ∞.
    pub load: f64,
    /// Φ_A = A/(2πRδ): 1 at both ends, below in between.
    pub area: f64,
    /// x_c/r, r = √(2Rδ): 0 at both ends, positive in between.
    pub centroid: f64,
    /// x_p/r: 0 at both ends, positive in between.
    pub pressure_centre: f64,
}

impl Ratios {
    /// ξ = 0: the relaxed elastic contact.
    pub const STATIC: Ratios = Ratios {
        load: 1.0,
        area: 1.0,
        centroid: 0.0,
        pressure_centre: 0.0,
    };

    fn as_array(&self) -> [f64; 4] {
        [self.load, self.area, self.centroid, self.pressure_centre]
    }
}

/// [`Ratios`] with Φ_P as its logarithm ([`SimilarityTable::log_ratios`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogRatios {
    /// ln Φ_P.
    pub log_load: f64,
    pub area: f64,
    pub centroid: f64,
    pub pressure_centre: f64,
}

impl LogRatios {
    pub fn ratios(&self) -> Ratios {
        Ratios {
            load: self.log_load.exp(),
            area: self.area,
            centroid: self.centroid,
            pressure_centre: self.pressure_centre,
        }
    }
}

impl From<Ratios> for LogRatios {
    fn from(r: Ratios) -> Self {
        LogRatios {
            log_load: r.load.ln(),
            area: r.area,
            centroid: r.centroid,
            pressure_centre: r.pressure_centre,
        }
    }
}

/// The exact ratios at one ξ and the quadrature error estimate of the rule that computed them
/// (what [`super::rolling::Verification::quadrature_error_estimate`] would report there).
pub type ExactRatios = (Ratios, f64);

/// Panels on which the table is evaluated, equal in s = (√u − 1)/(√u + 1).
const PANELS: usize = 128;
/// Samples (and so the largest number of coefficients) of each panel's local series.
const PANEL_SAMPLES: usize = 24;
/// Samples of a panel summed side by side ([`clenshaw_at`]); divides [`PANEL_SAMPLES`].
const SIDE_BY_SIDE: usize = 4;
const _: () = assert!(PANEL_SAMPLES % SIDE_BY_SIDE == 0);
/// A panel's series stops where the coefficients left out add up to less than this part of
/// the function's size there: far below the 1e-9 promised, and above the rounding noise of
/// the global series, which would otherwise keep every coefficient.
const TRUNCATION: f64 = 1e-14;
/// Points between the table's own at which [`SimilarityTable::build`] compares it with exact
/// solves.
const CHECK_POINTS: usize = 64;
/// The certified error is this many times the largest difference found at the check points:
/// a rolling answer carries a ratio's error through the load equation into δ, A, x_c and x_p
/// at most about twice, and the exact solve it is compared with stops its own load root at a
/// residual of 1e-14, which at the table's level of error (≈ 1e-14) doubles it again.
const PROPAGATION: f64 = 4.0;

/// Chebyshev points of the global series for viscosity strength κ. The transition of Φ
/// spans ξ from about 1/(1 + κ) to 1, wider as κ grows; these sizes keep every ratio within
/// 1e-11 of the exact solve over all ξ for κ up to 1e4 (tested; at κ = 1e4 what is left is
/// the exact solver's own rounding, 384 points do no better), and larger κ get the largest
/// table.
pub fn table_points(kappa: f64) -> usize {
    if kappa <= 100.0 {
        128
    } else if kappa <= 1e4 {
        256
    } else {
        512
    }
}

/// The four ratios of one κ as functions of ξ (see the module doc).
#[derive(Clone, Debug)]
pub struct SimilarityTable {
    kappa: f64,
    /// Local Chebyshev coefficients, panel after panel, each for the four functions
    /// (ln Φ_P, Φ_A, x_c/(r w), x_p/(r w)); only those that matter are kept.
    coefficients: Vec<[f64; 4]>,
    /// Where each panel's coefficients start in `coefficients` (and, last, where they end).
    starts: [usize; PANELS + 1],
    /// The largest quadrature error estimate of the global points on each panel and on its
    /// two neighbours.
    quadrature_errors: [f64; PANELS],
    /// See [`SimilarityTable::error`].
    error: f64,
}

impl SimilarityTable {
    /// Tabulates the ratios of viscosity strength κ > 0 from `exact`, which solves the contact
    /// at a given ξ (with the rule the table then stands for), and certifies the result.
    pub fn build(
        kappa: f64,
        exact: impl Fn(f64) -> Result<ExactRatios, ModelError>,
    ) -> Result<SimilarityTable, ModelError> {
        let n = table_points(kappa);
        let mut values = Vec::with_capacity(n);
        let mut on_panel = [0.0_f64; PANELS];
        for j in 0..n {
            // v = cos θ, w = (1 − v²)² = sin⁴θ, without cancellation.
            let theta = PI * (j as f64 + 0.5) / n as f64;
            let (ratios, quadrature_error) = exact(xi_at(theta, kappa))?;
            values.push(normalised(&ratios, theta.sin().powi(4)));
            let panel = panel_of((0.25 * PI - 0.5 * theta).tan());
            on_panel[panel] = on_panel[panel].max(quadrature_error);
        }
        let quadrature_errors: [f64; PANELS] = std::array::from_fn(|p| {
            on_panel[p.saturating_sub(1)..(p + 2).min(PANELS)]
                .iter()
                .fold(0.0_f64, |worst, e| worst.max(*e))
        });
        let global = chebyshev_coefficients(&dct(n), &values);
        let panel_transform = dct(PANEL_SAMPLES);
        let nodes: [f64; PANEL_SAMPLES] =
            std::array::from_fn(|i| (PI * (i as f64 + 0.5) / PANEL_SAMPLES as f64).cos());
        let mut coefficients = Vec::with_capacity(PANELS * PANEL_SAMPLES);
        let mut starts = [0; PANELS + 1];
        for panel in 0..PANELS {
            let samples: Vec<[f64; 4]> = nodes
                .chunks_exact(SIDE_BY_SIDE)
                .flat_map(|ts| {
                    let xs: [f64; SIDE_BY_SIDE] = std::array::from_fn(|k| {
                        let s = panel_centre(panel) + ts[k] / PANELS as f64;
                        2.0 * s / (1.0 + s * s)
                    });
                    clenshaw_at(&global, xs)
                })
                .collect();
            let local = chebyshev_coefficients(&panel_transform, &samples);
            coefficients.extend_from_slice(&local[..significant_terms(&local)]);
            starts[panel + 1] = coefficients.len();
        }
        let mut table = SimilarityTable {
            kappa,
            coefficients,
            starts,
            quadrature_errors,
            error: 0.0,
        };
        table.error = table.certify(&exact)?;
        Ok(table)
    }

    /// κ the table was built for.
    pub fn kappa(&self) -> f64 {
        self.kappa
    }

    /// A bound on the relative difference between what the table gives and what the exact
    /// solver (with the same rule) gives, for every ratio and every quantity of a rolling
    /// answer derived from them: [`PROPAGATION`] times the largest relative difference of
    /// any ratio at the check points, which lie between the table's own points over the
    /// whole range of ξ. Never below rounding.
    pub fn error(&self) -> f64 {
        self.error
    }

    /// The four ratios at ξ ≥ 0 (∞ allowed).
    pub fn ratios(&self, xi: f64) -> Ratios {
        self.end(xi).unwrap_or_else(|| self.log_ratios(xi).ratios())
    }

    /// The exact ratios at the ends ξ = 0 (the relaxed contact) and ξ = ∞ (the
    /// instantaneous one); `None` between.
    fn end(&self, xi: f64) -> Option<Ratios> {
        if xi == 0.0 {
            Some(Ratios::STATIC)
        } else if xi.is_infinite() {
            Some(Ratios {
                load: 1.0 + self.kappa,
                ..Ratios::STATIC
            })
        } else {
            None
        }
    }

    /// The four ratios at ξ ≥ 0 (∞ allowed), with Φ_P as its logarithm, as the table holds
    /// it: the load equation of a rolling answer is in ln Φ_P, and taking the logarithm
    /// there on every step was a fifth of the answer's time.
    pub fn log_ratios(&self, xi: f64) -> LogRatios {
        if let Some(end) = self.end(xi) {
            return end.into();
        }
        let u = (xi * (1.0 + self.kappa)).sqrt();
        let s = panel_variable(u);
        let panel = panel_of(s);
        let [log_load, area, centroid, pressure_centre] = clenshaw(
            &self.coefficients[self.starts[panel]..self.starts[panel + 1]],
            ((s - panel_centre(panel)) * PANELS as f64).clamp(-1.0, 1.0),
        );
        // w = (1 − v²)² = (4u/(1 + u)²)², exact where 1 − v would lose digits.
        let w = (4.0 * u / ((1.0 + u) * (1.0 + u))).powi(2);
        LogRatios {
            log_load,
            area,
            centroid: centroid * w,
            pressure_centre: pressure_centre * w,
        }
    }

    /// The exact solver's quadrature error estimate near ξ: the largest at the table points
    /// of ξ's panel and of the panels on either side.
    pub fn quadrature_error(&self, xi: f64) -> f64 {
        let s = if xi.is_infinite() {
            1.0
        } else {
            panel_variable((xi * (1.0 + self.kappa)).sqrt())
        };
        self.quadrature_errors[panel_of(s)]
    }

    /// [`PROPAGATION`] times the largest relative difference between the table and `exact`
    /// at [`CHECK_POINTS`] points halfway (in θ) between the table's own, spread over the
    /// range.
    fn certify(
        &self,
        exact: &impl Fn(f64) -> Result<ExactRatios, ModelError>,
    ) -> Result<f64, ModelError> {
        /// The table never claims less than rounding.
        const ROUNDING: f64 = 4.0 * f64::EPSILON;
        let n = table_points(self.kappa);
        let mut worst: f64 = 0.0;
        for k in 0..CHECK_POINTS {
            let j = (2 * k + 1) * (n - 1) / (2 * CHECK_POINTS);
            let xi = xi_at(PI * (j as f64 + 1.0) / n as f64, self.kappa);
            let (truth, _) = exact(xi)?;
            let table = self.ratios(xi);
            for (t, e) in table.as_array().into_iter().zip(truth.as_array()) {
                if e != t {
                    worst = worst.max(((t - e) / e).abs());
                }
            }
        }
        Ok((PROPAGATION * worst).max(ROUNDING))
    }
}

/// The tabulated functions at one point: ln Φ_P, Φ_A, and the shifts divided by
/// w = (1 − v²)².
fn normalised(ratios: &Ratios, w: f64) -> [f64; 4] {
    [
        ratios.load.ln(),
        ratios.area,
        ratios.centroid / w,
        ratios.pressure_centre / w,
    ]
}

/// ξ at the angle θ of v = cos θ: u = (1 + v)/(1 − v) = cot²(θ/2) (without the
/// cancellation of 1 − v), ξ = u²/(1 + κ).
fn xi_at(theta: f64, kappa: f64) -> f64 {
    let u = 1.0 / (0.5 * theta).tan().powi(2);
    u * u / (1.0 + kappa)
}

/// s = (√u − 1)/(√u + 1) ∈ [−1, 1], the variable the panels divide equally.
fn panel_variable(u: f64) -> f64 {
    let q = u.sqrt();
    (q - 1.0) / (q + 1.0)
}

/// The panel of s ∈ [−1, 1].
fn panel_of(s: f64) -> usize {
    (((s + 1.0) * 0.5 * PANELS as f64) as usize).min(PANELS - 1)
}

/// The centre of `panel` in s = (√u − 1)/(√u + 1) = tan(π/4 − θ/2) (v = cos θ = 2s/(1 + s²)).
/// Panels are 2/PANELS wide in s: within a factor 2 of equal in θ, so as fine near the ends
/// of v as the global points are, and found without an inverse cosine.
fn panel_centre(panel: usize) -> f64 {
    -1.0 + (2 * panel + 1) as f64 / PANELS as f64
}

/// Chebyshev coefficients cₖ of the series Σ cₖ Tₖ(x) through values at the n points of the
/// first kind xⱼ = cos(π(j + ½)/n): the discrete cosine transform `transform` ([`dct`] of
/// n), as one matrix product for the four functions.
fn chebyshev_coefficients(transform: &DMatrix<f64>, values: &[[f64; 4]]) -> Vec<[f64; 4]> {
    let coefficients = transform * DMatrix::from_fn(values.len(), 4, |j, f| values[j][f]);
    coefficients
        .row_iter()
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect()
}

/// The n × n matrix of the discrete cosine transform, (2 − δₖ₀)/n · cos(πk(2j + 1)/2n).
/// Built once per table for its 128 panels (each panel built its own, and their cosines were
/// a quarter of a table's build). Its angles take only 4n values, but looking them up
/// (k(2j + 1) mod 4n) instead moved the table's answers at the fast end by 2e-14, past what
/// its certification sees: the cosines are computed as they always were.
fn dct(n: usize) -> DMatrix<f64> {
    DMatrix::from_fn(n, n, |k, j| {
        let scale = if k == 0 { 1.0 } else { 2.0 } / n as f64;
        scale * (PI * (k * (2 * j + 1)) as f64 / (2 * n) as f64).cos()
    })
}

/// The number of leading coefficients that matter: trailing ones whose magnitudes add up to
/// less than [`TRUNCATION`] of every function's size on the panel are dropped.
fn significant_terms(coefficients: &[[f64; 4]]) -> usize {
    let size = coefficients.iter().fold([0.0_f64; 4], |size, c| {
        [0, 1, 2, 3].map(|f| size[f].max(c[f].abs()))
    });
    let mut dropped = [0.0; 4];
    let mut length = coefficients.len();
    while length > 1 {
        let c = coefficients[length - 1];
        let next = [0, 1, 2, 3].map(|f| dropped[f] + c[f].abs());
        if (0..4).any(|f| next[f] > TRUNCATION * size[f]) {
            break;
        }
        dropped = next;
        length -= 1;
    }
    length
}

/// Σ cₖ Tₖ(x) for the four functions at once (Clenshaw's recurrence).
#[inline]
fn clenshaw(coefficients: &[[f64; 4]], x: f64) -> [f64; 4] {
    clenshaw_at(coefficients, [x])[0]
}

/// [`clenshaw`] at K points at once. Written out lane by lane: this is the inner loop of
/// every table answer, and `array::map` here was not inlined (15 % of a sweep's time). A
/// table's build sums its global series at every panel's samples: K of them side by side
/// keep the processor busy where one waited on each step's result (a sixth of a cold
/// build), and each point's sums are the same operations, so the same bits.
#[inline]
fn clenshaw_at<const K: usize>(coefficients: &[[f64; 4]], xs: [f64; K]) -> [[f64; 4]; K] {
    let (mut b1, mut b2) = ([[0.0; 4]; K], [[0.0; 4]; K]);
    for c in coefficients[1..].iter().rev() {
        for k in 0..K {
            let (two_x, b1k, b2k) = (2.0 * xs[k], b1[k], b2[k]);
            b1[k] = [
                c[0] + two_x * b1k[0] - b2k[0],
                c[1] + two_x * b1k[1] - b2k[1],
                c[2] + two_x * b1k[2] - b2k[2],
                c[3] + two_x * b1k[3] - b2k[3],
            ];
            b2[k] = b1k;
        }
    }
    let c = coefficients[0];
    let mut sums = [[0.0; 4]; K];
    for k in 0..K {
        let (x, b1k, b2k) = (xs[k], b1[k], b2[k]);
        sums[k] = [
            c[0] + x * b1k[0] - b2k[0],
            c[1] + x * b1k[1] - b2k[1],
            c[2] + x * b1k[2] - b2k[2],
            c[3] + x * b1k[3] - b2k[3],
        ];
    }
    sums
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth stand-in for the contact: the table must reproduce it to rounding.
    fn stand_in(xi: f64) -> Result<ExactRatios, ModelError> {
        let (s, rest) = (xi / (1.0 + xi), 1.0 / (1.0 + xi)); // s and 1 − s
        Ok((
            Ratios {
                load: 1.0 + 4.0 * s,
                area: 1.0 - 0.3 * s * rest,
                centroid: s * rest,
                pressure_centre: 2.0 * s * rest / (1.0 + s),
            },
            1e-12 * (1.0 + s),
        ))
    }

    #[test]
    fn a_smooth_stand_in_is_reproduced_to_1e_12_with_exact_ends() {
        let table = SimilarityTable::build(4.0, stand_in).unwrap();
        assert!(table.error() < 1e-12, "{:e}", table.error());
        for i in 0..=400 {
            let xi = 10f64.powf(-12.0 + 24.0 * f64::from(i) / 400.0 + 0.0071);
            let (truth, _) = stand_in(xi).unwrap();
            let got = table.ratios(xi);
            for (t, e) in got.as_array().into_iter().zip(truth.as_array()) {
                assert!(((t - e) / e).abs() < 1e-12, "ξ = {xi:e}: {t} vs {e}");
            }
        }
        assert_eq!(table.ratios(0.0), Ratios::STATIC);
        assert_eq!(table.ratios(f64::INFINITY).load, 5.0);
        assert_eq!(table.ratios(f64::INFINITY).centroid, 0.0);
    }

    #[test]
    fn the_quadrature_error_is_the_largest_of_the_nearby_points() {
        let table = SimilarityTable::build(4.0, stand_in).unwrap();
        for xi in [0.0, 1e-9, 0.2, 1.0, 1e9, f64::INFINITY] {
            let (_, near) = stand_in(xi.min(1e300)).unwrap();
            let reported = table.quadrature_error(xi);
            assert!(
                reported >= near * (1.0 - 1e-3) && reported <= 2e-12,
                "ξ = {xi:e}: {reported:e} vs {near:e}"
            );
        }
    }

    #[test]
    fn a_failing_exact_solve_fails_the_build() {
        let failing = |_: f64| -> Result<ExactRatios, ModelError> {
            Err(ModelError::NoConvergence {
                what: "test",
                iterations: 1,
            })
        };
        assert!(SimilarityTable::build(4.0, failing).is_err());
    }
}
