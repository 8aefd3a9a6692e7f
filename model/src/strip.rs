//! One strip y = const of a sphere rolling over a viscoelastic layer: the exact solution of
//! docs/model.md §3 (eq. 5 integrated along x with p = 0 at the entry edge), for the
//! Kelvin layer and for a Prony series (§9), whose pressure is a sum of one such term per
//! Maxwell arm.
//!
//! Every function here works in any consistent length unit and returns its quantity divided
//! by the stiffness factor it carries (k/R for loads, k/2R for pressures): the caller scales.
//! The exit edge is carried as ρ = 1 + a/b ∈ [0, 2): ρ = 0 is the symmetric static strip
//! a = −b, so the small asymmetry of slow rolling is resolved to full relative precision.
//!
//! With p̂ = p·2R/k, the pressure is p̂ = b² − x² + Σ_j σ̂_j, where arm j (strength
//! κ_j = E_j/E_∞, relaxation length λ_j = V τ_j) carries σ̂_j = 2κ_jλ_j[(x + λ_j) −
//! (b + λ_j)e^{(x−b)/λ_j}], the solution of σ̂_j − λ_j σ̂_j′ = 2κ_jλ_j x with σ̂_j(b) = 0.
//! The Kelvin layer is the one arm κ, λ_σ.

use super::special::{exprel2, exprel3, exprel3_moments, exprel_kernels};
use super::spectrum::{Terms, CAPACITY};
use super::ModelError;

/// Arms with β = b/λ below this are "fast" in a strip: their stress is nearly the
/// instantaneous elastic one, and the exit root and the load and moment are written around
/// that limit.
const FAST_STRIP: f64 = 1.0;

/// A Newton step this small (relative to ρ) leaves an error below rounding.
const NEWTON_SETTLED: f64 = 1e-9;
/// Newton steps allowed for one exit root before the solver reports non-convergence.
const MAX_ROOT_ITERATIONS: u32 = 100;

/// The viscous state of one strip: its entry half-chord b and the layer's viscous terms.
#[derive(Clone, Copy, Debug)]
pub struct Strip<'a> {
    /// Entry edge b = √(2Rδ − y²) (> 0).
    pub entry: f64,
    /// (κ_j, λ_j = V τ_j) of every arm, in the strip's length unit (none at rest:
    /// [`crate::Layer::viscosity`]).
    pub terms: &'a Terms,
}

/// An exit root and the Newton steps it took.
#[derive(Clone, Copy, Debug)]
pub struct ExitRoot {
    /// ρ = 1 + a/b.
    pub rho: f64,
    pub iterations: u32,
}

