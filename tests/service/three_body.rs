//! The three-body system (docs/model.md §4) against independent computations, closed forms and
//! the single-particle model, and its stated trends as properties.

use proptest::prelude::*;
use serde_json::{json, Value};
use thirdbody::engine;
use thirdbody::job::sweep::SweepOutput;
use thirdbody::job::sweep::{SweepPoints, ThreeBodySweepPoint};
use thirdbody::job::three_body::ThreeBodyOutput;
use thirdbody::job::{Control, Job, JobError, Limits};
use thirdbody::model::limits::relaxed;
use thirdbody::model::three_body::{
    self, squeeze, Asperities, Diameters, LayerContact, LayerLaw, OperatingPoint, ThreeBody,
    ThreeBodyOptions, ThreeBodySolution, UpperLaw,
};
use thirdbody::model::{solve, Layer, ModelError, Rolling, SolveOptions};
use thirdbody::render::{Answer, Output};

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

fn system(operating: OperatingPoint) -> ThreeBody {
    ThreeBody::with_defaults(operating)
}

fn solve3(s: &ThreeBody) -> Result<ThreeBodySolution, ModelError> {
    three_body::solve(s, &ThreeBodyOptions::default())
}

/// Composite Simpson on [a, b] with n (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let inner: f64 = (1..n)
        .map(|i| f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(a) + f(b) + inner) * h / 3.0
}

#[test]
fn hertz_particle_sums_equal_an_independent_direct_quadrature_to_1e_8() {
    let layer = Layer::default();
    // Rigid particles: E_s1a = E₁/(1 − ν₁²), E_s2a = E_L/(1 − ν_L²).
    let e1 = 210e9 / (1.0 - 0.3 * 0.3);
    let e2 = layer.elastic_modulus / (1.0 - layer.poisson_ratio.powi(2));
    let split = 1.0 / (1.0 + (e2 / e1).powf(2.0 / 3.0)); // ω₂/ω
    let (mean, std) = (50e-9, 5e-9);
    let (lo_x, hi_x) = (mean - 3.0 * std, mean + 3.0 * std);
    let gauss = |x: f64| (-0.5 * ((x - mean) / std).powi(2)).exp();
    let norm = simpson(gauss, lo_x, hi_x, 20_000);
    let count = 1e-6 * 1e12;
    for d in [30e-9, 45e-9, 50e-9, 58e-9, 64e-9] {
        let mut s = system(OperatingPoint::Separation(d));
        s.layer_contact = LayerContact::Hertz;
        let state = solve3(&s).unwrap().rolling;
        // x = d + u², so the (x − d)^{3/2} edge becomes smooth in u.
        let lo = f64::max(d, lo_x);
        let (u0, u1) = ((lo - d).sqrt(), (hi_x - d).sqrt());
        let integral = |f: &dyn Fn(f64, f64) -> f64| {
            count / norm
                * simpson(
                    |u| {
                        let x = d + u * u;
                        f(x, x - d) * gauss(x) * 2.0 * u
                    },
                    u0,
                    u1,
                    200_000,
                )
        };
        let a_upper = integral(&|x, w| std::f64::consts::PI * x / 2.0 * w * (1.0 - split));
        let a_layer = integral(&|x, w| std::f64::consts::PI * x / 2.0 * w * split);
        let load = integral(&|x, w| 4.0 / 3.0 * e2 * (x / 2.0).sqrt() * (w * split).powf(1.5));
        let n_a = count / norm * simpson(gauss, lo, hi_x, 200_000);
        assert!(
            rel(state.areas.particle_upper, a_upper) < 1e-8,
            "d = {d}: A_s1a"
        );
        assert!(
            rel(state.areas.particle_layer, a_layer) < 1e-8,
            "d = {d}: A_s2a"
        );
        assert!(rel(state.loads.particles, load) < 1e-8, "d = {d}: W_a");
        assert!(rel(state.particles_in_contact, n_a) < 1e-8, "d = {d}: n_a");
    }
}

