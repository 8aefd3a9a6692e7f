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
use crate::Layer;

/// The deflection of the layer's surface under pixel pressures: n × n pixels of side h.
pub struct Influence {
    n: usize,
    /// The kernel at offset zero.
    own: f64,
    /// The spectrum of the zero-padded kernel, 2n rows × (n + 1) columns.
    kernel: Vec<Complex<f64>>,
    rows: Arc<dyn RealToComplex<f64>>,
    rows_back: Arc<dyn ComplexToReal<f64>>,
    columns: Arc<dyn Fft<f64>>,
    columns_back: Arc<dyn Fft<f64>>,
}

impl Influence {
    /// The influence on a grid of `n` × `n` pixels of side `h` on `layer`.
    pub fn new(layer: &Layer, n: usize, h: f64) -> Influence {
        let m = 2 * n;
        let mut real = RealFftPlanner::<f64>::new();
        let mut complex = FftPlanner::<f64>::new();
        let mut influence = Influence {
            n,
            own: 0.0,
            kernel: Vec::new(),
            rows: real.plan_fft_forward(m),
            rows_back: real.plan_fft_inverse(m),
            columns: complex.plan_fft_forward(m),
            columns_back: complex.plan_fft_inverse(m),
        };
        let correction = correction(layer, h, n);
        let e_star = contact_modulus(layer);
        // The kernel at every offset, wrapped: offset −k sits at index m − k.
        let mut kernel = vec![0.0; m * m];
        for i in 0..m {
            for j in 0..m {
                let di = if i < n { i as f64 } else { i as f64 - m as f64 };
                let dj = if j < n { j as f64 } else { j as f64 - m as f64 };
                let (x, y) = (di * h, dj * h);
                let r = x.hypot(y);
                kernel[i * m + j] =
                    rectangle(x, y, 0.5 * h) / (PI * e_star) + h * h * correction.at(r);
            }
        }
        influence.own = kernel[0];
        influence.kernel = influence.forward(&kernel);
        influence
    }

    /// A pixel's deflection at its own centre under unit pressure on it.
    pub fn own(&self) -> f64 {
        self.own
    }

    /// The grid's side in pixels.
    pub fn size(&self) -> usize {
        self.n
    }

    /// The deflection at every pixel's centre under `pressure` (n × n, row-major).
    pub fn deflect(&self, pressure: &[f64]) -> Vec<f64> {
        let (n, m) = (self.n, 2 * self.n);
        let mut padded = vec![0.0; m * m];
        for i in 0..n {
            padded[i * m..i * m + n].copy_from_slice(&pressure[i * n..(i + 1) * n]);
        }
        let mut spectrum = self.forward(&padded);
        for (s, k) in spectrum.iter_mut().zip(&self.kernel) {
            *s *= k;
        }
        let full = self.backward(spectrum);
        let scale = 1.0 / (m * m) as f64;
        (0..n * n)
            .map(|k| full[(k / n) * m + k % n] * scale)
            .collect()
    }

    /// The 2-D spectrum of an m × m real array: real FFTs along rows, then complex FFTs
    /// along the m + 1 … columns; stored column-major in (n + 1) columns of m.
    fn forward(&self, data: &[f64]) -> Vec<Complex<f64>> {
        let (n, m) = (self.n, 2 * self.n);
        let half = n + 1;
        let mut by_column = vec![Complex::default(); half * m];
        let mut row = vec![0.0; m];
        let mut out = vec![Complex::default(); half];
        for i in 0..m {
            row.copy_from_slice(&data[i * m..(i + 1) * m]);
            self.rows
                .process(&mut row, &mut out)
                .expect("buffers sized for the plan");
            for (j, value) in out.iter().enumerate() {
                by_column[j * m + i] = *value;
            }
        }
        for column in by_column.chunks_mut(m) {
            self.columns.process(column);
        }
        by_column
    }

    /// The inverse of [`Influence::forward`], unscaled (m² times the array).
    fn backward(&self, mut by_column: Vec<Complex<f64>>) -> Vec<f64> {
        let (n, m) = (self.n, 2 * self.n);
        let half = n + 1;
        for column in by_column.chunks_mut(m) {
            self.columns_back.process(column);
        }
        let mut data = vec![0.0; m * m];
        let mut row = vec![Complex::default(); half];
        for i in 0..m {
            for (j, value) in row.iter_mut().enumerate() {
                *value = by_column[j * m + i];
            }
            // The transform of a real array: its zero and Nyquist terms are real.
            row[0].im = 0.0;
            row[n].im = 0.0;
            self.rows_back
                .process(&mut row, &mut data[i * m..(i + 1) * m])
                .expect("buffers sized for the plan");
        }
        data
    }
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
/// (1/(πE*H)) ∫₀^∞ (C(s) − 1) J₀(s r/H) ds.
struct Correction {
    step: f64,
    values: Vec<f64>,
}

impl Correction {
    /// Linear interpolation (the correction is smooth on the pixel's scale).
    fn at(&self, r: f64) -> f64 {
        let t = r / self.step;
        let i = (t as usize).min(self.values.len() - 2);
        let u = t - i as f64;
        self.values[i] * (1.0 - u) + self.values[i + 1] * u
    }
}

/// The correction at half-pixel steps out past the grid's diagonal.
fn correction(layer: &Layer, h: f64, n: usize) -> Correction {
    let (nu, thickness) = (layer.poisson_ratio, layer.thickness);
    let step = 0.5 * h;
    let extent = 2.0 * (n as f64) * h * std::f64::consts::SQRT_2;
    let count = (extent / step).ceil() as usize + 2;
    let nodes = correction_rule(nu, extent / thickness);
    let scale = 1.0 / (PI * contact_modulus(layer) * thickness);
    let values = (0..count)
        .map(|i| {
            let r = i as f64 * step / thickness;
            scale * nodes.iter().map(|(s, w)| w * libm::j0(s * r)).sum::<f64>()
        })
        .collect();
    Correction { step, values }
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
        let (n, h) = (8, 1e-9);
        let influence = Influence::new(&layer, n, h);
        let mut pressure = vec![0.0; n * n];
        pressure[0] = 1.0; // a corner pixel
        pressure[3 * n + 5] = 2.0;
        let w = influence.deflect(&pressure);
        let e_star = contact_modulus(&layer);
        let corr = correction(&layer, h, n);
        let single = |di: f64, dj: f64| {
            let (x, y) = (di * h, dj * h);
            rectangle(x, y, 0.5 * h) / (PI * e_star) + h * h * corr.at(x.hypot(y))
        };
        for (i, j) in [(0, 0), (7, 7), (0, 7), (3, 5), (6, 1)] {
            let (i, j) = (i as f64, j as f64);
            let direct = single(i, j) + 2.0 * single(i - 3.0, j - 5.0);
            let got = w[i as usize * n + j as usize];
            assert!(
                (got / direct - 1.0).abs() < 1e-12,
                "({i}, {j}): {got:e} vs {direct:e}"
            );
        }
    }
}
