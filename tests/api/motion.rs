//! Roll or slide over HTTP (docs/model.md §11): every rolling and three-body answer says how
//! its particles move and the friction they transmit, against the counterface the job names.

use serde_json::{json, Value};

use crate::helpers::spawn_app;

fn number(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// The validity row named `name`.
fn row<'a>(answer: &'a Value, name: &str) -> &'a Value {
    answer["meta"]["validity"]["assumptions"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"] == name)
        .unwrap_or_else(|| panic!("no {name} row"))
}

/// The default particle rolls against steel: its friction is μ_roll = μ_r/2 = 0.0213830,
/// not eq. 12's 0.0947, and the pure-rolling row is ok. A weak counterface makes it slide
/// against the upper surface, at that contact's capacity, as another job (another key).
#[tokio::test]
async fn the_default_particle_rolls_and_a_weak_counterface_makes_it_slide() {
    let app = spawn_app(&[]).await;
    let answer = app.answer("/v1/rolling", &json!({})).await;
    let motion = &answer["motion"];
    assert_eq!(motion["mode"], "rolls");
    let need = 0.5 * number(&answer["rolling_resistance_coefficient"]);
    assert!((number(&motion["friction"]) / need - 1.0).abs() < 1e-12);
    assert!((number(&motion["friction"]) - 0.0213830).abs() < 5e-8);
    assert_eq!(motion["layer_capacity"], answer["friction_coefficient"]);
    assert!((number(&motion["upper_capacity"]) - 0.0476).abs() < 5e-5);
    let rolling = row(&answer, "pure_rolling");
    assert_eq!(rolling["status"], "ok");
    assert!(
        (number(&rolling["value"]) / (need / number(&motion["upper_capacity"])) - 1.0).abs()
            < 1e-12
    );
    assert_eq!(
        answer["meta"]["input"]["upper_surface"]["elastic_modulus"],
        210e9
    );

    let weak = json!({"upper_surface": {"shear_strength": "10 MPa"}});
    let response = app.post("/v1/rolling", &weak).await;
    assert_eq!(response.headers()["x-cache"], "miss");
    let answer: Value = response.json().await.unwrap();
    let motion = &answer["motion"];
    assert_eq!(motion["mode"], "slides_at_upper");
    assert_eq!(motion["friction"], motion["upper_capacity"]);
    // τ_u A_u/P with steel's contact area: 10 MPa instead of G₁/1000 = 80.77 MPa.
    let ratio = number(&motion["upper_capacity"]) / 0.047600487352898894;
    assert!(
        (ratio * 80.769_230_769e6 / 10e6 - 1.0).abs() < 1e-9,
        "{ratio}"
    );
    let note = row(&answer, "pure_rolling")["note"].as_str().unwrap();
    assert!(note.contains("slides against the upper surface"), "{note}");

    // As CSV, the motion's columns and its mode.
    let csv = app
        .post_with("/v1/rolling", &[("accept", "text/csv")], &weak)
        .await
        .text()
        .await
        .unwrap();
    let (head, line) = csv.split_once('\n').unwrap();
    let at = |name: &str| head.split(',').position(|h| h.starts_with(name)).unwrap();
    let cells: Vec<&str> = line.trim_end().split(',').collect();
    assert_eq!(cells[at("motion_mode")], "\"slides_at_upper\"");
    let friction: f64 = cells[at("motion_friction")].parse().unwrap();
    assert_eq!(friction, number(&motion["friction"]));
}

/// A counterface out of range is refused naming its field, the value and the range.
#[tokio::test]
async fn a_bad_counterface_is_refused_naming_its_field() {
    let app = spawn_app(&[]).await;
    let response = app
        .post(
            "/v1/rolling",
            &json!({"upper_surface": {"shear_strength": "-1 MPa", "poisson_ratio": 0.7}}),
        )
        .await;
    assert_eq!(response.status(), 422);
    let problem: Value = response.json().await.unwrap();
    let fields: Vec<&str> = problem["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["field"].as_str().unwrap())
        .collect();
    assert!(
        fields.contains(&"upper_surface.shear_strength"),
        "{problem}"
    );
    assert!(fields.contains(&"upper_surface.poisson_ratio"), "{problem}");
    assert!(problem.to_string().contains("> 0 Pa"), "{problem}");
}

/// At the paper's operating point the particles that roll and slide add up to those in
/// contact, the pure-rolling row warns with the count that slides, and the system's own
/// friction is below eq. 12's.
#[tokio::test]
async fn a_system_counts_the_particles_that_roll_and_slide() {
    let app = spawn_app(&[]).await;
    let answer = app
        .answer(
            "/v1/three-body",
            &json!({"operating": {"total_load": "1 mN"}}),
        )
        .await;
    let motion = &answer["motion"];
    let counted = number(&motion["rolling"])
        + number(&motion["sliding_at_layer"])
        + number(&motion["sliding_at_upper"]);
    let in_contact = number(&answer["particles_in_contact"]);
    assert!(
        (counted / in_contact - 1.0).abs() < 1e-9,
        "{counted} vs {in_contact}"
    );
    let friction = number(&motion["friction"]);
    let traction = number(&motion["particle_traction"]);
    assert!((friction / (traction / number(&answer["loads"]["total"])) - 1.0).abs() < 1e-12);
    assert!(friction < number(&answer["friction_coefficient"]["rolling"]));
    let changes = motion["changes"].as_array().unwrap();
    assert_eq!(changes[0]["below"], "rolls");
    // The particle furthest from rolling, the largest, slides on the layer.
    let furthest = &motion["furthest"];
    assert_eq!(furthest["mode"], "slides_at_layer");
    assert_eq!(furthest["friction"], furthest["layer_capacity"]);
    assert!(number(&furthest["rolling_need"]) > number(&furthest["layer_capacity"]));
    let rolling = row(&answer, "pure_rolling");
    assert_eq!(rolling["status"], "warn");
    let note = rolling["note"].as_str().unwrap();
    assert!(
        note.contains("18,900 of the 54,500 particles in contact slide"),
        "{note}"
    );
}
