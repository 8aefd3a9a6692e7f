//! The contact region solved strip by strip at a given half-width: the integrals (load, area,
//! area moment, pressure moment), their quadrature error, the boundary and the pressure grid,
//! with exit roots guessed from strips already solved.

use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::Arc;

use super::solution::{BoundaryPoint, PressureGrid};
use crate::quadrature::StripRule;
use crate::spectrum::Terms;
use crate::strip::Strip;
use crate::ModelError;

/// The error bound of an answer is this many times the error it measures
/// ([`quadrature_error`]): it covers rules whose error shrinks by less than 2 when the strips
/// double (midpoint strips: by 2^1.5).
pub(super) const ERROR_SAFETY: f64 = 2.0;

/// A bound on the relative error of every reported integral quantity (δ, A, x_c, x_p, and
/// so μ and μ_r), from the integrals and pressure moment of the rule and of its companion
/// ([`Quadrature::companion`]) at the same penetration, and from the relative residual
/// `load_residual` of the load equation there. δ solves P(δ) = P, so a relative error e in
/// P (of the quadrature, or left by the root) moves δ by e/2 to e/1.5 (d ln P/d ln δ lies
/// between 1.5 and 2): e bounds it. A, x_c and x_p follow δ at most linearly and add their
/// own quadrature error (x_c = ∬x dA/A and x_p = ∬x p dA/P add both of theirs); then
/// [`ERROR_SAFETY`].
fn quadrature_error(
    rule: (&Integrals, f64),
    companion: (&Integrals, f64),
    load_residual: f64,
) -> f64 {
    /// The bound never claims less than the rounding of the strip sums, the roots and the
    /// scaling to SI units: against 40-digit references (model/tests/physics/honest_edges.rs) exact
    /// answers whose quadrature and load residual leave next to nothing err by up to 1.3e-15
    /// (μ, which also rounds τ_a and P); 16 ε ≈ 3.6e-15 bounds that with a margin of 2.7
    /// (4 ε, 8.9e-16, did not).
    const ROUNDING: f64 = 16.0 * f64::EPSILON;
    let relative = |fine: f64, other: f64| {
        if fine == other {
            0.0
        } else {
            ((other - fine) / fine).abs()
        }
    };
    let ((fine, fine_moment), (other, other_moment)) = (rule, companion);
    let load = relative(fine.load, other.load);
    let area = relative(fine.area, other.area);
    let area_moment = relative(fine.area_moment, other.area_moment);
    let moment = relative(fine_moment, other_moment);
    let penetration = load + load_residual;
    let worst = [
        penetration,
        area + penetration,
        area_moment + area + penetration,
        moment + load + penetration,
    ]
    .into_iter()
    .fold(0.0, f64::max);
    (ERROR_SAFETY * worst).max(ROUNDING)
}

/// Exit roots known at some strips, as guesses for others. At given viscous terms a strip's
/// root depends only on β = b/λ (λ the terms' mean length, [`Terms::mean_scale`]), smoothly
/// (for one arm: ρ ≈ (2/3)κβ/(1 + κ) for fast strips and ≈ κ/β for
/// slow ones), so ρ(1 + β)²/β is nearly constant at both ends and smooth in u = β/(1 + β)
/// ∈ (0, 1) (≈ β for fast strips, its slow-strip expansion is one in 1/β ≈ 1 − u). The
/// quintic in u through the six known strips nearest lands close enough to save the Newton
/// steps of a cold start, across rules and across nearby penetrations; on the boundary of a
/// 64-strip contact most of its guesses are within 1e-9, where one Newton step settles the
/// root (with the cubic through four, half of them took two).
pub(super) struct RootGuide {
    /// (β/(1 + β), ρ(1 + β)²/β), ascending in β.
    known: Vec<(f64, f64)>,
}

impl RootGuide {
    /// The roots `rho` of the strips of `rule` in `section`.
    pub(super) fn new(section: &Section, rule: &StripRule, rho: &[f64]) -> RootGuide {
        let mut known: Vec<(f64, f64)> = rule
            .cos
            .iter()
            .zip(rho)
            .map(|(c, r)| {
                let beta = section.beta(section.half_width * c);
                (beta / (1.0 + beta), r * (1.0 + beta).powi(2) / beta)
            })
            .filter(|(x, f)| x.is_finite() && f.is_finite())
            .collect();
        known.sort_by(|a, b| a.0.total_cmp(&b.0));
        known.dedup_by(|a, b| a.0 == b.0);
        RootGuide { known }
    }

