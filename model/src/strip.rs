//! One strip y = const of a sphere rolling over a Kelvin layer: the exact solution of
//! docs/model.md §3 (eq. 5 integrated along x with p = 0 at the entry edge).
//!
//! Every function here works in any consistent length unit and returns its quantity divided
//! by the stiffness factor it carries (k/R for loads, k/2R for pressures): the caller scales.
//! The exit edge is carried as ρ = 1 + a/b ∈ [0, 2): ρ = 0 is the symmetric static strip
//! a = −b, so the small asymmetry of slow rolling is resolved to full relative precision.

use super::quadrature::gauss_legendre_16;
use super::special::{exprel2, exprel3, exprel_kernels};
use super::ModelError;

/// Strips with β = b/λ_σ below this are "fast": their pressure is nearly the instantaneous
/// elastic one, and the exit root and the moment are written around that limit.
const FAST_STRIP: f64 = 1.0;

/// A Newton step this small (relative to ρ) leaves an error below rounding.
const NEWTON_SETTLED: f64 = 1e-9;
/// Newton steps allowed for one exit root before the solver reports non-convergence.
const MAX_ROOT_ITERATIONS: u32 = 100;

/// The viscous state of one strip: its entry half-chord b and the relaxation length V T_σ.
#[derive(Clone, Copy, Debug)]
pub struct Strip {
    /// Entry edge b = √(2Rδ − y²) (> 0).
    pub entry: f64,
    /// λ_σ = V T_σ (0 for a sphere at rest).
    pub relaxation_length: f64,
    /// κ = (T_ε − T_σ)/T_σ ≥ 0 ([`super::Layer::kappa`]).
    pub kappa: f64,
}

/// An exit root and the Newton steps it took.
#[derive(Clone, Copy, Debug)]
pub struct ExitRoot {
    /// ρ = 1 + a/b.
    pub rho: f64,
    pub iterations: u32,
}

impl Strip {
    /// Whether the strip is elastic (at rest, or a layer without viscosity): then a = −b.
    fn is_elastic(&self) -> bool {
        self.relaxation_length == 0.0 || self.kappa == 0.0
    }

    /// λ_ε = V T_ε = (1 + κ) λ_σ.
    pub fn retardation_length(&self) -> f64 {
        (1.0 + self.kappa) * self.relaxation_length
    }