impl Strip<'_> {
    /// The exit edge: the root ρ ∈ (0, 2) of g(ρ) = −G(s)/(s − 1), s = ρ − 1 (docs/model.md §3),
    ///
    /// g(ρ) = ρ + Σ_j 2κ_j [E₁(z_j) + σ E₂(z_j)],  σ = ρ − 2,  z_j = β_jσ,  β_j = b/λ_j,
    ///
    /// with E₁ = exprel and E₂ = [`exprel2`] (see [`exprel_kernels`]). For fast arms (β < 1) the terms 2κ and
    /// 2κσE₂ nearly cancel; there the identical form
    /// κ[ρ(1 + β) − 2β + 2β(1 + β)σ²E₃(z)], E₃ = [`exprel3`], is used instead.
    /// g′(ρ) = 1 + Σ 2κ_j(β_j + 1)E₁′(z_j) > 0 and every term is
    /// convex, g(0) < 0 < g(2): exactly one root, and Newton steps from any point land on the
    /// right of it and then descend monotonically. A bisection bracket guards every step.
    /// `guess` (e.g. the root of the same strip at a nearby load) only saves iterations.
    pub fn exit_root(&self, guess: Option<f64>) -> Result<ExitRoot, ModelError> {
        if self.terms.is_empty() {
            return Ok(ExitRoot {
                rho: 0.0,
                iterations: 0,
            });
        }
        let b = self.entry;
        let g = |rho: f64| {
            let sigma = rho - 2.0;
            self.terms
                .iter()
                .fold((rho, 1.0), |(value, slope), (kappa, lambda)| {
                    let beta = b / lambda;
                    let z = beta * sigma;
                    let (e1, e2, e1_prime) = exprel_kernels(z);
                    let term = if beta < FAST_STRIP {
                        kappa
                            * (rho * (1.0 + beta) - 2.0 * beta
                                + 2.0 * beta * (1.0 + beta) * sigma * sigma * exprel3(z))
                    } else {
                        2.0 * kappa * (e1 + sigma * e2)
                    };
                    (value + term, slope + 2.0 * kappa * (beta + 1.0) * e1_prime)
                })
        };
        let (mut lo, mut hi) = (0.0_f64, 2.0_f64);
        let mut rho = guess
            .filter(|r| *r > lo && *r < hi)
            .unwrap_or_else(|| self.asymptotic_exit());
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

    /// Strip load q·R/k, with q = ∫ₐᵇ p dx, at the exit root ρ: the elastic part
    /// (b−a)²(2b+a)/6 and half of each arm's ∫σ̂_j, which its equation integrated over
    /// [a, b] gives as λ_j[κ_j(b² − a²) − σ̂_j(a)] = λ_j s_j, s_j the arm's shortfall at the
    /// exit ([`Strip::shortfalls`]). For the Kelvin layer this is the exact
    /// (k/R)[(b−a)²(2b+a)/6 + V T_ε (b² − a²)/2].
    pub fn load(&self, rho: f64) -> f64 {
        let b = self.entry;
        let b2 = b * b;
        let elastic = b2 * b * (2.0 - rho).powi(2) * (1.0 + rho) / 6.0;
        let shortfalls = self.shortfalls(rho);
        let viscous: f64 = self
            .terms
            .iter()
            .zip(shortfalls)
            .map(|((_, lambda), shortfall)| lambda * shortfall)
            .sum();
        elastic + 0.5 * viscous
    }

    /// Each arm's shortfall s_j = κ_j(b² − a²) − σ̂_j(a) at the exit edge a: how far its
    /// stress there is below its instantaneous elastic one. Since p(a) = 0,
    /// Σ s_j = (1 + Σκ_j)(b² − a²) exactly; the arm of the shortest λ takes its s from that
    /// sum (for the Kelvin layer the whole s = (1 + κ)(b² − a²), so no exponential enters),
    /// whose terms it then outweighs, and its error is multiplied by the smallest λ. The
    /// others are written not to cancel: κ_j(b² − a²) − σ̂_j(a) directly for slow arms, where
    /// σ̂_j(a) < 0, and (κ_j/λ_j) t²[b + 2(1 + β_j) t E₃(t/λ_j)], t = a − b, for fast ones,
    /// where both terms approach κ_j(b² − a²).
    fn shortfalls(&self, rho: f64) -> [f64; CAPACITY] {
        let b = self.entry;
        let a = (rho - 1.0) * b;
        let chord_squares = b * b * rho * (2.0 - rho); // b² − a²
        let mut shortfalls = [0.0; CAPACITY];
        let slowest = self
            .terms
            .iter()
            .enumerate()
            .min_by(|x, y| x.1 .1.total_cmp(&y.1 .1))
            .map_or(0, |(j, _)| j);
        let mut others = 0.0;
        for (j, (kappa, lambda)) in self.terms.iter().enumerate() {
            if j == slowest {
                continue;
            }
            shortfalls[j] = if b / lambda < FAST_STRIP {
                viscous_pressure(b, kappa, lambda, a - b)
            } else {
                kappa * chord_squares - arm_stress(b, kappa, lambda, a)
            };
            others += shortfalls[j];
        }
        shortfalls[slowest] = (1.0 + self.terms.strength()) * chord_squares - others;
        shortfalls
    }

    /// Strip moment m·R/k, with m = ∫ₐᵇ x p dx, at the exit root ρ: the elastic part
    /// (b² − a²)²/8 and half of each arm's ∫xσ̂_j.
    ///
    /// Slow arms use the arm's equation times x, integrated by parts:
    /// ∫xσ̂_j = λ_j[−aσ̂_j(a) − ∫σ̂_j] + (2/3)κ_jλ_j(b³ − a³), every term of which carries
    /// κ_j, and none of which cancels as the strip turns symmetric (for the Kelvin layer this
    /// is the exact m = (k/2R)[(b² − a²)²/4 + (2/3) V T_ε (b³ − a³)] − V T_σ q). For fast
    /// arms its terms grow like λ_j while the integral stays finite, so there it is split into
    /// the instantaneous part κ_j(b² − a²)²/4 (exact) and the small viscous correction of
    /// [`viscous_pressure`], integrated in closed form ([`fast_correction`]).
    pub fn moment(&self, rho: f64) -> f64 {
        let b = self.entry;
        let chord_squares = b * b * rho * (2.0 - rho); // b² − a²
        let a = (rho - 1.0) * b;
        let cubes = b * b * b * (2.0 - rho) * (rho * rho - rho + 1.0); // b³ − a³
        let shortfalls = self.shortfalls(rho);
        let viscous: f64 = self
            .terms
            .iter()
            .zip(shortfalls)
            .map(|((kappa, lambda), shortfall)| {
                if b / lambda < FAST_STRIP {
                    kappa * chord_squares * chord_squares / 4.0
                        - fast_correction(b, kappa, lambda, a - b)
                } else {
                    let stress = kappa * chord_squares - shortfall; // σ̂_j(a)
                    let integral = lambda * shortfall; // ∫σ̂_j
                    lambda * (-a * stress - integral) + 2.0 / 3.0 * kappa * lambda * cubes
                }
            })
            .sum();
        0.5 * (chord_squares * chord_squares / 4.0 + viscous)
    }

    /// Pressure p·2R/k at x (any x; zero outside [a, b]): b² − x² + Σ_j σ̂_j(x). `rho` is
    /// the strip's exit root.
    pub fn pressure(&self, x: f64, rho: f64) -> f64 {
        let b = self.entry;
        let a = (rho - 1.0) * b;
        if !(x > a && x < b) {
            return 0.0;
        }
        let viscous: f64 = self
            .terms
            .iter()
            .map(|(kappa, lambda)| arm_stress(b, kappa, lambda, x))
            .sum();
        (b * b - x * x + viscous).max(0.0)
    }

    /// A starting point for the exit root from its two limits: ρ → (2/3)Σκ_jβ_j/(1 + Σκ_j)
    /// for fast strips (β → 0) and ρ → Σκ_j/β_j for slow ones (β → ∞); the smaller is the
    /// better guess in between.
    fn asymptotic_exit(&self) -> f64 {
        let b = self.entry;
        let (fast, slow) = self
            .terms
            .iter()
            .fold((0.0, 0.0), |(fast, slow), (kappa, lambda)| {
                (fast + kappa * b / lambda, slow + kappa * lambda / b)
            });
        let fast = 2.0 / 3.0 * fast / (1.0 + self.terms.strength());
        fast.min(slow).clamp(f64::MIN_POSITIVE, 1.9)
    }
}

