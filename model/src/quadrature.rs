//! Quadrature across the contact: which strips y = const are evaluated and with what weight.
//!
//! Strips do not interact (docs/model.md §3), so with the exact strip load and moment the only
//! discretisation error of the whole solution is the quadrature in y. Two rules are offered:
//! Gauss–Legendre in θ with y = r sin θ, which makes the integrand smooth and reaches 1e-9
//! relative accuracy with about a hundred nodes, and the paper's uniform midpoint strips
//! (Haines & Ollerton), which converge like N^−1.5 and are kept so users can compare. In slow
//! rolling the Gauss nodes are graded towards the lateral tips ([`Spacing`]).

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
use std::sync::{Arc, Mutex, OnceLock};

use super::{ModelError, OptionError, SolveOption};

/// Gauss nodes used when a job does not ask for a number. Against a 1024-node rule, 64 nodes
/// err by at most 6.7e-15 (relative, in δ, A, x_c and x_p) over 1e-6 ≤ V T_σ/r₀ ≤ 20 and
/// 0.01 ≤ κ ≤ 1e4 (5e-11 before [`Spacing::Tips`]); `tests/physics/rolling_limits.rs` holds that
/// to 1e-9.
pub const DEFAULT_GAUSS_NODES: usize = 64;
/// Midpoint strips used when a job asks for the paper's method without a number.
pub const DEFAULT_MIDPOINT_STRIPS: usize = 40;
/// Largest Gauss rule offered: beyond it the node computation, not the solve, dominates.
pub const MAX_GAUSS_NODES: usize = 1024;
/// Largest number of midpoint strips offered.
pub const MAX_MIDPOINT_STRIPS: usize = 100_000;

/// How the half-width 0 ≤ y ≤ √(2Rδ) of the contact is divided into strips.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Quadrature {
    /// Gauss–Legendre with `nodes` nodes in θ, y = √(2Rδ) sin θ.
    Gauss { nodes: usize },
    /// The paper's `strips` uniform strips, each evaluated at its midpoint.
    Midpoint { strips: usize },
}

impl Default for Quadrature {
    fn default() -> Self {
        Quadrature::Gauss {
            nodes: DEFAULT_GAUSS_NODES,
        }
    }
}

impl Quadrature {
    /// Number of strips (nodes) the rule evaluates.
    pub fn size(self) -> usize {
        match self {
            Quadrature::Gauss { nodes } => nodes,
            Quadrature::Midpoint { strips } => strips,
        }
    }

    /// The allowed sizes of this kind of rule, as text for error messages.
    pub fn allowed_sizes(self) -> String {
        match self {
            Quadrature::Gauss { .. } => format!("2 ≤ n ≤ {MAX_GAUSS_NODES}"),
            Quadrature::Midpoint { .. } => format!("1 ≤ n ≤ {MAX_MIDPOINT_STRIPS}"),
        }
    }

    /// The rule's size, if it is outside the offered range.
    pub fn check(self) -> Result<(), OptionError> {
        let valid = match self {
            Quadrature::Gauss { nodes } => (2..=MAX_GAUSS_NODES).contains(&nodes),
            Quadrature::Midpoint { strips } => (1..=MAX_MIDPOINT_STRIPS).contains(&strips),
        };
        if valid {
            Ok(())
        } else {
            Err(OptionError {
                option: SolveOption::Strips,
                value: self.size(),
                allowed: self.allowed_sizes(),
            })
        }
    }

    /// The rule the quadrature error of this one is estimated against (see
    /// `rolling::Verification::quadrature_error_estimate`): the same kind with half the
    /// strips, whose error (at least twice this rule's once the rule converges) bounds this
    /// one's; below 8 strips, where that ratio is not yet reached, twice the strips instead.
    pub fn companion(self) -> Quadrature {
        const FEW: usize = 8;
        match self {
            Quadrature::Gauss { nodes } if nodes < FEW => Quadrature::Gauss { nodes: 2 * nodes },
            Quadrature::Gauss { nodes } => Quadrature::Gauss { nodes: nodes / 2 },
            Quadrature::Midpoint { strips } if strips < FEW => {
                Quadrature::Midpoint { strips: 2 * strips }
            }
            Quadrature::Midpoint { strips } => Quadrature::Midpoint { strips: strips / 2 },
        }
    }
}

