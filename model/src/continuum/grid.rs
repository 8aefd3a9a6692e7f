//! The layer's surface on a grid of square pixels (docs/model.md §8, "Discretisation"):
//! pressure constant on each pixel, deflection at each pixel's centre. The influence of a
//! pixel is the half-space's in closed form (a uniformly loaded rectangle, Love 1929) plus
//! the layer's correction sampled at the pixels' distance (smooth where the pixel is much
//! smaller than the layer). The convolution is free, not periodic: the kernel and the
//! pressures are zero-padded (Hockney) to at least twice the grid, so no image of the load
//! acts, and to lengths of small prime factors, which rustfft transforms fastest
//! ([`padded`]).

use std::cell::RefCell;
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

/// The lengths (mx, my) of the padded convolution of an nx × ny grid: mx along x (complex
/// FFTs), my along y (real FFTs). Pixels at most n − 1 apart meet, so a circular
/// convolution of any length m ≥ 2n − 1 is the free one. Exactly 2n often carries a large
/// prime (104 = 8·13, 152 = 8·19, 232 = 8·29, 376 = 8·47 on the default and four-term
/// answers' grids), where rustfft takes two to five times the instructions per point (at
/// 108, 160, 240, 378: 24 to 33 a point, against 50 to 163); so each length is twice
/// the least number ≥ n with no prime factor above 7. Twice: a real FFT of even length is
/// a complex one of half of it, and rustfft's odd lengths cost half as much again per point
/// (375 against 378).
fn padded(grid: Grid) -> (usize, usize) {
    (2 * smooth(grid.nx), 2 * smooth(grid.ny))
}

/// The least number ≥ `n` (and ≥ 1) with no prime factor above 7.
fn smooth(n: usize) -> usize {
    let is_smooth = |m: usize| [2, 3, 5, 7].iter().fold(m, |r, p| strip(r, *p)) == 1;
    (n.max(1)..)
        .find(|m| is_smooth(*m))
        .expect("a power of two lies ahead")
}

/// `m` with every factor `p` divided out.
fn strip(mut m: usize, p: usize) -> usize {
    while m % p == 0 {
        m /= p;
    }
    m
}

/// The deflection of the layer's surface under pixel pressures on a [`Grid`].
pub struct Influence {
    grid: Grid,
    /// The padded length along x ([`padded`]).
    mx: usize,
    /// The kernel at offset zero.
    own: f64,
    /// The spectrum of the zero-padded kernel, (my/2 + 1) columns of mx, over mx·my: the
    /// inverse transforms' scale taken once here rather than at every convolution.
    kernel: Vec<Complex<f64>>,
    rows: Arc<dyn RealToComplex<f64>>,
    rows_back: Arc<dyn ComplexToReal<f64>>,
    columns: Arc<dyn Fft<f64>>,
    columns_back: Arc<dyn Fft<f64>>,
    /// The buffers of a convolution, kept for the next: an answer convolves hundreds of
    /// times, and clearing them afresh was a tenth of its instructions. (A cell, so an
    /// influence convolves on one thread at a time; each march builds its own.)
    buffers: RefCell<Buffers>,
}

/// The working arrays of one convolution ([`Influence::forward`], [`Influence::backward`]).
struct Buffers {
    /// The 2-D spectrum, column by column: (my/2 + 1) columns of mx.
    spectrum: Vec<Complex<f64>>,
    /// A padded row, real (my values) and as its half spectrum (my/2 + 1).
    real: Vec<f64>,
    complex: Vec<Complex<f64>>,
    /// Scratch enough for any of the four transforms.
    scratch: Vec<Complex<f64>>,
}

