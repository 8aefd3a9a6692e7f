//! What a continuum answer takes, decided before any of it is done: its route (§8's
//! thin-layer path, or the grid), the grids of its three marches, and from them the memory
//! it holds and what it costs. All of it is a few table look-ups, so that a job is refused
//! in microseconds when it is validated, not after its coarse marches ran (a fine grid too
//! large was found after 18 s of them), and every size is a floating-point number until it
//! is known to be a count (a layer of 1e-300 m made the pixel count overflow).
//!
//! The grid is sized from the static continuum contact radius a₀ (the table of
//! [`super::static_area`]): a₀·[`MARGIN`] to each side and ahead (the rolling contact is
//! never wider than the static one), and behind that the wake where the layer is still
//! recovering, min(3 V θ, 6 a₀), θ the layer's longest retardation time (T_ε; none for an
//! elastic layer). The pixel is a [`PER_RADIUS`]th of the smallest contact's radius (the
//! instantaneous elastic one, V → ∞), at most the layer's thickness.

use std::f64::consts::PI;

use super::grid::Grid;
use super::table::static_area;
use crate::text::count;
use crate::{Layer, ModelError, Rolling};

/// Pixels in the radius of the smallest contact the sphere can have, the instantaneous
/// elastic one (V → ∞), on the fine grid: every rolling contact is at least 24 pixels
/// across (the `resolution` row warns below).
pub const PER_RADIUS: usize = 12;

/// The grid reaches this many static contact radii to each side of the contact and ahead.
const MARGIN: f64 = 1.25;

/// Pixels a grid may have: a finer grid is refused rather than left to run for minutes (at
/// the most, three marches on 65,536 pixels take about half a minute on one core).
pub const MAX_PIXELS: usize = 256 * 256;

/// Contacts of a radius r₀ = √(2Rδ₀) (the local law's at rest) at least this many
/// thicknesses are answered by the local law ...
pub const THIN: f64 = 20.0;
/// ... on layers of a Poisson ratio up to this (a thin incompressible layer is never local).
pub const THIN_POISSON: f64 = 0.4;

/// The fine grid of a reference cost: a march costs about (pixels/[`REFERENCE_PIXELS`])²
/// of it ([`Plan::cost`]): an FFT a conjugate-gradient iteration, more iterations a step
/// and more steps a march on a finer grid (measured with three marches each, in the test
/// profile: 5,824 fine pixels 0.14 s, 42,560 pixels 8 s, 63,984 pixels 28 s).
const REFERENCE_PIXELS: f64 = 4096.0;

/// Bytes a solve holds per fine pixel (measured on its peak resident memory: 430–480 with
/// the Kelvin layer, from 5,472 to 42,560 pixels), and per pixel and further term of a
/// Prony series (its history along the march, and the step's carry of it).
const BYTES_PER_PIXEL: f64 = 512.0;
const BYTES_PER_PIXEL_AND_TERM: f64 = 16.0;

/// A grid and the x of its middle from the sphere's centre (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Domain {
    pub grid: Grid,
    pub middle: f64,
}

/// The three marches of an answer on the grid: a fine grid, a coarse one (two thirds of the
/// pixels a side) and a coarse one reaching twice as far behind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Marches {
    /// a₀, the static continuum contact's radius (m).
    pub a0: f64,
    /// The wake behind the contact (m; 0 at rest).
    pub wake: f64,
    pub fine: Domain,
    pub coarse: Domain,
    /// Reaching twice as far behind; none at rest, where it is the same problem.
    pub far: Option<Domain>,
}

/// How a continuum answer is found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Route {
    /// §8's thin-layer path: the local law's exact answer, with the two laws' difference at
    /// rest as its error ([`super::thin_error`]).
    Thin {
        /// r₀/H.
        ratio: f64,
    },
    /// On the grid.
    Grid(Marches),
}

