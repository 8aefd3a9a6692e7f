//! A rigid parabolic sphere pressed, at rest, on the layer as a continuum: an elastic solid
//! of Young's modulus E ([`super::young_modulus`]) bonded to a rigid base, frictionless on
//! top (docs/model.md §8, V = 0). Axisymmetric, so the contact is a disc of radius a and
//! the pressure a function of r.
//!
//! The pressure is constant on each of N rings over [0, a]; the surface deflection at each
//! ring's middle is the sum of the rings' influences: the half-space's in closed form (a
//! uniformly loaded disc, Johnson §3.4) plus the layer's correction as a Hankel integral
//! of C(qH) − 1, which decays like e^{−2qH} and so needs no tail. For a given a, the
//! deflection matching the sphere on every ring and the load fix the pressures and δ; a is
//! where the outermost ring's pressure falls to zero (the edge of a frictionless,
//! non-adhesive contact). Three resolutions give two Richardson extrapolations: the answer
//! is the finer one, and their difference its error.

use std::f64::consts::PI;

use nalgebra::{DMatrix, DVector};

use super::compliance::{contact_modulus, correction_rule};
use crate::roots::brent;
use crate::{Layer, ModelError};

/// Rings of the coarsest of the three resolutions (each next has twice as many).
const RINGS: usize = 24;

/// The contact of a sphere at rest on the layer as a continuum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticContinuum {
    /// a (m), the contact radius.
    pub contact_radius: f64,
    /// δ (m), the approach of the sphere.
    pub penetration: f64,
    /// A = πa² (m²).
    pub contact_area: f64,
    /// An estimate of the relative error of A (and, halved, of a): the difference of the
    /// two extrapolations from three resolutions.
    pub relative_error: f64,
}

/// The static contact of a sphere of radius `radius` under `load` on `layer` taken as a
/// continuum (docs/model.md §8).
pub fn static_contact(
    radius: f64,
    load: f64,
    layer: &Layer,
) -> Result<StaticContinuum, ModelError> {
    let coarse = solve(radius, load, layer, RINGS)?;
    let middle = solve(radius, load, layer, 2 * RINGS)?;
    let fine = solve(radius, load, layer, 4 * RINGS)?;
    // The edge condition on piecewise-constant rings errs by O(1/N) (0.7/N in a on Hertz's
    // contact): extrapolate from each pair, and take the last.
    let extrapolated = |(a0, d0): (f64, f64), (a1, d1): (f64, f64)| (2.0 * a1 - a0, 2.0 * d1 - d0);
    let before = extrapolated(coarse, middle);
    let (a, delta) = extrapolated(middle, fine);
    let relative_error = 2.0 * (before.0 / a - 1.0).abs() + 1e-12;
    Ok(StaticContinuum {
        contact_radius: a,
        penetration: delta,
        contact_area: PI * a * a,
        relative_error,
    })
}

/// (a, δ) on `rings` rings.
fn solve(radius: f64, load: f64, layer: &Layer, rings: usize) -> Result<(f64, f64), ModelError> {
    let e_star = contact_modulus(layer);
    let hertz = (3.0 * load * radius / (4.0 * e_star)).cbrt();
    // The local law's radius at rest (docs/model.md §3): a real layer is stiffer than both
    // the half-space and the local law, so its contact is no wider than either.
    let k = layer.elastic_modulus / layer.thickness;
    let local = (2.0 * radius * (load / (PI * k * radius)).sqrt()).sqrt();
    let guess = hertz.min(local);
    let edge = |a: f64| Contact::new(radius, load, layer, rings, a).map(|c| c.edge_pressure());
    // The outermost ring's pressure is positive while the contact is too small.
    let mut lo = 0.5 * guess;
    let mut f_lo = edge(lo)?;
    while f_lo <= 0.0 {
        lo *= 0.5;
        f_lo = edge(lo)?;
        if lo < 1e-6 * guess {
            return Err(not_bracketed());
        }
    }
    let mut hi = 1.5 * guess;
    let mut f_hi = edge(hi)?;
    while f_hi >= 0.0 {
        hi *= 1.5;
        f_hi = edge(hi)?;
        if hi > 1e3 * guess {
            return Err(not_bracketed());
        }
    }
    let mut failed = None;
    let root = brent(
        |a| match edge(a) {
            Ok(p) => p,
            Err(e) => {
                failed = Some(e);
                f64::NAN
            }
        },
        (lo, f_lo),
        (hi, f_hi),
        1e-10 * guess,
        "continuum contact radius",
    );
    if let Some(e) = failed {
        return Err(e);
    }
    let a = root?.x;
    Ok((a, Contact::new(radius, load, layer, rings, a)?.penetration))
}

fn not_bracketed() -> ModelError {
    ModelError::NoConvergence {
        what: "continuum contact radius",
        iterations: 0,
    }
}

/// The rings over [0, a] solved for their pressures and δ.
struct Contact {
    pressures: DVector<f64>,
    penetration: f64,
}

