//! A rigid sphere rolling at constant speed over the Kelvin layer: penetration, contact
//! region, area, centroid and centre of pressure, friction (docs/model.md §3, eqs. 2–5, 9–12).
//!
//! The solution is computed in units of the static half-width r₀ = √(2Rδ₀): there the
//! contact shape depends only on ξ = V T_σ / r₀ and κ (the similarity law), the load to
//! carry is P̂ = π/4, and no intermediate quantity can over- or underflow.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
use std::sync::Arc;

use super::limits::{relaxed, ElasticContact};
use super::quadrature::{Spacing, StripRule};
use super::similarity::{ExactRatios, Ratios, SimilarityTable};
use super::spectrum::Terms;
use super::strip::Strip;
use super::{Layer, ModelError, OptionError, Parameter, Quadrature, SolveOption};

/// Iterations allowed for the penetration root P(δ) = P.
const MAX_LOAD_ITERATIONS: u32 = 60;
/// The load equation is solved to this relative residual: δ then carries an error of a
/// quarter of it, far below the 1e-9 of the quadrature.
const LOAD_TOLERANCE: f64 = 1e-14;
/// A residual still accepted when the bracket has shrunk to rounding: the sum over many
/// strips is only that exact.
const LOAD_ROUNDING: f64 = 1e-12;
/// d ln P̂/d ln r̂ at both elastic limits (P ∝ δ² ∝ r̂⁴), the first guess of the load
/// equation's slope.
const ELASTIC_SLOPE: f64 = 4.0;
/// The error bound of an answer is this many times the error it measures
/// ([`quadrature_error`]): it covers rules whose error shrinks by less than 2 when the strips
/// double (midpoint strips: by 2^1.5).
const ERROR_SAFETY: f64 = 2.0;
/// Largest number of boundary points a solve returns.
pub const MAX_BOUNDARY_POINTS: usize = 10_001;
/// Largest pressure grid (points per side).
pub const MAX_PRESSURE_GRID: usize = 501;

/// One particle rolling over the layer: the inputs of docs/model.md §3.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rolling {
    /// R (m).
    pub radius: f64,
    /// P (N).
    pub load: f64,
    /// V (m/s), ≥ 0; the sphere rolls in +x.
    pub velocity: f64,
    pub layer: Layer,
}

impl Default for Rolling {
    /// docs/model.md §5: R = 25 nm, P = 1 nN, V = 4 nm/s on the default layer.
    fn default() -> Self {
        Rolling {
            radius: 25e-9,
            load: 1e-9,
            velocity: 4e-9,
            layer: Layer::default(),
        }
    }
}

impl Rolling {
    /// Every parameter outside its physical range.
    pub fn violations(&self) -> Vec<super::ParameterError> {
        let mut errors: Vec<_> = [
            (Parameter::Radius, self.radius),
            (Parameter::Load, self.load),
            (Parameter::Velocity, self.velocity),
        ]
        .into_iter()
        .filter_map(|(parameter, value)| parameter.check(value).err())
        .collect();
        errors.extend(self.layer.violations());
        errors
    }
}

/// What to compute besides the integral quantities, and how.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SolveOptions {
    pub quadrature: Quadrature,
    /// Points of the contact boundary to return, spread evenly in θ over −r ≤ y ≤ r
    /// (0: none).
    pub boundary_points: usize,
    /// Pressure on an n × n grid over the square [−r, r]², if asked.
    pub pressure_grid: Option<usize>,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            quadrature: Quadrature::default(),
            boundary_points: 41,
            pressure_grid: None,
        }
    }
}

impl SolveOptions {
    /// Options that ask only for the integral quantities (used by sweeps).
    pub fn integrals_only(quadrature: Quadrature) -> Self {
        SolveOptions {
            quadrature,
            boundary_points: 0,
            pressure_grid: None,
        }
    }

    /// Every option outside its offered range.
    pub fn violations(&self) -> Vec<OptionError> {
        let mut errors: Vec<OptionError> = self.quadrature.check().err().into_iter().collect();
        if self.boundary_points > MAX_BOUNDARY_POINTS {
            errors.push(OptionError {
                option: SolveOption::BoundaryPoints,
                value: self.boundary_points,
                allowed: format!("0 ≤ n ≤ {MAX_BOUNDARY_POINTS}"),
            });
        }
        if let Some(n) = self
            .pressure_grid
            .filter(|n| !(2..=MAX_PRESSURE_GRID).contains(n))
        {
            errors.push(OptionError {
                option: SolveOption::PressureGrid,
                value: n,
                allowed: format!("2 ≤ n ≤ {MAX_PRESSURE_GRID}"),
            });
        }
        errors
    }
}