/// What a continuum answer takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plan {
    pub route: Route,
    /// Terms of the layer's creep (one for the Kelvin layer).
    terms: usize,
}

/// What sets a grid's pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fineness {
    /// The layer's thickness (a pixel is never coarser than the layer): a contact many
    /// thicknesses wide on a nearly incompressible layer, which the thin-layer path does
    /// not answer.
    Thickness,
    /// The instantaneous contact (V → ∞), far smaller than the relaxed one on a layer that
    /// stiffens E₀/E_∞ (T_ε/T_σ) times.
    Stiffening,
}

/// A continuum answer refused before it starts: the grid it would need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TooFine {
    /// Its pixels along x and across (real numbers: they may be beyond any count).
    pub nx: f64,
    pub ny: f64,
    pub cause: Fineness,
}

impl From<TooFine> for ModelError {
    fn from(e: TooFine) -> Self {
        let why = match e.cause {
            Fineness::Thickness => {
                "the contact is too wide for its pixels, which must be finer than the layer \
                 (a thin, nearly incompressible layer)"
            }
            Fineness::Stiffening => {
                "its pixels must resolve the contact at high speed, which is far smaller than \
                 at rest on a layer that stiffens this much (E₀/E_∞ = T_ε/T_σ)"
            }
        };
        ModelError::OutOfModel(format!(
            "the layer as a continuum would need a grid of {} along x by {} across here (at \
             most {} in all): {why}",
            count(e.nx, "pixel", "pixels"),
            count(e.ny, "pixel", "pixels"),
            count(MAX_PIXELS as f64, "pixel", "pixels"),
        ))
    }
}

impl Plan {
    /// Bytes the solve holds at most.
    pub fn bytes(&self) -> u64 {
        let per_pixel = BYTES_PER_PIXEL + BYTES_PER_PIXEL_AND_TERM * self.terms as f64;
        match self.route {
            // The local law's answer: its boundary and pressure map, counted with the answer.
            Route::Thin { .. } => 0,
            Route::Grid(m) => (m.fine.grid.pixels() as f64 * per_pixel) as u64,
        }
    }

    /// What the solve costs, in answers on a grid of [`REFERENCE_PIXELS`] (the local law's
    /// answer of the thin-layer path costs nothing beside them).
    pub fn cost(&self) -> f64 {
        match self.route {
            Route::Thin { .. } => 0.0,
            Route::Grid(m) => [Some(m.fine), Some(m.coarse), m.far]
                .into_iter()
                .flatten()
                .map(|d| (d.grid.pixels() as f64 / REFERENCE_PIXELS).powi(2))
                .sum(),
        }
    }
}

/// The plan of `rolling`'s continuum answer with `per_radius` pixels in the smallest
/// contact's radius on the fine grid (the coarse grid's pixel is half as large again), or
/// why it is refused. `rolling` is within the model's ranges.
pub fn plan(rolling: &Rolling, per_radius: usize) -> Result<Plan, TooFine> {
    let Rolling {
        radius,
        load,
        velocity,
        layer,
    } = *rolling;
    let terms = layer.creep().terms.len();
    let ratio = thin_ratio(radius, load, &layer);
    if ratio >= THIN && layer.poisson_ratio <= THIN_POISSON {
        return Ok(Plan {
            route: Route::Thin { ratio },
            terms,
        });
    }
    let a0 = (static_area(radius, load, &layer) / PI).sqrt();
    // The contact at V → ∞: the layer with the instantaneous modulus.
    let smallest = (static_area(radius, load, &layer.instantaneous()) / PI).sqrt();
    let wake = if velocity > 0.0 {
        (3.0 * velocity * layer.creep().terms.longest()).min(6.0 * a0)
    } else {
        0.0
    };
    // The pixel: at most the layer's thickness (finer, the layer's correction would vary
    // across a pixel faster than its Gauss rule follows).
    let by_contact = smallest / per_radius as f64;
    let (fine_pixel, cause) = if by_contact <= layer.thickness {
        (by_contact, Fineness::Stiffening)
    } else {
        (layer.thickness, Fineness::Thickness)
    };
    let coarse_pixel = 1.5 * fine_pixel;
    let fine = domain(a0, fine_pixel, wake, cause)?;
    let coarse = domain(a0, coarse_pixel, wake, cause)?;
    let far = if wake > 0.0 {
        Some(domain(a0, coarse_pixel, 2.0 * wake, cause)?)
    } else {
        None
    };
    Ok(Plan {
        route: Route::Grid(Marches {
            a0,
            wake,
            fine,
            coarse,
            far,
        }),
        terms,
    })
}

