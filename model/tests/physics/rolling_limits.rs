//! The rolling solver (docs/model.md §3) against its closed-form limits, the similarity law, the
//! accuracy of its quadrature and its input checks. Every comparison is relative: lengths
//! are ~1e-9 m (docs/model.md: "never absolute tolerances").
//!
//! Notation (docs/model.md §1, §3): R radius, P load, V speed, δ penetration, A contact area,
//! r = √(2Rδ) half-width, x_c area centroid, x_p centre of pressure, μ_r = x_p/R, μ = τ_a A/P,
//! k = E_L/H, κ = (T_ε − T_σ)/T_σ, ξ = V T_σ / r₀, r₀ = √(2Rδ₀) the static half-width.

use std::panic::{catch_unwind, AssertUnwindSafe};

use thirdbody_model::limits::{instantaneous, relaxed, slow_rolling};
use thirdbody_model::{
    solve, Layer, ModelError, Parameter, Quadrature, Rolling, RollingSolution, SolveOption,
    SolveOptions,
};

/// |x/y − 1|.
fn rel(x: f64, y: f64) -> f64 {
    (x / y - 1.0).abs()
}

fn layer(
    elastic_modulus: f64,
    thickness: f64,
    poisson_ratio: f64,
    retardation_time: f64,
    relaxation_time: f64,
) -> Layer {
    Layer {
        elastic_modulus,
        thickness,
        poisson_ratio,
        retardation_time,
        relaxation_time,
        ..Layer::default()
    }
}

/// (R, P, layer) combinations spanning the ranges of docs/model.md §5 and beyond (a macroscopic
/// rubber-like contact), with κ from 0.5 to 199.
fn cases() -> Vec<(f64, f64, Layer)> {
    vec![
        (25e-9, 1e-9, Layer::default()),
        (5e-9, 0.1e-9, layer(0.3e9, 20e-9, 0.0, 0.15, 0.1)),
        (500e-9, 10e-9, layer(30e9, 500e-9, 0.49, 2.0, 0.01)),
        (350e-9, 1.4e-9, layer(3e9, 100e-9, 0.35, 0.5, 0.1)),
        (1e-3, 1.0, layer(5e6, 2e-3, 0.45, 1e-1, 1e-3)),
    ]
}

fn rolling(radius: f64, load: f64, velocity: f64, layer: Layer) -> Rolling {
    Rolling {
        radius,
        load,
        velocity,
        layer,
    }
}

/// The speed V with V T_σ / r₀ = ξ for this sphere and layer.
fn speed_for(xi: f64, radius: f64, load: f64, layer: &Layer) -> f64 {
    xi * relaxed(radius, load, layer).half_width / layer.relaxation_time
}

fn options(quadrature: Quadrature) -> SolveOptions {
    SolveOptions::integrals_only(quadrature)
}

fn run(r: &Rolling, o: &SolveOptions) -> RollingSolution {
    solve(r, o).unwrap_or_else(|e| panic!("{r:?}: {e}"))
}

// ---------------------------------------------------------------------------------------
// V = 0: δ₀ = √(P/(πkR)), r₀ = √(2Rδ₀), A₀ = π r₀², μ₀ = τ_a A₀/P, symmetric contact.