impl Contact {
    fn new(
        radius: f64,
        load: f64,
        layer: &Layer,
        rings: usize,
        a: f64,
    ) -> Result<Contact, ModelError> {
        let edges: Vec<f64> = (0..=rings).map(|j| a * j as f64 / rings as f64).collect();
        let middles: Vec<f64> = edges.windows(2).map(|e| 0.5 * (e[0] + e[1])).collect();
        let influence = influence(layer, &middles, &edges);
        // [K −1; Aᵀ 0] [p; δ] = [−f; P].
        let n = rings;
        let mut system = DMatrix::zeros(n + 1, n + 1);
        let mut rhs = DVector::zeros(n + 1);
        for i in 0..n {
            for j in 0..n {
                system[(i, j)] = influence[(i, j)];
            }
            system[(i, n)] = -1.0;
            rhs[i] = -middles[i] * middles[i] / (2.0 * radius);
            system[(n, i)] = PI * (edges[i + 1] * edges[i + 1] - edges[i] * edges[i]);
        }
        rhs[n] = load;
        let solution = system.lu().solve(&rhs).ok_or(ModelError::NoConvergence {
            what: "continuum ring pressures",
            iterations: 0,
        })?;
        Ok(Contact {
            penetration: solution[n],
            pressures: solution.rows(0, n).into_owned(),
        })
    }

    /// The outermost ring's pressure relative to the mean (scale-free for the root finder).
    fn edge_pressure(&self) -> f64 {
        let n = self.pressures.len();
        self.pressures[n - 1] / self.pressures.mean().abs()
    }
}

/// The deflection at each of `points` under unit pressure on each ring between consecutive
/// `edges`: the half-space's in closed form plus the layer's correction by quadrature.
fn influence(layer: &Layer, points: &[f64], edges: &[f64]) -> DMatrix<f64> {
    let nu = layer.poisson_ratio;
    let e_star = contact_modulus(layer);
    let h = layer.thickness;
    // Disc influences: column j is the disc of radius edges[j].
    let mut disc = DMatrix::from_fn(points.len(), edges.len(), |i, j| {
        half_space_disc(points[i], edges[j]) / e_star
    });
    // (2(1 − ν²)/E) c ∫ (C(s) − 1) J1(sc/H) J0(sr/H) ds/s, with 2(1 − ν²)/E = 2/E*.
    let extent = edges.last().copied().unwrap_or(0.0) / h;
    let nodes: Vec<(f64, f64)> = correction_rule(nu, extent)
        .into_iter()
        .map(|(s, weight)| (s, weight / s))
        .collect();
    let at_points = DMatrix::from_fn(points.len(), nodes.len(), |i, k| {
        let (s, weight) = nodes[k];
        weight * libm::j0(s * points[i] / h)
    });
    let at_edges = DMatrix::from_fn(nodes.len(), edges.len(), |k, j| {
        edges[j] * libm::j1(nodes[k].0 * edges[j] / h)
    });
    disc += (at_points * at_edges) * (2.0 / e_star);
    // A ring is the disc of its outer edge less that of its inner one.
    DMatrix::from_fn(points.len(), edges.len() - 1, |i, j| {
        disc[(i, j + 1)] - disc[(i, j)]
    })
}

/// The deflection of a half-space of plane-strain modulus 1 at radius `r` under unit
/// pressure on the disc of radius `c` (Johnson, Contact Mechanics, §3.4).
fn half_space_disc(r: f64, c: f64) -> f64 {
    if c == 0.0 {
        return 0.0;
    }
    let scale = 4.0 / PI;
    if r <= c {
        let (_, e) = elliptic(r / c);
        scale * c * e
    } else {
        let k = c / r;
        let (kk, e) = elliptic(k);
        scale * r * (e - (1.0 - k * k) * kk)
    }
}

/// The complete elliptic integrals K(k) and E(k) of modulus 0 ≤ k ≤ 1, by the
/// arithmetic–geometric mean (exact to rounding in a few steps); K(1) is infinite, E(1) = 1.
fn elliptic(k: f64) -> (f64, f64) {
    if k >= 1.0 {
        return (f64::INFINITY, 1.0);
    }
    let (mut a, mut b) = (1.0, (1.0 - k * k).sqrt());
    let mut c = k;
    let mut sum = 0.5 * c * c;
    let mut power = 0.5;
    for _ in 0..40 {
        if c.abs() <= 1e-17 * a {
            break;
        }
        c = 0.5 * (a - b);
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
        power *= 2.0;
        sum += power * c * c;
    }
    let kk = PI / (2.0 * a);
    (kk, kk * (1.0 - sum))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_elliptic_integrals_are_the_tabulated_ones() {
        let (k0, e0) = elliptic(0.0);
        assert!((k0 - PI / 2.0).abs() < 1e-15 && (e0 - PI / 2.0).abs() < 1e-15);
        // K(1/√2) and E(1/√2) (Abramowitz & Stegun, table 17.1).
        let (kk, e) = elliptic(std::f64::consts::FRAC_1_SQRT_2);
        assert!((kk - 1.854_074_677_301_372).abs() < 1e-14, "{kk}");
        assert!((e - 1.350_643_881_047_675_5).abs() < 1e-14, "{e}");
    }

    /// A uniformly loaded disc deflects its centre by 2pc/E* and its edge by 4pc/(πE*).
    #[test]
    fn a_loaded_disc_deflects_the_half_space_as_johnson_gives() {
        assert!((half_space_disc(0.0, 2.0) - 4.0).abs() < 1e-14);
        assert!((half_space_disc(2.0, 2.0) - 8.0 / PI).abs() < 1e-14);
        // Far away, as a point load: P/(πE* r) with P = πc².
        let far = half_space_disc(1000.0, 1.0);
        assert!((far * 1000.0 - 1.0).abs() < 1e-6, "{far}");
    }
}