/// r₀/H, r₀ = √(2Rδ₀) the local law's contact radius at rest, δ₀ = √(PH/(πE_L R)) (in
/// closed form: the local answer itself is solved only where it is the answer), in
/// logarithms: the stiffness E_L/H of a layer of 1e-300 m overflows, and it is the thinnest
/// of layers (r₀/H then overflows to infinity, which is right).
fn thin_ratio(radius: f64, load: f64, layer: &Layer) -> f64 {
    let (r, p, e, h) = (
        radius.ln(),
        load.ln(),
        layer.elastic_modulus.ln(),
        layer.thickness.ln(),
    );
    (0.5 * (2f64.ln() + r) + 0.25 * (p + h - PI.ln() - e - r) - h).exp()
}

/// The grid of pixels of side `pixel` around the static contact of radius `a0`, and its
/// middle's x: [`MARGIN`] radii to each side and ahead, and `wake` more behind; refused
/// (for `cause`) beyond [`MAX_PIXELS`].
///
/// The middle is a whole number of pixels from the sphere's centre, so the centre lies on a
/// pixel boundary along x as it does across: the lattice then sits alike under every
/// contact, and an answer moves smoothly with the layer's times (a middle anywhere made the
/// area jump by up to 1e-3 when T_ε moved by 1e-3, as the wake moved the lattice under the
/// contact; a fit's differences need better). The grid has a pixel to spare for that.
fn domain(a0: f64, pixel: f64, wake: f64, cause: Fineness) -> Result<Domain, TooFine> {
    let side = MARGIN * a0;
    let (front, back) = (side, side + wake);
    let even = |length: f64| 2.0 * (0.5 * length / pixel).ceil();
    let (nx, ny) = (even(front + back + pixel), even(2.0 * side));
    let pixels = nx * ny;
    if pixels.is_nan() || pixels > MAX_PIXELS as f64 {
        return Err(TooFine { nx, ny, cause });
    }
    Ok(Domain {
        grid: Grid {
            nx: nx as usize,
            ny: ny as usize,
            pixel,
        },
        middle: (0.5 * (front - back) / pixel).round() * pixel,
    })
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::limits::relaxed;

    #[test]
    fn the_thin_ratio_is_the_local_radius_over_the_thickness() {
        let rolling = Rolling::default();
        for thickness in [1e-9, 100e-9, 1e-3] {
            let layer = Layer {
                thickness,
                ..rolling.layer
            };
            let want = relaxed(rolling.radius, rolling.load, &layer).half_width / thickness;
            let got = thin_ratio(rolling.radius, rolling.load, &layer);
            assert!((got / want - 1.0).abs() < 1e-12, "{got} vs {want}");
        }
    }

    /// The default job's grids are those its answers were measured on (112 × 52 fine
    /// pixels of 0.101 nm), and it costs about two reference answers.
    #[test]
    fn the_default_continuum_answer_is_planned_as_measured() {
        let rolling = Rolling::default();
        let plan = plan(&rolling, PER_RADIUS).unwrap();
        let Route::Grid(m) = plan.route else {
            panic!("{plan:?}")
        };
        assert_eq!((m.fine.grid.nx, m.fine.grid.ny), (112, 52));
        assert!((m.fine.grid.pixel / 1.0060956572741008e-10 - 1.0).abs() < 1e-12);
        assert!(m.far.is_some() && m.wake > 0.0);
        assert_eq!(plan.bytes(), 112 * 52 * (512 + 16));
        assert!((2.0..5.0).contains(&plan.cost()), "{}", plan.cost());
        let at_rest = Rolling {
            velocity: 0.0,
            ..rolling
        };
        let Route::Grid(m) = plan_of(&at_rest).route else {
            panic!()
        };
        assert!(m.far.is_none() && m.wake == 0.0);
    }

    fn plan_of(rolling: &Rolling) -> Plan {
        plan(rolling, PER_RADIUS).unwrap()
    }

    /// The extremes: a layer of 1e-300 m is the thinnest of layers; a layer that
    /// stiffens 1e30 times, or a thin nearly incompressible one, is refused with the grid it
    /// would need and why.
    #[test]
    fn extremes_are_routed_or_refused_without_overflow() {
        let with = |f: fn(&mut Layer)| {
            let mut rolling = Rolling::default();
            f(&mut rolling.layer);
            plan(&rolling, PER_RADIUS)
        };
        let thinnest = with(|l| l.thickness = 1e-300).unwrap();
        assert!(
            matches!(thinnest.route, Route::Thin { ratio } if ratio > 1e200),
            "{thinnest:?}"
        );
        for stiff in [
            with(|l| l.relaxation_time = 1e-30).unwrap_err(),
            with(|l| l.retardation_time = 1e30).unwrap_err(),
        ] {
            assert_eq!(stiff.cause, Fineness::Stiffening);
            assert!(stiff.nx * stiff.ny > MAX_PIXELS as f64, "{stiff:?}");
        }
        let squeezed = with(|l| {
            l.thickness = 1e-12;
            l.poisson_ratio = 0.49;
        })
        .unwrap_err();
        assert_eq!(squeezed.cause, Fineness::Thickness);
        let message = ModelError::from(squeezed).to_string();
        assert!(
            message.contains("at most 65,536 pixels in all"),
            "{message}"
        );
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// Whatever the inputs within the model's ranges, a plan is made or refused, and a
        /// grid planned is within the cap.
        #[test]
        fn every_plan_is_bounded(
            radius in -12.0..3.0f64, load in -15.0..3.0f64, velocity in -15.0..3.0f64,
            modulus in -3.0..12.0f64, thickness in -300.0..0.0f64, nu in 0.0..0.499f64,
            relaxation in -30.0..5.0f64, stiffening in 0.0..30.0f64,
        ) {
            let layer = Layer {
                elastic_modulus: 10f64.powf(modulus),
                thickness: 10f64.powf(thickness),
                poisson_ratio: nu,
                relaxation_time: 10f64.powf(relaxation),
                retardation_time: 10f64.powf(relaxation + stiffening),
                ..Layer::default()
            };
            let rolling = Rolling {
                radius: 10f64.powf(radius),
                load: 10f64.powf(load),
                velocity: 10f64.powf(velocity),
                layer,
            };
            prop_assume!(rolling.violations().is_empty());
            match plan(&rolling, PER_RADIUS) {
                Ok(Plan { route: Route::Grid(m), .. }) => {
                    for d in [Some(m.fine), Some(m.coarse), m.far].into_iter().flatten() {
                        prop_assert!(d.grid.pixels() <= MAX_PIXELS && d.grid.pixels() > 0);
                        prop_assert!(d.grid.pixel > 0.0 && d.middle.is_finite());
                    }
                }
                Ok(Plan { route: Route::Thin { ratio }, .. }) => prop_assert!(ratio >= THIN),
                Err(e) => prop_assert!(e.nx * e.ny > MAX_PIXELS as f64 || (e.nx * e.ny).is_nan()),
            }
        }
    }
}
