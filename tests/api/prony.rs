//! Layers from material data over HTTP (docs/model.md §9): a Prony series as JSON or CSV,
//! its WLF shift to the job's temperature, both layer laws, fits of a modulus scale and a
//! shift factor, and problems naming the field for what cannot be read.

use serde_json::{json, Value};
use thirdbody::model::{Layer, Rolling, SolveOptions};

use crate::helpers::{problem, spawn_app, TestApp};

/// The answer of a rolling job with `layer`, as JSON.
async fn rolling(app: &TestApp, layer: Value) -> Value {
    let input = json!({"radius": "25 nm", "load": "1 nN", "velocity": "4 nm/s", "layer": layer});
    let response = app.post("/v1/rolling", &input).await;
    assert_eq!(response.status(), 200, "{layer}");
    response.json().await.unwrap()
}

/// δ, A, x_c, x_p and μ of two answers within `tolerance` (relative) of each other.
fn assert_same(a: &Value, b: &Value, tolerance: f64) {
    for name in [
        "penetration",
        "contact_area",
        "centroid_shift",
        "pressure_centre_shift",
        "friction_coefficient",
    ] {
        let (x, y) = (a[name].as_f64().unwrap(), b[name].as_f64().unwrap());
        assert!((x / y - 1.0).abs() <= tolerance, "{name}: {x:e} vs {y:e}");
    }
}

/// A four-term series as a DMA fit gives one: (τ_j in s, E_j in Pa).
const SERIES: [(f64, f64); 4] = [(0.01, 6e9), (0.1, 4.5e9), (1.0, 3e9), (10.0, 1.5e9)];

fn series_json(factor: f64) -> Value {
    SERIES
        .iter()
        .map(|(t, e)| json!({"time": t * factor, "modulus": e}))
        .collect()
}

/// E_∞ = E_L, E₁ = κE_L, τ₁ = T_σ is the paper's layer: to 1e-9 on the local law (the
/// series is solved by strip sums, the Kelvin layer through its similarity table), within
/// the answers' own errors on the continuum.
#[tokio::test]
async fn a_one_term_series_is_the_papers_layer_on_both_laws() {
    let app = spawn_app(&[]).await;
    for model in ["local", "continuum"] {
        let kelvin = rolling(&app, json!({"model": model})).await;
        let prony = rolling(
            &app,
            json!({"model": model, "elastic_modulus": "3 GPa",
                   "prony": [{"modulus": "12 GPa", "time": "100 ms"}]}),
        )
        .await;
        let tolerance = match model {
            "local" => 1e-9,
            _ => ["penetration_error", "contact_area_error"]
                .iter()
                .map(|e| kelvin["meta"]["verification"][e].as_f64().unwrap())
                .fold(0.0, f64::max),
        };
        assert_same(&prony, &kelvin, tolerance);
        let layer = &prony["meta"]["input"]["layer"];
        assert_eq!(layer["prony"][0]["time"], 0.1, "{layer}");
    }
}

#[tokio::test]
async fn a_series_reads_the_same_as_json_and_as_csv() {
    let app = spawn_app(&[]).await;
    let json_answer = rolling(&app, json!({"prony": series_json(1.0)})).await;
    let csv: String = std::iter::once("tau_s,E_Pa".to_string())
        .chain(SERIES.iter().map(|(t, e)| format!("{t},{e}")))
        .collect::<Vec<_>>()
        .join("\n");
    let csv_answer = rolling(&app, json!({"prony_csv": csv})).await;
    assert_same(&csv_answer, &json_answer, 0.0);
    // Units in the cells, semicolons, no header.
    let typed = "10 ms; 6 GPa\n100 ms; 4.5 GPa\n1 s; 3 GPa\n10 s; 1.5 GPa\n";
    let typed_answer = rolling(&app, json!({"prony_csv": typed})).await;
    assert_same(&typed_answer, &json_answer, 0.0);
    // The canonical form writes the series back.
    let prony = &json_answer["meta"]["input"]["layer"]["prony"];
    assert_eq!(prony.as_array().unwrap().len(), 4, "{prony}");
    // Rolling over four decades of times: the area lies between the relaxed and the
    // instantaneous contacts.
    let area = json_answer["contact_area"].as_f64().unwrap();
    let at_rest = json_answer["static"]["contact_area"].as_f64().unwrap();
    let stiffening: f64 = 1.0 + SERIES.iter().map(|(_, e)| e / 3e9).sum::<f64>();
    assert!(area < at_rest && area > at_rest / stiffening.sqrt());
}