#[test]
fn kelvin_layer_at_rest_is_the_closed_form_per_particle() {
    let layer = Layer::default();
    let law = LayerLaw::Kelvin {
        stiffness: layer.stiffness(),
        relaxation_length: 0.0,
        table: None,
    };
    let upper = UpperLaw::Elastic {
        modulus: 210e9 / 0.91,
    };
    for (x, omega) in [(50e-9, 2e-9), (35e-9, 0.3e-9), (64e-9, 9e-9)] {
        let s = squeeze(&upper, &law, x, omega).unwrap();
        let w2 = s.layer_penetration;
        let force = std::f64::consts::PI * layer.stiffness() * (x / 2.0) * w2 * w2;
        assert!(rel(s.force, force) < 1e-14);
        assert!(rel(s.layer_area, std::f64::consts::PI * x * w2) < 1e-14);
        assert!(rel(s.upper_interference + w2, omega) < 1e-13);
        assert!(rel(upper.force(x / 2.0, s.upper_interference), s.force) < 1e-12);
    }
}

#[test]
fn plastic_upper_contact_carries_the_load_at_its_hardness_and_soft_particles_flatten_more() {
    let hardness = 2e9;
    let mut s = system(OperatingPoint::Separation(50e-9));
    s.upper.contact = three_body::UpperContact::Plastic;
    s.upper.hardness = Some(hardness);
    let state = solve3(&s).unwrap().rolling;
    // F = H₁A₁ for every particle, so the sums obey W_a = H₁ A_s1a exactly.
    assert!(rel(state.loads.particles, hardness * state.areas.particle_upper) < 1e-12);

    let rigid = solve3(&system(OperatingPoint::TotalLoad(1e-3)))
        .unwrap()
        .rolling;
    let mut soft = system(OperatingPoint::TotalLoad(1e-3));
    soft.particle.elastic_modulus = Some(70e9);
    let soft = solve3(&soft).unwrap().rolling;
    assert!(soft.areas.particle_upper > rigid.areas.particle_upper);
}

#[test]
fn particles_of_one_size_give_the_single_particle_friction_of_eq_12() {
    for (velocity, load) in [(4e-9, 1e-9), (10e-9, 1.3e-9), (0.0, 1e-9)] {
        let mut s = system(OperatingPoint::ParticleLoad(load));
        s.diameters = Diameters {
            mean: 50e-9,
            std: 0.0,
            min: 50e-9,
            max: 50e-9,
        };
        s.velocity = velocity;
        let sol = solve3(&s).unwrap();
        let single = solve(
            &Rolling {
                radius: 25e-9,
                load,
                velocity,
                layer: Layer::default(),
            },
            &SolveOptions::default(),
        )
        .unwrap();
        let mean_load = sol.rolling.mean_load().expect("particles are in contact");
        assert!(rel(mean_load, load) < 1e-12);
        assert!(
            rel(
                sol.rolling.friction_coefficient,
                single.friction_coefficient
            ) < 1e-9,
            "V = {velocity}: {} vs {}",
            sol.rolling.friction_coefficient,
            single.friction_coefficient
        );
        let mu0 = relaxed(25e-9, load, &Layer::default()).friction_coefficient;
        assert!(rel(sol.static_state.friction_coefficient, mu0) < 1e-9);
    }
    // σ_a → 0 approaches the same value, the gap closing like σ_a².
    let single = solve(&Rolling::default(), &SolveOptions::default()).unwrap();
    let gaps: Vec<f64> = [1e-10, 1e-11, 1e-12]
        .iter()
        .map(|&std| {
            let mut s = system(OperatingPoint::ParticleLoad(1e-9));
            s.diameters = Diameters::with_default_bounds(50e-9, std);
            rel(
                solve3(&s).unwrap().rolling.friction_coefficient,
                single.friction_coefficient,
            )
        })
        .collect();
    for pair in gaps.windows(2) {
        assert!((pair[0] / pair[1] - 100.0).abs() < 2.0, "{gaps:?}");
    }
    assert!(gaps[2] < 2e-6, "{gaps:?}");
}

#[test]
fn total_load_decreases_with_separation_and_the_total_load_mode_reproduces_it() {
    let mut last = f64::INFINITY;
    for i in 0..40 {
        let d = 20e-9 + 44.9e-9 * f64::from(i) / 39.0;
        let w = solve3(&system(OperatingPoint::Separation(d)))
            .unwrap()
            .rolling
            .loads
            .total;
        assert!(w < last, "W(d) not decreasing at d = {d}");
        last = w;
    }
    for target in [1e-6, 1e-4, 1e-3, 1e-2, 0.1] {
        let sol = solve3(&system(OperatingPoint::TotalLoad(target))).unwrap();
        assert!(sol.verification.load_residual < 1e-10);
        let again = solve3(&system(OperatingPoint::Separation(sol.rolling.separation))).unwrap();
        assert!(
            rel(again.rolling.loads.total, target) < 1e-10,
            "W = {target}"
        );
        // At V = 0 the same load is re-solved for its own separation.
        let at_rest = sol.static_state;
        assert!(rel(at_rest.loads.total, target) < 1e-10);
        assert_ne!(at_rest.separation, sol.rolling.separation);
    }
}