#[test]
fn v_zero_numerical_solution_equals_relaxed_closed_form() {
    let o = SolveOptions {
        boundary_points: 41,
        ..SolveOptions::default()
    };
    let mut worst: f64 = 0.0;
    for (radius, load, layer) in cases() {
        let s = run(&rolling(radius, load, 0.0, layer), &o);
        let c = relaxed(radius, load, &layer);
        for (name, got, want) in [
            ("δ", s.penetration, c.penetration),
            ("A", s.contact_area, c.contact_area),
            ("r", s.half_width, c.half_width),
            ("μ", s.friction_coefficient, c.friction_coefficient),
        ] {
            worst = worst.max(rel(got, want));
            assert!(
                rel(got, want) < 1e-9,
                "R = {radius}, P = {load}: {name} = {got} vs closed form {want}"
            );
        }
        // The closed form itself: δ₀ = √(P/(πkR)), A₀ = 2√(πRP/k),
        // μ₀ = √(πRHE_L/P)/(1000(1+ν)).
        let k = layer.elastic_modulus / layer.thickness;
        let pi = std::f64::consts::PI;
        assert!(rel(c.penetration, (load / (pi * k * radius)).sqrt()) < 1e-14);
        assert!(rel(c.contact_area, 2.0 * (pi * radius * load / k).sqrt()) < 1e-14);
        let mu0 = (pi * radius * layer.thickness * layer.elastic_modulus / load).sqrt()
            / (1000.0 * (1.0 + layer.poisson_ratio));
        assert!(rel(c.friction_coefficient, mu0) < 1e-14);
        assert_eq!(s.static_contact, c);
        // Symmetric: no shift of the centroid nor of the centre of pressure.
        assert!(
            s.centroid_shift.abs() < 1e-12 * s.half_width,
            "x_c = {}",
            s.centroid_shift
        );
        assert!(
            s.pressure_centre_shift.abs() < 1e-12 * s.half_width,
            "x_p = {}",
            s.pressure_centre_shift
        );
        assert!(s.rolling_resistance_coefficient.abs() < 1e-12 * s.half_width / radius);
        // Boundary: a(y) = −b(y), b(y) = √(r² − y²).
        assert_eq!(s.boundary.len(), 41);
        for p in &s.boundary {
            assert_eq!(p.exit, -p.entry, "y = {}", p.y);
            // √(r² − y²) loses half the digits near y = ±r, hence 1e-7 rather than 1e-15.
            let chord = (s.half_width * s.half_width - p.y * p.y).max(0.0).sqrt();
            assert!((p.entry - chord).abs() < 1e-7 * s.half_width, "y = {}", p.y);
        }
        assert_eq!(s.boundary[20].y, 0.0);
        assert!(rel(s.boundary[20].entry, s.half_width) < 1e-12);
    }
    eprintln!("V = 0: worst relative deviation from the closed form {worst:.2e}");
}

// ---------------------------------------------------------------------------------------
// V → ∞: δ_∞ = δ₀√(T_σ/T_ε), A_∞ = A₀√(T_σ/T_ε), symmetric. The fast strips have exit roots
// s* = −1 + (2/3)κβ/(1+κ) with β = b/(V T_σ) ≤ 1/ξ, so the approach is O(1/ξ).

/// Largest relative deviation of δ and A from the instantaneous limit at ξ.
fn instantaneous_error(xi: f64, radius: f64, load: f64, layer: &Layer) -> f64 {
    let v = speed_for(xi, radius, load, layer);
    let s = run(
        &rolling(radius, load, v, *layer),
        &options(Quadrature::default()),
    );
    let c = instantaneous(radius, load, layer);
    assert!(
        rel(
            c.penetration,
            relaxed(radius, load, layer).penetration
                * (layer.relaxation_time / layer.retardation_time).sqrt()
        ) < 1e-14
    );
    // Nearly symmetric: |x_c| is O(r₀/ξ) as well.
    assert!(
        s.centroid_shift.abs() < 10.0 * s.half_width / xi,
        "ξ = {xi}: x_c = {}",
        s.centroid_shift
    );
    rel(s.penetration, c.penetration).max(rel(s.contact_area, c.contact_area))
}

#[test]
fn large_v_approaches_instantaneous_elastic_limit_like_one_over_xi() {
    for (radius, load, layer) in cases() {
        let errors: Vec<f64> = [1e5, 1e6, 1e7]
            .iter()
            .map(|&xi| instantaneous_error(xi, radius, load, &layer))
            .collect();
        eprintln!(
            "κ = {:6.2}: |δ/δ_∞ − 1|, |A/A_∞ − 1| ≤ {:.3e} (ξ=1e5), {:.3e} (1e6), {:.3e} (1e7)",
            layer.kappa(),
            errors[0],
            errors[1],
            errors[2]
        );
        // O(1/ξ) with a measured coefficient of 0.12–0.25 over κ = 0.5…199: the tolerance
        // 1e-4 at ξ = 1e5 leaves a margin of 40, and the coefficient itself must stay < 1.
        assert!(errors[0] < 1e-4, "ξ = 1e5: {}", errors[0]);
        assert!(
            errors[0] * 1e5 < 1.0,
            "ξ = 1e5: coefficient {}",
            errors[0] * 1e5
        );
        for pair in errors.windows(2) {
            let ratio = pair[0] / pair[1];
            assert!(
                (7.0..14.0).contains(&ratio),
                "κ = {}: error ratio {ratio} for a 10× larger ξ (expected ≈ 10)",
                layer.kappa()
            );
        }
    }
}

// ---------------------------------------------------------------------------------------
// Small V (V T_ε ≪ r₀): A = A₀ − 2V(T_ε − T_σ) r₀, x_c = V(T_ε − T_σ)/2,
// μ_r = V(T_ε − T_σ)/R, to first order in ξ.

