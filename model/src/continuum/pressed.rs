//! A rigid parabolic sphere pressed, at rest, on the layer as a continuum, on the pixel grid
//! of [`super::grid`]: the symmetric positive-definite problem of docs/model.md §8, solved by
//! Polonsky & Keer's constrained conjugate gradient (Wear 231, 1999) with the load as a
//! constraint. It is the V = 0 companion of a rolling answer, the start of a rolling solve,
//! and, against the axisymmetric solver, the check of the grid's influence.

use super::grid::{Grid, Influence};
use crate::{ModelError, Stop};

/// Iterations allowed: conjugate gradients on N pixels settle in far fewer than N.
const MAX_ITERATIONS: u32 = 2000;

/// The pressure of a pressed contact on the grid.
#[derive(Clone, Debug, PartialEq)]
pub struct GridContact {
    pub grid: Grid,
    /// x₀ (m), the x of the grid's middle from the sphere's centre (negative: the grid
    /// reaches further behind).
    pub middle: f64,
    /// Pressure on each pixel (Pa), over the grid.
    pub pressure: Vec<f64>,
    /// δ (m).
    pub penetration: f64,
    /// The contact's exit and entry edges in each row, from the grid's middle (m; none
    /// where the row is out of contact), placed between pixels ([`row_edges`]).
    pub edges: Vec<Option<(f64, f64)>>,
    /// The contact area between the edges (m²).
    pub contact_area: f64,
    /// Conjugate-gradient iterations.
    pub iterations: u32,
}

/// A surface that deflects under pixel pressures: the layer as a continuum ([`Influence`]),
/// or as the local law ([`Springs`]), whose rolling solution §3 gives exactly.
pub trait Surface {
    /// The grid it is sampled on.
    fn grid(&self) -> Grid;
    /// The deflection at every pixel's centre under `pressure` (over the grid).
    fn deflect(&self, pressure: &[f64]) -> Vec<f64>;
    /// A pixel's deflection under its own unit pressure (the scale of the response).
    fn deflect_scale(&self) -> f64;
}

impl Surface for Influence {
    fn grid(&self) -> Grid {
        Influence::grid(self)
    }

    fn deflect(&self, pressure: &[f64]) -> Vec<f64> {
        Influence::deflect(self, pressure)
    }

    fn deflect_scale(&self) -> f64 {
        Influence::own(self)
    }
}

/// The local law on the grid: each pixel a spring of stiffness k = E_L/H per unit area.
pub struct Springs {
    pub grid: Grid,
    pub stiffness: f64,
}

impl Surface for Springs {
    fn grid(&self) -> Grid {
        self.grid
    }

    fn deflect(&self, pressure: &[f64]) -> Vec<f64> {
        pressure.iter().map(|p| p / self.stiffness).collect()
    }

    fn deflect_scale(&self) -> f64 {
        1.0 / self.stiffness
    }
}

/// A sphere pressed on a surface: what fixes its pressure.
pub struct Pressing<'a> {
    pub surface: &'a dyn Surface,
    /// R (m).
    pub radius: f64,
    /// P (N).
    pub load: f64,
    /// x₀ (m), the x of the grid's middle relative to the sphere's centre.
    pub middle: f64,
    /// The share of the surface's response that acts at once (1 at rest; less for a
    /// viscoelastic layer, whose memory gives the rest through `memory`).
    pub instant: f64,
    /// The deflection the layer's memory of earlier pressure adds at each pixel.
    pub memory: Option<&'a [f64]>,
    /// Asked at every iteration whether to stop.
    pub stop: Stop<'a>,
}

/// The pressure of `pressing`, from `start` (else uniform on a disc in the grid's middle),
/// converged until the gap is flat over the contact and nowhere negative outside it, to
/// `tolerance` of the penetration.
pub fn press(
    pressing: &Pressing,
    start: Option<Vec<f64>>,
    tolerance: f64,
) -> Result<GridContact, ModelError> {
    let Pressing {
        surface,
        radius,
        load,
        middle,
        instant,
        memory,
        stop,
    } = *pressing;
    let grid = surface.grid();
    let ny = grid.ny;
    let area = grid.pixel * grid.pixel;
    let mut profile: Vec<f64> = (0..grid.pixels())
        .map(|k| {
            let (x, y) = (middle + grid.x(k / ny), grid.y(k % ny));
            (x * x + y * y) / (2.0 * radius)
        })
        .collect();
    if let Some(memory) = memory {
        profile.iter_mut().zip(memory).for_each(|(f, m)| *f += m);
    }
    let mut pressure = start.unwrap_or_else(|| {
        let reach = grid.pixel * grid.nx.min(grid.ny) as f64 / 6.0;
        (0..grid.pixels())
            .map(|k| f64::from(u8::from(grid.x(k / ny).hypot(grid.y(k % ny)) < reach)))
            .collect()
    });
    normalise(&mut pressure, load / area);
    let descent = Descent {
        surface,
        instant,
        profile,
        total: load / area,
        tolerance,
    };
    let (pressure, penetration, iterations) = descent.run(pressure, stop)?;
    let edges = row_edges(&pressure, &grid);
    Ok(GridContact {
        grid,
        middle,
        contact_area: area_between(&edges, grid.pixel),
        edges,
        pressure,
        penetration,
        iterations,
    })
}