#[test]
fn the_diameter_quadrature_converges_to_1e_10_at_the_default_node_count() {
    for operating in [
        OperatingPoint::Separation(45e-9),
        OperatingPoint::Separation(62e-9),
        OperatingPoint::TotalLoad(1e-3),
    ] {
        let reference = three_body::solve(
            &system(operating),
            &ThreeBodyOptions {
                diameter_nodes: 512,
                ..Default::default()
            },
        )
        .unwrap();
        let mut errors = Vec::new();
        for nodes in [8, 16, 32, 48] {
            let s = three_body::solve(
                &system(operating),
                &ThreeBodyOptions {
                    diameter_nodes: nodes,
                    ..Default::default()
                },
            )
            .unwrap();
            let r = &reference.rolling;
            errors.push(
                [
                    rel(s.rolling.areas.particle_layer, r.areas.particle_layer),
                    rel(s.rolling.areas.particle_upper, r.areas.particle_upper),
                    rel(s.rolling.loads.total, r.loads.total),
                    rel(s.rolling.separation, r.separation),
                ]
                .into_iter()
                .fold(0.0, f64::max),
            );
        }
        assert!(
            errors.windows(2).all(|e| e[1] < e[0] || e[1] < 1e-13),
            "{operating:?}: {errors:?}"
        );
        assert!(
            errors[3] < 1e-10,
            "{operating:?}: 48 nodes err {}",
            errors[3]
        );
    }
}

#[test]
fn asperities_carry_load_when_the_gap_is_small_and_none_in_the_gap_regime() {
    let asperities = Asperities {
        density: 1e11,
        tip_radius: 1e-6,
        height_std: 5e-9,
        hardness: 1e9,
    };
    let at = |d: f64| {
        let mut s = system(OperatingPoint::Separation(d));
        s.asperities = Some(asperities);
        solve3(&s).unwrap().rolling
    };
    let close = at(5e-9);
    assert!(close.loads.asperities > 0.0 && close.areas.surface_surface > 0.0);
    assert_eq!(
        close.areas.total,
        close.areas.surface_surface + close.areas.particle_upper
    );
    // Several σ_s apart the asperities are out of contact (the paper's "always a gap").
    let gap = at(45e-9);
    assert!(gap.loads.asperities < 1e-12 * gap.loads.particles);
    assert!(at(10e-9).loads.asperities < close.loads.asperities);
}

/// Asperities whose heights spread over tens of nanometres: they touch beyond the largest
/// particle (x_max = 65 nm).
fn tall_asperities() -> Value {
    json!({"density": 1e11, "tip_radius": "1 um", "height_std": "30 nm", "hardness": "1 GPa"})
}

#[test]
fn where_the_asperities_carry_the_load_alone_the_system_is_answered_with_a_warning() {
    let out: ThreeBodyOutput = run(json!({"kind": "three_body", "input": {
        "operating": {"separation": "70 nm"}, "asperities": tall_asperities()}}))
    .unwrap()
    .downcast()
    .unwrap();
    let text = serde_json::to_value(&out).unwrap();
    assert_eq!(text["particles_in_contact"], 0.0);
    assert_eq!(text["loads"]["particles"], 0.0);
    let w = text["loads"]["total"].as_f64().unwrap();
    assert!(w > 0.0 && w == text["loads"]["asperities"].as_f64().unwrap());
    // No particle: no means per particle, rather than 0/0.
    assert!(text.get("per_particle").is_none(), "{text}");
    let mu = text["friction_coefficient"]["rolling"].as_f64().unwrap();
    assert!(mu.is_finite() && mu > 0.0);
    let warned: Vec<&str> = text["meta"]["validity"]["assumptions"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|a| a["status"] == "warn")
        .map(|a| a["name"].as_str().unwrap())
        .collect();
    assert!(warned.contains(&"particles_in_contact") && warned.contains(&"asperity_gap"));
    let csv = out.table().to_csv().unwrap();
    let row = csv.lines().nth(1).unwrap();
    assert!(
        row.contains(",,\"warn\""),
        "the means are empty cells: {row}"
    );
}

