//! Rolling answers through the similarity tables (src/similarity.rs) against the exact
//! strip solver over the whole range the service promises: ξ = V T_σ/r₀ ∈ [0, ∞) and
//! κ ∈ [0, 1e4], every integral quantity within 1e-9 (relative) and within the bound each
//! answer reports in `verification.table_error`.

use thirdbody_model::limits;
use thirdbody_model::rolling::penetration_contact;
use thirdbody_model::spectrum::Terms;
use thirdbody_model::tables::{self, Use};
use thirdbody_model::{self as model, Layer, Quadrature, Rolling, RollingSolution, SolveOptions};

/// A rolling contact on the default layer with viscosity strength κ at ξ = V T_σ/r₀.
fn contact(kappa: f64, xi: f64) -> Rolling {
    let base = Rolling::default();
    let layer = Layer {
        retardation_time: (1.0 + kappa) * base.layer.relaxation_time,
        ..base.layer
    };
    let r0 = limits::relaxed(base.radius, base.load, &layer).half_width;
    Rolling {
        velocity: xi * r0 / layer.relaxation_time,
        layer,
        ..base
    }
}

/// The largest relative difference of the integral quantities of two answers.
fn difference(a: &RollingSolution, b: &RollingSolution) -> f64 {
    [
        (a.penetration, b.penetration),
        (a.contact_area, b.contact_area),
        (a.half_width, b.half_width),
        (a.centroid_shift, b.centroid_shift),
        (a.pressure_centre_shift, b.pressure_centre_shift),
        (a.friction_coefficient, b.friction_coefficient),
    ]
    .into_iter()
    .map(|(x, y)| if x == y { 0.0 } else { ((x - y) / y).abs() })
    .fold(0.0, f64::max)
}

#[test]
fn table_answers_match_exact_solves_to_1e_9_over_xi_0_to_infinity_and_kappa_0_to_1e4() {
    let options = SolveOptions::integrals_only(Quadrature::default());
    let mut report = Vec::new();
    for kappa in [0.0, 1e-6, 0.01, 0.5, 4.0, 37.0, 100.0, 1e3, 1e4] {
        let mut worst: f64 = 0.0;
        let mut worst_over_bound: f64 = 0.0;
        let xis = (0..=80)
            .map(|i| 10f64.powf(-9.0 + 18.0 * f64::from(i) / 80.0 + 0.0137))
            .chain([0.0, 1e-200, 1e30]);
        for xi in xis {
            let rolling = contact(kappa, xi);
            let exact = model::solve(&rolling, &options).unwrap();
            let table = tables::solve(&rolling, &options, Use::Build).unwrap();
            let d = difference(&table, &exact);
            worst = worst.max(d);
            if let Some(bound) = table.verification.table_error {
                worst_over_bound = worst_over_bound.max(d / bound);
            }
            assert!(
                d <= 1e-9,
                "κ = {kappa}, ξ = {xi:e}: relative difference {d:e}"
            );
        }
        report.push(format!(
            "κ = {kappa}: worst {worst:.1e}, worst/bound {worst_over_bound:.2}"
        ));
        assert!(
            worst_over_bound <= 1.0,
            "κ = {kappa}: an answer differs by more than its table_error ({worst_over_bound})"
        );
    }
    println!("{}", report.join("\n"));
}

#[test]
fn the_ratios_at_a_given_penetration_match_the_strip_solver_between_the_table_points() {
    let quadrature = Quadrature::default();
    for kappa in [0.01, 4.0, 1e3, 1e4, 1e5] {
        let table = tables::get_or_build(kappa, quadrature).unwrap();
        // Within the promised range every table is certified well inside what rolling
        // answers accept (1e-10; the worst, at κ = 1e4, is the exact solver's own rounding
        // times four); beyond it, the table says how good it is.
        if kappa <= 1e4 {
            assert!(table.error() < 5e-11, "κ = {kappa}: {:e}", table.error());
        }
        let mut worst: f64 = 0.0;
        for i in 0..=300 {
            let xi = 10f64.powf(-10.0 + 20.0 * f64::from(i) / 300.0 + 0.0123);
            let (exact, quadrature_error) =
                penetration_contact(&Terms::one(kappa, xi), quadrature).unwrap();
            let got = table.ratios(xi);
            for (t, e) in [
                (got.load, exact.load),
                (got.area, exact.area),
                (got.centroid, exact.centroid),
                (got.pressure_centre, exact.pressure_centre),
            ] {
                worst = worst.max(((t - e) / e).abs());
            }
            assert!(
                table.quadrature_error(xi) >= 0.5 * quadrature_error,
                "κ = {kappa}, ξ = {xi:e}"
            );
        }
        assert!(
            worst <= table.error(),
            "κ = {kappa}: {worst:e} against the certified {:e}",
            table.error()
        );
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]

    /// Any κ in the promised range (a new table for each), any ξ: the table answer is the
    /// exact one to 1e-9 and within its own bound.
    #[test]
    fn any_layer_and_speed_in_range_agree_with_the_exact_solve(
        log_kappa in -6.0f64..4.0,
        log_xi in -12.0f64..12.0,
    ) {
        let (kappa, xi) = (10f64.powf(log_kappa), 10f64.powf(log_xi));
        let options = SolveOptions::integrals_only(Quadrature::default());
        let rolling = contact(kappa, xi);
        let exact = model::solve(&rolling, &options).unwrap();
        let table = tables::solve(&rolling, &options, Use::Build).unwrap();
        let bound = table.verification.table_error.unwrap();
        let d = difference(&table, &exact);
        proptest::prop_assert!(d <= 1e-9 && d <= bound, "κ = {kappa:e}, ξ = {xi:e}: {d:e} (bound {bound:e})");
    }
}
