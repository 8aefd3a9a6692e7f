//! The rolling answer on the layer as a continuum (docs/model.md §8) against its exact
//! anchors, each within the answer's own error estimate and §8's tolerances: Hertz on a
//! layer much thicker than the contact, the instantaneous elastic contact at high speed, the
//! slow-rolling shift, the local law on a thin layer, A falling with V; and the reported
//! error against a finer grid.

use std::f64::consts::PI;

use thirdbody_model::continuum::{
    self, contact_modulus, static_contact, ContinuumVerification, THIN,
};
use thirdbody_model::{solve, Layer, Rolling, RollingSolution, SolveOptions, Stop};

fn answer(rolling: &Rolling) -> RollingSolution<ContinuumVerification> {
    continuum::solve(
        rolling,
        &SolveOptions::integrals_only(Default::default()),
        Stop::NEVER,
    )
    .unwrap()
}

/// |got/want − 1|.
fn off(got: f64, want: f64) -> f64 {
    (got / want - 1.0).abs()
}

/// The default job as a continuum (issue 23): A ≈ 8.3 nm², not the local law's 85 nm²,
/// with a Hertz-like static companion (13.4 nm², the axisymmetric solver's), each within
/// its reported error, which is within §8's tolerances (1 % in A, 0.5 % in δ).
#[test]
fn the_default_job_on_the_continuum_has_the_measured_area() {
    let rolling = Rolling::default();
    let s = answer(&rolling);
    let e = s.verification.errors;
    assert!(
        (8.1e-18..8.4e-18).contains(&s.contact_area),
        "{:e}",
        s.contact_area
    );
    assert!(e.contact_area <= 0.01 && e.penetration <= 0.005, "{e:?}");
    let rest = static_contact(rolling.radius, rolling.load, &rolling.layer).unwrap();
    let exact = off(s.static_contact.contact_area, rest.contact_area);
    assert!(
        exact <= e.static_contact_area + rest.relative_error,
        "A₀ off by {exact:e}"
    );
    let exact = off(s.static_contact.penetration, rest.penetration);
    assert!(
        exact <= e.static_penetration + rest.relative_error,
        "δ₀ off by {exact:e}"
    );
    let local = solve(&rolling, &SolveOptions::default()).unwrap();
    assert!(local.contact_area / s.contact_area > 9.0);
    assert!(s.pressure_centre_shift > 0.0 && s.centroid_shift > 0.0);
}

/// The reported error bounds the change to a finer grid (pixels two thirds as large), for
/// δ, A, x_p and the static companion, at rest, slow, at the default speed and fast.
#[test]
fn the_reported_error_bounds_the_change_to_a_finer_grid() {
    let options = SolveOptions::integrals_only(Default::default());
    for velocity in [0.0, 1e-9, 4e-9, 1e-7] {
        let rolling = Rolling {
            velocity,
            ..Rolling::default()
        };
        let s = answer(&rolling);
        let finer = continuum::solve_at(&rolling, &options, 18, Stop::NEVER).unwrap();
        let e = s.verification.errors;
        let checks = [
            ("δ", off(finer.penetration, s.penetration), e.penetration),
            ("A", off(finer.contact_area, s.contact_area), e.contact_area),
            (
                "δ₀",
                off(
                    finer.static_contact.penetration,
                    s.static_contact.penetration,
                ),
                e.static_penetration,
            ),
            (
                "A₀",
                off(
                    finer.static_contact.contact_area,
                    s.static_contact.contact_area,
                ),
                e.static_contact_area,
            ),
        ];
        for (what, change, bound) in checks {
            assert!(
                change <= bound,
                "V = {velocity}: {what} changed {change:e} > {bound:e}"
            );
        }
        let change = (finer.pressure_centre_shift - s.pressure_centre_shift).abs();
        assert!(
            change <= e.pressure_centre_shift.max(1e-15),
            "V = {velocity}: x_p {change:e}"
        );
    }
}

/// V = 0 on a layer fifty contacts thick: Hertz with E* = E/(1 − ν²), a³ = 3PR/(4E*),
/// δ = a²/R, within the answer's error and §8's tolerances.
#[test]
fn at_rest_on_a_thick_layer_the_contact_is_hertz() {
    for (radius, load, nu) in [(25e-9, 1e-9, 0.35), (350e-9, 1.4e-9, 0.3)] {
        let layer = Layer {
            thickness: 5e-6,
            poisson_ratio: nu,
            ..Layer::default()
        };
        let a = (3.0 * load * radius / (4.0 * contact_modulus(&layer))).cbrt();
        assert!(layer.thickness / a >= 50.0);
        let s = answer(&Rolling {
            radius,
            load,
            velocity: 0.0,
            layer,
        });
        let e = s.verification.errors;
        // The half-space's remaining 1/50 of the layer's effect is within 0.2 %.
        let area = off(s.contact_area, PI * a * a);
        assert!(
            area <= e.contact_area + 2e-3 && area < 0.01,
            "R = {radius}: A {area:e}"
        );
        let delta = off(s.penetration, a * a / radius);
        assert!(
            delta <= e.penetration + 2e-3 && delta < 0.005,
            "R = {radius}: δ {delta:e}"
        );
        assert_eq!(s.pressure_centre_shift, 0.0);
    }
}