/// Where a Gauss rule puts its strips (midpoint strips are always uniform in y).
///
/// Near the lateral tips y → r the entry half-chord b = r cos θ falls below the relaxation
/// length V T_σ and the strips turn from slow (exit root ρ ≈ κ/β, β = b/(V T_σ)) to fast
/// (ρ ≈ (2/3)κβ/(1 + κ)): the integrands change over π/2 − θ ≈ ξ = V T_σ/r. Gauss–Legendre
/// in θ resolves an end layer only down to about 1/n² (n nodes), so in slow rolling every rule
/// steps over it, the rule and its companion alike: A and x_c erred by up to 2e-11 at 64
/// nodes (ξ ≈ 1e-5 … 3e-3), and the companion, missing the same layer, put the error bound
/// up to 58 times too low. Grading the nodes quadratically towards the tips resolves the
/// layer down to ξ ≈ 1/n⁴; below that it holds a part of order κξ³ < 1e-16 of the
/// integrals.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Spacing {
    /// Gauss–Legendre in θ: the best rule for smooth integrands (a contact rolling at
    /// ξ ≥ [`Spacing::TIPS_BELOW`]).
    Theta,
    /// Gauss–Legendre in t ∈ (0, 1) with π/2 − θ = (π/2)t²: the nodes near the tips are
    /// spaced like 1/n⁴ instead of 1/n². The integrands stay analytic in t, but a smooth one
    /// needs more nodes than in θ (in fast rolling 16 nodes and their 8-node companion differ
    /// by 1e-5 instead of 1e-9, which costs the nested solve a load iteration and a tenth
    /// more exit-root steps), so only slow rolling uses it.
    Tips,
}

impl Spacing {
    /// ξ = V T_σ/r₀ below which rules are graded towards the tips: at 64 nodes in θ the tip
    /// layer costs 3e-16 at ξ = 1e-2 and 4e-12 at ξ = 2e-3 (κ = 4).
    pub const TIPS_BELOW: f64 = 0.02;

    /// The spacing for a contact at ξ = V T_σ/r (r its half-width, or the static one r₀).
    pub fn for_speed(xi: f64) -> Spacing {
        if xi < Self::TIPS_BELOW {
            Spacing::Tips
        } else {
            Spacing::Theta
        }
    }
}

/// Strips of a contact of unit half-width: for a half-width r, ∫₀^r f(y) dy ≈ r Σ wᵢ f(r sᵢ),
/// and the entry edge of strip i is b = r cᵢ with cᵢ = √(1 − sᵢ²).
#[derive(Debug)]
pub struct StripRule {
    /// sᵢ = y/r of each strip.
    pub sin: Vec<f64>,
    /// cᵢ = b/r = √(1 − sᵢ²) of each strip.
    pub cos: Vec<f64>,
    /// wᵢ, the weight of each strip for an integral over y/r ∈ [0, 1].
    pub weight: Vec<f64>,
}

impl StripRule {
    /// The rule for `quadrature` with Gauss nodes spread as `spacing`, computed once per
    /// process and shared (it is pure data).
    pub fn shared(quadrature: Quadrature, spacing: Spacing) -> Result<Arc<StripRule>, ModelError> {
        quadrature.check().map_err(ModelError::InvalidOption)?;
        /// A handful of rules are in use at any time; older ones are dropped beyond this.
        const CACHED_RULES: usize = 16;
        type Cache = Mutex<Vec<((Quadrature, Spacing), Arc<StripRule>)>>;
        static CACHE: OnceLock<Cache> = OnceLock::new();
        let key = match quadrature {
            Quadrature::Gauss { .. } => (quadrature, spacing),
            Quadrature::Midpoint { .. } => (quadrature, Spacing::Theta),
        };
        let cache = CACHE.get_or_init(|| Mutex::new(Vec::new()));
        if let Some(rule) = lock(cache).iter().find(|(k, _)| *k == key) {
            return Ok(rule.1.clone());
        }
        let rule = Arc::new(StripRule::new(key.0, key.1));
        let mut rules = lock(cache);
        if rules.len() >= CACHED_RULES {
            rules.remove(0);
        }
        rules.push((key, rule.clone()));
        Ok(rule)
    }