/// One point of the contact boundary: at lateral position y, material leaves the contact at
/// x = exit (trailing edge a(y)) and enters it at x = entry (leading edge b(y)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundaryPoint {
    pub y: f64,
    pub exit: f64,
    pub entry: f64,
}

/// Contact pressure p(x, y) (Pa) on a grid: `values[j][i]` is p(x[i], y[j]).
#[derive(Clone, Debug, PartialEq)]
pub struct PressureGrid {
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub values: Vec<Vec<f64>>,
}

/// How far the answer can be trusted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Verification {
    /// |P(δ) − P|/P, with P(δ) recomputed from the returned penetration.
    pub load_residual: f64,
    /// A bound on the relative error of every quantity returned (δ, A, the half-width, x_c,
    /// x_p, μ, μ_r and the static companion) against the exact solution of docs/model.md §3:
    /// twice their largest relative change against a companion rule of half (for rules of
    /// fewer than 8 strips, twice) the strips, with the load residual, propagated through
    /// the load equation ([`quadrature_error`]). Never below rounding (16 ε). A table answer
    /// reports the exact solver's bound near its ξ here, and `table_error` beside it: the
    /// two add up.
    pub quadrature_error_estimate: f64,
    /// Strips (quadrature nodes) in the half-width.
    pub quadrature_nodes: usize,
    /// Iterations of the load equation P(δ) = P: strip-sum passes under every rule of the
    /// nested solve (coarsest first), or table look-ups.
    pub iterations: u32,
    /// Newton steps of all exit-edge roots together (every rule's).
    pub exit_root_iterations: u32,
    /// Whether every root converged (a solution is only returned when it did).
    pub converged: bool,
    /// When the load equation was solved through the layer's similarity table rather than
    /// by strip sums: the table's certified bound on the relative difference from the exact
    /// solve ([`SimilarityTable::error`]); the answer's error is then bounded by
    /// `quadrature_error_estimate + table_error`.
    pub table_error: Option<f64>,
}

/// The rolling contact (docs/model.md §3), in SI units, with how far it can be trusted:
/// [`Verification`] for the local law's exact solution, the grid's error for the layer as a
/// continuum ([`crate::continuum::GridVerification`]).
#[derive(Clone, Debug, PartialEq)]
pub struct RollingSolution<V = Verification> {
    /// δ (m).
    pub penetration: f64,
    /// A (m²).
    pub contact_area: f64,
    /// √(2Rδ) (m): lateral half-width of the contact, at every speed.
    pub half_width: f64,
    /// x_c (m), area centroid, positive in the rolling direction.
    pub centroid_shift: f64,
    /// x_p (m), centre of pressure.
    pub pressure_centre_shift: f64,
    /// μ_r = x_p/R, the hysteresis (rolling-resistance) coefficient; not part of eq. 12.
    pub rolling_resistance_coefficient: f64,
    /// μ = τ_a A / P (eq. 12).
    pub friction_coefficient: f64,
    /// The same sphere at V = 0 (closed form for the local law).
    pub static_contact: ElasticContact,
    pub boundary: Vec<BoundaryPoint>,
    pub pressure: Option<PressureGrid>,
    pub verification: V,
}

impl<V> RollingSolution<V> {
    /// The integral quantities an answer reports, in the order of the struct: δ, A,
    /// half-width, x_c, x_p, μ_r, μ, and the static companion's δ, A, μ.
    pub fn quantities(&self) -> [f64; 10] {
        [
            self.penetration,
            self.contact_area,
            self.half_width,
            self.centroid_shift,
            self.pressure_centre_shift,
            self.rolling_resistance_coefficient,
            self.friction_coefficient,
            self.static_contact.penetration,
            self.static_contact.contact_area,
            self.static_contact.friction_coefficient,
        ]
    }
}

/// Solves the rolling contact of `rolling` (docs/model.md §3).
///
/// Fails, never panics nor returns a non-finite number, on parameters outside their ranges,
/// scales beyond double precision, or a root that does not converge.
pub fn solve(rolling: &Rolling, options: &SolveOptions) -> Result<RollingSolution, ModelError> {
    solve_with(rolling, options, None)
}