/// ∫ₐᵇ x v(x − b) dx, v = [`viscous_pressure`], of a fast arm (β = b/λ < 1), with
/// t_a = a − b ∈ [−2b, 0]. With x = b + t and u = t/λ the integrand is
/// (κ/λ)(b + t)t²[b + 2(1 + β)t E₃(u)], whose cubic part integrates to −b(b t_a³/3 + t_a⁴/4)
/// and whose E₃ part, term by term, to −2(1 + β)t_a⁴[b M₃(u_a) + t_a M₄(u_a)], M_k(z) =
/// ∫₀¹ s^k E₃(zs) ds ([`exprel3_moments`]). Two short series, where 16-point Gauss–Legendre
/// summed E₃ at 16 points (a third of a cold similarity table's build).
fn fast_correction(b: f64, kappa: f64, lambda: f64, t_a: f64) -> f64 {
    let beta = b / lambda;
    let [m3, m4] = exprel3_moments(t_a / lambda);
    let t3 = t_a * t_a * t_a;
    let t4 = t3 * t_a;
    -kappa / lambda
        * (b * (b * t3 / 3.0 + t4 / 4.0) + 2.0 * (1.0 + beta) * t4 * (b * m3 + t_a * m4))
}

/// σ̂ = 2κλ[(x + λ) − (b + λ)e^{(x−b)/λ}] of one arm, with the bracket written as
/// −(x − b) u E₂(u) − b·expm1(u), u = (x − b)/λ, so it does not cancel.
fn arm_stress(b: f64, kappa: f64, lambda: f64, x: f64) -> f64 {
    let u = (x - b) / lambda;
    // λu² E₂(u) = (x − b)·u E₂(u): u² itself would overflow for very slow strips.
    let bracket = -(x - b) * (u * exprel2(u)) - b * u.exp_m1();
    2.0 * kappa * lambda * bracket
}

