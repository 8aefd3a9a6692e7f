//! Honest answers (docs/model.md §7): the domain of validity in every answer, inputs that mean one
//! thing, units and provenance in every output; each example of the issue as a case, and a
//! property over the whole input space: an answer is finite numbers with a validity block,
//! or a problem.

use proptest::prelude::*;
use serde_json::{json, Value};
use thirdbody::engine;
use thirdbody::job::{Control, Job, JobError, Limits};
use thirdbody::render::Format;

fn job(value: Value) -> Result<Job, JobError> {
    Job::from_value(value, &Limits::default())
}

/// The answer as clients read it, or the job's error.
fn answer(value: Value) -> Result<Value, JobError> {
    let answer = engine::run(&job(value)?, &Control::new(None, 1))?;
    let json = answer.render(Format::Json).expect("an answer renders");
    Ok(serde_json::from_slice(&json).unwrap())
}

fn rolling(input: Value) -> Result<Value, JobError> {
    answer(json!({"kind": "rolling", "input": input}))
}

fn validity<'a>(answer: &'a Value, name: &str) -> &'a Value {
    answer["meta"]["validity"]["assumptions"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"] == name)
        .unwrap_or_else(|| panic!("no {name} in {}", answer["meta"]["validity"]))
}

#[test]
fn a_sphere_pressed_through_the_layer_is_refused_with_the_numbers() {
    match rolling(json!({"load": "1 mN"})) {
        Err(JobError::OutOfDomain(m)) => assert_eq!(
            m,
            "the penetration 651 nm reaches the layer's thickness 100 nm: the sphere would \
             touch the rigid base"
        ),
        other => panic!("{other:?}"),
    }
    // Rolling penetrates less than resting: when only the V = 0 companion reaches the base,
    // the refusal says so.
    // R = 10 µm, δ₀ = √(P/(πkR)) = 150 nm at rest; rolling fast (ξ ≈ 600) it sinks only
    // δ₀ √(T_σ/T_ε) ≈ 47 nm.
    let at_rest = rolling(
        json!({"radius": "10 um", "load": "21.2 mN", "velocity": "1 mm/s",
        "layer": {"relaxation_time": "1 s", "retardation_time": "10 s"}}),
    );
    match at_rest {
        Err(JobError::OutOfDomain(m)) => {
            assert!(m.starts_with("at rest (V = 0"), "{m}");
            assert!(m.contains("the rolling contact stays inside"), "{m}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_bare_number_far_from_its_scale_is_answered_with_a_warning_naming_what_was_meant() {
    let answer = rolling(json!({"radius": 25})).unwrap();
    let warnings = answer["meta"]["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1);
    assert_eq!(warnings[0]["field"], "radius");
    assert_eq!(
        warnings[0]["message"],
        "radius: 25 is 25 m; did you mean \"25 nm\"?"
    );
    // μ = 3592 for a 25 m sphere: the friction row warns too.
    assert!(answer["friction_coefficient"].as_f64().unwrap() > 1000.0);
    assert_eq!(validity(&answer, "adhesive_friction")["status"], "warn");
    // The same value with its unit is what was meant: no warning, and another cache key.
    let meant = rolling(json!({"radius": "25 m"})).unwrap();
    assert!(meant["meta"]["warnings"].as_array().unwrap().is_empty());
    assert_ne!(meant["meta"]["input_hash"], answer["meta"]["input_hash"]);

    let stiff = rolling(json!({"layer": {"elastic_modulus": 1e300}})).unwrap();
    let message = stiff["meta"]["warnings"][0]["message"].as_str().unwrap();
    assert!(message.contains("above 1 TPa"), "{message}");
    assert_eq!(validity(&stiff, "adhesive_friction")["status"], "warn");
}

#[test]
fn a_string_without_a_unit_is_a_bare_number_and_warned_like_one() {
    let sent_as_text = rolling(json!({"radius": "25", "layer": {"retardation_time": "2e6"}}));
    let sent_as_number = rolling(json!({"radius": 25, "layer": {"retardation_time": 2e6}}));
    let (text, number) = (sent_as_text.unwrap(), sent_as_number.unwrap());
    let messages = |answer: &Value| -> Vec<String> {
        let warnings = answer["meta"]["warnings"].as_array().unwrap();
        warnings
            .iter()
            .map(|w| w["message"].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(
        messages(&text),
        [
            "radius: 25 is 25 m; did you mean \"25 nm\"?",
            "layer.retardation_time: 2e6 is 2e6 s; did you mean \"2e6 ms\"?"
        ]
    );
    assert_eq!(messages(&text), messages(&number));
    assert_eq!(text["meta"]["warnings"][0]["value"], "25");
    // One input, one answer: the same canonical form, the same cache key.
    assert_eq!(text["meta"]["input_hash"], number["meta"]["input_hash"]);
}

#[test]
fn a_vanishing_load_is_answered_but_its_friction_warns() {
    let answer = rolling(json!({"load": "1e-300 N"})).unwrap();
    let mu = answer["friction_coefficient"].as_f64().unwrap();
    assert!(mu > 1e140, "{mu}");
    let friction = validity(&answer, "adhesive_friction");
    assert_eq!(friction["status"], "warn");
    assert!(friction["note"].as_str().unwrap().contains("above 1"));
    assert_eq!(answer["meta"]["validity"]["status"], "warn");
}

#[test]
fn the_paper_s_particle_warns_on_the_local_layer_only_and_says_why() {
    let answer = rolling(json!({})).unwrap();
    assert_eq!(answer["meta"]["validity"]["status"], "warn");
    for assumption in answer["meta"]["validity"]["assumptions"]
        .as_array()
        .unwrap()
    {
        let expected = if assumption["name"] == "local_layer" {
            "warn"
        } else {
            "ok"
        };
        assert_eq!(assumption["status"], expected, "{assumption}");
    }
    let local = validity(&answer, "local_layer");
    let value = local["value"].as_f64().unwrap();
    // A_local/A_continuum at rest (docs/model.md §7): the local law's 102.333 nm² (§3)
    // against the continuum's 13.4 nm² (§8), within the table's 0.5 %.
    assert!((value / (102.333 / 13.39) - 1.0).abs() < 5e-3, "{value}");
    assert_eq!(local["at_rest"], local["value"]);
    let note = local["note"].as_str().unwrap();
    for said in [
        "102 nm²",
        "13.4 nm²",
        "overstates it 7.6",
        "paper's own parameters",
    ] {
        assert!(note.contains(said), "{note}");
    }
    // The inside-layer ratio is δ/H (0.6237 nm / 100 nm), and the V = 0 one δ₀/H.
    // (to the table's four digits).
    let inside = validity(&answer, "inside_layer");
    assert!((inside["value"].as_f64().unwrap() * 100.0 - 0.6237).abs() < 5e-5);
    assert!((inside["at_rest"].as_f64().unwrap() * 100.0 - 0.6515).abs() < 5e-5);
}

/// The local law is right where a compressible layer is much thinner than the contact, and
/// wrong, the other way, where the layer is thin but nearly incompressible (docs/model.md
/// §8): the row says which.
#[test]
fn the_local_layer_row_tells_a_thin_layer_from_a_squeezed_one() {
    let thin = rolling(json!({"radius": "10 um", "load": "1 uN",
        "layer": {"thickness": "2 nm", "poisson_ratio": 0.35}}))
    .unwrap();
    let local = validity(&thin, "local_layer");
    assert_eq!(local["status"], "ok", "{local}");
    assert!(
        (local["value"].as_f64().unwrap() - 1.0).abs() < 0.01,
        "{local}"
    );
    let squeezed = rolling(json!({"radius": "100 nm", "load": "2 nN",
        "layer": {"thickness": "1 nm", "poisson_ratio": 0.45}}))
    .unwrap();
    let local = validity(&squeezed, "local_layer");
    assert_eq!(local["status"], "warn", "{local}");
    assert!(local["value"].as_f64().unwrap() < 0.91, "{local}");
    assert!(
        local["note"].as_str().unwrap().contains("understates"),
        "{local}"
    );
}

/// A three-body system measures the row on its largest particle at rest, in the
/// Kelvin-layer contact; Hertz's contact treats the layer as a half-space, and has no row.
#[test]
fn a_system_measures_the_local_layer_on_its_largest_particle() {
    let system = |contact: &str| {
        answer(
            json!({"kind": "three_body", "input": {"layer_contact": contact,
            "operating": {"total_load": "1 mN"}}}),
        )
        .unwrap()
    };
    let kelvin = system("kelvin_layer");
    let local = validity(&kelvin, "local_layer");
    assert_eq!(local["status"], "warn");
    assert!(local["value"].as_f64().unwrap() > 2.0, "{local}");
    assert!(local["note"]
        .as_str()
        .unwrap()
        .contains("largest particle's"));
    let hertz = system("hertz");
    let names = hertz["meta"]["validity"]["assumptions"].as_array().unwrap();
    assert!(names.iter().all(|a| a["name"] != "local_layer"));
}

#[test]
fn inputs_mean_one_thing_and_errors_speak_the_users_terms() {
    // -0 is 0: one answer, one key.
    let minus_zero = rolling(json!({"velocity": -0.0})).unwrap();
    let zero = rolling(json!({"velocity": 0})).unwrap();
    assert_eq!(minus_zero["meta"]["input_hash"], zero["meta"]["input_hash"]);
    assert_eq!(minus_zero["centroid_shift"], 0.0);

    let refused = |input: Value| match rolling(input.clone()) {
        Err(e @ (JobError::Schema { .. } | JobError::Invalid(_))) => e.to_string(),
        other => panic!("{input}: {other:?}"),
    };
    let messages = [
        refused(json!(["50 nm", "2 nN", null, null, null])),
        refused(json!({"radius": "25 m^127 m^127 m^3"})),
        refused(json!({"radius": true})),
        refused(json!({"options": {"strips": 1.5}})),
        refused(json!({"options": {"strips": -3}})),
        refused(json!({"options": {"quadrature": 3}})),
        refused(json!({"layer": "thin"})),
        refused(json!({"layer": [1, 2]})),
    ];
    assert!(
        messages[0].contains("expected an object, got a list"),
        "{}",
        messages[0]
    );
    assert!(
        messages[1].contains("unit power out of range"),
        "{}",
        messages[1]
    );
    assert!(
        messages[3].contains("a whole number ≥ 0, got 1.5"),
        "{}",
        messages[3]
    );
    for message in messages {
        for rust in [
            "untagged", "usize", "i64", "u8", "struct", "enum", "variant", "Quantity",
        ] {
            assert!(!message.contains(rust), "{message}");
        }
    }
    match Job::from_json(
        br#"{"kind": "rolling", "input": {"load": 1, "load": 2}}"#,
        &Limits::default(),
    ) {
        Err(JobError::Schema { field, message }) => {
            assert_eq!(field, "input");
            assert!(message.contains("\"load\" is sent twice"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn every_numeric_field_of_every_answer_has_a_unit() {
    fn leaves(value: &Value, at: String, out: &mut Vec<String>) {
        match value {
            Value::Object(map) => {
                for (k, v) in map {
                    if at == "meta" && k == "input" {
                        continue;
                    }
                    let path = if at.is_empty() {
                        k.clone()
                    } else {
                        format!("{at}.{k}")
                    };
                    leaves(v, path, out);
                }
            }
            Value::Array(items) => items.iter().for_each(|v| leaves(v, format!("{at}[]"), out)),
            Value::Number(_) => out.push(at),
            _ => {}
        }
    }
    for job in [
        json!({"kind": "rolling", "input": {"options": {"pressure_grid": 3}}}),
        json!({"kind": "three_body", "input": {"operating": {"total_load": "1 mN"},
            "asperities": {"density": "1e14 m^-2", "tip_radius": "1 um",
                           "height_std": "2 nm", "hardness": "2 GPa"}}}),
        json!({"kind": "sweep", "input": {"vary": {"load": ["1 nN", "2 nN"]}}}),
        json!({"kind": "sweep", "input": {"kind": "three_body",
            "vary": {"separation": ["50 nm"]}}}),
        json!({"kind": "figure", "input": {"number": 3}}),
        serde_json::from_str(include_str!("../../examples/fit.json")).unwrap(),
        json!({"kind": "fit", "input": {"series": [{"quantity": "contact_area", "points": [
            {"load": "1 nN", "value": "90 nm^2"}, {"load": "1.4 nN", "value": "101 nm^2"},
            {"load": "1.2 nN", "value": "95 nm^2"}]}],
            "parameters": {"elastic_modulus": {}, "thickness": {}}}}),
        json!({"kind": "fit", "input": {"series": [{"system": {}, "total_load": "1 mN", "points": [
            {"velocity": 0, "value": 0.023}, {"velocity": "4 nm/s", "value": 0.021},
            {"velocity": "8 nm/s", "value": 0.019}]}],
            "parameters": {"relaxation_time": {}}}}),
    ] {
        let answer = answer(job.clone()).unwrap();
        let units = answer["meta"]["units"].as_object().unwrap();
        let mut paths = Vec::new();
        leaves(&answer, String::new(), &mut paths);
        for path in paths {
            assert!(
                units.contains_key(&path),
                "{}: no unit for {path}",
                job["kind"]
            );
        }
        assert_eq!(
            answer["meta"]["software"]["version"],
            env!("CARGO_PKG_VERSION")
        );
        assert!(!answer["meta"]["software"]["commit"]
            .as_str()
            .unwrap()
            .is_empty());
    }
}

/// A value drawn log-uniformly between 10^lo and 10^hi, as a bare SI number.
fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo..hi).prop_map(|e: f64| 10f64.powf(e))
}

/// Checks an answer: finite numbers only (serde_json writes a non-finite one as null), a
/// validity block, and no violated geometry.
fn honest(answer: &Value) -> Result<(), TestCaseError> {
    let text = answer.to_string();
    prop_assert!(!text.contains("null"), "{}", text);
    let validity = &answer["meta"]["validity"];
    let assumptions = validity["assumptions"].as_array();
    prop_assert!(assumptions.is_some_and(|a| !a.is_empty()), "{}", validity);
    for a in assumptions.into_iter().flatten() {
        let geometry = a["name"] == "inside_layer" || a["name"] == "parabolic_sphere";
        let worst = a["value"]
            .as_f64()
            .unwrap()
            .max(a["at_rest"].as_f64().unwrap());
        prop_assert!(!geometry || worst < 1.0, "{}", a);
    }
    Ok(())
}

fn judge(result: Result<Value, JobError>) -> Result<(), TestCaseError> {
    match result {
        Ok(answer) => honest(&answer),
        Err(JobError::Invalid(_) | JobError::Unsolvable(_) | JobError::OutOfDomain(_)) => Ok(()),
        Err(e) => Err(TestCaseError::fail(format!(
            "not a problem of the input: {e:?}"
        ))),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn every_rolling_answer_is_finite_and_valid_or_a_problem(
        radius in log_uniform(-12.0, 3.0),
        load in log_uniform(-18.0, 3.0),
        velocity in prop_oneof![Just(0.0), log_uniform(-15.0, 2.0)],
        modulus in log_uniform(2.0, 13.0),
        thickness in log_uniform(-10.0, -1.0),
        poisson in 0.0..0.5f64,
        relaxation in log_uniform(-6.0, 6.0),
        kappa in prop_oneof![Just(0.0), log_uniform(-12.0, 4.0)],
    ) {
        judge(rolling(json!({
            "radius": radius, "load": load, "velocity": velocity,
            "layer": {"elastic_modulus": modulus, "thickness": thickness,
                      "poisson_ratio": poisson, "relaxation_time": relaxation,
                      "retardation_time": relaxation * (1.0 + kappa)}})))?;
    }

    #[test]
    fn every_three_body_answer_is_finite_and_valid_or_a_problem(
        mean in log_uniform(-8.5, -6.5),
        spread in 0.0..0.3f64,
        load in log_uniform(-8.0, 1.0),
        velocity in prop_oneof![Just(0.0), log_uniform(-12.0, -3.0)],
        thickness in log_uniform(-8.0, -5.0),
        hertz in any::<bool>(),
    ) {
        judge(answer(json!({"kind": "three_body", "input": {
            "distribution": {"mean_diameter": mean, "std_diameter": mean * spread},
            "layer": {"thickness": thickness},
            "layer_contact": if hertz { "hertz" } else { "kelvin_layer" },
            "velocity": velocity,
            "operating": {"total_load": load}}})))?;
    }
}

#[test]
fn a_number_and_the_same_value_as_a_unit_string_are_one_input() {
    // Decimal texts whose nearest double the default serde_json parser misses by an ulp in
    // a fair share of cases; with float_roundtrip both readings are the correctly rounded one.
    let mut texts = Vec::new();
    for mantissa in [
        "1.2345678901234567",
        "2.5",
        "3.333333333333333",
        "7.0710678118654755",
    ] {
        for exponent in -12..=-3 {
            for digit in 1..=4 {
                texts.push(format!("{mantissa}{digit}e{exponent}"));
            }
        }
    }
    assert!(texts.len() >= 150);
    for text in texts {
        let number: Value = serde_json::from_str(&format!(r#"{{"radius": {text}}}"#)).unwrap();
        let bare = job(json!({"kind": "rolling", "input": number})).unwrap();
        let with_unit =
            job(json!({"kind": "rolling", "input": {"radius": format!("{text} m")}})).unwrap();
        assert_eq!(bare.canonical(), with_unit.canonical(), "{text}");
        assert_eq!(
            bare.canonical()["radius"].as_f64().unwrap(),
            text.parse::<f64>().unwrap()
        );
    }
}
