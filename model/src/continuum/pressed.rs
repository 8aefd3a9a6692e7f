//! A rigid parabolic sphere pressed, at rest, on the layer as a continuum, on the pixel grid
//! of [`super::grid`]: the symmetric positive-definite problem of docs/model.md §8, solved by
//! Polonsky & Keer's constrained conjugate gradient (Wear 231, 1999) with the load as a
//! constraint. It is the V = 0 companion of a rolling answer, the start of a rolling solve,
//! and, against the axisymmetric solver, the check of the grid's influence.

use std::f64::consts::PI;

use super::grid::Influence;
use super::table::static_area;
use crate::{Layer, ModelError};

/// Iterations allowed: conjugate gradients on N pixels settle in far fewer than N.
const MAX_ITERATIONS: u32 = 2000;

/// The pressure of a pressed contact on the grid.
#[derive(Clone, Debug, PartialEq)]
pub struct GridContact {
    /// Pixels per side (pixel (i, j) at x = x₀ + (i + ½ − n/2) h, y = (j + ½ − n/2) h).
    pub size: usize,
    /// x₀ (m), the x of the grid's middle (negative: the grid reaches further behind).
    pub middle: f64,
    /// The pixel's side (m).
    pub pixel: f64,
    /// Pressure on each pixel (Pa), row-major with x along rows.
    pub pressure: Vec<f64>,
    /// δ (m).
    pub penetration: f64,
    /// The contact area (m²), each row's edges placed between pixels ([`sub_cell_area`]).
    pub contact_area: f64,
    /// Conjugate-gradient iterations.
    pub iterations: u32,
}

/// The grid of `size` pixels a side for the contact of a sphere of radius `radius` under
/// `load` on `layer`: 2.5 times the continuum's static contact diameter across.
pub fn grid_for(radius: f64, load: f64, layer: &Layer, size: usize) -> f64 {
    let a = (static_area(radius, load, layer) / PI).sqrt();
    2.5 * 2.0 * a / size as f64
}

/// A surface that deflects under pixel pressures: the layer as a continuum ([`Influence`]),
/// or as the local law ([`Springs`]), whose rolling solution §3 gives exactly.
pub trait Surface {
    /// Pixels per side.
    fn size(&self) -> usize;
    /// The deflection at every pixel's centre under `pressure` (n × n, row-major).
    fn deflect(&self, pressure: &[f64]) -> Vec<f64>;
    /// A pixel's deflection under its own unit pressure (the scale of the response).
    fn deflect_scale(&self) -> f64;
}

