//! The continuum contact of a rigid sphere at a given penetration, for one layer and one
//! speed: what a three-body system needs of the layer at each particle size (docs/model.md
//! §4 with §8's layer).
//!
//! Lateral lengths in units of c = √(Rδ) (Hertz's contact radius at penetration δ) and
//! depths in units of δ, the sphere's profile is the same for every R and δ, so the answer
//! depends on R and δ only through c (besides the layer and V):
//!
//!     F = (4/3) E* √R δ^{3/2} Φ_P(c),    A = π R δ Φ_A(c).
//!
//! Φ_P and Φ_A are tabulated once per (layer, V) from [`super::solve`] at loads spread over
//! the c a system can reach, and interpolated by cubics in ln c of ln Φ; so is x_p/c, the
//! centre of pressure that sets the particle's rolling resistance (docs/model.md §11). As
//! c → 0 the contact is a half-space's (H/c → ∞) and, rolling, the instantaneous one
//! (V T_σ/c → ∞): Φ_P → 1 + κ (1 at rest), Φ_A → 1 and x_p/c → 0; below the table's first
//! node each goes linearly in c to that limit. Beyond the last node, each logarithm goes on
//! along the last cell's line.

use std::f64::consts::PI;

use super::answer::{solve, ContinuumVerification};
use super::compliance::contact_modulus;
use super::table::static_area;
use crate::limits::hertz_force;
use crate::roots::brent;
use crate::{Layer, ModelError, Quadrature, Rolling, RollingSolution, SolveOptions, Stop};

/// Nodes per decade of the static contact radius that places them
/// ([`PenetrationCurve::problems`]).
const PER_DECADE: f64 = 4.0;

/// The table starts where c is this share of the smaller of V T_σ and H: there the contact
/// is the instantaneous half-space's within about 0.5 % (measured at the defaults).
const FIRST: f64 = 1e-3;

/// Decades of c the table spans at most: at a speed so slow that V T_σ is this many decades
/// below the largest contact, the table starts there instead (33 nodes; the contacts
/// smaller still carry nothing of the sums, and their error is reported, see
/// [`PenetrationCurve::error_at`]).
const MOST_DECADES: f64 = 8.0;

/// The sphere the nodes are solved for (any radius gives the same Φ; one this large keeps
/// δ a minute share of the layer and the contact far smaller than the sphere).
const REFERENCE_RADIUS: f64 = 1e-3;

/// The share of c below which a node's x_p is taken as that (a rolling answer's x_p is
/// positive; this keeps its logarithm finite should rounding make it not).
const LEAST_SHIFT: f64 = 1e-12;

/// One node: ln c; ln Φ_P, ln Φ_A and ln(x_p/c); a bound on the relative error of the
/// curve's F and A there and one on x_p's (each the answer's own, then with the
/// interpolation's, [`PenetrationCurve::certify`]).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Node {
    ln_c: f64,
    ln: [f64; 3],
    error: f64,
    pressure_error: f64,
}

/// Φ_P and Φ_A of one layer at one speed (see the module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct PenetrationCurve {
    layer: Layer,
    velocity: f64,
    /// E* of the layer (Pa).
    modulus: f64,
    /// ln Φ_P, ln Φ_A and ln(x_p/c) as c → 0.
    limit: [f64; 3],
    nodes: Vec<Node>,
}

