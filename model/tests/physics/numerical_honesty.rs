//! What an answer says of its own numerical error holds: the quadrature error estimate
//! bounds the true error of every reported quantity for every rule offered, and the
//! quantities that vanish with the viscosity keep their relative precision as it does.

use thirdbody_model::{solve, Layer, Quadrature, Rolling, RollingSolution, SolveOptions};

fn at(radius: f64, load: f64, velocity: f64, kappa: f64) -> Rolling {
    let layer = Layer::default();
    Rolling {
        radius,
        load,
        velocity,
        layer: Layer {
            retardation_time: layer.relaxation_time * (1.0 + kappa),
            ..layer
        },
    }
}

fn solved(rolling: &Rolling, quadrature: Quadrature) -> RollingSolution {
    solve(rolling, &SolveOptions::integrals_only(quadrature)).unwrap()
}

/// |q/reference − 1|, and 0 when both are 0 (x_c, x_p at rest).
fn relative(q: f64, reference: f64) -> f64 {
    if q == reference {
        0.0
    } else {
        (q / reference - 1.0).abs()
    }
}

#[test]
fn the_quadrature_error_estimate_bounds_the_error_of_every_quantity_for_every_rule() {
    let reference_rule = Quadrature::Gauss { nodes: 1024 };
    let rules = crate::rules(&[2, 3, 4, 8, 16, 64], &[1, 2, 5, 40]);
    let mut worst_ratio: f64 = 0.0;
    for (radius, load) in [(25e-9, 1e-9), (350e-9, 1.4e-9)] {
        for velocity in [0.0, 2e-9, 4e-9, 1e-8, 1e-6] {
            for kappa in [0.01, 4.0, 1e4] {
                let contact = at(radius, load, velocity, kappa);
                let truth = solved(&contact, reference_rule);
                for &rule in &rules {
                    let s = solved(&contact, rule);
                    let estimate = s.verification.quadrature_error_estimate;
                    for (name, q, t) in [
                        ("δ", s.penetration, truth.penetration),
                        ("A", s.contact_area, truth.contact_area),
                        ("x_c", s.centroid_shift, truth.centroid_shift),
                        ("x_p", s.pressure_centre_shift, truth.pressure_centre_shift),
                        ("μ", s.friction_coefficient, truth.friction_coefficient),
                    ] {
                        // The reference itself is exact to ~1e-13 (and rounding beyond).
                        let error = (relative(q, t) - 1e-12).max(0.0);
                        assert!(
                            error <= estimate,
                            "{rule:?}, R = {radius}, P = {load}, V = {velocity}, κ = {kappa}: \
                             {name} errs by {error:e}, estimate {estimate:e}"
                        );
                        if error > 1e-10 {
                            worst_ratio = worst_ratio.max(error / estimate);
                        }
                    }
                }
            }
        }
    }
    // The bound is not loose beyond use: somewhere it is within a factor 100 of the error.
    assert!(worst_ratio > 0.01, "{worst_ratio}");
}

#[test]
fn tiny_rules_do_not_claim_to_be_exact() {
    let contact = Rolling::default();
    for rule in crate::rules(&[2], &[1]) {
        let estimate = solved(&contact, rule)
            .verification
            .quadrature_error_estimate;
        assert!(estimate > 1e-3, "{rule:?}: {estimate:e}");
    }
}