#[test]
fn a_three_body_sweep_across_the_asperity_only_regime_answers_every_point() {
    let out = three_body_sweep(json!({"kind": "sweep", "input": {"kind": "three_body",
        "base": {"asperities": tall_asperities()},
        "vary": {"separation": ["40 nm", "60 nm", "70 nm", "80 nm"]}}}));
    let points = three_body_rows(&out);
    assert_eq!(points.len(), 4);
    // 40 nm squeezes the largest particle beyond the model: that point alone is refused.
    let mut reason = String::new();
    points[0].notes.write_note(&mut reason);
    assert!(reason.contains("reaches the sphere's radius"), "{reason}");
    assert!(points[0].result.is_none());
    for p in &points[1..] {
        assert!(p.result.is_some(), "{p:?}");
    }
    assert!(points[2].result.as_ref().unwrap().per_particle.is_none());
    assert_eq!(out.meta.summary.counts.refused, 1);
    assert_eq!(out.meta.summary.counts.warn, 3);
}

fn run(value: Value) -> Result<Answer, JobError> {
    let job = Job::from_value(value, &Limits::default())?;
    engine::run(&job, &Control::default())
}

/// The answer of the three-body sweep job `value`.
fn three_body_sweep(value: Value) -> SweepOutput {
    run(value).unwrap().downcast().unwrap()
}

/// The rows of a three-body sweep's answer.
fn three_body_rows(out: &SweepOutput) -> &[ThreeBodySweepPoint] {
    let SweepPoints::ThreeBody(points) = &out.points else {
        panic!("not a three-body sweep")
    };
    points
}

#[test]
fn a_job_naming_only_the_operating_point_is_valid_and_canonical() {
    let out: ThreeBodyOutput =
        run(json!({"kind": "three_body", "input": {"operating": {"total_load": "1 mN"}}}))
            .unwrap()
            .downcast()
            .unwrap();
    let text = serde_json::to_value(&out).unwrap();
    assert!(rel(text["loads"]["total"].as_f64().unwrap(), 1e-3) < 1e-10);
    assert!(
        text["friction_coefficient"]["rolling"].as_f64().unwrap()
            < text["friction_coefficient"]["static"].as_f64().unwrap()
    );
    let min = text["meta"]["input"]["distribution"]["min_diameter"]
        .as_f64()
        .unwrap();
    assert!(rel(min, 35e-9) < 1e-15, "x_a − 3σ_a = {min}");
    assert_eq!(
        text["meta"]["input"]["operating"],
        json!({"total_load": 1e-3})
    );
    let verification = &text["meta"]["verification"];
    assert_eq!(verification["converged"], json!(true));
    assert!(verification["layer_table_error"].as_f64().unwrap() < 1e-12);
    assert!(!text.to_string().contains("null"));
    assert_eq!(text["meta"]["references"].as_array().unwrap().len(), 5);
    for key in [
        "separation",
        "particles_in_contact",
        "areas",
        "loads",
        "per_particle",
        "static_operating_point",
    ] {
        assert!(text.get(key).is_some(), "{key}");
    }
    let same = Job::from_value(json!({"kind": "three_body", "input": {"operating": {"total_load": 1e-3}, "nominal_area": "1 mm^2"}}), &Limits::default()).unwrap();
    assert_eq!(same.cache_key(), out.meta.meta.input_hash);
}