#[tokio::test]
async fn a_wlf_shift_of_some_decades_is_the_series_with_its_times_scaled() {
    let app = spawn_app(&[]).await;
    let (c1, c2) = (17.44, 51.6);
    for (reference, temperature, t_ref_k, t_k) in [
        ("25 °C", "35 °C", 298.15, 308.15),
        ("300 K", "290 K", 300.0, 290.0),
    ] {
        let shifted = rolling(
            &app,
            json!({"prony": series_json(1.0), "temperature": temperature,
                   "wlf": {"reference_temperature": reference, "c1": c1, "c2": c2}}),
        )
        .await;
        let decades: f64 = -c1 * (t_k - t_ref_k) / (c2 + t_k - t_ref_k);
        let scaled = rolling(&app, json!({"prony": series_json(10f64.powf(decades))})).await;
        assert_same(&shifted, &scaled, 1e-12);
    }
    // Warmer is faster relaxation: at one speed the contact is larger (softer).
    let at = |t: &'static str| {
        json!({"prony": series_json(1.0), "temperature": t,
               "wlf": {"reference_temperature": "25 °C", "c1": c1, "c2": c2}})
    };
    let warm = rolling(&app, at("60 °C")).await;
    let cold = rolling(&app, at("0 °C")).await;
    assert!(warm["contact_area"].as_f64() > cold["contact_area"].as_f64());
}

#[tokio::test]
async fn what_cannot_be_read_gets_a_problem_naming_the_field() {
    let app = spawn_app(&[]).await;
    let cases = [
        (
            json!({"prony": series_json(1.0), "relaxation_time": "100 ms"}),
            "layer.relaxation_time",
            "Prony",
        ),
        (
            json!({"prony_csv": "0.1,12e9\n0.2\n1 s,twelve"}),
            "layer.prony_csv",
            "row 2",
        ),
        (
            json!({"prony": [{"modulus": "-1 GPa", "time": "1 s"}]}),
            "layer.prony[0].modulus",
            "> 0",
        ),
        (
            json!({"prony": (0..25).map(|i| json!({"modulus": 1e9, "time": 10f64.powi(i - 12)})).collect::<Vec<_>>()}),
            "layer.prony",
            "24 terms",
        ),
        (json!({"temperature": "40 °C"}), "layer.temperature", "wlf"),
        (
            json!({"temperature": "-30 °C", "wlf": {"reference_temperature": "25 °C", "c1": 17.44, "c2": 51.6}}),
            "layer.temperature",
            "pole",
        ),
        (
            json!({"temperature": "30 °C", "wlf": {"reference_temperature": "25 °C", "c1": 17.44}}),
            "layer.wlf.c2",
            "required",
        ),
    ];
    for (layer, field, says) in cases {
        let input = json!({"layer": layer});
        let body = problem(app.post("/v1/rolling", &input).await, 422).await;
        let error = body["errors"]
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["field"] == field)
            .unwrap_or_else(|| panic!("no error at {field}: {body}"));
        let message = error["message"].as_str().unwrap();
        assert!(message.contains(says), "{field}: {message}");
    }
}