impl Surface for Influence {
    fn size(&self) -> usize {
        Influence::size(self)
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
    pub size: usize,
    pub stiffness: f64,
}

impl Surface for Springs {
    fn size(&self) -> usize {
        self.size
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
    /// The pixel's side (m).
    pub pixel: f64,
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
}

/// The pressure of `pressing`, from `start` (else uniform on the middle third of the grid),
/// converged until the gap is flat over the contact and nowhere negative outside it, to
/// `tolerance` of the penetration.
pub fn press(
    pressing: &Pressing,
    start: Option<Vec<f64>>,
    tolerance: f64,
) -> Result<GridContact, ModelError> {
    let Pressing {
        surface,
        pixel,
        radius,
        load,
        middle,
        instant,
        memory,
    } = *pressing;
    let n = surface.size();
    let area = pixel * pixel;
    let centre = |k: usize| (k as f64 + 0.5 - 0.5 * n as f64) * pixel;
    let mut profile: Vec<f64> = (0..n * n)
        .map(|k| {
            let (x, y) = (middle + centre(k / n), centre(k % n));
            (x * x + y * y) / (2.0 * radius)
        })
        .collect();
    if let Some(memory) = memory {
        profile.iter_mut().zip(memory).for_each(|(f, m)| *f += m);
    }
    let deflect = |p: &[f64]| -> Vec<f64> {
        let mut w = surface.deflect(p);
        w.iter_mut().for_each(|w| *w *= instant);
        w
    };
    let mut pressure = start.unwrap_or_else(|| {
        let reach = n as f64 * pixel / 6.0;
        (0..n * n)
            .map(|k| {
                let x = middle + centre(k / n);
                f64::from(u8::from(x.hypot(centre(k % n)) < reach))
            })
            .collect()
    });
    normalise(&mut pressure, load / area);
    let own = instant * surface.deflect_scale();
    let done = |pressure: Vec<f64>, gap: &[f64], penetration: f64, iterations: u32| GridContact {
        size: n,
        middle,
        pixel,
        contact_area: sub_cell_area(&pressure, gap, n, pixel, own),
        pressure,
        penetration,
        iterations,
    };
    let mut direction = vec![0.0; n * n];
    let (mut g_old, mut conjugate) = (1.0, false);
    for iteration in 1..=MAX_ITERATIONS {
        let deflection = deflect(&pressure);
        let mut gap: Vec<f64> = deflection
            .iter()
            .zip(&profile)
            .map(|(u, f)| u + f)
            .collect();
        let in_contact: Vec<bool> = pressure.iter().map(|p| *p > 0.0).collect();
        let mean_gap = mean_over(&gap, &in_contact);
        gap.iter_mut().for_each(|g| *g -= mean_gap);
        // Solved when the gap is flat over the contact and nowhere negative outside it, to
        // `tolerance` of the penetration.
        let slack = tolerance * mean_gap.abs();
        let flat = masked(&gap, &in_contact).all(|g| g.abs() <= slack);
        let apart = gap.iter().zip(&in_contact).all(|(g, c)| *c || *g >= -slack);
        if flat && apart {
            return Ok(done(pressure, &gap, mean_gap, iteration));
        }
        let g_norm: f64 = masked(&gap, &in_contact).map(|g| g * g).sum();
        let beta = if conjugate { g_norm / g_old } else { 0.0 };
        for k in 0..n * n {
            direction[k] = if in_contact[k] {
                gap[k] + beta * direction[k]
            } else {
                0.0
            };
        }
        g_old = g_norm;
        let mut response = deflect(&direction);
        let mean_response = mean_over(&response, &in_contact);
        response.iter_mut().for_each(|r| *r -= mean_response);
        let along: f64 = (0..n * n)
            .filter(|k| in_contact[*k])
            .map(|k| gap[k] * direction[k])
            .sum();
        let curvature: f64 = (0..n * n)
            .filter(|k| in_contact[*k])
            .map(|k| response[k] * direction[k])
            .sum();
        // A direction the load constraint cancels (constant over the contact) has no
        // curvature: start the conjugation again from the gap itself. The gap has none
        // only where it is flat over the contact to rounding: solved, if nothing outside
        // penetrates (else the method is stuck: say so rather than answer).
        let scale: f64 = masked(&direction, &in_contact).map(|d| d * d).sum();
        let curved = curvature > 1e-12 * scale * own;
        if !curved {
            if conjugate {
                conjugate = false;
                continue;
            }
            if apart {
                return Ok(done(pressure, &gap, mean_gap, iteration));
            }
            break;
        }
        let step = along / curvature;
        let before = pressure.clone();
        let mut overlap = false;
        for k in 0..n * n {
            if in_contact[k] {
                pressure[k] = (pressure[k] - step * direction[k]).max(0.0);
            } else if gap[k] < 0.0 {
                // Penetrated outside the contact: it joins, and the conjugation restarts.
                pressure[k] = -step * gap[k];
                overlap = true;
            }
        }
        conjugate = !overlap;
        if pressure.iter().all(|p| *p == 0.0) {
            // The step emptied the contact: take it back, and go down the gap alone.
            pressure = before;
            conjugate = false;
            continue;
        }
        normalise(&mut pressure, load / area);
    }
    Err(ModelError::NoConvergence {
        what: "continuum contact pressure (conjugate gradients)",
        iterations: MAX_ITERATIONS,
    })
}

/// The contact area of `pressure` on n × n pixels of side `pixel`, row by row along x: each
/// row's edges lie between its outermost pixels in contact and their neighbours out of it,
/// where the pressure (inside) and the gap as a pressure, gap/`own` (outside, `own` the
/// pixel's compliance to its own pressure), cross zero linearly. Counting pixels jumps as
/// the grid is refined; this converges smoothly (first order in the pixel: 3.5, 2.0, 1.0 %
/// on 32, 64, 128 pixels for Hertz), so two resolutions extrapolate it.
pub fn sub_cell_area(pressure: &[f64], gap: &[f64], n: usize, pixel: f64, own: f64) -> f64 {
    let signed = |k: usize| {
        if pressure[k] > 0.0 {
            pressure[k]
        } else {
            -gap[k].max(0.0) / own
        }
    };
    let mut length = 0.0;
    for j in 0..n {
        let at = |i: usize| i * n + j;
        let mut inside = (0..n).filter(|&i| pressure[at(i)] > 0.0);
        let Some(first) = inside.next() else {
            continue;
        };
        let last = inside.next_back().unwrap_or(first);
        // The distance past pixel `a` (in contact) towards its neighbour `b` where the
        // interpolated pressure vanishes; half a pixel at the grid's border.
        let beyond = |a: usize, b: Option<usize>| match b {
            Some(b) => {
                let (sa, sb) = (signed(at(a)), signed(at(b)));
                pixel * sa / (sa - sb)
            }
            None => 0.5 * pixel,
        };
        let left = beyond(first, first.checked_sub(1));
        let right = beyond(last, (last + 1 < n).then_some(last + 1));
        length += (last - first) as f64 * pixel + left + right;
    }
    length * pixel
}

/// Scales `pressure` to sum to `total`.
fn normalise(pressure: &mut [f64], total: f64) {
    let sum: f64 = pressure.iter().sum();
    if sum > 0.0 {
        pressure.iter_mut().for_each(|p| *p *= total / sum);
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
    use crate::continuum::static_contact;

    /// On the grid, the pressed contact is the axisymmetric solver's: δ within 0.5 %, the
    /// area within 3 % on 64 pixels a side, and, extrapolated from 64 and 128, within 0.3 %
    /// (the error of the edges is first order in the pixel and smooth).
    #[test]
    fn on_the_grid_the_pressed_contact_is_the_axisymmetric_one() {
        for (thickness, nu) in [(100e-9, 0.35), (5e-9, 0.3), (2e-9, 0.45)] {
            let layer = Layer {
                thickness,
                poisson_ratio: nu,
                ..Layer::default()
            };
            let (radius, load) = (25e-9, 1e-9);
            let pressed = |n: usize| {
                let pixel = grid_for(radius, load, &layer, n);
                let influence = Influence::new(&layer, n, pixel);
                let pressing = Pressing {
                    surface: &influence,
                    pixel,
                    radius,
                    load,
                    middle: 0.0,
                    instant: 1.0,
                    memory: None,
                };
                press(&pressing, None, 1e-10).unwrap()
            };
            let (coarse, fine) = (pressed(64), pressed(128));
            let exact = static_contact(radius, load, &layer).unwrap();
            let delta = coarse.penetration / exact.penetration - 1.0;
            assert!(delta.abs() < 5e-3, "H = {thickness}: δ off by {delta:e}");
            let area = coarse.contact_area / exact.contact_area - 1.0;
            assert!(area.abs() < 0.03, "H = {thickness}: A off by {area:e}");
            let extrapolated = 2.0 * fine.contact_area - coarse.contact_area;
            let area = extrapolated / exact.contact_area - 1.0;
            assert!(
                area.abs() < 3e-3,
                "H = {thickness}: A extrapolated off by {area:e}"
            );
        }
    }
}