/// Polonsky & Keer's constrained conjugate gradient on one pressed contact: kept apart from
/// [`press`], which only sets the problem up and reads the answer, so the iteration reads
/// as the method does.
struct Descent<'a> {
    surface: &'a dyn Surface,
    /// The share of the surface's response that acts at once ([`Pressing::instant`]).
    instant: f64,
    /// The undeformed gap at each pixel: the sphere's profile plus the layer's memory.
    profile: Vec<f64>,
    /// The sum of the pixel pressures that carries the load: P over a pixel's area.
    total: f64,
    tolerance: f64,
}

impl Descent<'_> {
    /// The deflection that acts at once under `pressure`.
    fn deflect(&self, pressure: &[f64]) -> Vec<f64> {
        let mut w = self.surface.deflect(pressure);
        w.iter_mut().for_each(|w| *w *= self.instant);
        w
    }

    /// Descends from `pressure` (normalised to the load) to the converged pressure, its
    /// penetration and the iterations taken.
    fn run(&self, mut pressure: Vec<f64>, stop: Stop) -> Result<(Vec<f64>, f64, u32), ModelError> {
        let own = self.instant * self.surface.deflect_scale();
        let mut direction = vec![0.0; pressure.len()];
        let (mut g_old, mut conjugate) = (1.0, false);
        // The deflection of `pressure`, carried along by the steps while they are linear (no
        // pixel clipped or joined): one convolution an iteration rather than two. `exact`
        // says whether it was just convolved (it is before an answer is returned).
        let mut deflection = self.deflect(&pressure);
        let mut exact = true;
        for iteration in 1..=MAX_ITERATIONS {
            stop.check()?;
            let gap = Gap::new(&deflection, &self.profile, &pressure, self.tolerance);
            if gap.flat && gap.apart {
                if exact {
                    return Ok((pressure, gap.mean, iteration));
                }
                deflection = self.deflect(&pressure);
                exact = true;
                continue;
            }
            let g_norm: f64 = masked(&gap.values, &gap.in_contact).map(|g| g * g).sum();
            let beta = if conjugate { g_norm / g_old } else { 0.0 };
            gap.conjugate(&mut direction, beta);
            g_old = g_norm;
            let response = self.deflect(&direction);
            let (along, curvature) = gap.along_and_curvature(&direction, &response);
            // A direction the load constraint cancels (constant over the contact) has no
            // curvature: start the conjugation again from the gap itself. The gap has none
            // only where it is flat over the contact to rounding: solved, if nothing outside
            // penetrates (else the method is stuck: say so rather than answer).
            let scale: f64 = masked(&direction, &gap.in_contact).map(|d| d * d).sum();
            let curved = curvature > 1e-12 * scale * own;
            if !curved {
                if conjugate {
                    conjugate = false;
                    continue;
                }
                if gap.apart && exact {
                    return Ok((pressure, gap.mean, iteration));
                }
                if !exact {
                    deflection = self.deflect(&pressure);
                    exact = true;
                    continue;
                }
                break;
            }
            let step = along / curvature;
            let before = pressure.clone();
            let (overlap, clipped) = gap.step(&mut pressure, &direction, step);
            conjugate = !overlap;
            if pressure.iter().all(|p| *p == 0.0) {
                // The step emptied the contact: take it back, and go down the gap alone.
                pressure = before;
                conjugate = false;
                continue;
            }
            let scale = normalise(&mut pressure, self.total);
            if overlap || clipped {
                deflection = self.deflect(&pressure);
                exact = true;
            } else {
                for (u, r) in deflection.iter_mut().zip(&response) {
                    *u = scale * (*u - step * r);
                }
                exact = false;
            }
        }
        Err(ModelError::NoConvergence {
            what: "continuum contact pressure (conjugate gradients)",
            iterations: MAX_ITERATIONS,
        })
    }
}

/// The gap at one iterate, less its mean over the contact (the penetration), and whether the
/// iterate is solved there.
struct Gap {
    values: Vec<f64>,
    /// Which pixels carry pressure.
    in_contact: Vec<bool>,
    /// The mean gap over the contact: the penetration.
    mean: f64,
    /// Flat over the contact to `tolerance` of the penetration.
    flat: bool,
    /// Nowhere negative outside the contact, to the same.
    apart: bool,
}

