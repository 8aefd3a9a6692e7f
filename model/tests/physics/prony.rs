//! Layers described by a Prony series (docs/model.md §9) against what must hold exactly:
//! the Kelvin layer is its one-term case, terms of one time add, a term far faster or far
//! slower than the contact acts as a spring or not at all, only V τ_j matters (so scaling the
//! times scales the speed), the slow- and fast-rolling limits with Σκ_j, and the continuum
//! law on the same series.

use thirdbody_model::continuum;
use thirdbody_model::limits::{instantaneous, relaxed, slow_rolling};
use thirdbody_model::spectrum::Terms;
use thirdbody_model::Stop;
use thirdbody_model::{solve, Layer, Rolling, RollingSolution, SolveOptions};

fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a / b - 1.0).abs()
    }
}

/// The layer with relaxed modulus `e`, Kelvin term (κ₁, τ₁) and `arms` (κ_j, τ_j).
fn series(e: f64, first: (f64, f64), arms: &[(f64, f64)]) -> Layer {
    Layer {
        elastic_modulus: e,
        retardation_time: first.1 * (1.0 + first.0),
        relaxation_time: first.1,
        arms: Terms::of(arms.iter().copied()).unwrap(),
        ..Layer::default()
    }
}

/// A four-term series spanning four decades, as a DMA fit gives one.
fn material() -> Layer {
    series(3e9, (2.0, 0.01), &[(1.5, 0.1), (1.0, 1.0), (0.5, 10.0)])
}

/// A series whose second term (of strength `k2`) is `slower` times slower than its first
/// (`k1`, `t1`), and the one-term layer it should act as: that term a spring in parallel.
fn slow_term_and_its_spring(e: f64, (k1, t1): (f64, f64), k2: f64, slower: f64) -> (Layer, Layer) {
    let stiff = series(e, (k1, t1), &[(k2, t1 * slower)]);
    let spring = series(e * (1.0 + k2), (k1 / (1.0 + k2), t1), &[]);
    (stiff, spring)
}

fn rolling(velocity: f64, layer: Layer) -> Rolling {
    Rolling {
        velocity,
        layer,
        ..Rolling::default()
    }
}

fn local(velocity: f64, layer: Layer) -> RollingSolution {
    solve(&rolling(velocity, layer), &SolveOptions::default()).unwrap()
}

/// δ, A, x_c, x_p within `tolerance` (relative) of each other.
fn assert_same(a: &RollingSolution, b: &RollingSolution, tolerance: f64, what: &str) {
    for (name, x, y) in [
        ("δ", a.penetration, b.penetration),
        ("A", a.contact_area, b.contact_area),
        ("x_c", a.centroid_shift, b.centroid_shift),
        ("x_p", a.pressure_centre_shift, b.pressure_centre_shift),
    ] {
        assert!(rel(x, y) < tolerance, "{what}: {name} {x:e} vs {y:e}");
    }
}

/// The series E_∞ = E_L, E₁ = κE_L, τ₁ = T_σ, solved as a series (an arm, no Kelvin
/// term), is the paper's layer.
#[test]
fn the_paper_layer_as_a_one_term_series_is_itself() {
    let d = Layer::default();
    let prony = Layer::from_prony(3e9, 100e-9, 0.35, &[(12e9, 0.1)]).unwrap();
    assert_eq!((prony.kappa(), prony.arms.len()), (0.0, 1));
    for v in [0.0, 1e-9, 4e-9, 1e-7] {
        assert_same(&local(v, prony), &local(v, d), 1e-12, "one term");
    }
}

/// A Kelvin term split into itself and an arm of the same time: the strip sums then run
/// over two terms (no similarity table), and must give the one-term answer.
#[test]
fn two_terms_of_one_time_are_one_term() {
    let whole = series(3e9, (4.0, 0.1), &[]);
    let split = series(3e9, (1.0, 0.1), &[(3.0, 0.1)]);
    for v in [1e-9, 4e-9, 3e-8, 1e-6] {
        assert_same(&local(v, split), &local(v, whole), 1e-11, "split");
    }
}