    /// A guess of the exit root at β (NaN if nothing is known).
    pub(super) fn guess(&self, beta: f64) -> f64 {
        const POINTS: usize = 6;
        let known = &self.known;
        // Above the known strips ρ(1 + β)²/β levels off towards κ: the polynomial carries on
        // for one spacing of the strips (the middle of the contact lies just past the rule's
        // last strip), and the value there is held beyond. Below them it is analytic in u
        // down to u = 0: the polynomial carries on.
        let x = match known.as_slice() {
            [.., before, last] => (beta / (1.0 + beta)).min(last.0 + (last.0 - before.0)),
            [last] => (beta / (1.0 + beta)).min(last.0),
            [] => return f64::NAN,
        };
        let scaled = if known.len() < POINTS {
            known
                .iter()
                .min_by(|a, b| (a.0 - x).abs().total_cmp(&(b.0 - x).abs()))
                .map_or(f64::NAN, |k| k.1)
        } else {
            let at = known.partition_point(|k| k.0 < x);
            let first = at.saturating_sub(POINTS / 2).min(known.len() - POINTS);
            let window = &known[first..first + POINTS];
            window
                .iter()
                .enumerate()
                .map(|(k, &(x_k, f_k))| {
                    let (num, den) = window
                        .iter()
                        .enumerate()
                        .filter(|(j, _)| *j != k)
                        .fold((1.0, 1.0), |(num, den), (_, &(x_j, _))| {
                            (num * (x - x_j), den * (x_k - x_j))
                        });
                    f_k * num / den
                })
                .sum()
        };
        scaled * beta / (1.0 + beta).powi(2)
    }

    /// Guesses for the strips of `rule` in `section`.
    pub(super) fn guesses(&self, section: &Section, rule: &StripRule) -> Vec<f64> {
        rule.cos
            .iter()
            .map(|c| self.guess(section.beta(section.half_width * c)))
            .collect()
    }
}

/// The contact region of half-width r (in units of r₀), strip by strip.
#[derive(Clone, Copy, Debug)]
pub(super) struct Section {
    pub(super) half_width: f64,
    /// The viscous terms (κ_j, V τ_j/r₀).
    viscosity: Terms,
}

/// Integrals over the contact, in units of r₀ and k/R.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Integrals {
    /// P̂ = P R/(k r₀⁴).
    pub(super) load: f64,
    /// Â = A/r₀².
    pub(super) area: f64,
    /// ∬ x dA / r₀³.
    pub(super) area_moment: f64,
    pub(super) exit_root_iterations: u32,
}

impl Integrals {
    /// x_c/r₀ = ∬ x dA / A.
    pub(super) fn centroid(&self) -> f64 {
        self.area_moment / self.area
    }
}

impl Section {
    pub(super) fn new(half_width: f64, viscosity: Terms) -> Self {
        Section {
            half_width,
            viscosity,
        }
    }

    /// β = b/λ of the strip with entry edge b (in units of r₀), λ the terms' mean length
    /// (λ_σ for the Kelvin layer); infinite at rest.
    pub(super) fn beta(&self, entry: f64) -> f64 {
        entry / self.viscosity.mean_scale()
    }