    /// The exit edge: the root ρ ∈ (0, 2) of g(ρ) = −G(s)/(s − 1), s = ρ − 1 (docs/model.md §3),
    ///
    /// g(ρ) = ρ + 2κ [E₁(z) + σ E₂(z)],  σ = ρ − 2,  z = βσ,  β = b/λ_σ,
    ///
    /// with E₁ = exprel and E₂ = [`exprel2`] (see [`exprel_kernels`]). For fast strips (β < 1) the terms 2κ and
    /// 2κσE₂ nearly cancel; there the identical form
    /// g(ρ) = ρ(1 + κ + κβ) − 2κβ + 2κβ(1 + β)σ²E₃(z), E₃ = [`exprel3`], is used instead.
    /// g′(ρ) = 1 + 2κ(β + 1)E₁′(z) > 0 and g is
    /// convex, g(0) < 0 < g(2): exactly one root, and Newton steps from any point land on the
    /// right of it and then descend monotonically. A bisection bracket guards every step.
    /// `guess` (e.g. the root of the same strip at a nearby load) only saves iterations.
    pub fn exit_root(&self, guess: Option<f64>) -> Result<ExitRoot, ModelError> {
        if self.is_elastic() {
            return Ok(ExitRoot {
                rho: 0.0,
                iterations: 0,
            });
        }
        let (beta, kappa) = (self.beta(), self.kappa);
        let g = |rho: f64| {
            let sigma = rho - 2.0;
            let z = beta * sigma;
            let (e1, e2, e1_prime) = exprel_kernels(z);
            let value = if beta < FAST_STRIP {
                rho * (1.0 + kappa + kappa * beta) - 2.0 * kappa * beta
                    + 2.0 * kappa * beta * (1.0 + beta) * sigma * sigma * exprel3(z)
            } else {
                rho + 2.0 * kappa * (e1 + sigma * e2)
            };
            let slope = 1.0 + 2.0 * kappa * (beta + 1.0) * e1_prime;
            (value, slope)
        };
        let (mut lo, mut hi) = (0.0_f64, 2.0_f64);
        let mut rho = guess
            .filter(|r| *r > lo && *r < hi)
            .unwrap_or_else(|| asymptotic_exit(beta, kappa));
        for iterations in 1..=MAX_ROOT_ITERATIONS {
            let (value, slope) = g(rho);
            let step = value / slope;
            // Newton converges quadratically: a step of 1e-9 ρ leaves an error ~1e-18 ρ.
            if step.abs() <= NEWTON_SETTLED * rho {
                return Ok(ExitRoot {
                    rho: (rho - step).clamp(lo, hi),
                    iterations,
                });
            }
            if value > 0.0 {
                hi = rho;
            } else {
                lo = rho;
            }
            let next = rho - step;
            rho = if next > lo && next < hi {
                next
            } else {
                0.5 * (lo + hi)
            };
            if hi - lo <= 4.0 * f64::EPSILON * hi {
                return Ok(ExitRoot { rho, iterations });
            }
        }
        Err(ModelError::NoConvergence {
            what: "exit edge of a strip",
            iterations: MAX_ROOT_ITERATIONS,
        })
    }

    /// Strip load q·R/k, with q = ∫ₐᵇ p dx = (k/R)[(b−a)²(2b+a)/6 + V T_ε (b² − a²)/2].
    pub fn load(&self, rho: f64) -> f64 {
        let b = self.entry;
        let b2 = b * b;
        b2 * b * (2.0 - rho).powi(2) * (1.0 + rho) / 6.0
            + self.retardation_length() * b2 * rho * (2.0 - rho) / 2.0
    }

    /// Strip moment m·R/k, with m = ∫ₐᵇ x p dx, at the exit root ρ.
    ///
    /// Slow strips use the exact m = (k/2R)[(b² − a²)²/4 + (2/3) V T_ε (b³ − a³)] − V T_σ q
    /// (from p(a) = p(b) = 0), written so that its two large terms, which cancel as κ → 0
    /// (the strip turns symmetric and m → 0), never meet: with a + b = ρb and Δλ = κλ_σ,
    /// m = (k/2R)(b − a)[(b − a)(a + b)²/4 + (a + b)λ_σ(a − λ_ε) + (2/3)Δλ(a² + ab + b²)],
    /// every term of which carries a factor ρ or κ. For fast strips its terms grow like λ_σ while m stays finite,
    /// so there m is split into the instantaneous part (1 + κ)(b² − a²)²/4 (exact) and the
    /// small viscous correction of [`Strip::viscous_pressure`], integrated by 16-point
    /// Gauss–Legendre (exact to rounding: the integrand is entire and varies on the scale
    /// λ_σ > b).
    pub fn moment(&self, rho: f64) -> f64 {
        let b = self.entry;
        let chord_squares = b * b * rho * (2.0 - rho); // b² − a²
        if self.beta() < FAST_STRIP {
            let a = (rho - 1.0) * b;
            let (half, mid) = (0.5 * (b - a), 0.5 * (b + a));
            let (nodes, weights) = gauss_legendre_16();
            let correction: f64 = nodes
                .iter()
                .zip(weights)
                .map(|(t, w)| {
                    let x = mid + half * t;
                    w * x * self.viscous_pressure(x - b)
                })
                .sum::<f64>()
                * half;
            return 0.5 * ((1.0 + self.kappa) * chord_squares * chord_squares / 4.0 - correction);
        }
        let (lambda, chord, sum) = (self.relaxation_length, b * (2.0 - rho), rho * b); // b − a, a + b
        let a = (rho - 1.0) * b;
        0.5 * chord
            * (chord * sum * sum / 4.0
                + sum * lambda * (a - self.retardation_length())
                + 2.0 / 3.0 * self.kappa * lambda * b * b * (rho * rho - rho + 1.0))
    }