/// Signed relative deviations of ΔA = A₀ − A, x_c and μ_r from the slow-rolling
/// asymptotics at ξ.
fn slow_rolling_errors(xi: f64, radius: f64, load: f64, layer: &Layer) -> [f64; 3] {
    let v = speed_for(xi, radius, load, layer);
    let s = run(
        &rolling(radius, load, v, *layer),
        &options(Quadrature::default()),
    );
    let asymptotic = slow_rolling(radius, load, v, layer);
    let c = relaxed(radius, load, layer);
    // The oracle is what docs/model.md §3 writes: A₀ − 2V(T_ε − T_σ)r₀, V(T_ε − T_σ)/2, V(T_ε − T_σ)/R.
    let lag = v * (layer.retardation_time - layer.relaxation_time);
    assert!(
        rel(
            asymptotic.contact_area,
            c.contact_area - 2.0 * lag * c.half_width
        ) < 1e-15
    );
    assert!(rel(asymptotic.centroid_shift, lag / 2.0) < 1e-15);
    assert!(rel(asymptotic.rolling_resistance_coefficient, lag / radius) < 1e-15);
    [
        (c.contact_area - s.contact_area) / (c.contact_area - asymptotic.contact_area) - 1.0,
        s.centroid_shift / asymptotic.centroid_shift - 1.0,
        s.rolling_resistance_coefficient / asymptotic.rolling_resistance_coefficient - 1.0,
    ]
}

#[test]
fn small_v_follows_slow_rolling_asymptotics_with_error_of_order_xi() {
    let xis = [1e-3, 3e-4, 1e-4];
    let names = [
        "(A₀ − A)/(2V(T_ε−T_σ)r₀)",
        "x_c/(V(T_ε−T_σ)/2)",
        "μ_r/(V(T_ε−T_σ)/R)",
    ];
    for (radius, load, layer) in cases() {
        let kappa = layer.kappa();
        let errors: Vec<[f64; 3]> = xis
            .iter()
            .map(|&xi| slow_rolling_errors(xi, radius, load, &layer))
            .collect();
        for (xi, e) in xis.iter().zip(&errors) {
            eprintln!(
                "κ = {kappa:6.2}, ξ = {xi:.0e}: (ratio − 1)/((2+κ)ξ): ΔA {:+.4}, x_c {:+.4}, \
                 μ_r {:+.4}",
                e[0] / ((2.0 + kappa) * xi),
                e[1] / ((2.0 + kappa) * xi),
                e[2] / ((2.0 + kappa) * xi),
            );
        }
        for q in 0..3 {
            for (xi, e) in xis.iter().zip(&errors) {
                let err = e[q].abs();
                // O(ξ): the natural small parameter is (V T_ε + V T_σ)/r₀ = (2 + κ)ξ. Measured:
                // x_c and μ_r ratios − 1 ≈ −(2/π)(2+κ)ξ and −(8/3π)(2+κ)ξ, the ΔA ratio − 1 is
                // O(ξ²). For κ ≤ 4 this is also below 20ξ; for κ = 199 it reaches 170ξ.
                assert!(
                    err < (2.0 + kappa) * xi,
                    "κ = {kappa}, ξ = {xi}: {} − 1 = {}",
                    names[q],
                    e[q]
                );
                if kappa <= 4.0 {
                    assert!(err < 20.0 * xi, "κ = {kappa}, ξ = {xi}: {}", names[q]);
                }
            }
            // The error falls with ξ: by ≈ 10× per decade for x_c and μ_r (first order);
            // ΔA is even right to second order (≈ 100× per decade).
            let (e0, e1, e2) = (errors[0][q].abs(), errors[1][q].abs(), errors[2][q].abs());
            assert!(
                e0 > e1 && e1 > e2,
                "κ = {kappa}: {} not decreasing",
                names[q]
            );
            let per_decade = e0 / e2;
            let least = if q == 0 { 50.0 } else { 8.0 };
            assert!(
                per_decade > least,
                "κ = {kappa}: {} error falls only {per_decade}× from ξ = 1e-3 to 1e-4",
                names[q]
            );
        }
    }
}

// ---------------------------------------------------------------------------------------
// T_ε = T_σ (κ = 0): the layer is elastic, the contact is the V = 0 one at every V.

