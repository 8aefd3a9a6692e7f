//! A rolling answer on the layer as a continuum (docs/model.md §8): the same quantities as the
//! local law's answer (§3), with their error.
//!
//! On the grid ([`super::roll`]), three marches ([`super::plan`] sizes them before any
//! starts): a fine grid, a coarse one (two thirds of the pixels a side) and a coarse one
//! reaching twice as far behind. The answer is the fine grid's; the others' differences
//! from it are its error.
//!
//! On a layer much thinner than the contact (r₀/H ≥ [`super::THIN`], ν ≤ [`super::THIN_POISSON`]) the
//! continuum is the local law to within a few per cent (§8's thin-layer fast path), and
//! a grid would need pixels finer than the layer: the answer is §3's exact local solution,
//! its error the two laws' difference at rest ([`super::thin_error`]).

use std::f64::consts::PI;

use super::grid::{Grid, Influence};
use super::plan::{plan, Domain, Marches, Route, PER_RADIUS};
use super::pressed::GridContact;
use super::rolling::{at_rest, roll, Rolled, RolledContact};
use super::shape::{boundary, chords, lateral_half_width, pressure_grid, resampled};
use super::thin::thin_error;
use crate::limits::ElasticContact;
use crate::{ModelError, Rolling, RollingSolution, SolveOptions, Stop};

/// §8's tolerances on an answer's relative error: 1 % in A, 0.5 % in δ (rolling and at rest).
const AREA_TOLERANCE: f64 = 0.01;
const PENETRATION_TOLERANCE: f64 = 0.005;

/// The march stops when a step changes the pressure by less than this share of its sum
/// (it then lies within about ten times that of its steady state).
const TOLERANCE: f64 = 1e-5;

/// How an answer on the layer as a continuum was found, and how far it can be trusted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContinuumVerification {
    pub errors: QuantityErrors,
    /// The part of the errors of δ and A that is the domain's: their largest relative
    /// change when the grid reaches twice as far behind (0 for the thin-layer path).
    pub domain_error: f64,
    /// The contact's largest extent from the sphere's centre (m): its lateral half-width or
    /// its farthest edge along x (the parabolic-sphere row's a_max).
    pub extent: f64,
    /// The fine grid, for an answer on the grid; none for the thin-layer path.
    pub grid: Option<GridUsed>,
}

/// The fine grid of an answer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridUsed {
    /// Pixels along x and across.
    pub nx: usize,
    pub ny: usize,
    /// The pixel (m).
    pub pixel: f64,
    /// Pixels across the rolling contact, 2√(A/π)/h, and across the static one.
    pub across: f64,
    pub across_at_rest: f64,
    /// Steps of the march.
    pub steps: usize,
}

/// Error bounds of the reported quantities. On the grid: each the change from the coarse
/// grid to the fine one (twice that for the areas, whose error is first order in the pixel:
/// at two thirds the pixels the change is half the fine grid's error), plus the change when
/// the grid reaches twice as far behind; for the areas never below the edges' error within
/// their pixels ([`area_floor`]). μ shares A's relative error, μ_r x_p's.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct QuantityErrors {
    /// Of δ (relative).
    pub penetration: f64,
    /// Of A (relative).
    pub contact_area: f64,
    /// Of x_c (m).
    pub centroid_shift: f64,
    /// Of x_p (m).
    pub pressure_centre_shift: f64,
    /// Of the static δ (relative).
    pub static_penetration: f64,
    /// Of the static A (relative).
    pub static_contact_area: f64,
}

impl QuantityErrors {
    /// The largest relative bound (δ and A, rolling and static).
    pub fn relative(&self) -> f64 {
        [
            self.penetration,
            self.contact_area,
            self.static_penetration,
            self.static_contact_area,
        ]
        .into_iter()
        .fold(0.0, f64::max)
    }