/// [`solve`], with the load equation solved through `table` (the similarity table of the
/// layer's κ under the same rule) instead of strip sums: the answer then differs from the
/// exact one by at most `verification.table_error`. The contact boundary and the pressure
/// are still the exact strip solutions at the table's penetration.
pub(super) fn solve_with(
    rolling: &Rolling,
    options: &SolveOptions,
    table: Option<&SimilarityTable>,
) -> Result<RollingSolution, ModelError> {
    if let Some(error) = rolling.violations().into_iter().next() {
        return Err(error.into());
    }
    if let Some(error) = options.violations().into_iter().next() {
        return Err(ModelError::InvalidOption(error));
    }
    let layer = &rolling.layer;
    let reference = relaxed(rolling.radius, rolling.load, layer);
    let r0 = reference.half_width;
    let xi = rolling.velocity * layer.relaxation_time / r0;
    let viscosity = layer.viscosity(rolling.velocity / r0);
    for (what, value) in [
        ("the static contact half-width √(2Rδ₀)", r0),
        ("V T_σ / r₀", xi),
        ("V τ_j / r₀", viscosity.longest()),
    ] {
        if !value.is_finite() || (value == 0.0 && what == "the static contact half-width √(2Rδ₀)")
        {
            return Err(ModelError::NotRepresentable {
                what: what.to_string(),
            });
        }
    }

    let contact = match table {
        Some(table) if xi > 0.0 => Contact::tabulated(xi, table)?,
        _ => Contact::exact(&viscosity, options.quadrature)?,
    };
    let section = Section::new(contact.half_width, viscosity);
    let half_width = contact.half_width * r0;
    let contact_area = contact.area * r0 * r0;
    let pressure_centre_shift = contact.pressure_centre * r0;
    let solution = RollingSolution {
        penetration: half_width * half_width / (2.0 * rolling.radius),
        contact_area,
        half_width,
        centroid_shift: contact.centroid * r0,
        pressure_centre_shift,
        rolling_resistance_coefficient: pressure_centre_shift / rolling.radius,
        friction_coefficient: layer.interfacial_shear_strength() * contact_area / rolling.load,
        static_contact: reference,
        boundary: section.boundary(options.boundary_points, r0, contact.solved.as_ref())?,
        pressure: match options.pressure_grid {
            Some(n) => Some(section.pressure_grid(n, r0, layer.stiffness() / rolling.radius)?),
            None => None,
        },
        verification: Verification {
            quadrature_nodes: options.quadrature.size(),
            ..contact.verification
        },
    };
    ensure_finite(&solution)?;
    Ok(solution)
}

/// The contact at a given penetration δ rather than a given load (the forward map of the
/// three-body model, docs/model.md §4, and the builder of the similarity tables), as the
/// ratios of the similarity law ([`Ratios`]), which depend only on the viscous terms in units
/// of the half-width √(2Rδ) (for the Kelvin layer ξ = V T_σ/√(2Rδ) and κ,
/// [`crate::Layer::viscosity`]), with the quadrature error estimate a rolling answer would
/// report there, under `quadrature` (its nodes spaced for the shortest term,
/// [`Spacing::for_speed`]). Φ_P runs from 1 (ξ = 0) to 1 + Σκ_j (ξ → ∞); Φ_A is 1 at both
/// ends and dips in between.
pub fn penetration_contact(
    viscosity: &Terms,
    quadrature: Quadrature,
) -> Result<ExactRatios, ModelError> {
    let spacing = Spacing::for_speed(viscosity.shortest());
    let rule = StripRule::shared(quadrature, spacing)?;
    let companion = StripRule::shared(quadrature.companion(), spacing)?;
    let section = Section::new(1.0, *viscosity);
    let mut roots = vec![f64::NAN; rule.len()];
    let integrals = section.integrate(&rule, Some(&mut roots))?;
    // At a given penetration there is no load equation, and so no residual to carry.
    let (moment, error) =
        section.moment_and_error(&rule, &roots, &integrals, &companion, None, 0.0)?;
    let ratios = Ratios {
        load: integrals.load / FRAC_PI_4,
        area: integrals.area / PI,
        centroid: integrals.centroid(),
        pressure_centre: moment / integrals.load,
    };
    Ok((ratios, error))
}

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