impl Influence {
    /// The influence on `grid` on `layer`, stopped when `stop` says so (its kernel takes
    /// about a tenth of a second on the largest grid).
    pub fn new(layer: &Layer, grid: Grid, stop: Stop) -> Result<Influence, ModelError> {
        let (mx, my) = padded(grid);
        let half = my / 2 + 1;
        let mut real = RealFftPlanner::<f64>::new();
        let mut complex = FftPlanner::<f64>::new();
        let (rows, rows_back) = (real.plan_fft_forward(my), real.plan_fft_inverse(my));
        let (columns, columns_back) = (complex.plan_fft_forward(mx), complex.plan_fft_inverse(mx));
        let scratch = [
            rows.get_scratch_len(),
            rows_back.get_scratch_len(),
            columns.get_inplace_scratch_len(),
            columns_back.get_inplace_scratch_len(),
        ]
        .into_iter()
        .max()
        .unwrap_or(0);
        let zero = Complex::default();
        let mut influence = Influence {
            grid,
            mx,
            own: 0.0,
            kernel: Vec::new(),
            rows,
            rows_back,
            columns,
            columns_back,
            buffers: RefCell::new(Buffers {
                spectrum: vec![zero; half * mx],
                real: vec![0.0; my],
                complex: vec![zero; half],
                scratch: vec![zero; scratch],
            }),
        };
        let h = grid.pixel;
        let correction = correction(layer, &grid, stop)?;
        let e_star = contact_modulus(layer);
        // The kernel at every offset, wrapped: offset −d sits at index m − d. Pixels meet
        // at offsets below n alone; the indices from n to m − n meet no pressure, and stay
        // zero.
        let distance = |i: usize, n: usize, m: usize| {
            if i < n {
                Some(i)
            } else if i > m - n {
                Some(m - i)
            } else {
                None
            }
        };
        let rule = pixel_rule(h, layer.thickness);
        // The kernel is even in x and y: computed once per distance, placed four times.
        let mut quarter = Vec::with_capacity(grid.nx * grid.ny);
        for i in 0..grid.nx {
            stop.check()?;
            quarter.extend((0..grid.ny).map(|j| {
                pixel_response(i as f64 * h, j as f64 * h, h, e_star, &correction, &rule)
            }));
        }
        let mut kernel = vec![0.0; mx * my];
        for i in 0..mx {
            let Some(di) = distance(i, grid.nx, mx) else {
                continue;
            };
            for j in 0..my {
                if let Some(dj) = distance(j, grid.ny, my) {
                    kernel[i * my + j] = quarter[di * grid.ny + dj];
                }
            }
        }
        influence.own = kernel[0];
        let scale = 1.0 / (mx * my) as f64;
        let mut buffers = influence.buffers.borrow_mut();
        influence.forward(&kernel, my, mx, &mut buffers);
        let spectrum = buffers.spectrum.iter().map(|k| k * scale).collect();
        drop(buffers);
        influence.kernel = spectrum;
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
        let mut buffers = self.buffers.borrow_mut();
        self.forward(pressure, ny, nx, &mut buffers);
        for (s, k) in buffers.spectrum.iter_mut().zip(&self.kernel) {
            *s *= k;
        }
        self.backward(&mut buffers)
    }

    /// The 2-D spectrum of an mx × my real array given by its first `filled` rows of
    /// `width` values each (the rest zero), into `buffers.spectrum`: real FFTs along rows,
    /// then complex FFTs along the my/2 + 1 columns; stored column by column.
    fn forward(&self, data: &[f64], width: usize, filled: usize, buffers: &mut Buffers) {
        let mx = self.mx;
        let Buffers {
            spectrum,
            real,
            complex,
            scratch,
        } = buffers;
        for i in 0..filled {
            // The row is the transform's scratch: padded afresh every time.
            real[..width].copy_from_slice(&data[i * width..(i + 1) * width]);
            real[width..].fill(0.0);
            self.rows
                .process_with_scratch(real, complex, scratch)
                .expect("buffers sized for the plan");
            for (j, value) in complex.iter().enumerate() {
                spectrum[j * mx + i] = *value;
            }
        }
        // The rows past `filled` are zero, and so is their transform.
        for column in spectrum.chunks_exact_mut(mx) {
            column[filled..].fill(Complex::default());
        }
        // Every column at once (they lie end to end).
        self.columns.process_with_scratch(spectrum, scratch);
    }