    /// The bounds against §8's tolerances, the larger of A's over 1 % and δ's over 0.5 %:
    /// rolling, and at rest. At most 1 (both): the answer is known to be as exact as §8 asks.
    pub fn tolerance_shares(&self) -> (f64, f64) {
        let share = |area: f64, penetration: f64| {
            (area / AREA_TOLERANCE).max(penetration / PENETRATION_TOLERANCE)
        };
        (
            share(self.contact_area, self.penetration),
            share(self.static_contact_area, self.static_penetration),
        )
    }
}

/// The contact edges' error within their pixels, in pixels: against the axisymmetric
/// solver at 6 to 24 pixels a radius on layers far thicker than a pixel, the area between
/// the edges ([`super::row_edges`]) is off by at most 0.113 pixels a radius, with no trend
/// in the sign. Two resolutions can both land near the same error and so miss it.
pub const AREA_SCATTER: f64 = 0.12;

/// The edges' bias where the pixel approaches the layer's thickness H: there the pressure
/// falls to the edge more steeply than the square root the edges assume, and the area
/// comes out short, by up to 1.7 % at a pixel of H, 1.2 % at H/2, 0.4 % at H/4 (against
/// the axisymmetric solver, a₀/H from 1 to 20, ν from 0 to 0.45): bounded by this times
/// √(h/H), at most this.
pub const EDGE_BIAS: f64 = 0.025;

/// The grid's bias in δ where the layer is about as thin as the contact, which two grids of
/// like pixels share and so do not see: against the axisymmetric solver at rest, δ was off
/// by up to 1.1e-3 at H/a ≈ 0.5 (ν 0.3 to 0.49; a the static contact radius), 1.7e-4 at
/// H/a ≈ 1.7 and 3e-5 beyond H/a ≈ 5, while the two grids' change claimed as little as
/// 1.5e-5 (6 times short). Bounded by this times min(1, (a/H)²), added to that change.
pub const DEPTH_BIAS: f64 = 1.2e-3;

/// The bias in δ that [`DEPTH_BIAS`] bounds, for a static contact of area `area` on a
/// layer of thickness `thickness`.
pub fn depth_bias(area: f64, thickness: f64) -> f64 {
    let radius = (area / PI).sqrt();
    DEPTH_BIAS * (radius / thickness).powi(2).min(1.0)
}

/// The floor of the shifts' error (x_c, x_p) on a grid, in pixels: slowly rolling, where the
/// lag V(T_ε − T_σ) is a fraction of a pixel, the grid's x_p fell 0.06 to 0.095 pixels short
/// of its first-order limit (default layer, lags of 0.08 to 2 pixels) while two grids of
/// like pixels agreed to a few hundredths.
pub const SHIFT_SCATTER: f64 = 0.12;

/// The relative error of the first-order slow-rolling x_p (the lag), per unit of V θ/r₀ (θ
/// the layer's longest retardation time, r₀ the static contact radius): it is first order
/// in V; on the local law, whose answer is exact, the factor is 1.0 (0.89 to 1.02 for V θ/r₀
/// up to 0.1), and 0.75 to 1 against the grid on the continuum. Half again, for a bound.
pub const SLOW_ROLLING_ERROR: f64 = 1.5;

/// The floor of the area's relative error on a grid of pixel `pixel` for a contact of
/// area `area` on a layer of thickness `thickness`: the edges' scatter and bias.
pub fn area_floor(area: f64, pixel: f64, thickness: f64) -> f64 {
    AREA_SCATTER * pixel / (area / PI).sqrt() + EDGE_BIAS * (pixel / thickness).min(1.0).sqrt()
}

/// The steady rolling answer of `rolling` on the layer as a continuum, with `options`'
/// boundary points and pressure grid (its quadrature is the local law's and unused here),
/// stopped when `stop` says so.
pub fn solve(
    rolling: &Rolling,
    options: &SolveOptions,
    stop: Stop,
) -> Result<RollingSolution<ContinuumVerification>, ModelError> {
    solve_at(rolling, options, PER_RADIUS, stop)
}

