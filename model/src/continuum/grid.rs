//! The layer's surface on a grid of square pixels (docs/model.md §8, "Discretisation"):
//! pressure constant on each pixel, deflection at each pixel's centre. The influence of a
//! pixel is the half-space's in closed form (a uniformly loaded rectangle, Love 1929) plus
//! the layer's correction sampled at the pixels' distance (smooth where the pixel is much
//! smaller than the layer). The convolution is free, not periodic: the kernel and the
//! pressures are zero-padded to twice the grid (Hockney), so no image of the load acts.

use std::f64::consts::PI;
use std::sync::Arc;

use realfft::num_complex::Complex;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::{Fft, FftPlanner};

use super::compliance::{contact_modulus, correction_rule};
use crate::quadrature::{gauss_legendre, GaussRule};
use crate::{Layer, ModelError, Stop};

/// A grid of pixels: `nx` along the rolling direction x, `ny` across it, of side `pixel`.
/// Pixel (i, j) is at x = x₀ + (i + ½ − nx/2) h, y = (j + ½ − ny/2) h (x₀ the grid's
/// middle, which the contact gives); arrays over the grid are row-major in i, index
/// k = i·ny + j, so the pixel one step ahead in x is k + ny.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    pub nx: usize,
    pub ny: usize,
    /// h (m).
    pub pixel: f64,
}

impl Grid {
    /// Pixels in all.
    pub fn pixels(&self) -> usize {
        self.nx * self.ny
    }

    /// The x of pixel row `i` from the grid's middle (m).
    pub fn x(&self, i: usize) -> f64 {
        (i as f64 + 0.5 - 0.5 * self.nx as f64) * self.pixel
    }

    /// The y of pixel column `j` (m).
    pub fn y(&self, j: usize) -> f64 {
        (j as f64 + 0.5 - 0.5 * self.ny as f64) * self.pixel
    }
}

/// The deflection of the layer's surface under pixel pressures on a [`Grid`].
pub struct Influence {
    grid: Grid,
    /// The kernel at offset zero.
    own: f64,
    /// The spectrum of the zero-padded kernel, (ny + 1) columns of 2nx.
    kernel: Vec<Complex<f64>>,
    rows: Arc<dyn RealToComplex<f64>>,
    rows_back: Arc<dyn ComplexToReal<f64>>,
    columns: Arc<dyn Fft<f64>>,
    columns_back: Arc<dyn Fft<f64>>,
}

impl Influence {
    /// The influence on `grid` on `layer`, stopped when `stop` says so (its kernel takes
    /// about a tenth of a second on the largest grid).
    pub fn new(layer: &Layer, grid: Grid, stop: Stop) -> Result<Influence, ModelError> {
        let (mx, my) = (2 * grid.nx, 2 * grid.ny);
        let mut real = RealFftPlanner::<f64>::new();
        let mut complex = FftPlanner::<f64>::new();
        let mut influence = Influence {
            grid,
            own: 0.0,
            kernel: Vec::new(),
            rows: real.plan_fft_forward(my),
            rows_back: real.plan_fft_inverse(my),
            columns: complex.plan_fft_forward(mx),
            columns_back: complex.plan_fft_inverse(mx),
        };
        let h = grid.pixel;
        let correction = correction(layer, &grid, stop)?;
        let e_star = contact_modulus(layer);
        // The kernel at every offset, wrapped: offset −k sits at index m − k.
        let offset = |i: usize, n: usize| {
            if i < n {
                i as f64
            } else {
                i as f64 - 2.0 * n as f64
            }
        };
        let rule = pixel_rule(h, layer.thickness);
        // The kernel is even in x and y: computed once per distance, placed four times.
        let mut quarter = Vec::with_capacity((grid.nx + 1) * (grid.ny + 1));
        for i in 0..=grid.nx {
            stop.check()?;
            quarter.extend((0..=grid.ny).map(|j| {
                pixel_response(i as f64 * h, j as f64 * h, h, e_star, &correction, &rule)
            }));
        }
        let mut kernel = vec![0.0; mx * my];
        for i in 0..mx {
            for j in 0..my {
                let (di, dj) = (offset(i, grid.nx).abs(), offset(j, grid.ny).abs());
                kernel[i * my + j] = quarter[di as usize * (grid.ny + 1) + dj as usize];
            }
        }
        influence.own = kernel[0];
        influence.kernel = influence.forward(&kernel, my, mx);
        Ok(influence)
    }

    /// A pixel's deflection at its own centre under unit pressure on it.
    pub fn own(&self) -> f64 {
        self.own
    }

    /// The grid.
    pub fn grid(&self) -> Grid {
        self.grid
    }

