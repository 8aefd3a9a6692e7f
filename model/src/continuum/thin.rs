//! §8's thin-layer path's error: where the contact is many layer thicknesses wide
//! (r₀/H ≥ [`THIN`], ν ≤ [`THIN_POISSON`]) the continuum answer is the local law's exact one,
//! and its error the two laws' relative difference at rest.
//!
//! That difference depends only on r₀/H and ν (lengths in units of H, pressures in units
//! of E_L H/R: nothing else is left), and it falls as the contact widens: the layer departs
//! from the local law only within a few thicknesses of the contact's edge. It was found
//! by the axisymmetric solver on every request (1 s at r₀/H = 20, growing with r₀/H
//! without bound: its rings must resolve the layer, and a layer of 1e-14 m under a
//! nanometre contact took minutes and gigabytes). It is tabulated instead at the path's
//! entry, r₀/H = 20, and at 40, for ν every 0.05 (`print_the_thin_table` prints the
//! table), with the solver's own error. The bound at r₀/H ≥ 20 is the entry's difference
//! with that error, falling as (20H/r₀)^p, p the slowest decay the two nodes allow within
//! the solver's errors, at most 1 (the edge's share of the contact, H/r₀). Measured at
//! ν = 0.35: the area's difference 4.5e-3, 1.7e-3, 1.1e-4 at r₀/H = 20, 40, 80, faster than
//! 1/r₀ (past 80 the solver's rings are coarser than the layer and what it gives is its own
//! error).

use super::plan::{THIN, THIN_POISSON};

/// ν between the table's columns.
const DNU: f64 = 0.05;
/// Columns: ν = 0, 0.05, …, 0.4.
const NNU: usize = 9;

/// The relative errors of δ and of A of the local law's answer as the continuum's on a
/// layer of Poisson ratio `nu` ≤ [`THIN_POISSON`], under a contact of relaxed local radius
/// r₀ = `ratio`·H, `ratio` ≥ [`THIN`]: (δ, A). Between two columns, the larger of theirs.
pub fn thin_error(ratio: f64, nu: f64) -> (f64, f64) {
    debug_assert!(
        ratio >= THIN && nu <= THIN_POISSON,
        "the thin-layer path's domain"
    );
    let column = (nu.clamp(0.0, THIN_POISSON) / DNU).min((NNU - 1) as f64);
    let (low, high) = (column.floor() as usize, column.ceil() as usize);
    let at = |j: usize, quantity: usize| {
        let ([d20, e20], [d40, e40]) = (
            [THIN_TABLE[0][j][quantity].abs(), THIN_TABLE[0][j][2]],
            [THIN_TABLE[1][j][quantity].abs(), THIN_TABLE[1][j][2]],
        );
        let power = ((d20 - e20).max(0.0) / (d40 + e40)).log2().clamp(0.0, 1.0);
        (d20 + e20) * (THIN / ratio.max(THIN)).powf(power)
    };
    let error = |quantity: usize| at(low, quantity).max(at(high, quantity));
    (error(0), error(1))
}

/// The two laws' relative differences at rest in δ and in A, and the axisymmetric solver's
/// error (the inner triple), at r₀/H = 20 and 40 (rows) and ν = 0, 0.05, …, 0.4 (columns).
static THIN_TABLE: [[[f64; 3]; NNU]; 2] = include!("thin_table.in");

#[cfg(test)]
mod tests {
    use super::super::static_contact;
    use super::*;
    use crate::limits::relaxed;
    use crate::Layer;

    /// The two laws' relative differences in δ and A at rest, and the axisymmetric solver's
    /// own error, at r₀/H = `ratio` on a layer of Poisson ratio `nu`.
    fn measured(ratio: f64, nu: f64) -> [f64; 3] {
        let layer = Layer {
            poisson_ratio: nu,
            ..Layer::default()
        };
        let radius = 25e-9;
        let r0 = ratio * layer.thickness;
        let delta = r0 * r0 / (2.0 * radius);
        let load = std::f64::consts::PI * layer.stiffness() * radius * delta * delta;
        let local = relaxed(radius, load, &layer);
        let rest = static_contact(radius, load, &layer).unwrap();
        [
            local.penetration / rest.penetration - 1.0,
            local.contact_area / rest.contact_area - 1.0,
            rest.relative_error,
        ]
    }

    /// The table is the solver's (to the five digits it is printed with).
    #[test]
    fn the_table_is_the_solvers_at_a_node() {
        let column = 7;
        let got = measured(THIN, column as f64 * DNU);
        for (got, table) in got.iter().zip(THIN_TABLE[0][column]) {
            assert!((got / table - 1.0).abs() < 1e-4, "{got:e} vs {table:e}");
        }
    }

    /// Between the nodes, between the columns and beyond the table, the solver's difference
    /// stays within the bound.
    #[test]
    fn the_bound_holds_between_the_nodes_and_beyond() {
        for (ratio, nu) in [
            (28.3, 0.35),
            (28.3, 0.175),
            (56.6, 0.2),
            (30.0, 0.0),
            (30.0, 0.4),
        ] {
            let [d, a, _] = measured(ratio, nu);
            let (bound_d, bound_a) = thin_error(ratio, nu);
            assert!(
                d.abs() <= bound_d,
                "δ at r₀/H = {ratio}, ν = {nu}: {d:e} > {bound_d:e}"
            );
            assert!(
                a.abs() <= bound_a,
                "A at r₀/H = {ratio}, ν = {nu}: {a:e} > {bound_a:e}"
            );
        }
    }

    /// The bound is finite, positive and never grows as the contact widens, to the widest
    /// (a layer of 1e-300 m), in every column.
    #[test]
    fn the_bound_falls_as_the_contact_widens() {
        for j in 0..=16 {
            let nu = j as f64 * THIN_POISSON / 16.0;
            let mut last = (f64::INFINITY, f64::INFINITY);
            for k in 0..=60 {
                let ratio = THIN * 10f64.powi(k * 5);
                let (d, a) = thin_error(ratio.min(f64::MAX), nu);
                assert!(
                    d > 0.0 && a > 0.0 && d.is_finite() && a.is_finite(),
                    "{ratio:e}, {nu}"
                );
                assert!(d <= last.0 && a <= last.1, "r₀/H = {ratio:e}, ν = {nu}");
                last = (d, a);
            }
        }
    }

    /// Prints the table (run with `--ignored` after changing the solver, and paste).
    #[test]
    #[ignore]
    fn print_the_thin_table() {
        println!("[");
        for ratio in [THIN, 2.0 * THIN] {
            let row: Vec<String> = (0..NNU)
                .map(|j| {
                    let [d, a, e] = measured(ratio, j as f64 * DNU);
                    format!("[{d:.4e}, {a:.4e}, {e:.4e}]")
                })
                .collect();
            println!("    [{}],", row.join(", "));
        }
        println!("]");
    }
}
