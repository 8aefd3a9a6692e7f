//! Every trend that docs/model.md §6 states the paper makes, as a property over random valid
//! parameters:
//!
//! A decreases with V; the contact shifts in the rolling direction (x_c > 0, a(0) > −b(0));
//! A(V) < A₀; A grows with R and with P (through R·P); ΔA = A₀ − A(V) grows with R and with P;
//! μ decreases with P (μ₀ ∝ P^−1/2) and with V, grows with R (μ₀ ∝ R^1/2); μ(V) < μ₀;
//! Δμ = μ₀ − μ(V) is larger at smaller P and at larger R.
//!
//! Parameters are drawn two ways (half each): over physically sensible ranges around the
//! defaults of docs/model.md §5 (R 5–500 nm, P 0.1–10 nN, V 0.5–20 nm/s, E_L 0.3–30 GPa,
//! H 20–500 nm, ν 0–0.49, T_σ 0.01–1 s, T_ε/T_σ 1.5–20), which reach ξ = V T_σ/r₀ from
//! ~1e-4 to ~25; and with the same sphere and layer ranges but V chosen for a log-uniform
//! ξ in [1e-5, 1e3], so the whole similarity range (A/A₀ depends only on ξ and κ) is covered
//! evenly, up to the instantaneous limit. A pair compares a parameter x with x·(1 + f),
//! f ∈ [0.05, 2].

use proptest::prelude::*;
use proptest::test_runner::Config as ProptestConfig;
use thirdbody_model::limits::relaxed;
use thirdbody_model::{solve, Layer, Quadrature, Rolling, RollingSolution, SolveOptions};

fn config() -> ProptestConfig {
    ProptestConfig {
        // 256 solves per property take ~0.1 s; PROPTEST_CASES overrides (e.g. for a long hunt).
        cases: std::env::var("PROPTEST_CASES")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(256),
        // Counterexamples are printed (shrunk) on failure; no regression files are written.
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// Log-uniform on [lo, hi].
fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..=hi.ln()).prop_map(f64::exp)
}

prop_compose! {
    fn layers()(
        elastic_modulus in log_uniform(0.3e9, 30e9),
        thickness in log_uniform(20e-9, 500e-9),
        poisson_ratio in 0.0..=0.49,
        relaxation_time in log_uniform(0.01, 1.0),
        ratio in log_uniform(1.5, 20.0),
    ) -> Layer {
        Layer {
            elastic_modulus,
            thickness,
            poisson_ratio,
            retardation_time: relaxation_time * ratio,
            relaxation_time,
            ..Layer::default()
        }
    }
}

prop_compose! {
    /// docs/model.md §5 ranges for every parameter, V included.
    fn physical()(
        radius in log_uniform(5e-9, 500e-9),
        load in log_uniform(0.1e-9, 10e-9),
        velocity in log_uniform(0.5e-9, 20e-9),
        layer in layers(),
    ) -> Rolling {
        Rolling { radius, load, velocity, layer }
    }
}

prop_compose! {
    /// The same sphere and layer ranges, V from a log-uniform ξ = V T_σ / r₀ ∈ [1e-5, 1e3].
    fn dimensionless()(
        radius in log_uniform(5e-9, 500e-9),
        load in log_uniform(0.1e-9, 10e-9),
        xi in log_uniform(1e-5, 1e3),
        layer in layers(),
    ) -> Rolling {
        let r0 = relaxed(radius, load, &layer).half_width;
        Rolling { radius, load, velocity: xi * r0 / layer.relaxation_time, layer }
    }
}

fn contacts() -> impl Strategy<Value = Rolling> {
    prop_oneof![physical(), dimensionless()]
}

/// The relative step f of a pair x, x·(1 + f).
fn step() -> impl Strategy<Value = f64> {
    0.05..=2.0
}

fn run(r: &Rolling) -> RollingSolution {
    solve(r, &SolveOptions::integrals_only(Quadrature::default()))
        .unwrap_or_else(|e| panic!("{r:?}: {e}"))
}

/// ξ = V T_σ / r₀ and κ of a contact, for messages.
fn xi_kappa(r: &Rolling) -> String {
    let r0 = relaxed(r.radius, r.load, &r.layer).half_width;
    format!(
        "ξ = {:.4e}, κ = {:.4}",
        r.velocity * r.layer.relaxation_time / r0,
        r.layer.kappa()
    )
}