    fn new(quadrature: Quadrature, spacing: Spacing) -> StripRule {
        match quadrature {
            Quadrature::Gauss { nodes } => {
                let rule = gauss_legendre(nodes);
                let (x, w) = &*rule;
                // Each node as (y/r, b/r, weight), in ascending θ: with φ = π/2 − θ,
                // y = r cos φ, b = r sin φ (b keeps its digits at the tips), dy = r sin φ dφ.
                let strips = x.iter().zip(w).map(|(x, w)| match spacing {
                    // φ = (π/4)(1 − x) ∈ (0, π/2), dφ = (π/4) dx.
                    Spacing::Theta => {
                        let (b, y) = (FRAC_PI_4 * (1.0 - x)).sin_cos();
                        (y, b, FRAC_PI_4 * w * b)
                    }
                    // t = (1 − x)/2, φ = (π/2)t², |dφ| = π t dt = (π/2) t dx.
                    Spacing::Tips => {
                        let t = 0.5 * (1.0 - x);
                        let (b, y) = (FRAC_PI_2 * t * t).sin_cos();
                        (y, b, FRAC_PI_2 * w * t * b)
                    }
                });
                let mut rule = StripRule {
                    sin: Vec::with_capacity(nodes),
                    cos: Vec::with_capacity(nodes),
                    weight: Vec::with_capacity(nodes),
                };
                for (y, b, weight) in strips {
                    rule.sin.push(y);
                    rule.cos.push(b);
                    rule.weight.push(weight);
                }
                rule
            }
            Quadrature::Midpoint { strips } => {
                let n = strips as f64;
                let sin: Vec<f64> = (0..strips).map(|j| (j as f64 + 0.5) / n).collect();
                StripRule {
                    cos: sin.iter().map(|s| (1.0 - s * s).sqrt()).collect(),
                    weight: vec![1.0 / n; strips],
                    sin,
                }
            }
        }
    }

    /// Number of strips.
    pub fn len(&self) -> usize {
        self.weight.len()
    }

    /// Whether the rule has no strips (never, for a validated quadrature).
    pub fn is_empty(&self) -> bool {
        self.weight.is_empty()
    }
}

/// The cache holds only immutable data, so a poisoned lock is still consistent.
fn lock<T>(mutex: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    mutex
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// A Gauss–Legendre rule on [−1, 1]: its nodes, ascending, and their weights.
pub type GaussRule = Arc<(Vec<f64>, Vec<f64>)>;

/// The Gauss–Legendre rule of `n` nodes, computed once per process and shared (it is pure
/// data, and computing it costs an eigen-solve: 64 % of an asperity job's instructions
/// when it was rebuilt on every use, BENCHMARKS.md).
pub fn gauss_legendre(n: usize) -> GaussRule {
    /// The sizes in use: strip rules, diameter rules and their halves, asperity regimes.
    const CACHED_RULES: usize = 32;
    type Cache = Mutex<Vec<(usize, GaussRule)>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let cache = CACHE.get_or_init(|| Mutex::new(Vec::new()));
    if let Some((_, rule)) = lock(cache).iter().find(|(size, _)| *size == n) {
        return rule.clone();
    }
    let rule = Arc::new(compute_gauss_legendre(n));
    let mut rules = lock(cache);
    if rules.len() >= CACHED_RULES {
        rules.remove(0);
    }
    rules.push((n, rule.clone()));
    rule
}

/// The 16-point Gauss–Legendre rule on [−1, 1], without even a lock (the layer's compliance
/// builds its rules from it, panel after panel).
pub fn gauss_legendre_16() -> (&'static [f64], &'static [f64]) {
    static RULE: OnceLock<GaussRule> = OnceLock::new();
    let rule = RULE.get_or_init(|| gauss_legendre(16));
    (&rule.0, &rule.1)
}

/// Gauss–Legendre nodes and weights on [−1, 1], ascending.
///
/// Newton's method on Pₙ from Tricomi's approximation of each root, which is close enough
/// for every n that Newton converges to that root in a few steps; the rule is symmetric, so
/// half the roots are computed. O(n²), where the Golub–Welsch eigen-solve used before was
/// O(n³) and 11 % of a single-job CLI process (BENCHMARKS.md). The weights come from
/// 2/((1 − x²) Pₙ′(x)²), accurate to the last bit.
fn compute_gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    /// Newton converges quadratically: after a step this small the root is exact.
    const SETTLED: f64 = 1e-15;
    const MAX_STEPS: usize = 20;
    let size = n as f64;
    let (mut nodes, mut weights) = (vec![0.0; n], vec![0.0; n]);
    for k in 0..n.div_ceil(2) {
        let theta = PI * (k as f64 + 0.75) / (size + 0.5);
        let mut x = (1.0 - (size - 1.0) / (8.0 * size * size * size)) * theta.cos();
        for _ in 0..MAX_STEPS {
            let (p, dp) = legendre(n, x);
            let step = p / dp;
            x -= step;
            if step.abs() <= SETTLED {
                break;
            }
        }
        if 2 * k + 1 == n {
            x = 0.0; // the middle root of an odd rule
        }
        let (_, dp) = legendre(n, x);
        let weight = 2.0 / ((1.0 - x * x) * dp * dp);
        (nodes[n - 1 - k], weights[n - 1 - k]) = (x, weight);
        (nodes[k], weights[k]) = (-x, weight);
    }
    (nodes, weights)
}