    /// β = b/λ_σ (infinite at rest).
    fn beta(&self) -> f64 {
        self.entry / self.relaxation_length
    }

    /// The amount by which the viscosity lowers the pressure below the instantaneous elastic
    /// one, (1 + κ)(b² − x²) − p·2R/k = (κ/λ_σ) t² [b + 2(1 + β) t E₃(t/λ_σ)], t = x − b.
    fn viscous_pressure(&self, t: f64) -> f64 {
        let lambda = self.relaxation_length;
        self.kappa / lambda
            * t
            * t
            * (self.entry + 2.0 * (1.0 + self.beta()) * t * exprel3(t / lambda))
    }

    /// Pressure p·2R/k at x (any x; zero outside [a, b]):
    /// p = (k/2R){b² − x² + 2Δλ[(x + λ_σ) − (b + λ_σ)e^{(x−b)/λ_σ}]}, Δλ = κλ_σ,
    /// with the bracket written as −(x − b) u E₂(u) − b·expm1(u), u = (x − b)/λ_σ, so it does not
    /// cancel. `rho` is the strip's exit root.
    pub fn pressure(&self, x: f64, rho: f64) -> f64 {
        let b = self.entry;
        let a = (rho - 1.0) * b;
        if !(x > a && x < b) {
            return 0.0;
        }
        let elastic = b * b - x * x;
        if self.is_elastic() {
            return elastic;
        }
        let lambda = self.relaxation_length;
        let u = (x - b) / lambda;
        // λu² E₂(u) = (x − b)·u E₂(u): u² itself would overflow for very slow strips.
        let bracket = -(x - b) * (u * exprel2(u)) - b * u.exp_m1();
        (elastic + 2.0 * self.kappa * lambda * bracket).max(0.0)
    }
}

