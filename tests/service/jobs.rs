//! The job layer and the engine: validation, canonical form and cache key, and the answers
//! of rolling jobs, sweeps and figures, checked against the model and docs/model.md.

use serde_json::{json, Value};
use thirdbody::engine;
use thirdbody::job::figure::FigureOutput;
use thirdbody::job::rolling::RollingOutput;
use thirdbody::job::sweep::{SweepOutput, SweepPoint, SweepPoints};
use thirdbody::job::{Control, FieldError, Job, JobError, Limits, RollingJob, Work};
use thirdbody::model::limits::relaxed;
use thirdbody::model::tables::{self, Use};
use thirdbody::model::{solve, Layer, Quadrature, Rolling, SolveOptions};
use thirdbody::render::{Format, Output};

fn job(value: Value) -> Result<Job, JobError> {
    Job::from_value(value, &Limits::default())
}

fn run<T: Output>(value: Value) -> T {
    let answer = engine::run(&job(value).unwrap(), &Control::default()).unwrap();
    answer.downcast().unwrap()
}

fn rolling_points(value: Value) -> Vec<SweepPoint> {
    match run::<SweepOutput>(value).points {
        SweepPoints::Rolling(points) => points,
        other => panic!("{other:?}"),
    }
}

fn invalid_fields(value: Value) -> Vec<FieldError> {
    match job(value) {
        Err(JobError::Invalid(errors)) => errors,
        other => panic!("expected invalid fields, got {other:?}"),
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

#[test]
fn an_empty_rolling_job_is_the_default_particle_of_model_section_5() {
    let j = *job(json!({"kind": "rolling"}))
        .unwrap()
        .downcast_ref::<RollingJob>()
        .unwrap();
    assert_eq!(j.rolling, Rolling::default());
    assert_eq!(j.rolling.radius, 25e-9);
    assert_eq!(j.rolling.load, 1e-9);
    assert_eq!(j.rolling.velocity, 4e-9);
    assert_eq!(j.rolling.layer, Layer::default());
    assert_eq!(
        job(json!({"kind": "rolling", "input": {}})).unwrap(),
        Job::new(j)
    );
}

#[test]
fn units_and_numbers_have_one_canonical_form_and_one_cache_key() {
    let with_units = job(json!({"kind": "rolling", "input": {
        "radius": "25 nm", "load": "1 nN", "velocity": "4 nm/s",
        "layer": {"elastic_modulus": "3 GPa", "thickness": "100 nm", "poisson_ratio": 0.35,
                  "retardation_time": "500 ms", "relaxation_time": "0.1 s"}}}))
    .unwrap();
    let in_si = job(json!({"kind": "rolling", "input": {
        "radius": 2.5e-8, "load": 1e-9, "velocity": 4e-9,
        "layer": {"elastic_modulus": 3e9, "thickness": 1e-7, "poisson_ratio": "0.35",
                  "retardation_time": 0.5, "relaxation_time": 0.1}}}))
    .unwrap();
    let defaults = job(json!({"kind": "rolling"})).unwrap();
    assert_eq!(with_units.canonical(), in_si.canonical());
    assert_eq!(with_units.cache_key(), in_si.cache_key());
    assert_eq!(with_units.cache_key(), defaults.cache_key());
    assert_eq!(with_units.cache_key().len(), 64);

    // The canonical input is itself a valid input, with the same key.
    let again = job(json!({"kind": "rolling", "input": with_units.canonical()})).unwrap();
    assert_eq!(again.cache_key(), with_units.cache_key());

    // -0 and 0 are the same speed.
    let minus_zero = job(json!({"kind": "rolling", "input": {"velocity": -0.0}})).unwrap();
    let zero = job(json!({"kind": "rolling", "input": {"velocity": "0 m/s"}})).unwrap();
    assert_eq!(minus_zero.cache_key(), zero.cache_key());
}

#[test]
fn anything_that_changes_the_answer_changes_the_cache_key() {
    let base = job(json!({"kind": "rolling"})).unwrap().cache_key();
    for input in [
        json!({"radius": "26 nm"}),
        json!({"velocity": "5 nm/s"}),
        json!({"layer": {"thickness": "101 nm"}}),
        json!({"options": {"quadrature": "midpoint"}}),
        json!({"options": {"strips": 65}}),
        json!({"options": {"boundary_points": 3}}),
        json!({"options": {"pressure_grid": 11}}),
    ] {
        let key = job(json!({"kind": "rolling", "input": input}))
            .unwrap()
            .cache_key();
        assert_ne!(key, base, "{input}");
    }
    let sweep = job(json!({"kind": "sweep"})).unwrap().cache_key();
    assert_ne!(sweep, base);
}

#[test]
fn every_bad_field_is_reported_with_its_path_value_and_range() {
    let errors = invalid_fields(json!({"kind": "rolling", "input": {
        "radius": "3 GPa",
        "load": -1,
        "velocity": "-4 nm/s",
        "layer": {"poisson_ratio": 0.5, "retardation_time": "10 ms", "thickness": 0},
        "options": {"strips": 1, "pressure_grid": 100000, "boundary_points": 20000}}}));
    let fields: Vec<&str> = errors.iter().map(|e| e.field.as_str()).collect();
    assert_eq!(
        fields,
        [
            "radius",
            "load",
            "velocity",
            "layer.thickness",
            "layer.poisson_ratio",
            "layer.retardation_time",
            "options.strips",
            "options.boundary_points",
            "options.pressure_grid",
        ]
    );
    let radius = &errors[0];
    assert_eq!(radius.value, json!("3 GPa"));
    assert!(
        radius.message.contains("is a pressure"),
        "{}",
        radius.message
    );
    assert!(radius.allowed.contains("a length"), "{}", radius.allowed);
    let velocity = &errors[2];
    assert_eq!(velocity.value, json!("-4 nm/s"));
    assert_eq!(
        velocity.message,
        "velocity = \"-4 nm/s\" is out of range; expected finite and ≥ 0 m/s"
    );
    assert!(velocity.allowed.contains("≥ 0"), "{}", velocity.allowed);
    assert!(
        errors[5].allowed.contains("relaxation time"),
        "{}",
        errors[5].allowed
    );
    assert!(errors[6].allowed.contains("1024"), "{}", errors[6].allowed);
}

#[test]
fn non_finite_and_unreadable_quantities_are_errors() {
    for (value, needle) in [
        (json!("1e999 nm"), "finite"),
        (json!("twenty nm"), "number"),
        (json!("25 parsecs"), "unknown unit"),
        (json!("25 nm/s"), "a speed"),
    ] {
        let errors = invalid_fields(json!({"kind": "rolling", "input": {"radius": value}}));
        assert_eq!(errors.len(), 1);
        assert_eq!(errors[0].field, "radius");
        assert!(errors[0].message.contains(needle), "{}", errors[0].message);
    }
}

#[test]
fn misshapen_json_names_the_field_and_malformed_json_is_a_syntax_error() {
    match job(json!({"kind": "rolling", "input": {"layer": {"thicknes": 1}}})) {
        Err(JobError::Schema { field, message }) => {
            assert_eq!(field, "layer.thicknes");
            assert!(message.contains("unknown field"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    match job(json!({"kind": "rolling", "input": {"options": {"strips": -3}}})) {
        Err(JobError::Schema { field, .. }) => assert_eq!(field, "options.strips"),
        other => panic!("{other:?}"),
    }
    match job(json!({"kind": "three_bodies"})) {
        Err(JobError::Schema { field, .. }) => assert_eq!(field, "kind"),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        Job::from_json(b"{\"kind\": ", &Limits::default()),
        Err(JobError::Syntax(_))
    ));
}

#[test]
fn a_rolling_answer_carries_the_model_numbers_and_its_own_verification() {
    // A single rolling answer is the exact strip solve, whatever tables the process has
    // built (issue 52: after a figure had built the layer's table, the same input answered
    // other digits than in a fresh process). Build the table first, then check that the
    // answer is the exact solve to the bit, and that the table agrees with it to 1e-9.
    let rolling = Rolling::default();
    let table = tables::get_or_build(rolling.layer.kappa(), Quadrature::default()).unwrap();
    let tabulated = tables::solve(&rolling, &SolveOptions::default(), Use::Build).unwrap();
    let s = solve(&rolling, &SolveOptions::default()).unwrap();
    assert!(table.error() <= 1e-10);
    for (table, exact) in [
        (tabulated.contact_area, s.contact_area),
        (tabulated.friction_coefficient, s.friction_coefficient),
    ] {
        assert!((table / exact - 1.0).abs() < 1e-9, "{table:e} vs {exact:e}");
    }
    assert_ne!(
        tabulated.contact_area, s.contact_area,
        "the table's own digits"
    );
    let out: RollingOutput = run(json!({"kind": "rolling"}));
    assert_eq!(out.contact.contact_area, s.contact_area);
    assert_eq!(out.contact.friction_coefficient, s.friction_coefficient);
    assert_eq!(
        out.contact.r#static.contact_area,
        s.static_contact.contact_area
    );
    assert_eq!(out.boundary.len(), 41);
    assert!(out.pressure.is_none());

    let text = serde_json::to_value(&out).unwrap();
    assert_eq!(
        text["meta"]["model_version"],
        json!(thirdbody::model::MODEL_VERSION)
    );
    assert_eq!(text["meta"]["input"]["radius"], json!(2.5e-8));
    let verification = &text["meta"]["verification"];
    assert_eq!(verification["converged"], json!(true));
    assert!(verification["relative_load_residual"].as_f64().unwrap() < 1e-12);
    let dois: Vec<&Value> = text["meta"]["references"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| &r["doi"])
        .collect();
    assert!(dois.contains(&&json!("10.1177/1687814019872303")));
    assert!(!text.to_string().contains("null"), "no silent nulls");
    // docs/model.md §3 reference row R = 25 nm, P = 1 nN, V = 4 nm/s.
    assert!((text["friction_coefficient"].as_f64().unwrap() - 0.09470).abs() < 5e-6);
}

#[test]
fn the_pressure_grid_is_non_negative_and_carries_the_load() {
    let n = 201;
    let out: RollingOutput =
        run(json!({"kind": "rolling", "input": {"options": {"pressure_grid": n}}}));
    let grid = out.pressure.unwrap();
    assert_eq!(grid.x.len(), n);
    assert_eq!(grid.values.len(), n);
    assert!(grid
        .values
        .iter()
        .flatten()
        .all(|p| *p >= 0.0 && p.is_finite()));
    // Zero on the rim of the square (outside the contact) and positive at the centre.
    assert!(grid.values[0].iter().all(|p| *p == 0.0));
    assert!(grid.values[n / 2][n / 2] > 0.0);
    // Riemann sum of p over the grid ≈ P = 1 nN (the grid resolves the contact to ~1 %).
    let (dx, dy) = (grid.x[1] - grid.x[0], grid.y[1] - grid.y[0]);
    let load: f64 = grid.values.iter().flatten().sum::<f64>() * dx * dy;
    assert!(rel(load, 1e-9) < 0.01, "∬p = {load}");
}

#[test]
fn a_sweep_is_the_product_of_its_lists_in_order_and_equals_single_solves() {
    let points = rolling_points(json!({"kind": "sweep", "input": {
        "base": {"load": "1.2 nN"},
        "vary": {"radius": ["25 nm", "150 nm"], "load": ["1 nN", "1.4 nN"], "velocity": [0, "4 nm/s", "10 nm/s"]}}}));
    assert_eq!(points.len(), 12);
    let mut i = 0;
    for radius in [25e-9, 150e-9] {
        for load in [1e-9, 1.4e-9] {
            for velocity in [0.0, 4e-9, 10e-9] {
                let p = &points[i];
                assert_eq!((p.radius, p.load, p.velocity), (radius, load, velocity));
                let rolling = Rolling {
                    radius,
                    load,
                    velocity,
                    layer: Layer::default(),
                };
                let s = solve(&rolling, &SolveOptions::integrals_only(Default::default())).unwrap();
                let contact = p.contact.as_ref().expect("the point is answered");
                assert_eq!(contact.contact_area, s.contact_area);
                assert_eq!(contact.pressure_centre_shift, s.pressure_centre_shift);
                i += 1;
            }
        }
    }
    // Absent lists keep the base value.
    let points = rolling_points(json!({"kind": "sweep", "input": {"base": {"load": "1.2 nN"}}}));
    assert_eq!(points.len(), 1);
    assert_eq!(points[0].load, 1.2e-9);

    let csv = {
        let out: SweepOutput =
            run(json!({"kind": "sweep", "input": {"vary": {"velocity": [0, 4e-9]}}}));
        out.table().to_csv().unwrap()
    };
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 3);
    assert!(lines[0]
        .starts_with("radius [m],load [N],velocity [m/s],penetration [m],contact_area [m²]"));
    let area: f64 = lines[2].split(',').nth(4).unwrap().parse().unwrap();
    assert!((area * 1e18 - 85.234).abs() < 5e-4, "{area}");
}

#[test]
fn sweep_lists_are_validated_element_by_element_and_bounded_in_size() {
    let errors = invalid_fields(json!({"kind": "sweep", "input": {
        "base": {"radius": -1},
        "vary": {"radius": ["25 nm", "-1 nm"], "velocity": []}}}));
    let fields: Vec<&str> = errors.iter().map(|e| e.field.as_str()).collect();
    assert_eq!(fields, ["base.radius", "vary.radius[1]", "vary.velocity"]);

    let many: Vec<f64> = (1..=200).map(|i| f64::from(i) * 1e-9).collect();
    let errors =
        invalid_fields(json!({"kind": "sweep", "input": {"vary": {"radius": many, "load": many}}}));
    assert_eq!(errors[0].field, "vary");
    assert!(errors[0].allowed.contains("10000"), "{}", errors[0].allowed);
}

#[test]
fn figures_3_to_9_hold_the_series_of_model_section_5() {
    // (figure, series, points per series)
    for (number, series, points) in [
        (3, 4, 202),
        (4, 10, 5),
        (5, 5, 5),
        (6, 10, 5),
        (7, 5, 5),
        (8, 10, 14),
        (9, 10, 14),
    ] {
        let f: FigureOutput = run(json!({"kind": "figure", "input": {"number": number}}));
        assert_eq!(f.figure, number);
        assert_eq!(f.series.len(), series, "figure {number}");
        assert!(
            f.series.iter().all(|s| s.points.len() == points),
            "figure {number}"
        );
        assert!(f
            .series
            .iter()
            .flat_map(|s| &s.points)
            .flatten()
            .all(|x| x.is_finite()));
    }
    // Fig. 4: the static series are the closed form A₀, the rolling ones lie below them.
    let f: FigureOutput = run(json!({"kind": "figure", "input": {"number": 4}}));
    for pair in f.series.chunks(2) {
        let (fixed, rolling) = (&pair[0], &pair[1]);
        assert_eq!((fixed.velocity, rolling.velocity), (0.0, 4e-9));
        for (p0, p) in fixed.points.iter().zip(&rolling.points) {
            let a0 = relaxed(fixed.radius.unwrap(), p0[0], &Layer::default()).contact_area;
            assert!(rel(p0[1], a0) < 1e-9);
            assert!(p[1] < p0[1]);
        }
    }
    // Fig. 6 at R = 25 nm, V = 4 nm/s, P = 1 nN: μ of the reference table.
    let f: FigureOutput = run(json!({"kind": "figure", "input": {"number": 6}}));
    assert_eq!(f.series[1].label, "R = 25 nm, V = 4 nm/s");
    assert!((f.series[1].points[0][1] - 0.09470).abs() < 5e-6);
    // Fig. 3: each contour is closed and lies within |y| ≤ √(2Rδ).
    let f: FigureOutput = run(json!({"kind": "figure", "input": {"number": 3}}));
    for s in &f.series {
        assert_eq!(s.points.first(), s.points.last());
    }
    let csv = f.table().to_csv().unwrap();
    // The conditions each contour holds fixed are columns of their own (issue 52).
    assert_eq!(
        csv.lines().next(),
        Some("series,label,x [m],y [m],radius [m],load [N],velocity [m/s]")
    );
    assert!(csv.lines().nth(1).unwrap().ends_with(",2.5e-8,1e-9,0"));
    assert_eq!(csv.lines().count(), 1 + 4 * 202);
}

#[test]
fn a_figure_number_outside_3_to_9_is_an_error() {
    for n in [0, 2, 10, -1, 300] {
        let errors = invalid_fields(json!({"kind": "figure", "input": {"number": n}}));
        assert_eq!(errors[0].field, "number");
        assert_eq!(errors[0].allowed, "3 to 9");
    }
}

#[test]
fn the_engine_reports_progress_and_stops_on_cancel_or_deadline() {
    let sweep =
        job(json!({"kind": "sweep", "input": {"vary": {"velocity": [0, 1e-9, 2e-9, 3e-9]}}}))
            .unwrap();
    let control = Control::default();
    engine::run(&sweep, &control).unwrap();
    assert_eq!(control.done(), 4);
    assert_eq!(sweep.work(), Work::Known(4));

    let cancelled = Control::default();
    cancelled.cancel();
    assert_eq!(engine::run(&sweep, &cancelled), Err(JobError::Cancelled));
    assert_eq!(cancelled.done(), 0);

    let late = Control::new(Some(std::time::Instant::now()), 2);
    assert_eq!(engine::run(&sweep, &late), Err(JobError::DeadlineExceeded));
}

#[test]
fn parallel_and_serial_engines_give_identical_answers() {
    let sweep = job(json!({"kind": "sweep", "input": {"vary": {"radius": [25e-9, 50e-9, 75e-9], "velocity": [0, 4e-9, 8e-9]}}})).unwrap();
    let serial = engine::run(&sweep, &Control::new(None, 1)).unwrap();
    let parallel = engine::run(&sweep, &Control::new(None, 4)).unwrap();
    assert_eq!(serial, parallel);
}

/// The room an asynchronous job's store makes for its result (`Job::result_bytes`) holds the
/// result's JSON and CSV, for every kind and at the sizes that make answers large: an estimate
/// too small would let the store hold more than its budget.
#[test]
fn the_room_made_for_a_result_holds_it() {
    let loads: Vec<String> = (0..50).map(|i| format!("{} pN", 900 + 7 * i)).collect();
    let jobs = [
        json!({"kind": "rolling"}),
        json!({"kind": "rolling", "input": {"options": {"boundary_points": 10001}}}),
        json!({"kind": "rolling", "input": {"options": {"pressure_grid": 201}}}),
        json!({"kind": "three_body", "input": {"operating": {"total_load": "1 mN"}}}),
        json!({"kind": "sweep", "input": {"vary": {"load": loads, "radius": ["25 nm", "3 um"],
            "velocity": [0, "1e-13 m/s", "0.3 m/s"]}}}),
        json!({"kind": "sweep", "input": {"vary": {"load": ["1 nN", "1 mN", "10 mN"]}}}),
        json!({"kind": "sweep", "input": {"kind": "three_body",
            "base": {"operating": {"total_load": "1 mN"}},
            "vary": {"velocity": ["0 nm/s", "4 nm/s"], "mean_diameter": ["30 nm", "50 nm"]}}}),
        json!({"kind": "figure", "input": {"number": 9}}),
        serde_json::from_str(include_str!("../../examples/fit.json")).unwrap(),
    ];
    for envelope in jobs {
        let job = Job::from_value(envelope.clone(), &Limits::default()).unwrap();
        let answer = engine::run(&job, &Control::default()).unwrap();
        let bytes = answer
            .render(thirdbody::render::Format::Json)
            .unwrap()
            .len()
            + answer.render(thirdbody::render::Format::Csv).unwrap().len();
        assert!(
            bytes as u64 <= job.result_bytes(),
            "{envelope}: {bytes} bytes, room for {}",
            job.result_bytes()
        );
    }
}

/// A sweep's `meta.units` lists its own rows' fields: a rolling sweep's none of a three-body
/// sweep's, and the other way round (issue 52: a rolling sweep listed 17 of them).
#[test]
fn a_sweep_lists_the_units_of_its_own_rows_only() {
    let units = |job: Value| -> Vec<String> {
        let job = Job::from_value(job, &Limits::default()).unwrap();
        let answer = engine::run(&job, &Control::default()).unwrap();
        let text: Value = serde_json::from_slice(&answer.render(Format::Json).unwrap()).unwrap();
        let units = text["meta"]["units"].as_object().unwrap();
        units
            .keys()
            .filter(|k| k.starts_with("points[]"))
            .cloned()
            .collect()
    };
    let rolling = units(json!({"kind": "sweep", "input": {"vary": {"load": ["1 nN", "2 nN"]}}}));
    assert!(rolling.contains(&"points[].contact_area".to_string()));
    assert!(
        !rolling.iter().any(|k| k.starts_with("points[].areas")),
        "{rolling:?}"
    );
    assert!(!rolling.contains(&"points[].mean_diameter".to_string()));
    let systems = units(json!({"kind": "sweep", "input": {"kind": "three_body",
        "base": {"operating": {"total_load": "1 mN"}},
        "vary": {"total_load": ["1 mN", "2 mN"]}}}));
    assert!(systems.contains(&"points[].areas.total".to_string()));
    assert!(
        !systems.contains(&"points[].contact_area".to_string()),
        "{systems:?}"
    );
}