/// The amount by which one arm's stress falls short of its instantaneous elastic one,
/// κ(b² − x²) − σ̂ = (κ/λ) t² [b + 2(1 + β) t E₃(t/λ)], t = x − b, β = b/λ.
fn viscous_pressure(b: f64, kappa: f64, lambda: f64, t: f64) -> f64 {
    kappa / lambda * t * t * (b + 2.0 * (1.0 + b / lambda) * t * exprel3(t / lambda))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One Kelvin arm of strength κ whose strip has β = b/λ_σ (b = 1).
    fn arm(beta: f64, kappa: f64) -> Terms {
        Terms::of([(kappa, 1.0 / beta)]).unwrap()
    }

    fn strip(terms: &Terms) -> Strip<'_> {
        Strip { entry: 1.0, terms }
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
                let root = strip(&arm(beta, kappa)).exit_root(None).unwrap();
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
            let rho = strip(&arm(beta, kappa)).exit_root(None).unwrap().rho;
            let fast = 2.0 / 3.0 * kappa * beta / (1.0 + kappa);
            assert!(
                (rho / fast - 1.0).abs() < 10.0 * beta,
                "β = {beta}: {rho} vs {fast}"
            );
        }
        for &beta in &[1e4, 1e6] {
            let rho = strip(&arm(beta, kappa)).exit_root(None).unwrap().rho;
            assert!((rho * beta / kappa - 1.0).abs() < 10.0 / beta, "β = {beta}");
        }
    }

    #[test]
    fn pressure_vanishes_at_both_edges_and_is_positive_between() {
        for &beta in &[0.05, 1.0, 50.0, 1e4] {
            let terms = arm(beta, 4.0);
            let s = strip(&terms);
            let (kappa, lambda) = (4.0, 1.0 / beta);
            let rho = s.exit_root(None).unwrap().rho;
            let a = (rho - 1.0) * s.entry;
            let peak = (0..=1000)
                .map(|i| s.pressure(a + (s.entry - a) * f64::from(i) / 1000.0, rho))
                .fold(0.0, f64::max);
            // Evaluate the closed form exactly at the edges (bypassing the support test).
            let at = |x: f64| {
                let u = (x - s.entry) / lambda;
                s.entry * s.entry - x * x
                    + 2.0 * kappa * lambda * (-lambda * u * u * exprel2(u) - s.entry * u.exp_m1())
            };
            assert_eq!(at(s.entry), 0.0);
            assert!(at(a).abs() < 1e-12 * peak, "β = {beta}: p(a) = {}", at(a));
            for i in 1..100 {
                let x = a + (s.entry - a) * f64::from(i) / 100.0;
                assert!(s.pressure(x, rho) > 0.0, "β = {beta}: p({x}) ≤ 0");
            }
        }
    }

    /// The closed form of a fast arm's moment correction against the 16-point Gauss–Legendre
    /// sum it replaced (exact to rounding there: the integrand is entire and varies on the
    /// scale λ > b), over β and exit edges across the whole range.
    #[test]
    fn the_fast_correction_in_closed_form_is_the_quadrature_of_its_integrand() {
        let (nodes, weights) = crate::quadrature::gauss_legendre_16();
        for beta in [1e-6, 1e-3, 0.1, 0.3, 0.6, 0.99] {
            for rho in [1e-9, 1e-4, 0.01, 0.3, 1.0, 4.0 / 3.0, 1.7, 1.999] {
                let (b, kappa, lambda) = (1.0, 2.5, 1.0 / beta);
                // Over t = x − b ∈ [t_a, 0], t_a = (ρ − 2)b: x − b would lose digits for a
                // short chord (ρ near 2), where the old sum was good to only ~1e-13.
                let t_a = (rho - 2.0) * b;
                let half = -0.5 * t_a;
                let summed = |f: &dyn Fn(f64) -> f64| -> f64 {
                    nodes
                        .iter()
                        .zip(weights)
                        .map(|(node, w)| w * f(half * (node - 1.0)))
                        .sum::<f64>()
                        * half
                };
                let integrand = |t: f64| (b + t) * viscous_pressure(b, kappa, lambda, t);
                let quadrature = summed(&integrand);
                // The scale its rounding is relative to: the integral of |x v|.
                let scale = summed(&|t| integrand(t).abs());
                let closed = fast_correction(b, kappa, lambda, t_a);
                assert!(
                    (closed - quadrature).abs() <= 1e-14 * scale,
                    "β = {beta}, ρ = {rho}: {closed} vs {quadrature} (scale {scale})"
                );
            }
        }
    }

    /// ∫ₐᵇ p dx and ∫ₐᵇ x p dx by composite Gauss–Legendre on a mesh graded towards the entry
    /// edge (where slow arms have a boundary layer of width V τ_j), against the closed forms,
    /// for the Kelvin layer and for Prony series whose arms are fast, slow or both in one
    /// strip.
    #[test]
    fn exact_strip_load_and_moment_equal_a_quadrature_of_the_pressure() {
        let (x16, w16) = crate::quadrature::gauss_legendre_16();
        let mut series: Vec<Terms> = [0.1, 1.0, 10.0, 100.0]
            .iter()
            .map(|&beta| arm(beta, 4.0))
            .collect();
        series.push(Terms::of([(4.0, 10.0), (0.5, 0.01)]).unwrap());
        series.push(Terms::of([(0.3, 0.02), (2.0, 0.7), (1.0, 30.0), (0.05, 1e3)]).unwrap());
        for terms in &series {
            let s = strip(terms);
            let rho = s.exit_root(None).unwrap().rho;
            let (a, b) = ((rho - 1.0) * s.entry, s.entry);
            // p vanishes at the exit edge whatever the arms.
            let peak = s.pressure(0.5 * (a + b), rho);
            let at_exit = b * b - a * a
                + terms
                    .iter()
                    .map(|(k, l)| arm_stress(b, k, l, a))
                    .sum::<f64>();
            assert!(at_exit.abs() < 1e-12 * peak, "{terms:?}: p(a) = {at_exit}");
            // Panels: geometric grading towards b down to a width of 1e-3 of the shortest λ.
            let mut edges = vec![a];
            let mut gap = (b - a) / 2.0;
            while gap > 1e-3 * terms.shortest().min(b - a) {
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
                "{terms:?}: load {load} vs {exact_load}"
            );
            assert!(
                (moment - exact_moment).abs() < 1e-11 * exact_load * b,
                "{terms:?}: moment {moment} vs {exact_moment}"
            );
        }
    }

    /// Arms of equal time act as one arm of their summed strength.
    #[test]
    fn arms_of_one_time_are_one_arm() {
        for &lambda in &[0.05, 0.8, 20.0] {
            let split = Terms::of([(1.5, lambda), (2.5, lambda)]).unwrap();
            let whole = Terms::of([(4.0, lambda)]).unwrap();
            let (s, w) = (strip(&split), strip(&whole));
            let (rs, rw) = (
                s.exit_root(None).unwrap().rho,
                w.exit_root(None).unwrap().rho,
            );
            assert!(
                (rs / rw - 1.0).abs() < 1e-13,
                "λ = {lambda}: ρ {rs} vs {rw}"
            );
            assert!((s.load(rs) / w.load(rw) - 1.0).abs() < 1e-13);
            assert!((s.moment(rs) / w.moment(rw) - 1.0).abs() < 1e-12);
        }
    }
}