/// A starting point for the exit root from its two limits: ρ → (2/3)κβ/(1+κ) for fast strips
/// (β → 0) and ρ → κ/β for slow ones (β → ∞); the smaller is the better guess in between.
fn asymptotic_exit(beta: f64, kappa: f64) -> f64 {
    let fast = 2.0 / 3.0 * kappa * beta / (1.0 + kappa);
    let slow = kappa / beta;
    fast.min(slow).clamp(f64::MIN_POSITIVE, 1.9)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn strip(beta: f64, kappa: f64) -> Strip {
        Strip {
            entry: 1.0,
            relaxation_length: 1.0 / beta,
            kappa,
        }
    }

    /// G(s) of docs/model.md §3 written literally, for checking the root where it does not cancel.
    fn g_literal(s: f64, beta: f64, kappa: f64) -> f64 {
        1.0 - s * s
            + 2.0 * kappa / (beta * beta)
                * ((s * beta + 1.0) - (beta + 1.0) * (beta * (s - 1.0)).exp())
    }

    #[test]
    fn exit_root_solves_the_literal_exit_equation() {
        for &beta in &[0.3, 1.0, 3.0, 10.0, 40.0] {
            for &kappa in &[0.1, 1.0, 4.0, 20.0] {
                let root = strip(beta, kappa).exit_root(None).unwrap();
                let s = root.rho - 1.0;
                assert!(s > -1.0 && s < 1.0);
                let h = 1e-7;
                let slope =
                    (g_literal(s + h, beta, kappa) - g_literal(s - h, beta, kappa)) / (2.0 * h);
                let ds = g_literal(s, beta, kappa) / slope;
                assert!(
                    ds.abs() < 1e-12,
                    "β = {beta}, κ = {kappa}: Newton correction {ds}"
                );
            }
        }
    }

    #[test]
    fn exit_root_takes_its_fast_and_slow_limits() {
        let kappa = 4.0;
        for &beta in &[1e-6, 1e-4] {
            let rho = strip(beta, kappa).exit_root(None).unwrap().rho;
            let fast = 2.0 / 3.0 * kappa * beta / (1.0 + kappa);
            assert!(
                (rho / fast - 1.0).abs() < 10.0 * beta,
                "β = {beta}: {rho} vs {fast}"
            );
        }
        for &beta in &[1e4, 1e6] {
            let rho = strip(beta, kappa).exit_root(None).unwrap().rho;
            assert!((rho * beta / kappa - 1.0).abs() < 10.0 / beta, "β = {beta}");
        }
    }

    #[test]
    fn pressure_vanishes_at_both_edges_and_is_positive_between() {
        for &beta in &[0.05, 1.0, 50.0, 1e4] {
            let s = strip(beta, 4.0);
            let rho = s.exit_root(None).unwrap().rho;
            let a = (rho - 1.0) * s.entry;
            let peak = (0..=1000)
                .map(|i| s.pressure(a + (s.entry - a) * f64::from(i) / 1000.0, rho))
                .fold(0.0, f64::max);
            // Evaluate the closed form exactly at the edges (bypassing the support test).
            let at = |x: f64| {
                let u = (x - s.entry) / s.relaxation_length;
                s.entry * s.entry - x * x
                    + 2.0
                        * s.kappa
                        * s.relaxation_length
                        * (-s.relaxation_length * u * u * exprel2(u) - s.entry * u.exp_m1())
            };
            assert_eq!(at(s.entry), 0.0);
            assert!(at(a).abs() < 1e-12 * peak, "β = {beta}: p(a) = {}", at(a));
            for i in 1..100 {
                let x = a + (s.entry - a) * f64::from(i) / 100.0;
                assert!(s.pressure(x, rho) > 0.0, "β = {beta}: p({x}) ≤ 0");
            }
        }
    }

    /// ∫ₐᵇ p dx and ∫ₐᵇ x p dx by composite Gauss–Legendre on a mesh graded towards the entry
    /// edge (where slow strips have a boundary layer of width V T_σ), against the closed forms.
    #[test]
    fn exact_strip_load_and_moment_equal_a_quadrature_of_the_pressure() {
        let (x16, w16) = crate::quadrature::gauss_legendre_16();
        for &beta in &[0.1, 1.0, 10.0, 100.0] {
            let s = strip(beta, 4.0);
            let rho = s.exit_root(None).unwrap().rho;
            let (a, b) = ((rho - 1.0) * s.entry, s.entry);
            // Panels: geometric grading towards b down to a width of 1e-3 λ_σ.
            let mut edges = vec![a];
            let mut gap = (b - a) / 2.0;
            while gap > 1e-3 * s.relaxation_length.min(b - a) {
                edges.push(b - gap);
                gap /= 2.0;
            }
            edges.push(b);
            let (mut load, mut moment) = (0.0, 0.0);
            for pair in edges.windows(2) {
                let (lo, hi) = (pair[0], pair[1]);
                for (x, w) in x16.iter().zip(w16) {
                    let xm = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x;
                    let p = s.pressure(xm, rho) / 2.0; // p·R/k
                    load += 0.5 * (hi - lo) * w * p;
                    moment += 0.5 * (hi - lo) * w * xm * p;
                }
            }
            let exact_load = s.load(rho);
            let exact_moment = s.moment(rho);
            assert!(
                (load / exact_load - 1.0).abs() < 1e-11,
                "β = {beta}: load {load} vs {exact_load}"
            );
            assert!(
                (moment - exact_moment).abs() < 1e-11 * exact_load * b,
                "β = {beta}: moment {moment} vs {exact_moment}"
            );
        }
    }
}