/// Refuses to hand out a non-finite number (serde_json would write it as a silent `null`).
fn ensure_finite(s: &RollingSolution) -> Result<(), ModelError> {
    let verification = [
        s.verification.load_residual,
        s.verification.quadrature_error_estimate,
    ];
    let scalars = s.quantities().into_iter().chain(verification);
    let boundary = s.boundary.iter().flat_map(|p| [p.y, p.exit, p.entry]);
    let pressure = s.pressure.iter().flat_map(|g| {
        g.x.iter()
            .chain(&g.y)
            .chain(g.values.iter().flatten())
            .copied()
    });
    if scalars.chain(boundary).chain(pressure).all(f64::is_finite) {
        Ok(())
    } else {
        Err(ModelError::NotRepresentable {
            what: "a result of this job".to_string(),
        })
    }
}

/// The solved contact in units of r₀ (P̂(r̂) = π/4) and how far to trust it.
struct Contact {
    /// r̂ = √(2Rδ)/r₀ = √(δ/δ₀).
    half_width: f64,
    /// A/r₀².
    area: f64,
    /// x_c/r₀.
    centroid: f64,
    /// x_p/r₀.
    pressure_centre: f64,
    verification: Verification,
    /// The rule solved and its strips' exit roots, if solved by strip sums: a guide for the
    /// boundary's roots.
    solved: Option<(Arc<StripRule>, Vec<f64>)>,
}

impl Contact {
    /// By strip sums: the load root ([`Shape::nested`]), then the pressure moment, then the
    /// same integrals under the companion rule for the quadrature error estimate.
    fn exact(viscosity: &Terms, quadrature: Quadrature) -> Result<Contact, ModelError> {
        let (shape, coarse) = Shape::nested(viscosity, quadrature)?;
        let spacing = Spacing::for_speed(viscosity.shortest());
        let companion = StripRule::shared(quadrature.companion(), spacing)?;
        let section = shape.section(viscosity);
        let (pressure_moment, quadrature_error_estimate) = section.moment_and_error(
            &shape.rule,
            &shape.exit_roots,
            &shape.integrals,
            &companion,
            coarse.map(|coarse| coarse.exit_roots),
            shape.load_residual,
        )?;
        Ok(Contact {
            half_width: shape.half_width,
            area: shape.integrals.area,
            centroid: shape.integrals.centroid(),
            pressure_centre: pressure_moment / shape.integrals.load,
            verification: Verification {
                load_residual: shape.load_residual,
                quadrature_error_estimate,
                quadrature_nodes: shape.rule.len(),
                iterations: shape.iterations,
                exit_root_iterations: shape.integrals.exit_root_iterations,
                converged: true,
                table_error: None,
            },
            solved: Some((shape.rule, shape.exit_roots)),
        })
    }

    /// Through the similarity table: at r̂ the contact is the table's at ξ/r̂ scaled by r̂
    /// (P̂ = (π/4) r̂⁴ Φ_P, Â = π r̂² Φ_A, x/r₀ = r̂ · x/r), so the load equation is
    /// f(t) = 4t + ln Φ_P(ξ e^{−t}) = 0 in t = ln r̂ (nearly linear: f′ lies between 3 and
    /// 4; in r̂ itself the secant needs one or two steps more), solved by the secant method
    /// ([`load_root`]) from t = −¼ ln Φ_P(ξ) and the known f(0) = ln Φ_P(ξ).
    fn tabulated(xi: f64, table: &SimilarityTable) -> Result<Contact, ModelError> {
        let at_rest = table.log_ratios(xi).log_load;
        let root = load_root(
            log_bracket(1.0 + table.kappa()),
            -0.25 * at_rest,
            Some((0.0, at_rest)),
            ELASTIC_SLOPE,
            "penetration (load equation through the similarity table)",
            |t| {
                let ratios = table.log_ratios(xi * (-t).exp());
                Ok((4.0 * t + ratios.log_load, ratios))
            },
        )?;
        let (r, ratios) = (root.t.exp(), root.at);
        let load_residual = root.value.exp_m1().abs();
        Ok(Contact {
            half_width: r,
            area: PI * r * r * ratios.area,
            centroid: r * ratios.centroid,
            pressure_centre: r * ratios.pressure_centre,
            verification: Verification {
                load_residual,
                // The exact solver's bound near ξ (at a given penetration) and what this
                // root leaves, as [`quadrature_error`] carries it.
                quadrature_error_estimate: table.quadrature_error(xi / r)
                    + ERROR_SAFETY * load_residual,
                quadrature_nodes: 0,
                iterations: root.iterations,
                exit_root_iterations: 0,
                converged: true,
                table_error: Some(table.error()),
            },
            solved: None,
        })
    }
}