/// V → ∞ (ξ = V T_σ/a ≈ 10⁴) on a thick layer: the elastic contact with the instantaneous
/// modulus E T_ε/T_σ, whose area is the relaxed one's times (1 + κ)^(−2/3), and symmetric.
#[test]
fn fast_rolling_is_the_instantaneous_contact() {
    let layer = Layer {
        thickness: 5e-6,
        ..Layer::default()
    };
    let at = |velocity: f64| {
        answer(&Rolling {
            velocity,
            layer,
            ..Rolling::default()
        })
    };
    let (rest, fast) = (at(0.0), at(1e-4));
    let want = (1.0 + layer.kappa()).powf(-2.0 / 3.0);
    let ratio = fast.contact_area / rest.contact_area;
    let bound = fast.verification.errors.contact_area + rest.verification.errors.contact_area;
    assert!(
        off(ratio, want) <= bound + 2e-3,
        "A∞/A₀ = {ratio}, want {want}"
    );
    let a = (fast.contact_area / PI).sqrt();
    assert!(
        fast.pressure_centre_shift.abs() < 0.01 * a,
        "{:e}",
        fast.pressure_centre_shift
    );
}

/// Slow rolling shifts the contact by the layer's lag V (T_ε − T_σ) (its memory of a
/// pressure that barely changes along x), so μ_r → V (T_ε − T_σ)/R. The next order falls
/// with V (x_p/lag is 0.82 at 1 nm/s, 0.90 at 0.5 nm/s, converged on the grid): extrapolated
/// linearly from those two speeds, x_p/lag is 1 within the answers' errors and a share of
/// the order after.
#[test]
fn slow_rolling_shifts_the_pressure_by_the_layers_lag() {
    let options = SolveOptions::integrals_only(Default::default());
    let shift = |velocity: f64| {
        let rolling = Rolling {
            velocity,
            ..Rolling::default()
        };
        let s = continuum::solve_at(&rolling, &options, 18, Stop::NEVER).unwrap();
        let layer = rolling.layer;
        let lag = velocity * (layer.retardation_time - layer.relaxation_time);
        let got = s.rolling_resistance_coefficient * rolling.radius;
        (got / lag, s.verification.errors.pressure_centre_shift / lag)
    };
    let ((fast, e_fast), (slow, e_slow)) = (shift(1e-9), shift(5e-10));
    assert!(fast < slow && slow < 1.0, "{fast} then {slow}");
    let limit = 2.0 * slow - fast;
    let bound = 2.0 * e_slow + e_fast + 0.02;
    assert!(
        (limit - 1.0).abs() <= bound,
        "x_p/lag → {limit} (bound {bound})"
    );
}

/// Slower still the lag is a fraction of a pixel, which the grid cannot place (issue 47: at
/// 0.02 nm/s it gave x_p = 0.51 pm for a lag of 8 pm, and claimed ±0.45 pm): the answer
/// weighs in the first-order limit, so μ_r is V (T_ε − T_σ)/R within 1 % there, inside its
/// reported error; and x_p/lag moves smoothly with V, from that limit to the grid's
/// answer, with no step between speeds 10 % apart up to 1.2 nm/s, where the grid's weight
/// has long taken over (the grid's alone went from 0.06 to 0.82 of the lag between 0.02 and
/// 0.1 nm/s).
#[test]
fn very_slow_rolling_has_the_first_order_limit_and_x_p_is_smooth_in_v() {
    let d = Rolling::default();
    let lag = |v: f64| v * (d.layer.retardation_time - d.layer.relaxation_time);
    let at = |velocity: f64| {
        answer(&Rolling {
            velocity,
            ..Rolling::default()
        })
    };
    let slow = at(2e-11);
    let mu_r = lag(2e-11) / d.radius;
    assert!(
        off(slow.rolling_resistance_coefficient, mu_r) < 0.01,
        "μ_r = {:e}, the limit {mu_r:e}",
        slow.rolling_resistance_coefficient
    );
    let error = slow.verification.errors.pressure_centre_shift;
    assert!((slow.pressure_centre_shift - lag(2e-11)).abs() <= error);
    assert!(error < 0.01 * lag(2e-11), "{error:e}");
    let mut last = (1.0, 1e-11);
    let mut v = 1e-11;
    while v < 1.2e-9 {
        v *= 1.1;
        let ratio = at(v).pressure_centre_shift / lag(v);
        assert!(
            (ratio - last.0).abs() < 0.03 && ratio <= 1.0,
            "x_p/lag {} at {:e} m/s, then {ratio} at {v:e}",
            last.0,
            last.1
        );
        last = (ratio, v);
    }
}