/// Only V τ_j enters: every time times f is the speed times f (a WLF shift of log₁₀ f).
#[test]
fn scaling_every_time_is_scaling_the_speed() {
    let layer = material();
    for (v, f) in [(4e-9, 10.0), (1e-9, 1e-3), (2e-7, 0.5)] {
        let shifted = local(v, layer.with_times_scaled(f));
        assert_same(&shifted, &local(v * f, layer), 1e-12, "shift");
    }
}

/// A term 10⁹ times slower than the other is a spring in parallel with the relaxed one; a
/// term 10⁹ times faster has relaxed: the series is then the Kelvin layer of the other term,
/// to about the ratio of the contact's size to the term's V τ (or its inverse).
#[test]
fn terms_far_from_the_contact_time_are_springs_or_nothing() {
    let (e, k1, t1, k2) = (3e9, 2.0, 0.1, 1.5);
    let v = 4e-9;
    let (stiff, spring) = slow_term_and_its_spring(e, (k1, t1), k2, 1e9);
    assert_same(&local(v, stiff), &local(v, spring), 1e-6, "slow arm");
    let relaxed_arm = series(e, (k1, t1), &[(k2, t1 * 1e-9)]);
    assert_same(
        &local(v, relaxed_arm),
        &local(v, series(e, (k1, t1), &[])),
        1e-6,
        "fast arm",
    );
}

/// Slow rolling: A₀ − A → 2VΣκ_jτ_j r₀ and x_c → VΣκ_jτ_j/2 at first order; fast rolling:
/// the elastic contact of the instantaneous modulus E_∞(1 + Σκ_j).
#[test]
fn slow_and_fast_rolling_take_the_series_limits() {
    let layer = material();
    let (r, p) = (25e-9, 1e-9);
    let r0 = relaxed(r, p, &layer).half_width;
    // V Σκτ/r₀ = 1e-4: the first-order error is of that order times a few.
    let v = 1e-4 * r0 / layer.lag_time();
    let s = local(v, layer);
    let slow = slow_rolling(r, p, v, &layer);
    let c = relaxed(r, p, &layer);
    let drop = (c.contact_area - s.contact_area) / (c.contact_area - slow.contact_area);
    assert!((drop - 1.0).abs() < 1e-3, "ΔA ratio {drop}");
    assert!(rel(s.centroid_shift, slow.centroid_shift) < 1e-3);
    let fast = local(1e3 * r0 / layer.terms().shortest(), layer);
    let limit = instantaneous(r, p, &layer);
    assert!(rel(fast.penetration, limit.penetration) < 1e-2);
    assert!(rel(fast.contact_area, limit.contact_area) < 1e-2);
    assert!(fast.contact_area < s.contact_area);
}

/// The area falls monotonically with speed, from the relaxed to the instantaneous contact,
/// across the series' four decades.
#[test]
fn the_area_falls_with_speed_across_the_series() {
    let layer = material();
    let areas: Vec<f64> = (-12..=-4)
        .map(|e| local(10f64.powi(e), layer).contact_area)
        .collect();
    assert!(areas.windows(2).all(|w| w[1] < w[0]), "{areas:?}");
}

/// On the continuum the series changes only E(ω): a term far slower than the contact is
/// again a spring in parallel, within the answers' own errors.
#[test]
fn on_the_continuum_a_far_slow_term_is_a_spring() {
    let (e, k1, t1, k2) = (3e9, 4.0, 0.1, 1.0);
    let v = 4e-9;
    let (stiff, spring) = slow_term_and_its_spring(e, (k1, t1), k2, 1e6);
    let options = SolveOptions::default();
    let a = continuum::solve(&rolling(v, stiff), &options, Stop::NEVER).unwrap();
    let b = continuum::solve(&rolling(v, spring), &options, Stop::NEVER).unwrap();
    let (ea, eb) = (&a.verification.errors, &b.verification.errors);
    let area = ea.contact_area + eb.contact_area + 1e-5;
    let delta = ea.penetration + eb.penetration + 1e-5;
    assert!(rel(a.contact_area, b.contact_area) < area, "{a:?} vs {b:?}");
    assert!(rel(a.penetration, b.penetration) < delta);
    // And the series rolls: its area lies between the relaxed and instantaneous ones.
    let rest = continuum::solve(&rolling(0.0, stiff), &options, Stop::NEVER).unwrap();
    assert!(a.contact_area < rest.contact_area);
}