    /// The inverse of [`Influence::forward`] on `buffers.spectrum` (which it overwrites),
    /// on the grid's first nx rows and ny columns (the deflection is wanted only there),
    /// unnormalised (mx·my times the array: the kernel's spectrum carries the 1/(mx·my)).
    fn backward(&self, buffers: &mut Buffers) -> Vec<f64> {
        let Grid { nx, ny, .. } = self.grid;
        let (mx, b) = (self.mx, buffers);
        self.columns_back
            .process_with_scratch(&mut b.spectrum, &mut b.scratch);
        let mut data = Vec::with_capacity(nx * ny);
        let last = b.complex.len() - 1;
        for i in 0..nx {
            for (j, value) in b.complex.iter_mut().enumerate() {
                *value = b.spectrum[j * mx + i];
            }
            // The transform of a real array: its zero and Nyquist terms are real.
            b.complex[0].im = 0.0;
            b.complex[last].im = 0.0;
            self.rows_back
                .process_with_scratch(&mut b.complex, &mut b.real, &mut b.scratch)
                .expect("buffers sized for the plan");
            data.extend_from_slice(&b.real[..ny]);
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

    /// Every padded length is even, has no prime factor above 7, is at least twice its
    /// side (so no image of the load acts), and is the least such.
    #[test]
    fn the_padded_lengths_are_even_and_7_smooth() {
        let smooth = |m: usize| {
            let mut rest = m;
            for p in [2, 3, 5, 7] {
                while rest % p == 0 {
                    rest /= p;
                }
            }
            rest == 1
        };
        for n in 1..=600 {
            let (mx, my) = padded(Grid {
                nx: n,
                ny: n + 1,
                pixel: 1.0,
            });
            for (m, n) in [(mx, n), (my, n + 1)] {
                assert!(m % 2 == 0 && smooth(m) && m >= 2 * n, "{n} pixels: {m}");
                let shorter = (2 * n..m).find(|k| k % 2 == 0 && smooth(*k));
                assert!(shorter.is_none(), "{n} pixels: {m}, not {shorter:?}");
            }
        }
        // The default and four-term answers' fine grids: 104 = 8·13 and 376 = 8·47 passed
        // over.
        let fine = |nx, ny| padded(Grid { nx, ny, pixel: 1.0 });
        assert_eq!(fine(112, 52), (224, 108));
        assert_eq!(fine(188, 56), (378, 112));
    }

    /// On a grid padded to neither twice its sides nor a power of two (13 × 11 pixels in
    /// 28 × 24), the convolution of a pressure on every pixel is the direct O(n²) sum over
    /// pixels: the wrapped kernel follows the padded length.
    #[test]
    fn on_the_smooth_padding_the_convolution_is_the_direct_sum() {
        let layer = Layer::default();
        let (nx, ny, h) = (13, 11, 1e-9);
        let grid = Grid { nx, ny, pixel: h };
        assert_eq!(padded(grid), (28, 24));
        let influence = Influence::new(&layer, grid, Stop::NEVER).unwrap();
        let pressure: Vec<f64> = (0..nx * ny)
            .map(|k| 1.0 + ((k * 7919) % 101) as f64 / 50.0)
            .collect();
        let w = influence.deflect(&pressure);
        let e_star = contact_modulus(&layer);
        let corr = correction(&layer, &grid, Stop::NEVER).unwrap();
        let rule = pixel_rule(h, layer.thickness);
        let single = |di: usize, dj: usize| {
            pixel_response(di as f64 * h, dj as f64 * h, h, e_star, &corr, &rule)
        };
        for (i, j) in (0..nx).flat_map(|i| (0..ny).map(move |j| (i, j))) {
            let direct: f64 = (0..nx)
                .flat_map(|a| (0..ny).map(move |b| (a, b)))
                .map(|(a, b)| single(i.abs_diff(a), j.abs_diff(b)) * pressure[a * ny + b])
                .sum();
            let got = w[i * ny + j];
            assert!(
                (got / direct - 1.0).abs() < 1e-12,
                "({i}, {j}): {got:e} vs {direct:e}"
            );
        }
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