/// Noise-free friction from a layer twice as stiff and ten times slower than the series as
/// given: the fit finds both factors to 1e-4, with the series' shape held.
#[tokio::test]
async fn a_fit_finds_the_modulus_scale_and_shift_factor_of_a_series() {
    let app = spawn_app(&[]).await;
    let terms: Vec<(f64, f64)> = SERIES.iter().map(|&(t, e)| (e, t)).collect();
    let base = Layer::from_prony(3e9, 100e-9, 0.35, &terms).unwrap();
    let truth = Layer {
        elastic_modulus: 2.0 * base.elastic_modulus,
        ..base.with_times_scaled(10.0)
    };
    let points: Vec<Value> = [0.0, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0]
        .iter()
        .map(|&v| {
            let rolling = Rolling {
                velocity: v * 1e-9,
                layer: truth,
                ..Rolling::default()
            };
            let options = SolveOptions::integrals_only(Default::default());
            let mu = thirdbody::model::solve(&rolling, &options)
                .unwrap()
                .friction_coefficient;
            json!({"velocity": format!("{v} nm/s"), "value": mu})
        })
        .collect();
    let input = json!({"layer": {"prony": series_json(1.0)},
                       "series": [{"points": points}],
                       "parameters": {"modulus_scale": {}, "shift_factor": {}}});
    let answer = app.answer("/v1/fits", &input).await;
    for (name, expected) in [("modulus_scale", 2.0), ("shift_factor", 10.0)] {
        let value = answer["parameters"][name]["value"].as_f64().unwrap();
        assert!((value / expected - 1.0).abs() < 1e-4, "{name}: {value}");
    }
    // Its single times are not what such a layer is fitted by.
    let input = json!({"layer": {"prony": series_json(1.0)},
                       "series": [{"points": points}],
                       "parameters": {"relaxation_time": {}}});
    let body = problem(app.post("/v1/fits", &input).await, 422).await;
    assert_eq!(
        body["errors"][0]["field"], "parameters.relaxation_time",
        "{body}"
    );
}

/// The README's layer (its μ 0.0497 at 20 °C) with its series as CSV text `csv`.
fn readme_layer(csv: &str) -> Value {
    json!({"elastic_modulus": "3 GPa", "prony_csv": csv,
           "wlf": {"reference_temperature": "25 °C", "c1": 17.44, "c2": 51.6},
           "temperature": "20 °C"})
}

/// A header's units are its columns' units, in each of its spellings: the same answer as
/// the rows in SI, to the bit (a header `tau [ms]` was read as seconds: μ 0.1137 for
/// 0.0497). A cell with a unit of its own keeps it.
#[tokio::test]
async fn a_header_s_units_are_the_units_of_its_columns() {
    let app = spawn_app(&[]).await;
    let si = rolling(
        &app,
        readme_layer("tau_s,E_Pa\n0.01,6e9\n0.1,4.5e9\n1,3e9\n10,1.5e9"),
    )
    .await;
    let mu = si["friction_coefficient"].as_f64().unwrap();
    assert_eq!(format!("{mu:.4}"), "0.0497", "the README's example");
    for csv in [
        "tau [ms],E [GPa]\n10,6\n100,4.5\n1000,3\n10000,1.5",
        "tau (ms); E (GPa)\n10; 6\n100; 4.5\n1000; 3\n10000; 1.5",
        "tau_ms\tE_MPa\n10\t6000\n100\t4500\n1000\t3000\n10000\t1500",
        "τ/ms,E/GPa\n10,6\n100,4.5\n1 s,3 GPa\n10000,1.5",
    ] {
        let answer = rolling(&app, readme_layer(csv)).await;
        assert_same(&answer, &si, 0.0);
        assert_eq!(answer["meta"]["warnings"], json!([]), "{csv}");
    }
}