/// The contact in units of r₀ with its load solved: P̂(r̂) = π/4.
struct Shape {
    rule: Arc<StripRule>,
    /// r̂ = √(2Rδ)/r₀ = √(δ/δ₀).
    half_width: f64,
    integrals: Integrals,
    /// Exit root ρ of each strip of the rule.
    exit_roots: Vec<f64>,
    load_residual: f64,
    iterations: u32,
    /// The secant's last estimate of d ln P̂/dt.
    slope: f64,
}

/// Where a load-root search starts: t = ln r̂, the slope of ln P̂ in t assumed for the first
/// step, and a guess of each strip's exit root (NaN: none).
struct Start {
    t: f64,
    slope: f64,
    roots: Vec<f64>,
}

impl Start {
    /// From the static answer t = 0 (exact at V = 0), with the slope of both elastic limits.
    fn cold(strips: usize) -> Start {
        Start {
            t: 0.0,
            slope: ELASTIC_SLOPE,
            roots: vec![f64::NAN; strips],
        }
    }
}

impl Shape {
    /// The shape under `quadrature` and, if its companion rule is the coarser one, under
    /// that too. The load root is found on the companion first (recursively, down to
    /// [`NESTED_FROM`] strips): its root, secant slope and exit roots start the finer rule
    /// within the coarse rule's quadrature error of its root, so the finer rule, which costs
    /// twice as much per pass, needs one or two passes instead of five. The iterations
    /// reported count every rule's.
    fn nested(
        viscosity: &Terms,
        quadrature: Quadrature,
    ) -> Result<(Shape, Option<Shape>), ModelError> {
        /// Rules of fewer strips start cold.
        const NESTED_FROM: usize = 16;
        let rule = StripRule::shared(quadrature, Spacing::for_speed(viscosity.shortest()))?;
        let companion = quadrature.companion();
        // An elastic contact (at rest, or no viscosity) has its root at t = 0, found in one
        // pass: nothing to start.
        let elastic = viscosity.is_empty();
        if elastic || companion.size() >= rule.len() || rule.len() < NESTED_FROM {
            let cold = Start::cold(rule.len());
            return Ok((Shape::solve(viscosity, rule, cold)?, None));
        }
        let (coarse, _) = Shape::nested(viscosity, companion)?;
        let section = coarse.section(viscosity);
        let start = Start {
            t: coarse.half_width.ln(),
            slope: coarse.slope,
            roots: RootGuide::new(&section, &coarse.rule, &coarse.exit_roots)
                .guesses(&section, &rule),
        };
        let mut fine = Shape::solve(viscosity, rule, start)?;
        fine.iterations += coarse.iterations;
        fine.integrals.exit_root_iterations += coarse.integrals.exit_root_iterations;
        Ok((fine, Some(coarse)))
    }

    /// Solves ln P̂(e^t) = ln(π/4) for t = ln r̂ ([`load_root`]) from `start`; the exit roots
    /// of every strip are warm-started from the previous step.
    fn solve(viscosity: &Terms, rule: Arc<StripRule>, start: Start) -> Result<Shape, ModelError> {
        let target = FRAC_PI_4.ln();
        let mut rho = start.roots;
        let mut exit_root_iterations = 0;
        // The step and roots of the evaluation before the last, for extrapolating each
        // strip's root to the next step; the step of the last evaluation.
        let mut before: Option<(f64, Vec<f64>)> = None;
        let mut last: Option<f64> = None;
        let what = "penetration (load equation P(δ) = P)";
        let bracket = log_bracket(1.0 + viscosity.strength());
        let root = load_root(bracket, start.t, None, start.slope, what, |t| {
            let roots = last.map(|t1| (t1, rho.clone()));
            if let (Some(t1), Some((t0, rho0))) = (last, &before) {
                // Each root is a smooth function of t: linear extrapolation from the last
                // two steps lands within the secant's own (shrinking) error of the new root.
                let ratio = (t - t1) / (t1 - t0);
                for (r, r0) in rho.iter_mut().zip(rho0) {
                    *r += (*r - r0) * ratio;
                }
            }
            (before, last) = (roots, Some(t));
            let integrals = Section::new(t.exp(), *viscosity).integrate(&rule, Some(&mut rho))?;
            exit_root_iterations += integrals.exit_root_iterations;
            Ok((integrals.load.ln() - target, integrals))
        })?;
        let mut integrals = root.at;
        integrals.exit_root_iterations = exit_root_iterations;
        Ok(Shape {
            rule,
            half_width: root.t.exp(),
            integrals,
            exit_roots: rho,
            load_residual: root.value.exp_m1().abs(),
            iterations: root.iterations,
            slope: root.slope,
        })
    }