#[test]
fn equal_retardation_and_relaxation_times_give_static_contact_at_any_v() {
    let o = SolveOptions {
        boundary_points: 21,
        ..SolveOptions::default()
    };
    for (radius, load, mut layer) in cases() {
        layer.retardation_time = layer.relaxation_time;
        assert_eq!(layer.kappa(), 0.0);
        let c = relaxed(radius, load, &layer);
        for v in [0.0, 1e-12, 4e-9, 1e-3, 1.0, 1e3] {
            let s = run(&rolling(radius, load, v, layer), &o);
            for (name, got, want) in [
                ("δ", s.penetration, c.penetration),
                ("A", s.contact_area, c.contact_area),
                ("r", s.half_width, c.half_width),
                ("μ", s.friction_coefficient, c.friction_coefficient),
            ] {
                assert!(rel(got, want) < 1e-12, "V = {v}: {name} = {got} vs {want}");
            }
            assert!(
                s.centroid_shift.abs() <= 1e-12 * s.half_width,
                "V = {v}: x_c"
            );
            assert!(
                s.pressure_centre_shift.abs() <= 1e-12 * s.half_width,
                "V = {v}: x_p"
            );
            for p in &s.boundary {
                assert_eq!(p.exit, -p.entry, "V = {v}, y = {}", p.y);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// Similarity (docs/model.md §3): the contact shape depends on R and P only through R·P; A/A₀,
// δ/δ₀, x_c/r₀ depend only on ξ = V T_σ/r₀ and κ.

#[test]
fn contact_shape_depends_on_radius_and_load_only_through_their_product() {
    let o = SolveOptions {
        boundary_points: 17,
        ..SolveOptions::default()
    };
    for (radius, load, layer) in cases() {
        for v in [0.0, 1e-9, 4e-9, 3e-8] {
            let base = run(&rolling(radius, load, v, layer), &o);
            for lambda in [0.13, 3.7, 42.0] {
                let s = run(&rolling(lambda * radius, load / lambda, v, layer), &o);
                for (name, got, want) in [
                    ("A", s.contact_area, base.contact_area),
                    ("r", s.half_width, base.half_width),
                ] {
                    assert!(rel(got, want) < 1e-12, "λ = {lambda}, V = {v}: {name}");
                }
                for (name, got, want) in [
                    ("x_c", s.centroid_shift, base.centroid_shift),
                    ("x_p", s.pressure_centre_shift, base.pressure_centre_shift),
                ] {
                    assert!(
                        (got - want).abs() <= 1e-12 * want.abs() + 1e-15 * base.half_width,
                        "λ = {lambda}, V = {v}: {name} = {got} vs {want}"
                    );
                }
                assert_eq!(s.boundary.len(), base.boundary.len());
                for (p, q) in s.boundary.iter().zip(&base.boundary) {
                    let tol = 1e-12 * base.half_width;
                    assert!((p.y - q.y).abs() <= tol, "λ = {lambda}, V = {v}: y");
                    assert!(
                        (p.exit - q.exit).abs() <= tol,
                        "λ = {lambda}, V = {v}: a(y)"
                    );
                    assert!(
                        (p.entry - q.entry).abs() <= tol,
                        "λ = {lambda}, V = {v}: b(y)"
                    );
                }
                // δ = r²/(2R) is not a function of R·P: it scales as 1/λ.
                assert!(rel(s.penetration * lambda, base.penetration) < 1e-12);
                assert!(rel(s.penetration, base.penetration) > 0.5);
            }
        }
    }
}

/// A/A₀, δ/δ₀, x_c/r₀, x_p/r₀ of a solution.
fn similarity_ratios(r: &Rolling) -> [f64; 4] {
    similarity_ratios_with(r, Quadrature::default())
}

/// A/A₀, δ/δ₀, x_c/r₀, x_p/r₀ of a solution with `quadrature`.
fn similarity_ratios_with(r: &Rolling, quadrature: Quadrature) -> [f64; 4] {
    let s = run(r, &options(quadrature));
    let c = relaxed(r.radius, r.load, &r.layer);
    [
        s.contact_area / c.contact_area,
        s.penetration / c.penetration,
        s.centroid_shift / c.half_width,
        s.pressure_centre_shift / c.half_width,
    ]
}

#[test]
fn ratios_to_static_contact_depend_only_on_xi_and_kappa() {
    let (radius, load) = (25e-9, 1e-9);
    for kappa in [0.5, 4.0, 100.0] {
        let base_layer = Layer {
            retardation_time: 0.1 * (1.0 + kappa),
            ..Layer::default()
        };
        for xi in [1e-3, 0.2, 3.0, 50.0] {
            let base = rolling(
                radius,
                load,
                speed_for(xi, radius, load, &base_layer),
                base_layer,
            );
            let want = similarity_ratios(&base);
            assert!(want[0] < 1.0 && want[2] > 0.0, "ξ = {xi}, κ = {kappa}");
            // (a) V·c with T_σ/c, T_ε/c: same ξ and κ.
            let c = 7.3;
            let times = Rolling {
                velocity: base.velocity * c,
                layer: Layer {
                    relaxation_time: base_layer.relaxation_time / c,
                    retardation_time: base_layer.retardation_time / c,
                    ..base_layer
                },
                ..base
            };
            // (b) a different sphere, load and layer, with V chosen for the same ξ, and the
            // same κ from other times.
            let other_layer = layer(0.7e9, 310e-9, 0.1, 0.02 * (1.0 + kappa), 0.02);
            let (r2, p2) = (180e-9, 6.1e-9);
            let other = rolling(r2, p2, speed_for(xi, r2, p2, &other_layer), other_layer);
            for variant in [times, other] {
                let got = similarity_ratios(&variant);
                for q in 0..4 {
                    assert!(
                        (got[q] - want[q]).abs() <= 1e-12 * want[q].abs(),
                        "ξ = {xi}, κ = {kappa}, ratio {q}: {} vs {}",
                        got[q],
                        want[q]
                    );
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// Quadrature in y (the only discretisation error, docs/model.md §3).

/// δ, A, x_c, x_p of a solution.
fn integrals(s: &RollingSolution) -> [f64; 4] {
    [
        s.penetration,
        s.contact_area,
        s.centroid_shift,
        s.pressure_centre_shift,
    ]
}

#[test]
fn default_gauss_rule_agrees_with_1024_nodes_to_1e_9_over_the_whole_xi_kappa_range() {
    let (radius, load) = (25e-9, 1e-9);
    let fine = options(Quadrature::Gauss { nodes: 1024 });
    let default = options(Quadrature::default());
    let names = ["δ", "A", "x_c", "x_p"];
    let mut worst = [(0.0_f64, 0.0, 0.0); 4];
    // Largest actual error of A / quadrature_error_estimate, where the error exceeds 1e-12.
    let mut worst_estimate_ratio: f64 = 0.0;
    let points = 60;
    for kappa in [0.01, 1.0, 4.0, 100.0, 1e4] {
        let layer = Layer {
            retardation_time: 0.1 * (1.0 + kappa),
            ..Layer::default()
        };
        for i in 0..points {
            // ξ from 1e-6 to 20, log-spaced.
            let xi = 1e-6 * (2e7_f64).powf(i as f64 / (points - 1) as f64);
            let r = rolling(radius, load, speed_for(xi, radius, load, &layer), layer);
            let reference = run(&r, &fine);
            let s = run(&r, &default);
            let (want, got) = (integrals(&reference), integrals(&s));
            for q in 0..4 {
                let err = rel(got[q], want[q]);
                if err > worst[q].0 {
                    worst[q] = (err, xi, kappa);
                }
                assert!(
                    err < 1e-9,
                    "ξ = {xi:.3e}, κ = {kappa}: {} = {} vs {} with 1024 nodes",
                    names[q],
                    got[q],
                    want[q]
                );
            }
            // The estimate |A(32)/A(64) − 1| bounds the actual error of A(64) up to 1e-11.
            let actual = rel(s.contact_area, reference.contact_area);
            let estimate = s.verification.quadrature_error_estimate;
            // Not a strict bound: where the 64-node error is ~1e-12 the 32-node rule can land
            // closer still (measured: up to 3.6× below the actual error above 1e-12, 80× at
            // 1e-13). It never falls short by more than 5.5e-12 (dense scan of 3200 points).
            assert!(
                actual <= estimate + 1e-11,
                "ξ = {xi:.3e}, κ = {kappa}: estimate {estimate:e} < actual error {actual:e}"
            );
            if actual > 1e-12 {
                worst_estimate_ratio = worst_estimate_ratio.max(actual / estimate);
            }
            assert_eq!(s.verification.quadrature_nodes, 64);
            assert_eq!(reference.verification.quadrature_nodes, 1024);
        }
    }
    for q in 0..4 {
        eprintln!(
            "default Gauss vs 1024 nodes: worst |{}/{}₁₀₂₄ − 1| = {:.2e} at ξ = {:.2e}, κ = {}",
            names[q], names[q], worst[q].0, worst[q].1, worst[q].2
        );
    }
    eprintln!(
        "actual A error / quadrature_error_estimate ≤ {worst_estimate_ratio:.2} where the error \
         exceeds 1e-12"
    );
}

/// Contact area with `strips` midpoint strips (the paper's method).
fn midpoint_area(r: &Rolling, strips: usize) -> f64 {
    run(r, &options(Quadrature::Midpoint { strips })).contact_area
}

#[test]
fn midpoint_strips_converge_like_n_to_the_minus_1_5() {
    for velocity in [0.0, 2e-9, 4e-9, 10e-9] {
        let r = Rolling {
            velocity,
            ..Rolling::default()
        };
        let exact = run(&r, &options(Quadrature::Gauss { nodes: 1024 })).contact_area;
        let errors: Vec<f64> = [10, 40, 160, 640]
            .iter()
            .map(|&n| rel(midpoint_area(&r, n), exact))
            .collect();
        eprintln!(
            "V = {:4.1} nm/s: midpoint |A_N/A − 1| = {:.3e} (N=10), {:.3e} (40), {:.3e} (160), \
             {:.3e} (640); ratios {:.3}, {:.3}, {:.3}",
            velocity * 1e9,
            errors[0],
            errors[1],
            errors[2],
            errors[3],
            errors[0] / errors[1],
            errors[1] / errors[2],
            errors[2] / errors[3],
        );
        // docs/model.md: N = 40 errs by 0.04 % in A.
        assert!(
            errors[1] < 5e-4,
            "V = {velocity}: N = 40 errs by {}",
            errors[1]
        );
        // N^−1.5: err(N)/err(4N) ≈ 4^1.5 = 8.
        for pair in errors[..3].windows(2) {
            let ratio = pair[0] / pair[1];
            assert!(
                (6.0..10.0).contains(&ratio),
                "V = {velocity}: err(N)/err(4N) = {ratio}"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------
// Verification record.

#[test]
fn verification_reports_a_converged_load_equation() {
    for (radius, load, layer) in cases() {
        for xi in [0.0, 1e-6, 1e-3, 0.2, 1.0, 20.0, 1e4] {
            for quadrature in [
                Quadrature::default(),
                Quadrature::Gauss { nodes: 2 },
                Quadrature::Gauss { nodes: 300 },
                Quadrature::Midpoint { strips: 1 },
                Quadrature::Midpoint { strips: 40 },
            ] {
                let v = speed_for(xi, radius, load, &layer);
                let s = run(&rolling(radius, load, v, layer), &options(quadrature));
                let check = s.verification;
                assert!(check.converged, "ξ = {xi}, {quadrature:?}");
                assert!(check.iterations >= 1, "ξ = {xi}, {quadrature:?}");
                assert!(
                    check.load_residual < 1e-12,
                    "ξ = {xi}, {quadrature:?}: load residual {}",
                    check.load_residual
                );
                assert_eq!(check.quadrature_nodes, quadrature.size());
                assert!(check.quadrature_error_estimate.is_finite());
                if xi > 0.0 {
                    assert!(check.exit_root_iterations >= 1, "ξ = {xi}, {quadrature:?}");
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// Bad input: an error, never a panic.

fn solve_without_panic(r: &Rolling, o: &SolveOptions) -> Result<RollingSolution, ModelError> {
    catch_unwind(AssertUnwindSafe(|| solve(r, o)))
        .unwrap_or_else(|_| panic!("solve panicked on {r:?}, {o:?}"))
}

#[test]
fn invalid_parameters_are_errors_not_panics() {
    let good = Rolling::default();
    let default = SolveOptions::default();
    let with_layer = |layer: Layer| Rolling { layer, ..good };
    let invalid: Vec<(Rolling, Parameter)> = vec![
        (
            Rolling {
                radius: -25e-9,
                ..good
            },
            Parameter::Radius,
        ),
        (
            Rolling {
                radius: 0.0,
                ..good
            },
            Parameter::Radius,
        ),
        (
            Rolling {
                radius: f64::INFINITY,
                ..good
            },
            Parameter::Radius,
        ),
        (
            Rolling {
                load: f64::NAN,
                ..good
            },
            Parameter::Load,
        ),
        (
            Rolling {
                load: -1e-9,
                ..good
            },
            Parameter::Load,
        ),
        (
            Rolling {
                velocity: -1e-9,
                ..good
            },
            Parameter::Velocity,
        ),
        (
            Rolling {
                velocity: f64::NAN,
                ..good
            },
            Parameter::Velocity,
        ),
        (
            Rolling {
                velocity: f64::INFINITY,
                ..good
            },
            Parameter::Velocity,
        ),
        (
            with_layer(Layer {
                poisson_ratio: 0.5,
                ..good.layer
            }),
            Parameter::PoissonRatio,
        ),
        (
            with_layer(Layer {
                poisson_ratio: -0.1,
                ..good.layer
            }),
            Parameter::PoissonRatio,
        ),
        (
            with_layer(Layer {
                retardation_time: 0.05,
                ..good.layer
            }),
            Parameter::RetardationTime,
        ),
        (
            with_layer(Layer {
                relaxation_time: 0.0,
                ..good.layer
            }),
            Parameter::RelaxationTime,
        ),
        (
            with_layer(Layer {
                elastic_modulus: f64::NAN,
                ..good.layer
            }),
            Parameter::ElasticModulus,
        ),
        (
            with_layer(Layer {
                thickness: -1e-9,
                ..good.layer
            }),
            Parameter::Thickness,
        ),
    ];
    for (r, parameter) in invalid {
        match solve_without_panic(&r, &default) {
            Err(ModelError::InvalidParameter(e)) => assert_eq!(e.parameter, parameter, "{r:?}"),
            other => panic!("{r:?}: expected an invalid {parameter}, got {other:?}"),
        }
    }
    // ν = 0.5 is the first value refused; just below it is fine.
    let almost_incompressible = with_layer(Layer {
        poisson_ratio: 0.4999,
        ..good.layer
    });
    assert!(solve_without_panic(&almost_incompressible, &default).is_ok());
}

#[test]
fn invalid_options_are_errors_not_panics() {
    let good = Rolling::default();
    for quadrature in crate::rules(&[0, 1, 1025], &[0, 100_001]) {
        match solve_without_panic(&good, &options(quadrature)) {
            Err(ModelError::InvalidOption(e)) => {
                assert_eq!(e.option, SolveOption::Strips, "{quadrature:?}");
                assert_eq!(e.value, quadrature.size(), "{quadrature:?}");
            }
            other => panic!("{quadrature:?}: expected an invalid option, got {other:?}"),
        }
    }
    for (o, option) in [
        (
            SolveOptions {
                boundary_points: usize::MAX,
                ..SolveOptions::default()
            },
            SolveOption::BoundaryPoints,
        ),
        (
            SolveOptions {
                pressure_grid: Some(1),
                ..SolveOptions::default()
            },
            SolveOption::PressureGrid,
        ),
        (
            SolveOptions {
                pressure_grid: Some(100_000),
                ..SolveOptions::default()
            },
            SolveOption::PressureGrid,
        ),
    ] {
        match solve_without_panic(&good, &o) {
            Err(ModelError::InvalidOption(e)) => assert_eq!(e.option, option, "{o:?}"),
            other => panic!("{o:?}: expected an invalid {option}, got {other:?}"),
        }
    }
}

#[test]
fn extreme_scales_give_finite_results_or_errors_not_panics() {
    let good = Rolling::default();
    let extremes = [
        Rolling {
            radius: 1e300,
            load: 1e300,
            ..good
        },
        Rolling {
            radius: 1e-300,
            load: 1e-300,
            ..good
        },
        Rolling {
            radius: 1e-300,
            load: 1e300,
            ..good
        },
        Rolling {
            velocity: 1e300,
            ..good
        },
        Rolling {
            velocity: 1e-300,
            ..good
        },
        Rolling {
            layer: Layer {
                retardation_time: 1e300,
                relaxation_time: 1e-300,
                ..good.layer
            },
            ..good
        },
        Rolling {
            layer: Layer {
                elastic_modulus: 1e-300,
                thickness: 1e300,
                ..good.layer
            },
            ..good
        },
    ];
    for r in extremes {
        match solve_without_panic(&r, &SolveOptions::default()) {
            Ok(s) => {
                for x in integrals(&s) {
                    assert!(x.is_finite(), "{r:?}");
                }
                assert!(s.contact_area > 0.0 && s.penetration > 0.0, "{r:?}");
                assert!(s.verification.load_residual < 1e-12, "{r:?}");
            }
            Err(e) => assert!(
                matches!(
                    e,
                    ModelError::NotRepresentable { .. } | ModelError::NoConvergence { .. }
                ),
                "{r:?}: {e}"
            ),
        }
    }
}

// ---------------------------------------------------------------------------------------
// An independent solution of the same contact: the strip closed forms of `strip::Strip`
// (checked there against docs/model.md's literal G(s)), but integrated across y by composite
// 16-point Gauss–Legendre on panels graded geometrically towards the contact edge
// y → r (where the strips turn fast, b ≲ V T_σ), and with its own load solve.

/// (P̂, Â, ∬x dA, ∬x p dA) in units of r₀ for a contact of half-width r̂ (units of r₀).
fn graded_integrals(half_width: f64, xi: f64, kappa: f64) -> [f64; 4] {
    let viscosity = thirdbody_model::spectrum::Terms::one(kappa, xi);
    let (x16, w16) = thirdbody_model::quadrature::gauss_legendre_16();
    // φ = π/2 − θ, y = r cos φ, b = r sin φ, dy = r sin φ dφ. Panels [φ/2, φ] down to
    // φ ~ 1e-4 min(ξ/r, 1), then one panel [0, φ_min].
    let mut edges = vec![std::f64::consts::FRAC_PI_2];
    let smallest = 1e-4 * (xi / half_width).min(1.0);
    while edges[edges.len() - 1] > smallest {
        let last = edges[edges.len() - 1];
        edges.push(last / 2.0);
    }
    edges.push(0.0);
    let mut sum = [0.0; 4];
    for pair in edges.windows(2) {
        let (hi, lo) = (pair[0], pair[1]);
        for (t, w) in x16.iter().zip(w16) {
            let phi = 0.5 * (lo + hi) + 0.5 * (hi - lo) * t;
            let weight = 0.5 * (hi - lo) * w * phi.sin();
            let strip = thirdbody_model::strip::Strip {
                entry: half_width * phi.sin(),
                terms: &viscosity,
            };
            let rho = strip.exit_root(None).unwrap().rho;
            let b = strip.entry;
            let q = strip.load(rho);
            sum[0] += weight * q;
            sum[1] += weight * b * (2.0 - rho);
            sum[2] += weight * b * b * rho * (2.0 - rho);
            sum[3] += weight * strip.moment(rho);
        }
    }
    // ∫₀^r f dy = r ∫ f sin φ dφ; P = 2∫q dy, A = 2∫(b − a) dy, ∬x dA = ∫(b² − a²) dy,
    // ∬x p dA = 2∫m dy.
    let r = half_width;
    [
        2.0 * r * sum[0],
        2.0 * r * sum[1],
        r * sum[2],
        2.0 * r * sum[3],
    ]
}

/// A/A₀, δ/δ₀, x_c/r₀, x_p/r₀ from the graded quadrature, with P̂(r̂) = π/4 solved by secant
/// steps on ln P̂(ln r̂).
fn independent(xi: f64, kappa: f64) -> [f64; 4] {
    let target = std::f64::consts::FRAC_PI_4.ln();
    let f = |u: f64| graded_integrals(u.exp(), xi, kappa)[0].ln() - target;
    let (mut u0, mut f0) = (0.0, f(0.0));
    let mut u1 = -f0 / 4.0;
    for _ in 0..50 {
        let f1 = f(u1);
        if f1.abs() < 1e-15 || f1 == f0 {
            break;
        }
        let next = u1 - f1 * (u1 - u0) / (f1 - f0);
        (u0, f0, u1) = (u1, f1, next);
    }
    let r = u1.exp();
    let [load, area, area_moment, pressure_moment] = graded_integrals(r, xi, kappa);
    assert!(
        (load.ln() - target).abs() < 1e-13,
        "ξ = {xi}, κ = {kappa}: load not solved"
    );
    [
        area / std::f64::consts::PI,
        r * r,
        area_moment / area,
        pressure_moment / load,
    ]
}

#[test]
fn gauss_solutions_agree_with_an_independent_graded_quadrature() {
    let (radius, load) = (25e-9, 1e-9);
    let names = ["A/A₀", "δ/δ₀", "x_c/r₀", "x_p/r₀"];
    let mut worst = [[0.0_f64; 4]; 2];
    for (xi, kappa) in [
        (1e-6, 100.0),
        (4.4e-5, 1e4),
        (1.2e-4, 1.0),
        (5.1e-4, 1e3),
        (5.15e-4, 4.0),
        (3e-3, 0.01),
        (0.2, 4.0),
        (1.0, 1e4),
        (20.0, 0.01),
    ] {
        let layer = Layer {
            retardation_time: 0.1 * (1.0 + kappa),
            ..Layer::default()
        };
        let r = rolling(radius, load, speed_for(xi, radius, load, &layer), layer);
        let want = independent(xi, kappa);
        for (k, nodes) in [64, 1024].into_iter().enumerate() {
            let got = similarity_ratios_with(&r, Quadrature::Gauss { nodes });
            for q in 0..4 {
                let err = rel(got[q], want[q]);
                worst[k][q] = worst[k][q].max(err);
                assert!(
                    err < 1e-9,
                    "ξ = {xi}, κ = {kappa}, {nodes} nodes: {} = {} vs {}",
                    names[q],
                    got[q],
                    want[q]
                );
            }
        }
    }
    eprintln!(
        "vs graded quadrature: 64 nodes worst {}, 1024 nodes worst {} ({names:?})",
        Fmt(worst[0]),
        Fmt(worst[1])
    );
}

/// Four relative errors, in scientific notation.
struct Fmt([f64; 4]);

impl std::fmt::Display for Fmt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [a, b, c, d] = self.0;
        write!(f, "[{a:.2e}, {b:.2e}, {c:.2e}, {d:.2e}]")
    }
}