#[test]
fn bad_three_body_input_gets_clear_errors() {
    let fields = |input: Value| -> Vec<String> {
        match Job::from_value(
            json!({"kind": "three_body", "input": input}),
            &Limits::default(),
        ) {
            Err(JobError::Invalid(errors)) => errors.into_iter().map(|e| e.field).collect(),
            other => panic!("{other:?}"),
        }
    };
    assert_eq!(
        fields(
            json!({"operating": {"separation": "40 nm"}, "distribution": {"std_diameter": "-1 nm"}})
        ),
        ["distribution.std_diameter"]
    );
    assert_eq!(
        fields(
            json!({"operating": {"separation": "40 nm"}, "distribution": {"min_diameter": "60 nm", "max_diameter": "40 nm"}})
        ),
        ["distribution.max_diameter"]
    );
    assert_eq!(
        fields(json!({"operating": {"separation": "40 nm", "total_load": "1 mN"}})),
        ["operating"]
    );
    assert_eq!(fields(json!({})), ["operating"]);
    assert_eq!(
        fields(
            json!({"operating": {"total_load": "1 mN"}, "upper_surface": {"contact": "plastic"}})
        ),
        ["upper_surface.hardness"]
    );
    assert_eq!(
        fields(json!({"operating": {"total_load": "1 mN"}, "asperities": {"density": 1e11}})),
        [
            "asperities.tip_radius",
            "asperities.height_std",
            "asperities.hardness"
        ]
    );

    // Loads the system cannot carry, and no particle in contact, are errors that say why.
    for (input, needle) in [
        (
            json!({"operating": {"total_load": "1 kN"}}),
            "cannot be carried",
        ),
        (
            json!({"operating": {"separation": "70 nm"}}),
            "nothing is in contact",
        ),
        (
            json!({"operating": {"particle_load": "1 mN"}}),
            "cannot be carried",
        ),
    ] {
        match run(json!({"kind": "three_body", "input": input})) {
            Err(JobError::Unsolvable(e)) => assert!(e.contains(needle), "{e}"),
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn three_body_sweeps_vary_the_operating_point_speed_and_mean_diameter() {
    let out = three_body_sweep(json!({"kind": "sweep", "input": {
        "kind": "three_body",
        "vary": {"total_load": ["0.1 mN", "1 mN"], "velocity": [0, "4 nm/s"], "mean_diameter": ["40 nm", "50 nm"]}}}));
    let points = three_body_rows(&out);
    assert_eq!(points.len(), 8);
    let first = &points[0];
    assert_eq!(first.operating, json!({"total_load": 1e-4}));
    assert_eq!((first.velocity, first.mean_diameter), (0.0, 40e-9));
    let mut single = system(OperatingPoint::TotalLoad(1e-4));
    single.velocity = 0.0;
    single.diameters = Diameters::with_default_bounds(40e-9, 5e-9);
    let direct = solve3(&single).unwrap();
    let result = first.result.as_ref().expect("the point is answered");
    assert_eq!(result.state.separation, direct.rolling.separation);
    let csv = out.table().to_csv().unwrap();
    assert!(csv.starts_with("total_load [N],velocity [m/s],mean_diameter [m],separation [m]"));
    assert_eq!(csv.lines().count(), 9);
    // Two operating lists at once are refused.
    assert!(matches!(
        run(
            json!({"kind": "sweep", "input": {"kind": "three_body", "vary": {"total_load": [1e-3], "separation": [4e-8]}}})
        ),
        Err(JobError::Invalid(_))
    ));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, ..ProptestConfig::default() })]

    /// Rolling lowers the friction of the system (kelvin_layer), at any load it can carry.
    #[test]
    fn rolling_lowers_the_system_friction(d in 30e-9..63e-9f64, v in 0.5e-9..20e-9f64, relax in 0.02..0.5f64) {
        let mut s = system(OperatingPoint::Separation(d));
        s.velocity = v;
        s.layer.relaxation_time = relax;
        let w = solve3(&s).unwrap().rolling.loads.total;
        s.operating = OperatingPoint::TotalLoad(w);
        let sol = solve3(&s).unwrap();
        prop_assert!(sol.rolling.friction_coefficient < sol.static_state.friction_coefficient);
    }

    /// More load, lower friction: the system μ falls as the total load grows.
    #[test]
    fn more_load_lowers_the_system_friction(d in 30e-9..63e-9f64, f in 0.05..2.0f64, v in 0.0..10e-9f64) {
        let mut s = system(OperatingPoint::Separation(d));
        s.velocity = v;
        let w = solve3(&s).unwrap().rolling.loads.total;
        s.operating = OperatingPoint::TotalLoad(w);
        let mu_low = solve3(&s).unwrap();
        s.operating = OperatingPoint::TotalLoad(w * (1.0 + f));
        let mu_high = solve3(&s).unwrap();
        prop_assert!(mu_high.rolling.friction_coefficient < mu_low.rolling.friction_coefficient);
        prop_assert!(mu_high.static_state.friction_coefficient < mu_low.static_state.friction_coefficient);
    }
}