impl Gap {
    fn new(deflection: &[f64], profile: &[f64], pressure: &[f64], tolerance: f64) -> Gap {
        let mut values: Vec<f64> = deflection.iter().zip(profile).map(|(u, f)| u + f).collect();
        let in_contact: Vec<bool> = pressure.iter().map(|p| *p > 0.0).collect();
        let mean = mean_over(&values, &in_contact);
        values.iter_mut().for_each(|g| *g -= mean);
        let slack = tolerance * mean.abs();
        let flat = masked(&values, &in_contact).all(|g| g.abs() <= slack);
        let apart = values
            .iter()
            .zip(&in_contact)
            .all(|(g, c)| *c || *g >= -slack);
        Gap {
            values,
            in_contact,
            mean,
            flat,
            apart,
        }
    }

    /// The next search direction: the gap over the contact plus `beta` times the last
    /// direction (conjugation), zero outside it.
    fn conjugate(&self, direction: &mut [f64], beta: f64) {
        for (k, d) in direction.iter_mut().enumerate() {
            *d = if self.in_contact[k] {
                self.values[k] + beta * *d
            } else {
                0.0
            };
        }
    }

    /// Over the contact, the gap along `direction` and the curvature of the surface's
    /// `response` to it, with the load constraint's mean taken out.
    fn along_and_curvature(&self, direction: &[f64], response: &[f64]) -> (f64, f64) {
        let count = direction.len();
        let mean_response = mean_over(response, &self.in_contact);
        let along: f64 = (0..count)
            .filter(|k| self.in_contact[*k])
            .map(|k| self.values[k] * direction[k])
            .sum();
        let curvature: f64 = (0..count)
            .filter(|k| self.in_contact[*k])
            .map(|k| (response[k] - mean_response) * direction[k])
            .sum();
        (along, curvature)
    }

    /// Moves the contact's pressure by `step` along `direction`, clipped at zero; pixels
    /// penetrated outside the contact join it. Says whether any joined and any was clipped.
    fn step(&self, pressure: &mut [f64], direction: &[f64], step: f64) -> (bool, bool) {
        let (mut overlap, mut clipped) = (false, false);
        for k in 0..pressure.len() {
            if self.in_contact[k] {
                let moved = pressure[k] - step * direction[k];
                clipped |= moved < 0.0;
                pressure[k] = moved.max(0.0);
            } else if self.values[k] < 0.0 {
                // Penetrated outside the contact: it joins, and the conjugation restarts.
                pressure[k] = -step * self.values[k];
                overlap = true;
            }
        }
        (overlap, clipped)
    }
}

/// The contact's edges along x in each row of `grid` (y = grid.y(j)), from the grid's
/// middle: the exit (behind) and the entry (ahead), or none where the row is out of
/// contact. Near a smooth contact's edge the pressure falls as the square root of the
/// distance, so p² is linear there: each edge lies where p², extended from the row's
/// outermost pixel in contact and the one inside it, vanishes (at most a pixel out; half a
/// pixel where the row has one pixel in contact or p does not fall outwards). Extending p
/// itself places the edges a tenth of a pixel too far out on average (+1.4 % in area at
/// 16 pixels a radius against the axisymmetric solver); p² is within ±0.4 % at 12 pixels a
/// radius or more, with no bias, the rest a scatter with the edge's place in its pixel.
pub fn row_edges(pressure: &[f64], grid: &Grid) -> Vec<Option<(f64, f64)>> {
    let Grid { nx, ny, pixel } = *grid;
    (0..ny)
        .map(|j| {
            let at = |i: usize| pressure[i * ny + j];
            let squared = |i: usize| at(i).max(0.0).powi(2);
            let first = (0..nx).find(|&i| at(i) > 0.0)?;
            let last = (0..nx).rev().find(|&i| at(i) > 0.0)?;
            // The distance past pixel `a` (outermost in contact) where p², extended from
            // `a` and `b` (one further in), vanishes.
            let beyond = |a: usize, b: usize| {
                let (pa, pb) = (squared(a), squared(b));
                if last > first && pb > pa {
                    (pixel * pa / (pb - pa)).min(pixel)
                } else {
                    0.5 * pixel
                }
            };
            let exit = grid.x(first) - beyond(first, (first + 1).min(last));
            let entry = grid.x(last) + beyond(last, last.saturating_sub(1).max(first));
            Some((exit, entry))
        })
        .collect()
}

/// The area between a contact's row edges ([`row_edges`]) on pixels of side `pixel`.
pub fn area_between(edges: &[Option<(f64, f64)>], pixel: f64) -> f64 {
    edges
        .iter()
        .flatten()
        .map(|(exit, entry)| entry - exit)
        .sum::<f64>()
        * pixel
}