#[test]
fn the_shifts_keep_their_relative_precision_as_the_viscosity_vanishes() {
    // x_c and x_p vanish like κ: x/κ tends to a limit, to first order in κ. (κ is the
    // layer's own (T_ε − T_σ)/T_σ: T_ε = T_σ(1 + κ) rounds it by up to 1e-16.)
    let shifts = |kappa: f64| {
        let contact = at(25e-9, 1e-9, 4e-9, kappa);
        let kappa = contact.layer.kappa();
        let s = solved(&contact, Quadrature::default());
        (s.centroid_shift / kappa, s.pressure_centre_shift / kappa)
    };
    let (xc_limit, xp_limit) = shifts(1e-10);
    for kappa in [1e-8, 1e-12, 1e-14] {
        let (xc, xp) = shifts(kappa);
        assert!(
            relative(xc, xc_limit) < 1e-7,
            "κ = {kappa}: x_c/κ {xc} vs {xc_limit}"
        );
        assert!(
            relative(xp, xp_limit) < 1e-7,
            "κ = {kappa}: x_p/κ {xp} vs {xp_limit}"
        );
    }
    // Without viscosity the contact is the symmetric static one, exactly.
    let elastic = solved(&at(25e-9, 1e-9, 4e-9, 0.0), Quadrature::default());
    assert_eq!(elastic.centroid_shift, 0.0);
    assert_eq!(elastic.pressure_centre_shift, 0.0);
    assert_eq!(elastic.rolling_resistance_coefficient, 0.0);
    assert!(relative(elastic.contact_area, elastic.static_contact.contact_area) < 1e-14);
}

#[test]
fn a_vanishing_spread_of_diameters_joins_the_single_size_answer() {
    use thirdbody_model::three_body::{
        solve, Diameters, OperatingPoint, ThreeBody, ThreeBodyOptions,
    };
    let at = |std: f64| {
        let mut system = ThreeBody::with_defaults(OperatingPoint::ParticleLoad(1e-9));
        system.diameters = Diameters::with_default_bounds(50e-9, std);
        let s = solve(&system, &ThreeBodyOptions::default()).unwrap();
        (
            s.rolling.friction_coefficient,
            s.rolling.areas.total,
            s.rolling.separation,
        )
    };
    let single = at(0.0);
    for ratio in [1e-16, 1e-12, 1e-10, 1e-8, 1e-7] {
        let spread = at(ratio * 50e-9);
        for (q, s) in [
            (spread.0, single.0),
            (spread.1, single.1),
            (spread.2, single.2),
        ] {
            assert!(relative(q, s) < 1e-10, "σ_a/x_a = {ratio}: {q} vs {s}");
        }
    }
}

#[test]
fn a_finite_particle_modulus_softens_the_hertz_layer_contact_as_model_section_4_says() {
    use thirdbody_model::three_body::{
        solve, Diameters, LayerContact, OperatingPoint, Particle, ThreeBody, ThreeBodyOptions,
    };
    // Particles of one size at a given separation: each is squeezed by ω = x − d, split so
    // that both Hertz contacts carry the same force: ω₁/ω₂ = (E_s2a/E_s1a)^{2/3}.
    let (x, d) = (50e-9, 49e-9);
    let force = |particle: Particle| {
        let mut system = ThreeBody::with_defaults(OperatingPoint::Separation(d));
        system.diameters = Diameters {
            mean: x,
            std: 0.0,
            min: x,
            max: x,
        };
        system.layer_contact = LayerContact::Hertz;
        system.particle = particle;
        let s = solve(&system, &ThreeBodyOptions::default()).unwrap();
        let count = system.nominal_area * system.areal_density;
        (s.rolling.loads.particles / count, system)
    };
    let compliance = |e: f64, nu: f64| (1.0 - nu * nu) / e;
    for modulus in [None, Some(70e9), Some(5e9)] {
        let particle = Particle {
            elastic_modulus: modulus,
            poisson_ratio: 0.25,
        };
        let (f, system) = force(particle);
        let particle_compliance = modulus.map_or(0.0, |e| compliance(e, 0.25));
        let (upper, layer) = (system.upper, system.layer);
        let e1 =
            1.0 / (compliance(upper.elastic_modulus, upper.poisson_ratio) + particle_compliance);
        let e2 =
            1.0 / (compliance(layer.elastic_modulus, layer.poisson_ratio) + particle_compliance);
        let omega2 = (x - d) / (1.0 + (e2 / e1).powf(2.0 / 3.0));
        let expected = 4.0 / 3.0 * e2 * (x / 2.0).sqrt() * omega2.powf(1.5);
        assert!(
            relative(f, expected) < 1e-12,
            "E_a = {modulus:?}: {f} vs {expected}"
        );
    }
}