/// [`solve`] with `per_radius` pixels in the smallest contact's radius on the fine grid (the
/// coarse grid's pixel is half as large again): finer than the service's to check its
/// error.
pub fn solve_at(
    rolling: &Rolling,
    options: &SolveOptions,
    per_radius: usize,
    stop: Stop,
) -> Result<RollingSolution<ContinuumVerification>, ModelError> {
    ModelError::check_inputs(rolling.violations(), options.violations())?;
    let solution = match plan(rolling, per_radius)?.route {
        Route::Thin { ratio } => thin_layer(rolling, ratio, crate::solve(rolling, options)?),
        Route::Grid(marches) => on_grid(rolling, options, &marches, stop)?,
    };
    let e = &solution.verification.errors;
    let bounds = [e.relative(), e.centroid_shift, e.pressure_centre_shift];
    if solution
        .quantities()
        .iter()
        .chain(&bounds)
        .any(|q| !q.is_finite())
    {
        return Err(ModelError::NotRepresentable {
            what: "the continuum contact".to_string(),
        });
    }
    Ok(solution)
}

/// §8's thin-layer fast path: `local`, the exact local answer at r₀/H = `ratio`, with the
/// two laws' relative difference at rest ([`thin_error`]) as its error.
fn thin_layer(
    rolling: &Rolling,
    ratio: f64,
    local: RollingSolution,
) -> RollingSolution<ContinuumVerification> {
    let (penetration, area) = thin_error(ratio, rolling.layer.poisson_ratio);
    let extent = local.boundary.iter().fold(local.half_width, |m, b| {
        m.max(b.exit.abs()).max(b.entry.abs())
    });
    let errors = QuantityErrors {
        penetration,
        contact_area: area,
        centroid_shift: area * local.centroid_shift.abs(),
        pressure_centre_shift: area * local.pressure_centre_shift.abs(),
        static_penetration: penetration,
        static_contact_area: area,
    };
    RollingSolution {
        penetration: local.penetration,
        contact_area: local.contact_area,
        half_width: local.half_width,
        centroid_shift: local.centroid_shift,
        pressure_centre_shift: local.pressure_centre_shift,
        rolling_resistance_coefficient: local.rolling_resistance_coefficient,
        friction_coefficient: local.friction_coefficient,
        static_contact: local.static_contact,
        boundary: local.boundary,
        pressure: local.pressure,
        verification: ContinuumVerification {
            errors,
            domain_error: 0.0,
            extent,
            grid: None,
        },
    }
}

/// The answer on the grid: fine, coarse, and coarse reaching twice as far behind, as
/// `marches` plans them.
fn on_grid(
    rolling: &Rolling,
    options: &SolveOptions,
    marches: &Marches,
    stop: Stop,
) -> Result<RollingSolution<ContinuumVerification>, ModelError> {
    // The coarse march first, from rest: the others start from its steady contact.
    let coarse = march(rolling, &marches.coarse, None, None, stop)?;
    let coarse_rest = coarse.rest.as_ref();
    let far = match &marches.far {
        Some(far) => march(rolling, far, Some(&coarse.rolled.contact), None, stop)?,
        None => coarse.clone(),
    };
    let fine = march(
        rolling,
        &marches.fine,
        Some(&coarse.rolled.contact),
        coarse_rest,
        stop,
    )?;
    let (errors, domain_error) = grid_errors(rolling, &coarse, &far, &fine);
    Ok(fine_answer(rolling, options, &fine, errors, domain_error))
}