/// Scales `pressure` to sum to `total`; the factor.
fn normalise(pressure: &mut [f64], total: f64) -> f64 {
    let sum: f64 = pressure.iter().sum();
    if sum > 0.0 {
        pressure.iter_mut().for_each(|p| *p *= total / sum);
        total / sum
    } else {
        1.0
    }
}

fn masked<'a>(values: &'a [f64], mask: &'a [bool]) -> impl Iterator<Item = f64> + 'a {
    values
        .iter()
        .zip(mask)
        .filter(|(_, m)| **m)
        .map(|(v, _)| *v)
}

fn mean_over(values: &[f64], mask: &[bool]) -> f64 {
    let (sum, count) = masked(values, mask).fold((0.0, 0usize), |(s, c), v| (s + v, c + 1));
    if count == 0 {
        0.0
    } else {
        sum / count as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::continuum::{area_floor, static_contact};
    use crate::Layer;

    /// The contact of a sphere of `radius` under `load` on `layer` pressed on a square grid
    /// of `q` pixels in the axisymmetric contact's radius, and that contact.
    fn pressed_and_exact(
        radius: f64,
        load: f64,
        layer: &Layer,
        q: f64,
    ) -> (GridContact, crate::continuum::StaticContinuum) {
        let exact = static_contact(radius, load, layer).unwrap();
        let a = (exact.contact_area / std::f64::consts::PI).sqrt();
        let n = 2 * (1.25 * q).ceil() as usize;
        let grid = Grid {
            nx: n,
            ny: n,
            pixel: a / q,
        };
        let influence = Influence::new(layer, grid, Stop::NEVER).unwrap();
        let pressing = Pressing {
            surface: &influence,
            radius,
            load,
            middle: 0.0,
            instant: 1.0,
            memory: None,
            stop: Stop::NEVER,
        };
        (press(&pressing, None, 1e-10).unwrap(), exact)
    }

    /// On the grid, the pressed contact is the axisymmetric solver's: δ within 0.2 % and the
    /// area within 1 % at 16 pixels a radius, and the area within AREA_SCATTER/q at q
    /// pixels a radius, for q from 6 to 24 (the edges' scatter in their pixels, with no
    /// bias), on layers much thicker than a pixel.
    #[test]
    fn on_the_grid_the_pressed_contact_is_the_axisymmetric_one() {
        for (thickness, nu) in [(100e-9, 0.35), (5e-9, 0.3), (2e-9, 0.45)] {
            let layer = Layer {
                thickness,
                poisson_ratio: nu,
                ..Layer::default()
            };
            for q in [6.0, 8.0, 10.25, 12.0, 16.0, 20.5, 24.0] {
                let (pressed, exact) = pressed_and_exact(25e-9, 1e-9, &layer, q);
                let area = pressed.contact_area / exact.contact_area - 1.0;
                let bound = crate::continuum::AREA_SCATTER / q;
                assert!(
                    area.abs() < bound,
                    "H = {thickness}, q = {q}: A off by {area:e}"
                );
                if q >= 16.0 {
                    let delta = pressed.penetration / exact.penetration - 1.0;
                    assert!(delta.abs() < 2e-3, "H = {thickness}: δ off by {delta:e}");
                    assert!(area.abs() < 0.01, "H = {thickness}: A off by {area:e}");
                }
            }
        }
    }

    /// Where the pixel approaches or passes the layer's thickness (contacts 6 to 20
    /// thicknesses wide, pixels of 0.25 to 2.5 H), δ is still the axisymmetric solver's
    /// within 0.5 % (the layer's correction averaged over each pixel), and the area is short
    /// by no more than the floor the answer's error keeps ([`area_floor`]).
    #[test]
    fn on_a_layer_as_thin_as_a_pixel_the_area_is_within_its_floor() {
        for (thickness, nu) in [(1e-9, 0.3), (1e-9, 0.45), (5e-9, 0.3)] {
            let layer = Layer {
                thickness,
                poisson_ratio: nu,
                ..Layer::default()
            };
            for q in [8.0, 12.0] {
                let (pressed, exact) = pressed_and_exact(1e-6, 4e-7, &layer, q);
                let area = pressed.contact_area / exact.contact_area - 1.0;
                let floor = area_floor(pressed.contact_area, pressed.grid.pixel, thickness);
                assert!(
                    area.abs() < floor,
                    "H = {thickness}, ν = {nu}, q = {q}: A {area:e}"
                );
                let delta = pressed.penetration / exact.penetration - 1.0;
                assert!(
                    delta.abs() < 5e-3,
                    "H = {thickness}, ν = {nu}: δ off by {delta:e}"
                );
            }
        }
    }
}