/// A header whose unit cannot be read refuses the series, naming the cell and what a
/// header may be: never read as SI.
#[tokio::test]
async fn a_header_s_unit_that_cannot_be_read_is_422_naming_it() {
    let app = spawn_app(&[]).await;
    let forms = "expected a header naming each column's unit as \"tau [ms]\", \"tau (ms)\", \
        \"tau/ms\" or \"tau_ms\" (an SI unit with an SI prefix: a time, then a pressure such \
        as \"E [GPa]\"), or no unit for numbers in s and Pa";
    for (csv, value, whats) in [
        (
            "tau [min],E [GPa]\n10,6",
            "tau [min],E [GPa]",
            &[
                "the header's \"tau [min]\" has an unknown unit \"min\" (SI symbols m, g, s, N, \
               Pa, K with SI prefixes, or °C)",
            ][..],
        ),
        (
            "tau [ms],E_psi\n10,6",
            "tau [ms],E_psi",
            &[
                "the header's \"E_psi\" has an unknown unit \"psi\" (SI symbols m, g, s, N, Pa, \
               K with SI prefixes, or °C)",
            ],
        ),
        (
            "E [GPa],tau [ms]\n6,10",
            "E [GPa],tau [ms]",
            &[
                "the header's \"E [GPa]\" names a pressure, and its column holds τ_j, a time",
                "the header's \"tau [ms]\" names a time, and its column holds E_j, a pressure",
            ],
        ),
    ] {
        let input = json!({"layer": {"prony_csv": csv}});
        let body = problem(app.post("/v1/rolling", &input).await, 422).await;
        let expected: Vec<Value> = whats
            .iter()
            .map(|what| {
                let allowed = format!("row 1: {what}; {forms}");
                let message = format!(
                    "layer.prony_csv: \"{value}\" is not a valid value; expected {allowed}"
                );
                json!({"field": "layer.prony_csv", "value": value, "allowed": allowed,
                       "message": message})
            })
            .collect();
        // The header alone: its rows are not read under it.
        assert_eq!(body["errors"], json!(expected), "{csv}");
    }
}

/// Bare numbers in the rows are warned of as a bare number in a field of its own is (a
/// modulus below 1 kPa, a time above 1e6 s), each naming its row and column; under a
/// header's unit they are not bare.
#[tokio::test]
async fn implausible_bare_numbers_in_the_rows_are_warned_of() {
    let app = spawn_app(&[]).await;
    let answer = rolling(&app, json!({"prony_csv": "tau,E\n0.1,6\n2e6,3e9"})).await;
    assert_eq!(
        answer["meta"]["warnings"],
        json!([
            {"field": "layer.prony_csv", "value": "6",
             "message": "layer.prony_csv (row 2, E_j): 6 is 6 Pa; did you mean \"6 GPa\"?"},
            {"field": "layer.prony_csv", "value": "2e6",
             "message": "layer.prony_csv (row 3, τ_j): 2e6 is 2e6 s; did you mean \"2e6 ms\"?"},
        ])
    );
    // As the same numbers given as JSON terms are.
    let json_terms = rolling(
        &app,
        json!({"prony": [{"time": 0.1, "modulus": 6}, {"time": 2e6, "modulus": 3e9}]}),
    )
    .await;
    let messages = |answer: &Value| -> Vec<String> {
        let warnings = answer["meta"]["warnings"].as_array().unwrap();
        warnings
            .iter()
            .map(|w| {
                w["message"]
                    .as_str()
                    .unwrap()
                    .split(": ")
                    .nth(1)
                    .unwrap()
                    .to_string()
            })
            .collect()
    };
    assert_eq!(messages(&answer), messages(&json_terms));
    let under_units = rolling(&app, json!({"prony_csv": "tau [s],E [GPa]\n0.1,6"})).await;
    assert_eq!(under_units["meta"]["warnings"], json!([]));
}