/// A march on `domain`, from `start` (a contact on another grid, resampled; else the contact
/// at rest on this grid, solved here, from `rest_from` resampled if given): its steady
/// contact, and its contact at rest.
fn march(
    rolling: &Rolling,
    domain: &Domain,
    start: Option<&GridContact>,
    rest_from: Option<&GridContact>,
    stop: Stop,
) -> Result<Solved, ModelError> {
    let Rolling {
        radius,
        load,
        velocity,
        layer,
    } = *rolling;
    let Domain { grid, middle } = *domain;
    let influence = Influence::new(&layer, grid, stop)?;
    let rolled = Rolled {
        radius,
        load,
        velocity,
        layer: &layer,
        surface: &influence,
        middle,
        stop,
    };
    let resample = |contact: &GridContact| resampled(contact, &grid, middle);
    let rest = match start {
        Some(_) if rest_from.is_none() => None,
        _ => Some(at_rest(&rolled, rest_from.map(resample), 0.1 * TOLERANCE)?),
    };
    let from = match (start, &rest) {
        (Some(contact), _) => resample(contact),
        (None, Some(rest)) => rest.pressure.clone(),
        (None, None) => unreachable!("a march starts from a contact or from rest"),
    };
    let rolled = roll(&rolled, from, TOLERANCE)?;
    if touches_border(&rolled.contact) {
        return Err(ModelError::OutOfModel(
            "the continuum contact reached the border of its grid".to_string(),
        ));
    }
    Ok(Solved { rolled, rest })
}

/// Each quantity's error on the fine grid, from its change to the fine grid and to the far
/// domain against the coarse grid (at rest the far domain is the same problem: no change),
/// and the domain's share of the worst.
fn grid_errors(
    rolling: &Rolling,
    coarse: &Solved,
    far: &Solved,
    fine: &Solved,
) -> (QuantityErrors, f64) {
    let velocity = rolling.velocity;
    let changes = |f: fn(&Solved) -> f64| {
        let change = |a: &Solved| (f(a) / f(coarse) - 1.0).abs();
        (change(fine), change(far))
    };
    let rest_changes = |f: fn(&GridContact) -> f64| {
        let rest = |s: &Solved| f(s.rest.as_ref().expect("solved at rest"));
        ((rest(fine) / rest(coarse) - 1.0).abs(), 0.0)
    };
    let absolute = |f: fn(&Solved) -> f64| (f(fine) - f(coarse)).abs() + (f(far) - f(coarse)).abs();
    let contact = &fine.rolled.contact;
    let rest = fine.rest.as_ref().expect("solved at rest");
    let pixel = contact.grid.pixel;
    let area_error = |(grid, domain): (f64, f64), area: f64| {
        (2.0 * grid + domain).max(area_floor(area, pixel, rolling.layer.thickness))
    };
    let (d, a, d0, a0_) = (
        changes(|s| s.rolled.contact.penetration),
        changes(|s| s.rolled.contact.contact_area),
        rest_changes(|c| c.penetration),
        rest_changes(|c| c.contact_area),
    );
    let floor = SHIFT_SCATTER * pixel;
    let bias = depth_bias(rest.contact_area, rolling.layer.thickness);
    let errors = QuantityErrors {
        penetration: d.0 + d.1 + bias,
        contact_area: area_error(a, contact.contact_area),
        centroid_shift: shift(velocity, absolute(|s| s.rolled.centroid_shift).max(floor)),
        pressure_centre_shift: shift(
            velocity,
            absolute(|s| s.rolled.pressure_centre_shift).max(floor),
        ),
        static_penetration: d0.0 + d0.1 + bias,
        static_contact_area: area_error(a0_, rest.contact_area),
    };
    (errors, d.1.max(a.1))
}

/// At rest the contact is symmetric in x: its shifts are nought, not the grid's rounding.
fn shift(velocity: f64, x: f64) -> f64 {
    if velocity > 0.0 {
        x
    } else {
        0.0
    }
}