    /// The contact region at the solved half-width.
    fn section(&self, viscosity: &Terms) -> Section {
        Section::new(self.half_width, *viscosity)
    }
}

/// The root of a load equation and what was computed there.
struct LoadRoot<T> {
    t: f64,
    at: T,
    /// The equation's value at the root.
    value: f64,
    iterations: u32,
    /// The last slope estimate (the assumed one if the start was the root).
    slope: f64,
}

/// The bracket δ ∈ [0.9 δ_∞, 1.05 δ₀] of docs/model.md §3, in t = ln r̂ (r̂ = √(δ/δ₀)),
/// for a layer whose instantaneous modulus is `stiffening` times its relaxed one.
fn log_bracket(stiffening: f64) -> (f64, f64) {
    (
        0.5 * 0.9_f64.ln() - 0.25 * stiffening.ln(),
        0.5 * 1.05_f64.ln(),
    )
}

/// Solves a load equation `f` (returning f(t) and what it computed at t; f is a relative
/// residual of the load, increasing in t) by the secant method from `start` (and from a
/// point `known` = (t, f(t)) already computed, if any), guarded by `bracket`.
/// The equations in use are ln P̂/(π/4) in t = ln r̂, nearly linear with slope 4 at both
/// elastic limits ([`ELASTIC_SLOPE`]), so the secant converges in a handful of steps;
/// without a known point its first step assumes the slope `slope`.
fn load_root<T>(
    bracket: (f64, f64),
    start: f64,
    known: Option<(f64, f64)>,
    slope: f64,
    what: &'static str,
    mut f: impl FnMut(f64) -> Result<(f64, T), ModelError>,
) -> Result<LoadRoot<T>, ModelError> {
    let (mut lo, mut hi) = bracket;
    let (mut t_prev, mut f_prev) = known.unwrap_or((f64::NAN, f64::NAN));
    let mut t = start.clamp(lo, hi);
    let (assumed, mut slope) = (slope, slope);
    let mut iterations = 0;
    loop {
        iterations += 1;
        let (value, at) = f(t)?;
        if value > 0.0 {
            hi = hi.min(t);
        } else {
            lo = lo.max(t);
        }
        let collapsed = hi - lo <= 4.0 * f64::EPSILON * t.abs().max(1.0);
        if value.abs() <= LOAD_TOLERANCE || collapsed && value.abs() <= LOAD_ROUNDING {
            return Ok(LoadRoot {
                t,
                at,
                value,
                iterations,
                slope,
            });
        }
        slope = if f_prev.is_nan() || value == f_prev || t == t_prev {
            assumed
        } else {
            (value - f_prev) / (t - t_prev)
        };
        let mut next = t - value / slope;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if collapsed || iterations >= MAX_LOAD_ITERATIONS {
            // Out of iterations, or the bracket collapsed onto a point that does not
            // carry the load.
            return Err(ModelError::NoConvergence { what, iterations });
        }
        (t_prev, f_prev, t) = (t, value, next);
    }
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
struct RootGuide {
    /// (β/(1 + β), ρ(1 + β)²/β), ascending in β.
    known: Vec<(f64, f64)>,
}

impl RootGuide {
    /// The roots `rho` of the strips of `rule` in `section`.
    fn new(section: &Section, rule: &StripRule, rho: &[f64]) -> RootGuide {
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
    fn guess(&self, beta: f64) -> f64 {
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
    fn guesses(&self, section: &Section, rule: &StripRule) -> Vec<f64> {
        rule.cos
            .iter()
            .map(|c| self.guess(section.beta(section.half_width * c)))
            .collect()
    }
}

/// The contact region of half-width r (in units of r₀), strip by strip.
#[derive(Clone, Copy, Debug)]
struct Section {
    half_width: f64,
    /// The viscous terms (κ_j, V τ_j/r₀).
    viscosity: Terms,
}

/// Integrals over the contact, in units of r₀ and k/R.
#[derive(Clone, Copy, Debug, Default)]
struct Integrals {
    /// P̂ = P R/(k r₀⁴).
    load: f64,
    /// Â = A/r₀².
    area: f64,
    /// ∬ x dA / r₀³.
    area_moment: f64,
    exit_root_iterations: u32,
}

impl Integrals {
    /// x_c/r₀ = ∬ x dA / A.
    fn centroid(&self) -> f64 {
        self.area_moment / self.area
    }
}

impl Section {
    fn new(half_width: f64, viscosity: Terms) -> Self {
        Section {
            half_width,
            viscosity,
        }
    }

    /// β = b/λ of the strip with entry edge b (in units of r₀), λ the terms' mean length
    /// (λ_σ for the Kelvin layer); infinite at rest.
    fn beta(&self, entry: f64) -> f64 {
        entry / self.viscosity.mean_scale()
    }

    /// The strip at lateral position y = r sin θ, whose entry edge is b = r cos θ.
    fn strip(&self, cos_theta: f64) -> Strip<'_> {
        Strip {
            entry: self.half_width * cos_theta,
            terms: &self.viscosity,
        }
    }

    /// P = 2∫q dy, A = 2∫(b − a) dy and ∬x dA = ∫(b² − a²) dy over the strips of `rule`.
    /// `warm`, if given, holds each strip's exit root from a previous call and receives the
    /// new ones.
    fn integrate(
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
    fn moment_and_error(
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
    fn boundary(
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
    fn pressure_grid(
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

    /// The nested solve is only a faster path to the same root: it must agree with the fine
    /// rule solved alone, and be cheaper in exit-root Newton steps, across the range of ξ.
    #[test]
    fn nested_solves_agree_with_the_fine_rule_alone_in_fewer_exit_root_steps() {
        let quadrature = Quadrature::default();
        for kappa in [0.5, 4.0, 100.0] {
            for xi in [1e-5, 1e-3, 0.07, 0.5, 3.0, 100.0] {
                let viscosity = Terms::one(kappa, xi);
                let rule = StripRule::shared(quadrature, Spacing::for_speed(xi)).unwrap();
                let cold = Shape::solve(&viscosity, rule.clone(), Start::cold(rule.len())).unwrap();
                let (nested, coarse) = Shape::nested(&viscosity, quadrature).unwrap();
                let coarse = coarse.expect("the default rule's companion is coarser");
                assert!(coarse.rule.len() < rule.len());
                let relative = (nested.half_width / cold.half_width - 1.0).abs();
                assert!(relative < 1e-14, "ξ = {xi}, κ = {kappa}: {relative:e}");
                for (a, b) in nested.exit_roots.iter().zip(&cold.exit_roots) {
                    assert!((a - b).abs() <= 1e-12 * b.abs().max(1e-300), "{a} vs {b}");
                }
                assert!(
                    nested.integrals.exit_root_iterations < cold.integrals.exit_root_iterations,
                    "ξ = {xi}, κ = {kappa}: {} vs {}",
                    nested.integrals.exit_root_iterations,
                    cold.integrals.exit_root_iterations
                );
            }
        }
    }

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

    /// The points at θ > 0 are reflections, so they are checked here against their own
    /// strips' exit roots.
    #[test]
    fn the_reflected_half_of_the_boundary_is_that_of_its_own_strips() {
        let rolling = Rolling::default();
        let solution = solve(&rolling, &SolveOptions::default()).unwrap();
        let n = solution.boundary.len();
        let r0 = solution.static_contact.half_width;
        let r = solution.half_width / r0;
        let section = Section::new(r, rolling.layer.viscosity(rolling.velocity / r0));
        for (j, point) in solution.boundary.iter().enumerate().skip(n / 2 + 1) {
            let theta = -FRAC_PI_2 + PI * j as f64 / (n - 1) as f64;
            let strip = section.strip(theta.cos());
            let rho = strip.exit_root(None).unwrap().rho;
            let exit = (rho - 1.0) * strip.entry * r0;
            assert!((point.y / (theta.sin() * r * r0) - 1.0).abs() < 1e-13);
            if j + 1 < n {
                assert!(
                    (point.exit / exit - 1.0).abs() < 1e-12,
                    "{} vs {exit}",
                    point.exit
                );
                assert!((point.entry / (strip.entry * r0) - 1.0).abs() < 1e-13);
            }
        }
    }
}