/// A 900 kB cell is echoed cut to 100 characters, in the error's value, its allowed values,
/// its message and the detail: a problem of a few kB naming the field (it was 5.4 MB).
#[tokio::test]
async fn a_huge_bad_cell_is_echoed_cut() {
    let app = spawn_app(&[]).await;
    let huge = "x".repeat(900_000);
    let input = json!({"layer": {"prony_csv": format!("tau_s,E_Pa\n0.1,{huge}")}});
    let response = app.post("/v1/rolling", &input).await;
    assert_eq!(response.status(), 422);
    let text = response.text().await.unwrap();
    assert!(text.len() < 4000, "{} bytes: {}", text.len(), &text[..2000]);
    let body: Value = serde_json::from_str(&text).unwrap();
    let error = &body["errors"][0];
    assert_eq!(error["field"], "layer.prony_csv");
    let cut = format!("0.1,{}…", "x".repeat(96));
    assert_eq!(error["value"], cut.as_str());
    let head = format!("\"{}…\"", "x".repeat(100));
    assert_eq!(
        error["allowed"],
        format!(
            "row 2: {head} does not start with a number; expected rows \"τ_j, E_j\" such as \
             \"0.1, 12e9\" or \"100 ms, 12 GPa\""
        )
    );
    assert_eq!(
        error["message"],
        format!(
            "layer.prony_csv: \"{cut}\" is not a valid value; expected {}",
            error["allowed"].as_str().unwrap()
        )
    );
    assert_eq!(body["detail"], error["message"]);
}

/// Issue 47: a lab's Young's modulus E is read as the constrained modulus E_L the layer law
/// takes, E_L = E(1 − ν)/((1 + ν)(1 − 2ν)) (docs/model.md §8): E = 1 GPa at ν = 0.25 is
/// E_L = 1.2 GPa, the same job (one canonical input, one cache key, one answer) on both
/// laws. Both moduli at once are refused, naming the field.
#[tokio::test]
async fn a_youngs_modulus_is_the_constrained_modulus_it_makes() {
    let app = spawn_app(&[]).await;
    for model in ["local", "continuum"] {
        let youngs = json!({"model": model, "youngs_modulus": "1 GPa", "poisson_ratio": 0.25});
        let constrained = json!({"model": model, "elastic_modulus": 1.2e9, "poisson_ratio": 0.25});
        let (a, b) = (
            rolling(&app, youngs).await,
            rolling(&app, constrained).await,
        );
        assert_eq!(a["meta"]["input_hash"], b["meta"]["input_hash"], "{model}");
        assert_eq!(a["meta"]["input"]["layer"]["elastic_modulus"], json!(1.2e9));
        assert_same(&a, &b, 0.0);
    }
    let both = json!({"layer": {"elastic_modulus": "3 GPa", "youngs_modulus": "2 GPa"}});
    let refused = problem(app.post("/v1/rolling", &both).await, 422).await;
    assert_eq!(
        refused["errors"][0]["field"], "layer.youngs_modulus",
        "{refused}"
    );
    let allowed = refused["errors"][0]["allowed"].as_str().unwrap();
    assert!(allowed.contains("absent with elastic_modulus"), "{allowed}");
    let bad = json!({"layer": {"youngs_modulus": "-2 GPa"}});
    let refused = problem(app.post("/v1/rolling", &bad).await, 422).await;
    assert_eq!(
        refused["errors"][0]["field"], "layer.youngs_modulus",
        "{refused}"
    );
    assert_eq!(refused["errors"][0]["value"], "-2 GPa", "{refused}");
    // A ν out of range is blamed alone, not the modulus it would have converted.
    let bad_nu = json!({"layer": {"youngs_modulus": "2 GPa", "poisson_ratio": 0.7}});
    let refused = problem(app.post("/v1/rolling", &bad_nu).await, 422).await;
    let errors = refused["errors"].as_array().unwrap();
    assert_eq!(errors.len(), 1, "{refused}");
    assert_eq!(errors[0]["field"], "layer.poisson_ratio", "{refused}");
    // An E whose E_L passes double precision is refused at E, saying why.
    let huge = json!({"layer": {"youngs_modulus": 1e308, "poisson_ratio": 0.49}});
    let refused = problem(app.post("/v1/rolling", &huge).await, 422).await;
    assert_eq!(
        refused["errors"][0]["field"], "layer.youngs_modulus",
        "{refused}"
    );
    let allowed = refused["errors"][0]["allowed"].as_str().unwrap();
    assert!(
        allowed.contains("at ν = 0.49") && allowed.contains("E_L"),
        "{allowed}"
    );
}
