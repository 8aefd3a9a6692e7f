//! The static continuum contact area in one look-up: a sphere at rest on a bonded elastic
//! layer is Hertz's contact scaled by a factor that depends only on the layer's thickness
//! in units of Hertz's radius and on ν. Measured lengths in units of a_H = (3PR/4E*)^{1/3},
//! the layer enters only through H/a_H and ν, so
//!
//!     A_continuum = F(log₁₀(H/a_H), ν) · π a_H².
//!
//! F is tabulated once from [`super::static_contact`] (`cargo test -p thirdbody-model
//! --release -- --ignored print_the_area_table` prints the table below) and interpolated
//! by bicubic Catmull–Rom in ln F. A test holds the interpolation to direct solves between the nodes.
//! Thinner than the table (H < a_H/100), F follows the local law's scaling from the table's
//! edge (for ν ≤ 0.45 the continuum is the local law there).

use std::f64::consts::PI;

use super::compliance::contact_modulus;
use crate::Layer;

/// The table's first log₁₀(H/a_H), its step and its number of nodes.
const X0: f64 = -2.0;
const DX: f64 = 0.125;
const NX: usize = 41;
/// ν from 0 to 0.5 in steps of 0.05.
const DNU: f64 = 0.05;
const NNU: usize = 11;

/// The static continuum contact area (m²) of a sphere of radius `radius` under `load` on
/// `layer`, by the table (within 0.5 % of the direct solve, which is within 0.1 %).
pub fn static_area(radius: f64, load: f64, layer: &Layer) -> f64 {
    let hertz = hertz_radius(radius, load, layer);
    let x = (layer.thickness / hertz).log10();
    let nu = layer.poisson_ratio;
    let ln_factor = if x < X0 {
        // A_local/A_H ∝ (H/a_H)^{1/2} at fixed load: keep A/A_local as at the edge.
        interpolate(X0, nu).ln() + 0.5 * (x - X0) * std::f64::consts::LN_10
    } else {
        interpolate(x.min(X0 + DX * (NX - 1) as f64), nu).ln()
    };
    // In logarithms: a sphere of 1e280 m under 1e56 N has a finite area whose a_H² and
    // factor alone are not (found by the fuzzer).
    (ln_factor + PI.ln() + 2.0 * hertz.ln()).exp()
}

/// a_H = (3PR/(4E*))^{1/3}, Hertz's contact radius with the layer's E* as a half-space
/// (the cube roots taken apart: P R alone may overflow).
pub fn hertz_radius(radius: f64, load: f64, layer: &Layer) -> f64 {
    (3.0 * load / (4.0 * contact_modulus(layer))).cbrt() * radius.cbrt()
}

/// F at (x, ν) by bicubic Catmull–Rom over the nodes' ln F (x inside the table): ln F is
/// nearly linear in x where the layer is thin (F ∝ (H/a_H)^{1/2}) and flat where thick.
fn interpolate(x: f64, nu: f64) -> f64 {
    let (i, u) = cell((x - X0) / DX, NX);
    let (j, v) = cell(nu.clamp(0.0, 0.5) / DNU, NNU);
    let node =
        |a: isize, b: isize| extended(a, NX, |a| extended(b, NNU, |b| AREA_FACTOR[a][b].ln()));
    let along_nu = |a: isize| {
        let b = j as isize;
        catmull_rom(
            [node(a, b - 1), node(a, b), node(a, b + 1), node(a, b + 2)],
            v,
        )
    };
    let a = i as isize;
    catmull_rom(
        [
            along_nu(a - 1),
            along_nu(a),
            along_nu(a + 1),
            along_nu(a + 2),
        ],
        u,
    )
    .exp()
}

/// `value` at node `i` of `n`, continued linearly past either end by a ghost node
/// (clamping instead would bend the cubic in the first and last cells: 0.9 % off there).
fn extended(i: isize, n: usize, value: impl Fn(usize) -> f64) -> f64 {
    match i {
        i if i < 0 => 2.0 * value(0) - value(1),
        i if i >= n as isize => 2.0 * value(n - 1) - value(n - 2),
        i => value(i as usize),
    }
}

/// The node below position `t` (in node units) of a grid of `n` nodes, and the fraction past it.
fn cell(t: f64, n: usize) -> (usize, f64) {
    let i = (t.floor().max(0.0) as usize).min(n - 2);
    (i, t - i as f64)
}