fn with_radius(r: &Rolling, factor: f64) -> Rolling {
    Rolling {
        radius: r.radius * factor,
        ..*r
    }
}

fn with_load(r: &Rolling, factor: f64) -> Rolling {
    Rolling {
        load: r.load * factor,
        ..*r
    }
}

fn with_velocity(r: &Rolling, factor: f64) -> Rolling {
    Rolling {
        velocity: r.velocity * factor,
        ..*r
    }
}

/// ΔA = A₀ − A(V), with A₀ the closed form the solution carries.
fn area_loss(s: &RollingSolution) -> f64 {
    s.static_contact.contact_area - s.contact_area
}

/// Δμ = μ₀ − μ(V).
fn friction_loss(s: &RollingSolution) -> f64 {
    s.static_contact.friction_coefficient - s.friction_coefficient
}

proptest! {
    #![proptest_config(config())]

    // ---- A: contact area -----------------------------------------------------------------

    /// A decreases with V.
    #[test]
    fn area_decreases_with_velocity(r in contacts(), f in step()) {
        let (slow, fast) = (run(&r), run(&with_velocity(&r, 1.0 + f)));
        prop_assert!(
            fast.contact_area < slow.contact_area,
            "{}: A(V(1+f)) = {:e} ≥ A(V) = {:e}", xi_kappa(&r), fast.contact_area,
            slow.contact_area
        );
    }

    /// The contact shifts in the rolling direction: x_c > 0 and a(0) > −b(0).
    #[test]
    fn contact_shifts_in_rolling_direction(r in contacts()) {
        let options = SolveOptions { boundary_points: 3, ..SolveOptions::default() };
        let s = solve(&r, &options).unwrap();
        prop_assert!(s.centroid_shift > 0.0, "{}: x_c = {:e}", xi_kappa(&r), s.centroid_shift);
        let centre = s.boundary[1];
        prop_assert_eq!(centre.y, 0.0);
        prop_assert!(
            centre.exit > -centre.entry,
            "{}: a(0) = {:e}, b(0) = {:e}", xi_kappa(&r), centre.exit, centre.entry
        );
    }

    /// A(V) < A₀ (and the solver's V = 0 area is A₀).
    #[test]
    fn rolling_area_is_below_static_area(r in contacts()) {
        let s = run(&r);
        let at_rest = run(&with_velocity(&r, 0.0));
        prop_assert!((at_rest.contact_area / s.static_contact.contact_area - 1.0).abs() < 1e-12);
        prop_assert!(
            s.contact_area < s.static_contact.contact_area,
            "{}: A = {:e}, A₀ = {:e}", xi_kappa(&r), s.contact_area,
            s.static_contact.contact_area
        );
    }

    /// A grows with R.
    #[test]
    fn area_grows_with_radius(r in contacts(), f in step()) {
        let (small, large) = (run(&r), run(&with_radius(&r, 1.0 + f)));
        prop_assert!(
            large.contact_area > small.contact_area,
            "{}: A(R(1+f)) = {:e} ≤ A(R) = {:e}", xi_kappa(&r), large.contact_area,
            small.contact_area
        );
    }

    /// A grows with P.
    #[test]
    fn area_grows_with_load(r in contacts(), f in step()) {
        let (light, heavy) = (run(&r), run(&with_load(&r, 1.0 + f)));
        prop_assert!(
            heavy.contact_area > light.contact_area,
            "{}: A(P(1+f)) = {:e} ≤ A(P) = {:e}", xi_kappa(&r), heavy.contact_area,
            light.contact_area
        );
    }

    /// A depends on R and P only through R·P: (R(1+f), P) and (R, P(1+f)) have one contact.
    #[test]
    fn area_depends_on_radius_and_load_through_their_product(r in contacts(), f in step()) {
        let (a, b) = (run(&with_radius(&r, 1.0 + f)), run(&with_load(&r, 1.0 + f)));
        prop_assert!(
            (a.contact_area / b.contact_area - 1.0).abs() < 1e-12,
            "{}: {:e} vs {:e}", xi_kappa(&r), a.contact_area, b.contact_area
        );
        prop_assert!((a.centroid_shift - b.centroid_shift).abs() <= 1e-12 * a.half_width);
    }

    /// ΔA = A₀ − A(V) grows with R.
    #[test]
    fn area_loss_grows_with_radius(r in contacts(), f in step()) {
        let (small, large) = (run(&r), run(&with_radius(&r, 1.0 + f)));
        prop_assert!(
            area_loss(&large) > area_loss(&small),
            "{}: ΔA(R(1+f)) = {:e} ≤ ΔA(R) = {:e}", xi_kappa(&r), area_loss(&large),
            area_loss(&small)
        );
    }

    /// ΔA = A₀ − A(V) grows with P.
    #[test]
    fn area_loss_grows_with_load(r in contacts(), f in step()) {
        let (light, heavy) = (run(&r), run(&with_load(&r, 1.0 + f)));
        prop_assert!(
            area_loss(&heavy) > area_loss(&light),
            "{}: ΔA(P(1+f)) = {:e} ≤ ΔA(P) = {:e}", xi_kappa(&r), area_loss(&heavy),
            area_loss(&light)
        );
    }

    // ---- μ = τ_a A / P (eq. 12) ----------------------------------------------------------

    /// μ decreases with P, and μ₀ ∝ P^−1/2.
    #[test]
    fn friction_decreases_with_load(r in contacts(), f in step()) {
        let (light, heavy) = (run(&r), run(&with_load(&r, 1.0 + f)));
        prop_assert!(
            heavy.friction_coefficient < light.friction_coefficient,
            "{}: μ(P(1+f)) = {} ≥ μ(P) = {}", xi_kappa(&r), heavy.friction_coefficient,
            light.friction_coefficient
        );
        let ratio = heavy.static_contact.friction_coefficient
            / light.static_contact.friction_coefficient;
        prop_assert!((ratio * (1.0 + f).sqrt() - 1.0).abs() < 1e-12, "μ₀ ratio {}", ratio);
    }

    /// μ decreases with V.
    #[test]
    fn friction_decreases_with_velocity(r in contacts(), f in step()) {
        let (slow, fast) = (run(&r), run(&with_velocity(&r, 1.0 + f)));
        prop_assert!(
            fast.friction_coefficient < slow.friction_coefficient,
            "{}: μ(V(1+f)) = {} ≥ μ(V) = {}", xi_kappa(&r), fast.friction_coefficient,
            slow.friction_coefficient
        );
    }

    /// μ grows with R, and μ₀ ∝ R^1/2.
    #[test]
    fn friction_grows_with_radius(r in contacts(), f in step()) {
        let (small, large) = (run(&r), run(&with_radius(&r, 1.0 + f)));
        prop_assert!(
            large.friction_coefficient > small.friction_coefficient,
            "{}: μ(R(1+f)) = {} ≤ μ(R) = {}", xi_kappa(&r), large.friction_coefficient,
            small.friction_coefficient
        );
        let ratio = large.static_contact.friction_coefficient
            / small.static_contact.friction_coefficient;
        prop_assert!((ratio / (1.0 + f).sqrt() - 1.0).abs() < 1e-12, "μ₀ ratio {}", ratio);
    }

    /// μ(V) < μ₀.
    #[test]
    fn rolling_friction_is_below_static_friction(r in contacts()) {
        let s = run(&r);
        prop_assert!(
            s.friction_coefficient < s.static_contact.friction_coefficient,
            "{}: μ = {}, μ₀ = {}", xi_kappa(&r), s.friction_coefficient,
            s.static_contact.friction_coefficient
        );
    }

    /// Δμ = μ₀ − μ(V) is larger at smaller P.
    #[test]
    fn friction_loss_is_larger_at_smaller_load(r in contacts(), f in step()) {
        let (light, heavy) = (run(&r), run(&with_load(&r, 1.0 + f)));
        prop_assert!(
            friction_loss(&light) > friction_loss(&heavy),
            "{}: Δμ(P) = {:e} ≤ Δμ(P(1+f)) = {:e}", xi_kappa(&r), friction_loss(&light),
            friction_loss(&heavy)
        );
    }

    /// Δμ = μ₀ − μ(V) is larger at larger R.
    #[test]
    fn friction_loss_is_larger_at_larger_radius(r in contacts(), f in step()) {
        let (small, large) = (run(&r), run(&with_radius(&r, 1.0 + f)));
        prop_assert!(
            friction_loss(&large) > friction_loss(&small),
            "{}: Δμ(R(1+f)) = {:e} ≤ Δμ(R) = {:e}", xi_kappa(&r), friction_loss(&large),
            friction_loss(&small)
        );
    }
}