impl PenetrationCurve {
    /// The rolling problems whose answers make the curve of `layer` at `velocity` up to
    /// c = `reach`: spheres of one radius under loads spaced [`PER_DECADE`] a decade, from
    /// where the contact is its c → 0 limit to beyond `reach`.
    ///
    /// The loads are placed by the static contact radius a on the instantaneous layer (a
    /// table look-up): a rolling contact is softer than that one, and δ ≥ a²/(4R) on any
    /// bonded layer (Hertz δ = a²/R, the local law a²/(2R), a thin incompressible layer
    /// a²/(4R)), so c ≥ a/2 and a node with a = 2·reach reaches c ≥ reach.
    pub fn problems(layer: &Layer, velocity: f64, reach: f64) -> Vec<Rolling> {
        let stiff = layer.instantaneous();
        let scale = if velocity > 0.0 {
            (velocity * layer.terms().shortest()).min(layer.thickness)
        } else {
            layer.thickness
        };
        let top = 2.0 * reach.max(FIRST * scale);
        let bottom = (FIRST * scale).max(top * 10f64.powf(-MOST_DECADES));
        let decades = (top / bottom).log10();
        let n = (decades * PER_DECADE).ceil().max(3.0) as usize;
        (0..=n)
            .map(|i| Rolling {
                radius: REFERENCE_RADIUS,
                load: load_for_radius(bottom * 10f64.powf(decades * i as f64 / n as f64), &stiff),
                velocity,
                layer: *layer,
            })
            .collect()
    }

    /// The options the problems are solved with: no boundary, no pressure map.
    pub fn options() -> SolveOptions {
        SolveOptions::integrals_only(Quadrature::default())
    }

    /// Solves `problem` (one of [`PenetrationCurve::problems`]), stopped when `stop` says so.
    pub fn solve(
        problem: &Rolling,
        stop: Stop,
    ) -> Result<RollingSolution<ContinuumVerification>, ModelError> {
        solve(problem, &Self::options(), stop)
    }

    /// The curve from the answers to [`PenetrationCurve::problems`], in their order.
    pub fn from_answers(
        layer: &Layer,
        velocity: f64,
        problems: &[Rolling],
        answers: &[RollingSolution<ContinuumVerification>],
    ) -> PenetrationCurve {
        debug_assert!(
            problems.len() == answers.len() && problems.len() >= 4,
            "a curve takes an answer to each of its problems, at least four"
        );
        let modulus = contact_modulus(layer);
        let nodes: Vec<Node> = problems
            .iter()
            .zip(answers)
            .map(|(problem, answer)| {
                let (radius, delta) = (problem.radius, answer.penetration);
                let hertz = hertz_force(modulus, radius, delta);
                let e = answer.verification.errors;
                let c = (radius * delta).sqrt();
                let shift = answer.pressure_centre_shift.max(LEAST_SHIFT * c);
                Node {
                    ln_c: c.ln(),
                    ln: [
                        (problem.load / hertz).ln(),
                        (answer.contact_area / (PI * radius * delta)).ln(),
                        (shift / c).ln(),
                    ],
                    // Φ_P ∝ δ^{-3/2} at the node's load, and the node's c moves with δ^{1/2}
                    // along a curve of slope at most about 1 in ln–ln: 2 ε_δ in all; Φ_A
                    // ∝ A/δ, and moves likewise; x_p/c likewise with x_p's own error.
                    error: (2.0 * e.penetration).max(e.contact_area + 1.5 * e.penetration),
                    pressure_error: e.pressure_centre_shift / shift + e.penetration,
                }
            })
            .collect();
        let limit = [
            if velocity > 0.0 {
                layer.stiffening().ln()
            } else {
                0.0
            },
            0.0,
            f64::NEG_INFINITY,
        ];
        let mut curve = PenetrationCurve {
            layer: *layer,
            velocity,
            modulus,
            limit,
            nodes,
        };
        curve.certify();
        curve
    }