/// The pressure centre x_p and its error: the grid's `(x_p, error)` weighed against the
/// first-order slow-rolling limit, the lag V Σκ_jτ_j (V(T_ε − T_σ)), each by the inverse
/// square of its error. Slowly rolling the lag is a fraction of a pixel and the grid cannot
/// place it; faster the limit's error, first order in V, outgrows the grid's. The weights
/// move smoothly with V, so x_p and μ_r do, with no switch between the two; the error is
/// the weighted bound.
fn pressure_centre(
    rolling: &Rolling,
    static_area: f64,
    (grid, grid_error): (f64, f64),
) -> (f64, f64) {
    let layer = &rolling.layer;
    let lag = rolling.velocity * layer.lag_time();
    let longest = layer.creep().terms.longest();
    let limit_error =
        SLOW_ROLLING_ERROR * rolling.velocity * longest / (static_area / PI).sqrt() * lag;
    if limit_error == 0.0 || grid_error == 0.0 {
        // At rest, or an elastic layer (no lag): the grid's, exact in x_p's symmetry.
        return (grid, grid_error);
    }
    let (w_limit, w_grid) = (limit_error.powi(-2), grid_error.powi(-2));
    let total = w_limit + w_grid;
    (
        (w_limit * lag + w_grid * grid) / total,
        (w_limit * limit_error + w_grid * grid_error) / total,
    )
}

/// The answer in SI units from the fine grid's march, with its `errors`.
fn fine_answer(
    rolling: &Rolling,
    options: &SolveOptions,
    fine: &Solved,
    errors: QuantityErrors,
    domain_error: f64,
) -> RollingSolution<ContinuumVerification> {
    let (radius, load, velocity) = (rolling.radius, rolling.load, rolling.velocity);
    let contact = &fine.rolled.contact;
    let rest = fine.rest.as_ref().expect("solved at rest");
    let pixel = contact.grid.pixel;
    let shear = rolling.layer.interfacial_shear_strength();
    let half_width = lateral_half_width(contact);
    let (contact_area, static_area) = (contact.contact_area, rest.contact_area);
    let grid_centre = shift(velocity, fine.rolled.pressure_centre_shift);
    let (pressure_centre_shift, centre_error) = pressure_centre(
        rolling,
        static_area,
        (grid_centre, errors.pressure_centre_shift),
    );
    let errors = QuantityErrors {
        pressure_centre_shift: centre_error,
        ..errors
    };
    let across = |area: f64| 2.0 * (area / PI).sqrt() / pixel;
    // The contact's largest extent from the centre: the lateral half-width, or an edge
    // along x (a rolling contact reaches a little further ahead than to the side).
    let extent = chords(contact)
        .iter()
        .fold(half_width, |m, (_, exit, entry)| {
            m.max(exit.abs()).max(entry.abs())
        });
    RollingSolution {
        penetration: contact.penetration,
        contact_area,
        half_width,
        centroid_shift: shift(velocity, fine.rolled.centroid_shift),
        pressure_centre_shift,
        rolling_resistance_coefficient: pressure_centre_shift / radius,
        friction_coefficient: shear * contact_area / load,
        static_contact: ElasticContact {
            penetration: rest.penetration,
            half_width: (static_area / PI).sqrt(),
            contact_area: static_area,
            friction_coefficient: shear * static_area / load,
        },
        boundary: boundary(contact, half_width, options.boundary_points),
        pressure: options
            .pressure_grid
            .map(|n| pressure_grid(contact, extent, n)),
        verification: ContinuumVerification {
            errors,
            domain_error,
            extent,
            grid: Some(GridUsed {
                nx: contact.grid.nx,
                ny: contact.grid.ny,
                pixel,
                across: across(contact_area),
                across_at_rest: across(static_area),
                steps: fine.rolled.steps,
            }),
        },
    }
}

/// A march's steady contact, and the contact at rest on its grid (where it was solved).
#[derive(Clone)]
struct Solved {
    rolled: RolledContact,
    rest: Option<GridContact>,
}

/// Whether a pixel on the grid's border carries pressure (the contact is cut off there).
fn touches_border(contact: &GridContact) -> bool {
    let Grid { nx, ny, .. } = contact.grid;
    let loaded = |i: usize, j: usize| contact.pressure[i * ny + j] > 0.0;
    (0..nx).any(|i| loaded(i, 0) || loaded(i, ny - 1))
        || (0..ny).any(|j| loaded(0, j) || loaded(nx - 1, j))
}