    /// The deflection at every pixel's centre under `pressure` (over the grid).
    pub fn deflect(&self, pressure: &[f64]) -> Vec<f64> {
        let Grid { nx, ny, .. } = self.grid;
        let (mx, my) = (2 * nx, 2 * ny);
        let mut spectrum = self.forward(pressure, ny, nx);
        for (s, k) in spectrum.iter_mut().zip(&self.kernel) {
            *s *= k;
        }
        let mut deflection = self.backward(spectrum);
        let scale = 1.0 / (mx * my) as f64;
        deflection.iter_mut().for_each(|w| *w *= scale);
        deflection
    }

    /// The 2-D spectrum of a 2nx × 2ny real array given by its first `filled` rows of
    /// `width` values each (the rest zero): real FFTs along rows, then complex FFTs along
    /// the ny + 1 columns; stored column by column.
    fn forward(&self, data: &[f64], width: usize, filled: usize) -> Vec<Complex<f64>> {
        let Grid { nx, ny, .. } = self.grid;
        let (mx, my) = (2 * nx, 2 * ny);
        let half = ny + 1;
        let mut by_column = vec![Complex::default(); half * mx];
        let mut row = vec![0.0; my];
        let mut out = vec![Complex::default(); half];
        let mut scratch = self.rows.make_scratch_vec();
        for i in 0..filled {
            row[..width].copy_from_slice(&data[i * width..(i + 1) * width]);
            row[width..].fill(0.0);
            self.rows
                .process_with_scratch(&mut row, &mut out, &mut scratch)
                .expect("buffers sized for the plan");
            for (j, value) in out.iter().enumerate() {
                by_column[j * mx + i] = *value;
            }
        }
        // Every column at once (they lie end to end), with one scratch buffer.
        let mut scratch = vec![Complex::default(); self.columns.get_inplace_scratch_len()];
        self.columns
            .process_with_scratch(&mut by_column, &mut scratch);
        by_column
    }

    /// The inverse of [`Influence::forward`] on the grid's first nx rows and ny columns
    /// (the deflection is wanted only there), unscaled (4 nx ny times the array).
    fn backward(&self, mut by_column: Vec<Complex<f64>>) -> Vec<f64> {
        let Grid { nx, ny, .. } = self.grid;
        let (mx, my) = (2 * nx, 2 * ny);
        let half = ny + 1;
        let mut scratch = vec![Complex::default(); self.columns_back.get_inplace_scratch_len()];
        self.columns_back
            .process_with_scratch(&mut by_column, &mut scratch);
        let mut data = vec![0.0; nx * ny];
        let mut row = vec![Complex::default(); half];
        let mut out = vec![0.0; my];
        let mut scratch = self.rows_back.make_scratch_vec();
        for i in 0..nx {
            for (j, value) in row.iter_mut().enumerate() {
                *value = by_column[j * mx + i];
            }
            // The transform of a real array: its zero and Nyquist terms are real.
            row[0].im = 0.0;
            row[ny].im = 0.0;
            self.rows_back
                .process_with_scratch(&mut row, &mut out, &mut scratch)
                .expect("buffers sized for the plan");
            data[i * ny..(i + 1) * ny].copy_from_slice(&out[..ny]);
        }
        data
    }
}

/// The deflection at (x, y) from the centre of a pixel of side `h` under unit pressure on
/// it: the half-space's in closed form, plus the layer's correction averaged over the pixel
/// by a Gauss rule (`rule`, a side): the correction varies over the layer's thickness,
/// which a pixel may approach on a thin layer, where sampling it at the centre alone left
/// the area 5 % off at a pixel as wide as the layer.
fn pixel_response(
    x: f64,
    y: f64,
    h: f64,
    e_star: f64,
    correction: &Correction,
    rule: &GaussRule,
) -> f64 {
    let (nodes, weights) = (&rule.0, &rule.1);
    let mut averaged = 0.0;
    for (u, wu) in nodes.iter().zip(weights) {
        for (v, wv) in nodes.iter().zip(weights) {
            let r = (x + 0.5 * h * u).hypot(y + 0.5 * h * v);
            averaged += 0.25 * wu * wv * correction.at(r);
        }
    }
    rectangle(x, y, 0.5 * h) / (PI * e_star) + h * h * averaged
}

/// ∬ dx′dy′/√((x − x′)² + (y − y′)²) over the square |x′|, |y′| ≤ c: the half-space's
/// deflection under unit pressure on a pixel is this over πE* (Love 1929; Johnson eq. 3.25).
fn rectangle(x: f64, y: f64, c: f64) -> f64 {
    /// An antiderivative in both coordinates, ∂²F/∂X∂Y = 1/√(X² + Y²), for either sign of
    /// each (up to terms in one coordinate alone, which the four corners cancel).
    fn f(x: f64, y: f64) -> f64 {
        let term = |a: f64, b: f64| {
            if a == 0.0 {
                0.0
            } else {
                a * (b / a.abs()).asinh()
            }
        };
        term(x, y) + term(y, x)
    }
    f(x + c, y + c) - f(x + c, y - c) - f(x - c, y + c) + f(x - c, y - c)
}