/// Pₙ(x) and Pₙ′(x) by the three-term recurrence.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p_prev, mut p) = (1.0, x);
    for k in 2..=n {
        let k = k as f64;
        let p_next = ((2.0 * k - 1.0) * x * p - (k - 1.0) * p_prev) / k;
        p_prev = p;
        p = p_next;
    }
    if n == 0 {
        return (1.0, 0.0);
    }
    let n = n as f64;
    (p, n * (x * p - p_prev) / (x * x - 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_of_degree_2n_minus_1_exactly() {
        for n in [2usize, 3, 5, 16, 33, 64, 128, 1024] {
            let rule = gauss_legendre(n);
            let (x, w) = &*rule;
            assert!(
                x.windows(2).all(|p| p[0] < p[1]),
                "n = {n}: nodes not ascending"
            );
            assert!(x[0] > -1.0 && x[n - 1] < 1.0 && w.iter().all(|w| *w > 0.0));
            let total: f64 = w.iter().sum();
            assert!((total - 2.0).abs() < 1e-14, "n = {n}: Σw = {total}");
            let degree = 2 * n - 2; // even, so the exact integral is 2/(degree + 1)
            let integral: f64 = x
                .iter()
                .zip(w)
                .map(|(x, w)| w * x.powi(degree as i32))
                .sum();
            let exact = 2.0 / (degree as f64 + 1.0);
            assert!(
                (integral / exact - 1.0).abs() < 1e-13,
                "n = {n}: {integral} vs {exact}"
            );
        }
    }

    #[test]
    fn gauss_rules_integrate_the_static_strip_load() {
        // ∫₀¹ (1 − y²)^{3/2} dy = 3π/16: the static load integrand, singular in y at y = 1.
        for spacing in [Spacing::Theta, Spacing::Tips] {
            let rule = StripRule::shared(Quadrature::default(), spacing).unwrap();
            let integral: f64 = (0..rule.len())
                .map(|i| rule.weight[i] * rule.cos[i].powi(3))
                .sum();
            let exact = 3.0 * std::f64::consts::PI / 16.0;
            assert!((integral / exact - 1.0).abs() < 1e-14, "{spacing:?}");
        }
    }

    /// A stand-in for the tip layer of slow rolling: the integrand of ∫₀¹ b/(b + ξ) dy,
    /// b = √(1 − y²), turns from ≈ 1 to ≈ b/ξ where b < ξ. In θ it is 1 − ξπ/2 + ξ²J with
    /// J = ∫₀^{π/2} dθ/(ξ + cos θ) = 2 artanh(√((1 − ξ)/(1 + ξ)))/√(1 − ξ²).
    #[test]
    fn rules_graded_towards_the_tips_resolve_a_tip_layer_that_rules_in_theta_step_over() {
        let rule = |spacing| StripRule::shared(Quadrature::default(), spacing).unwrap();
        let (theta, tips) = (rule(Spacing::Theta), rule(Spacing::Tips));
        for xi in [1e-7_f64, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 0.1] {
            let j = 2.0 * ((1.0 - xi) / (1.0 + xi)).sqrt().atanh() / (1.0 - xi * xi).sqrt();
            let exact = 1.0 - xi * FRAC_PI_2 + xi * xi * j;
            let error = |rule: &StripRule| {
                let sum: f64 = (0..rule.len())
                    .map(|i| rule.weight[i] * rule.cos[i] / (rule.cos[i] + xi))
                    .sum();
                (sum / exact - 1.0).abs()
            };
            let (graded, even) = (error(&tips), error(&theta));
            // This layer holds a part ξ²J of the integral (the contact's, only κξ³).
            assert!(graded < 2e-13, "ξ = {xi}: graded {graded:e}");
            if (1e-6..=1e-2).contains(&xi) {
                assert!(100.0 * graded < even, "ξ = {xi}: {graded:e} vs {even:e}");
            }
        }
    }

    #[test]
    fn invalid_sizes_are_errors_not_panics() {
        for spacing in [Spacing::Theta, Spacing::Tips] {
            assert!(StripRule::shared(Quadrature::Gauss { nodes: 1 }, spacing).is_err());
            assert!(StripRule::shared(Quadrature::Gauss { nodes: 5000 }, spacing).is_err());
            assert!(StripRule::shared(Quadrature::Midpoint { strips: 0 }, spacing).is_err());
        }
    }
}