/// Between the limits: A falls with V, from the relaxed contact towards the instantaneous
/// one, beyond the answers' errors; the contact and its pressure lie ahead of the centre.
#[test]
fn the_area_falls_with_speed() {
    let answers: Vec<_> = [0.0, 1e-9, 4e-9, 1.6e-8, 1e-7]
        .into_iter()
        .map(|velocity| {
            answer(&Rolling {
                velocity,
                ..Rolling::default()
            })
        })
        .collect();
    for pair in answers.windows(2) {
        let (slow, fast) = (&pair[0], &pair[1]);
        let margin = slow.verification.errors.contact_area + fast.verification.errors.contact_area;
        assert!(
            fast.contact_area < slow.contact_area * (1.0 - margin),
            "{:e}",
            fast.contact_area
        );
        assert!(fast.centroid_shift > 0.0 && fast.pressure_centre_shift > 0.0);
    }
}

/// On a layer much thinner than the contact (r₀/H ≥ 20, ν ≤ 0.4) the continuum is the local
/// law, whose exact answer it gives, at rest and at ξ = 0.2; its error is the two laws'
/// difference at rest, which bounds the axisymmetric continuum's difference from it.
#[test]
fn on_a_thin_layer_the_answer_is_the_local_law_within_its_error() {
    let layer = Layer {
        thickness: 1e-9,
        poisson_ratio: 0.3,
        ..Layer::default()
    };
    let base = Rolling {
        radius: 1e-6,
        load: 4e-7,
        velocity: 0.0,
        layer,
    };
    let options = SolveOptions::integrals_only(Default::default());
    let r0 = solve(&base, &options).unwrap().static_contact.half_width;
    assert!(r0 / layer.thickness >= THIN);
    for xi in [0.0, 0.2] {
        let rolling = Rolling {
            velocity: xi * r0 / layer.relaxation_time,
            ..base
        };
        let local = solve(&rolling, &options).unwrap();
        let s = answer(&rolling);
        assert!(s.verification.grid.is_none());
        assert_eq!(s.contact_area, local.contact_area);
        assert_eq!(s.pressure_centre_shift, local.pressure_centre_shift);
        let rest = static_contact(base.radius, base.load, &layer).unwrap();
        let difference = off(local.static_contact.contact_area, rest.contact_area);
        assert!(difference <= s.verification.errors.contact_area);
        assert!(s.verification.errors.contact_area < 0.02);
    }
}

/// The pressure map spans the contact (its square reaches the farthest edge), never
/// negative, carries the load, and peaks ahead of the centre when rolling.
#[test]
fn the_pressure_map_carries_the_load_and_peaks_ahead() {
    let rolling = Rolling::default();
    let options = SolveOptions {
        pressure_grid: Some(81),
        ..SolveOptions::default()
    };
    let s = continuum::solve(&rolling, &options, Stop::NEVER).unwrap();
    let map = s.pressure.unwrap();
    let step = map.x[1] - map.x[0];
    let edges = s
        .boundary
        .iter()
        .flat_map(|b| [b.exit.abs(), b.entry.abs()]);
    let reach = edges.fold(s.half_width, f64::max);
    // The boundary's points lie between the grid's rows: their farthest is the map's edge
    // to rounding.
    assert!(
        (map.x[80] / reach - 1.0).abs() < 1e-6,
        "{} vs {reach}",
        map.x[80]
    );
    let values = map.values.iter().flatten();
    assert!(values.clone().all(|p| *p >= 0.0));
    let load: f64 = values.sum::<f64>() * step * step;
    assert!(off(load, rolling.load) < 0.05, "the map carries {load:e} N");
    let (row, column) = (0..81)
        .flat_map(|j| (0..81).map(move |i| (j, i)))
        .max_by(|a, b| map.values[a.0][a.1].total_cmp(&map.values[b.0][b.1]))
        .unwrap();
    assert!(map.x[column] > 0.0 && map.y[row].abs() < 3.0 * step);
}