/// The layer's correction to a point load's deflection, per unit load, tabulated in r:
/// (1/(πE*H)) ∫₀^∞ (C(s) − 1) J₀(s r/H) ds. Past [`FAR`] thicknesses it is −1/(πE* r),
/// the half-space's deflection cancelled: C − 1 is −1 plus an odd function of s, whose
/// share of the integral falls off exponentially in r/H (1e-5 of it at 10 H, 1e-7 at 15 H
/// for ν = 0.3).
struct Correction {
    step: f64,
    values: Vec<f64>,
    /// Where the table ends and the far form begins (m).
    far: f64,
    /// 1/(πE*).
    far_scale: f64,
}

impl Correction {
    /// Linear interpolation within the table (the correction is smooth on its step).
    fn at(&self, r: f64) -> f64 {
        if r >= self.far {
            return -self.far_scale / r;
        }
        let t = r / self.step;
        let i = (t as usize).min(self.values.len() - 2);
        let u = t - i as f64;
        self.values[i] * (1.0 - u) + self.values[i + 1] * u
    }
}

/// Gauss nodes a side of a pixel over which the layer's correction is averaged.
const PIXEL_NODES: usize = 4;

/// The rule averaging the correction over a pixel of side `h` on a layer of `thickness`: a
/// pixel much finer than the layer sees the correction as flat (one node).
fn pixel_rule(h: f64, thickness: f64) -> GaussRule {
    gauss_legendre(if h <= thickness / 8.0 { 1 } else { PIXEL_NODES })
}

/// Thicknesses from the load past which the correction takes its far form.
const FAR: f64 = 15.0;

/// Table steps in a layer's thickness: the correction varies over H, so linear
/// interpolation between steps of H/32 errs by about 1e-4 of it.
const STEPS_PER_THICKNESS: f64 = 32.0;

/// The correction out past the grid's diagonal (or to [`FAR`] thicknesses), stopped when
/// `stop` says so.
fn correction(layer: &Layer, grid: &Grid, stop: Stop) -> Result<Correction, ModelError> {
    let (nu, thickness) = (layer.poisson_ratio, layer.thickness);
    let step = thickness / STEPS_PER_THICKNESS;
    let far = FAR * thickness;
    let diagonal = 2.0 * (grid.nx as f64).hypot(grid.ny as f64) * grid.pixel;
    let extent = diagonal.min(far);
    let count = (extent / step).ceil() as usize + 2;
    let nodes = correction_rule(nu, extent / thickness);
    let far_scale = 1.0 / (PI * contact_modulus(layer));
    let mut values = Vec::with_capacity(count);
    for i in 0..count {
        stop.check()?;
        let r = i as f64 * step / thickness;
        values.push(
            far_scale / thickness * nodes.iter().map(|(s, w)| w * libm::j0(s * r)).sum::<f64>(),
        );
    }
    Ok(Correction {
        step,
        values,
        far,
        far_scale,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pixel's own deflection at its centre, 4c·ln(1 + √2)·2 (a square of side 2c), and
    /// far away a point load's, 4c²/r.
    #[test]
    fn a_pixel_deflects_as_love_gives() {
        let c = 0.5;
        let centre = rectangle(0.0, 0.0, c);
        assert!(
            (centre - 8.0 * c * (1.0 + 2f64.sqrt()).ln()).abs() < 1e-14,
            "{centre}"
        );
        let far = rectangle(300.0, 400.0, c);
        assert!((far * 500.0 / (4.0 * c * c) - 1.0).abs() < 1e-6, "{far}");
    }

    /// The padded convolution is the direct sum over pixels, with no image of the load.
    #[test]
    fn the_convolution_is_the_direct_free_sum() {
        let layer = Layer::default();
        let (nx, ny, h) = (8, 6, 1e-9);
        let grid = Grid { nx, ny, pixel: h };
        let influence = Influence::new(&layer, grid, Stop::NEVER).unwrap();
        let mut pressure = vec![0.0; nx * ny];
        pressure[0] = 1.0; // a corner pixel
        pressure[3 * ny + 5] = 2.0;
        let w = influence.deflect(&pressure);
        let e_star = contact_modulus(&layer);
        let corr = correction(&layer, &grid, Stop::NEVER).unwrap();
        let rule = pixel_rule(h, layer.thickness);
        let single = |di: f64, dj: f64| pixel_response(di * h, dj * h, h, e_star, &corr, &rule);
        for (i, j) in [(0, 0), (7, 5), (0, 5), (3, 5), (6, 1), (7, 0)] {
            let (i, j) = (i as f64, j as f64);
            let direct = single(i, j) + 2.0 * single(i - 3.0, j - 5.0);
            let got = w[i as usize * ny + j as usize];
            assert!(
                (got / direct - 1.0).abs() < 1e-12,
                "({i}, {j}): {got:e} vs {direct:e}"
            );
        }
    }
}