    /// The curve of `layer` at `velocity` up to c = `reach`, solved here one node after
    /// another, to the end (a caller with threads, or one that may stop it, solves
    /// [`PenetrationCurve::problems`] itself).
    pub fn build(layer: &Layer, velocity: f64, reach: f64) -> Result<PenetrationCurve, ModelError> {
        let problems = Self::problems(layer, velocity, reach);
        let answers = problems
            .iter()
            .map(|p| Self::solve(p, Stop::NEVER))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self::from_answers(layer, velocity, &problems, &answers))
    }

    /// The layer and speed of the curve.
    pub fn layer(&self) -> &Layer {
        &self.layer
    }

    pub fn velocity(&self) -> f64 {
        self.velocity
    }

    /// The largest c of the table (m): beyond it the curve is extrapolated.
    pub fn reach(&self) -> f64 {
        self.nodes.last().map_or(0.0, |n| n.ln_c.exp())
    }

    /// A bound on the relative error of the force and the area the curve gives anywhere:
    /// the worst of [`PenetrationCurve::error_at`] (at a node, below the first, beyond the
    /// last).
    pub fn error(&self) -> f64 {
        let (first, last) = (self.nodes[0], self.nodes[self.nodes.len() - 1]);
        self.nodes
            .iter()
            .map(|n| n.error)
            .fold(self.below(&first).max(2.0 * last.error), f64::max)
    }

    /// The error bound below the first node: its own, and the limit's difference from it.
    fn below(&self, first: &Node) -> f64 {
        let off = (first.ln[0] - self.limit[0])
            .abs()
            .max((first.ln[1] - self.limit[1]).abs());
        first.error + off
    }

    /// A bound on the relative error of the force and the area of a sphere of radius
    /// `radius` at penetration `delta`: the worse of its cell's two nodes; below the first
    /// node, that node's and the limit's difference from it; beyond the last, twice the
    /// last's.
    pub fn error_at(&self, radius: f64, delta: f64) -> f64 {
        let ln_c = 0.5 * (radius * delta).ln();
        let (first, last) = (self.nodes[0], self.nodes[self.nodes.len() - 1]);
        if ln_c <= first.ln_c {
            return self.below(&first);
        }
        if ln_c >= last.ln_c {
            return 2.0 * last.error;
        }
        let cell = self.nodes.partition_point(|node| node.ln_c <= ln_c);
        self.nodes[cell - 1].error.max(self.nodes[cell].error)
    }

    /// (F, A) of a sphere of radius `radius` pressed to penetration `delta`.
    pub fn contact(&self, radius: f64, delta: f64) -> (f64, f64) {
        if delta <= 0.0 {
            return (0.0, 0.0);
        }
        let [ln_force, ln_area, _] = self.ratios(0.5 * (radius * delta).ln());
        (
            hertz_force(self.modulus, radius, delta) * ln_force.exp(),
            PI * radius * delta * ln_area.exp(),
        )
    }

    /// x_p (m), the centre of pressure of a sphere of radius `radius` pressed to
    /// penetration `delta` (0 at rest).
    pub fn pressure_centre(&self, radius: f64, delta: f64) -> f64 {
        if delta <= 0.0 || self.velocity == 0.0 {
            return 0.0;
        }
        let ln_c = 0.5 * (radius * delta).ln();
        (self.ratios(ln_c)[2] + ln_c).exp()
    }

    /// A bound on the relative error of [`PenetrationCurve::pressure_centre`], as
    /// [`PenetrationCurve::error_at`] bounds the force's and the area's. Below the first
    /// node x_p/c falls linearly in c to its limit 0 (x_p ∝ c² as V T_σ/c → ∞): that node's
    /// bound, and how far the first cell's slope in ln–ln is from that, carried over the
    /// distance in ln c.
    pub fn pressure_error_at(&self, radius: f64, delta: f64) -> f64 {
        let ln_c = 0.5 * (radius * delta).ln();
        let (first, last) = (self.nodes[0], self.nodes[self.nodes.len() - 1]);
        if ln_c <= first.ln_c {
            let next = self.nodes[1];
            let slope = (next.ln[2] - first.ln[2]) / (next.ln_c - first.ln_c);
            return first.pressure_error + (slope - 1.0).abs() * (first.ln_c - ln_c);
        }
        if ln_c >= last.ln_c {
            return 2.0 * last.pressure_error;
        }
        let cell = self.nodes.partition_point(|node| node.ln_c <= ln_c);
        self.nodes[cell - 1]
            .pressure_error
            .max(self.nodes[cell].pressure_error)
    }

    /// ln Φ_P, ln Φ_A and ln(x_p/c) at ln c.
    fn ratios(&self, ln_c: f64) -> [f64; 3] {
        self.ratios_from(&self.nodes, ln_c)
    }

    /// ln Φ_P, ln Φ_A and ln(x_p/c) at ln c from `nodes` (ascending in c, at least two).
    fn ratios_from(&self, nodes: &[Node], ln_c: f64) -> [f64; 3] {
        let first = nodes[0];
        if ln_c <= first.ln_c {
            // Linear in c from the limit at c = 0 to the first node.
            let t = (ln_c - first.ln_c).exp();
            let blend = |limit: f64, node: f64| (limit.exp() + t * (node.exp() - limit.exp())).ln();
            return [0, 1, 2].map(|k| blend(self.limit[k], first.ln[k]));
        }
        let n = nodes.len();
        // The cell holding ln c (the last cell beyond the table), and the four nodes around
        // it (three at either end).
        let cell = nodes
            .partition_point(|node| node.ln_c <= ln_c)
            .clamp(1, n - 1)
            - 1;
        if ln_c >= nodes[n - 1].ln_c || n < 4 {
            let (a, b) = (nodes[cell], nodes[cell + 1]);
            let t = (ln_c - a.ln_c) / (b.ln_c - a.ln_c);
            return [0, 1, 2].map(|k| a.ln[k] + t * (b.ln[k] - a.ln[k]));
        }
        let start = cell.saturating_sub(1).min(n - 4);
        let around = &nodes[start..start + 4];
        [0, 1, 2].map(|k| lagrange(around, ln_c, |node| node.ln[k]))
    }

    /// Adds the interpolation's error to each node's own. It is estimated by leaving each
    /// inner node out and interpolating it from the others: that is the error of a table of
    /// twice the spacing there, sixteen times a cubic's on this one; a quarter of it is kept
    /// (the leave-out difference also holds the nodes' own scatter, counted already). The
    /// end nodes take their neighbours'.
    fn certify(&mut self) {
        let nodes = &self.nodes;
        let n = nodes.len();
        let left_out: Vec<[f64; 3]> = (1..n - 1)
            .map(|i| {
                let mut others = nodes.clone();
                let node = others.remove(i);
                let interpolated = self.ratios_from(&others, node.ln_c);
                [0, 1, 2].map(|k| (interpolated[k] - node.ln[k]).abs())
            })
            .collect();
        for i in 0..n {
            let [force, area, shift] = left_out[i.clamp(1, n - 2) - 1];
            self.nodes[i].error += 0.25 * force.max(area);
            self.nodes[i].pressure_error += 0.25 * shift;
        }
    }
}