    /// The strip at lateral position y = r sin θ, whose entry edge is b = r cos θ.
    pub(super) fn strip(&self, cos_theta: f64) -> Strip<'_> {
        Strip {
            entry: self.half_width * cos_theta,
            terms: &self.viscosity,
        }
    }

    /// P = 2∫q dy, A = 2∫(b − a) dy and ∬x dA = ∫(b² − a²) dy over the strips of `rule`.
    /// `warm`, if given, holds each strip's exit root from a previous call and receives the
    /// new ones.
    pub(super) fn integrate(
        &self,
        rule: &StripRule,
        mut warm: Option<&mut [f64]>,
    ) -> Result<Integrals, ModelError> {
        let mut sum = Integrals::default();
        let mut neighbour = None;
        for i in 0..rule.len() {
            let strip = self.strip(rule.cos[i]);
            // A strip without a root from before starts from its neighbour's: the strips
            // are in order of θ, and the root varies smoothly with it.
            let guess = warm
                .as_deref()
                .map(|rho| rho[i])
                .filter(|r| r.is_finite())
                .or(neighbour);
            let root = strip.exit_root(guess)?;
            neighbour = Some(root.rho);
            if let Some(rho) = warm.as_deref_mut() {
                rho[i] = root.rho;
            }
            let (w, b, rho) = (rule.weight[i], strip.entry, root.rho);
            let load = strip.load(rho);
            sum.load += w * load;
            sum.area += w * b * (2.0 - rho);
            sum.area_moment += w * b * b * rho * (2.0 - rho);
            sum.exit_root_iterations += root.iterations;
        }
        let r = self.half_width;
        sum.load *= 2.0 * r;
        sum.area *= 2.0 * r;
        sum.area_moment *= r;
        Ok(sum)
    }

    /// The pressure moment under `rule` (whose exit roots `rho` and `integrals` are known)
    /// and the error bound of everything reported ([`quadrature_error`]), from the same
    /// integrals under `companion`, whose exit roots start from `companion_roots` if given
    /// (e.g. its own at a nearby penetration), else from those of `rule` ([`RootGuide`]),
    /// and the load equation's relative residual `load_residual`.
    pub(super) fn moment_and_error(
        &self,
        rule: &StripRule,
        rho: &[f64],
        integrals: &Integrals,
        companion: &StripRule,
        companion_roots: Option<Vec<f64>>,
        load_residual: f64,
    ) -> Result<(f64, f64), ModelError> {
        let moment = self.pressure_moment(rule, rho);
        let mut companion_roots = companion_roots
            .unwrap_or_else(|| RootGuide::new(self, rule, rho).guesses(self, companion));
        let companion_integrals = self.integrate(companion, Some(&mut companion_roots))?;
        let companion_moment = self.pressure_moment(companion, &companion_roots);
        let error = quadrature_error(
            (integrals, moment),
            (&companion_integrals, companion_moment),
            load_residual,
        );
        Ok((moment, error))
    }

    /// ∬ x p dA = 2∫m dy in units of k r₀⁵/R, given each strip's exit root `rho` under `rule`.
    fn pressure_moment(&self, rule: &StripRule, rho: &[f64]) -> f64 {
        let sum: f64 = (0..rule.len())
            .map(|i| {
                let strip = self.strip(rule.cos[i]);
                rule.weight[i] * strip.moment(rho[i])
            })
            .sum();
        2.0 * self.half_width * sum
    }

    /// `n` boundary points spread evenly in θ ∈ [−π/2, π/2], y = r sin θ, in metres.
    /// Each exit root starts from the roots of `solved` (a rule and its strips' roots) if
    /// given ([`RootGuide`]), else from the previous strip's. The contact is symmetric in y,
    /// so the points at θ > 0 are those at −θ reflected.
    pub(super) fn boundary(
        &self,
        n: usize,
        scale: f64,
        solved: Option<&(Arc<StripRule>, Vec<f64>)>,
    ) -> Result<Vec<BoundaryPoint>, ModelError> {
        // Only points strictly inside (−π/2, π/2) need a root (n = 2 is the two tips).
        let roots = solved
            .filter(|_| n == 1 || n > 2)
            .map(|(rule, rho)| RootGuide::new(self, rule, rho));
        let mut points: Vec<BoundaryPoint> = Vec::with_capacity(n);
        let mut previous = None;
        for j in 0..n {
            let mirror = n - 1 - j;
            if mirror < j {
                let reflected = points[mirror];
                points.push(BoundaryPoint {
                    y: -reflected.y,
                    ..reflected
                });
                continue;
            }
            let theta = if n == 1 {
                0.0
            } else {
                -FRAC_PI_2 + PI * j as f64 / (n - 1) as f64
            };
            let (y, exit, entry) = if j == 0 && n > 1 {
                (-self.half_width, 0.0, 0.0)
            } else {
                let strip = self.strip(theta.cos());
                let guess = roots.as_ref().map(|r| r.guess(self.beta(strip.entry)));
                let rho = strip.exit_root(guess.or(previous))?.rho;
                previous = Some(rho);
                (
                    theta.sin() * self.half_width,
                    (rho - 1.0) * strip.entry,
                    strip.entry,
                )
            };
            points.push(BoundaryPoint {
                y: y * scale,
                exit: exit * scale,
                entry: entry * scale,
            });
        }
        Ok(points)
    }

    /// p(x, y) on an n × n grid over [−r, r]², in Pa. `scale` is r₀ (m) and `k_over_r` is k/R.
    pub(super) fn pressure_grid(
        &self,
        n: usize,
        scale: f64,
        k_over_r: f64,
    ) -> Result<PressureGrid, ModelError> {
        let r = self.half_width;
        let axis: Vec<f64> = (0..n)
            .map(|i| -r + 2.0 * r * i as f64 / (n - 1) as f64)
            .collect();
        // p = (k/2R) r₀² p̂ where p̂ is the strip pressure in units of r₀.
        let unit = 0.5 * k_over_r * scale * scale;
        let values = axis
            .iter()
            .map(|&y| {
                let chord = r * r - y * y;
                if chord <= 0.0 {
                    return Ok(vec![0.0; n]);
                }
                let strip = Strip {
                    entry: chord.sqrt(),
                    terms: &self.viscosity,
                };
                let rho = strip.exit_root(None)?.rho;
                Ok(axis
                    .iter()
                    .map(|&x| unit * strip.pressure(x, rho))
                    .collect())
            })
            .collect::<Result<Vec<_>, ModelError>>()?;
        let metres: Vec<f64> = axis.iter().map(|v| v * scale).collect();
        Ok(PressureGrid {
            x: metres.clone(),
            y: metres,
            values,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::Spacing;
    use crate::Quadrature;

    /// Roots guessed from another rule's strips land within half a percent of the exact ones
    /// (most within 1e-5, so a Newton step or two settles them; a cold start from the
    /// asymptotic forms is far off near β ≈ 1), including the strips faster
    /// and slower than any known.
    /// (At ξ ≪ 0.01 the coarse rule has no strip as fast as the fine rule's fastest, and
    /// guesses there are only rough; the nested test above still holds.)
    #[test]
    fn root_guides_guess_other_strips_roots_closely() {
        for kappa in [0.5, 4.0, 100.0] {
            for xi in [0.07, 0.5, 3.0, 30.0] {
                let rule =
                    |nodes| StripRule::shared(Quadrature::Gauss { nodes }, Spacing::for_speed(xi));
                let (fine, coarse) = (rule(64).unwrap(), rule(32).unwrap());
                let section = Section::new(0.9, Terms::one(kappa, xi));
                let mut known = vec![f64::NAN; coarse.len()];
                section.integrate(&coarse, Some(&mut known)).unwrap();
                let guesses = RootGuide::new(&section, &coarse, &known).guesses(&section, &fine);
                for (c, guess) in fine.cos.iter().zip(guesses) {
                    let exact = section.strip(*c).exit_root(None).unwrap().rho;
                    assert!(
                        (guess - exact).abs() <= 5e-3 * exact,
                        "ξ = {xi}, κ = {kappa}, cos θ = {c}: {guess} vs {exact}"
                    );
                }
            }
        }
    }

    /// The boundary's middle strip (cos θ = 1) is a little slower than any strip of the rule:
    /// its guess, carried on past the last known strip, is close enough for the first
    /// Newton step to settle it (held at the last strip's, it was off by 1e-8 and took two).
    #[test]
    fn root_guides_reach_the_middle_strip_past_the_rules_last() {
        for kappa in [0.5, 4.0, 100.0] {
            for xi in [0.07, 0.5, 3.0, 30.0] {
                let rule =
                    StripRule::shared(Quadrature::Gauss { nodes: 64 }, Spacing::for_speed(xi))
                        .unwrap();
                let section = Section::new(0.9, Terms::one(kappa, xi));
                let mut known = vec![f64::NAN; rule.len()];
                section.integrate(&rule, Some(&mut known)).unwrap();
                let middle = section.strip(1.0);
                let guess =
                    RootGuide::new(&section, &rule, &known).guess(section.beta(middle.entry));
                let root = middle.exit_root(Some(guess)).unwrap();
                let exact = middle.exit_root(None).unwrap().rho;
                assert!(
                    (guess - exact).abs() <= 1e-9 * exact && root.iterations == 1,
                    "ξ = {xi}, κ = {kappa}: {guess} vs {exact}, {} Newton steps",
                    root.iterations
                );
            }
        }
    }
}