/// The Catmull–Rom cubic through p[1] (u = 0) and p[2] (u = 1).
fn catmull_rom(p: [f64; 4], u: f64) -> f64 {
    let [p0, p1, p2, p3] = p;
    p1 + 0.5
        * u
        * (p2 - p0 + u * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + u * (3.0 * (p1 - p2) + p3 - p0)))
}

/// F = A_continuum/(π a_H²) at log₁₀(H/a_H) = X0 + i·DX (rows) and ν = j·DNU (columns).
static AREA_FACTOR: [[f64; NNU]; NX] = include!("area_table.in");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::continuum::static_contact;

    /// The layer of E* = 1 GPa and ν with thickness `x` (log₁₀ of H/a_H) for R = 1 µm,
    /// P = 1 µN.
    fn layer(x: f64, nu: f64) -> (f64, f64, Layer) {
        let (radius, load) = (1e-6, 1e-6);
        let mut layer = Layer {
            poisson_ratio: nu,
            ..Layer::default()
        };
        // E_L for E* = 1 GPa: E* = E_L (1 + ν)(1 − 2ν)/((1 − ν)(1 − ν²)).
        layer.elastic_modulus =
            1e9 * (1.0 - nu) * (1.0 - nu * nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
        layer.thickness = hertz_radius(radius, load, &layer) * 10f64.powf(x);
        (radius, load, layer)
    }

    /// Prints the table (run with `--ignored` after changing the solver, and paste).
    #[test]
    #[ignore]
    fn print_the_area_table() {
        println!("[");
        for i in 0..NX {
            let row: Vec<String> = (0..NNU)
                .map(|j| {
                    // ν = 0.5 itself has no finite E_L: its neighbour stands in.
                    let nu = (j as f64 * DNU).min(0.4999);
                    let (radius, load, layer) = layer(X0 + i as f64 * DX, nu);
                    let c = static_contact(radius, load, &layer).unwrap();
                    let a = hertz_radius(radius, load, &layer);
                    format!("{:.6e}", c.contact_area / (PI * a * a))
                })
                .collect();
            println!("    [{}],", row.join(", "));
        }
        println!("]");
    }

    /// Thinner than the table, the area follows the local law's scaling from its edge: on a
    /// compressible layer that is the local law itself there (within 1 %).
    /// A sphere of 1e284 m under 1e56 N (valid inputs, found by the fuzzer) has a finite
    /// area: neither P R nor a_H² overflows on the way, and it is the local law's (the
    /// layer is thin against such a contact) to the table's edge.
    #[test]
    fn an_astronomical_contact_has_a_finite_area() {
        let layer = Layer::default();
        let (radius, load) = (3.5e284, 4.4e56);
        let area = static_area(radius, load, &layer);
        assert!(area.is_finite() && area > 0.0, "{area:e}");
        let k = layer.elastic_modulus / layer.thickness;
        let local = 2.0 * (PI * radius / k).sqrt() * load.sqrt();
        assert!((area / local - 1.0).abs() < 0.02, "{:e} vs {local:e}", area);
    }

    #[test]
    fn past_the_thin_edge_the_table_is_the_local_law() {
        for nu in [0.0, 0.35] {
            let (radius, load, layer) = layer(-2.5, nu);
            let k = layer.elastic_modulus / layer.thickness;
            let local = 2.0 * (PI * radius / k).sqrt() * load.sqrt();
            let table = static_area(radius, load, &layer);
            assert!(
                (table / local - 1.0).abs() < 0.01,
                "ν = {nu}: {table:e} vs {local:e}"
            );
        }
    }

    /// Between the nodes, in the middle of each cell (where interpolation errs most), the
    /// table is the direct solve within 0.5 %.
    #[test]
    fn the_table_is_the_direct_solve_between_its_nodes() {
        for (x, nu) in [
            (-1.9375, 0.025),
            (-1.0625, 0.325),
            (-0.4375, 0.475),
            (0.0625, 0.175),
            (0.5625, 0.425),
            (1.3125, 0.275),
            (2.6875, 0.375),
        ] {
            let (radius, load, layer) = layer(x, nu);
            let direct = static_contact(radius, load, &layer).unwrap().contact_area;
            let table = static_area(radius, load, &layer);
            assert!(
                (table / direct - 1.0).abs() < 5e-3,
                "x = {x}, ν = {nu}: {table:e} vs {direct:e}"
            );
        }
    }
}