/// The cubic through four nodes, at `x`, of the value `f` gives.
fn lagrange(nodes: &[Node], x: f64, f: impl Fn(&Node) -> f64) -> f64 {
    (0..4)
        .map(|i| {
            let weight: f64 = (0..4)
                .filter(|j| *j != i)
                .map(|j| (x - nodes[j].ln_c) / (nodes[i].ln_c - nodes[j].ln_c))
                .product();
            weight * f(&nodes[i])
        })
        .sum()
}

/// The load under which the static continuum contact on `layer` of a sphere of
/// [`REFERENCE_RADIUS`] has radius `radius` (the area table, inverted in ln P).
fn load_for_radius(radius: f64, layer: &Layer) -> f64 {
    let area = PI * radius * radius;
    let r = REFERENCE_RADIUS;
    // Hertz's load for that radius brackets it: a bonded layer is stiffer than a half-space,
    // and within a factor 1e12 of it for any layer the table covers.
    let hertz = 4.0 * contact_modulus(layer) * radius.powi(3) / (3.0 * r);
    let mismatch = |ln_p: f64| (static_area(r, ln_p.exp(), layer) / area).ln();
    let (lo, hi) = (hertz.ln(), hertz.ln() + 28.0);
    brent(
        mismatch,
        (lo, mismatch(lo)),
        (hi, mismatch(hi)),
        1e-6,
        "load of a node of the continuum penetration curve",
    )
    .map_or(hertz, |root| root.x.exp())
}
