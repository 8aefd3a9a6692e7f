//! Fitting the layer as a continuum (issue 24, docs/model.md §8): `"layer": {"model":
//! "continuum"}` on a fit. At rest the continuum sees E_L and H apart where the contact is
//! about as wide as the layer (the local law's static friction fixes only E_L·H): noiseless
//! static friction gives both back to 1e-4, and with noise of known σ the 95 % intervals
//! hold the truth 90–99 % of the time over 50 seeded fits. Rolling, the continuum gives the
//! times back to within its grid's scatter (a few per cent).

use serde_json::{json, Value};
use thirdbody::model::fit::{Law, Measured, Point, Setting};
use thirdbody::model::{Layer, Stop};

use crate::fit::{against_speed, fit, value, Noise};

/// A layer 5 nm thick: contacts of 2–6 nm radius at these loads, as wide as it is thick.
fn thin() -> Layer {
    Layer {
        thickness: 5e-9,
        ..Layer::default()
    }
}

/// μ on the continuum on `layer` at R = `radius` nm, P = `load` nN, V = `speed` nm/s.
fn friction(layer: &Layer, radius: f64, load: f64, speed: f64) -> f64 {
    let point = Point {
        setting: Setting::Particle {
            radius: radius * 1e-9,
            load: load * 1e-9,
            upper: Default::default(),
        },
        velocity: speed * 1e-9,
        measured: Measured::FrictionCoefficient,
    };
    point.value(layer, Law::Continuum, Stop::NEVER).unwrap()
}

/// Radius (nm) and load (nN) of the static points.
const AT_REST: [(f64, f64); 6] = [
    (10.0, 0.05),
    (10.0, 1.0),
    (25.0, 0.2),
    (25.0, 5.0),
    (50.0, 1.0),
    (50.0, 20.0),
];

/// μ at rest on `layer` on the continuum at each of [`AT_REST`], times (1 + `sigma` × a
/// normal deviate); the points carry that relative uncertainty if `sigma` > 0.
fn static_friction(layer: &Layer, sigma: f64, noise: &mut Noise) -> Vec<Value> {
    AT_REST
        .iter()
        .map(|&(radius, load)| {
            let exact = friction(layer, radius, load, 0.0);
            let mut series = json!({"radius": format!("{radius} nm"), "load": format!("{load} nN"),
                "points": [{"velocity": "0 nm/s", "value": exact * (1.0 + sigma * noise.normal())}]});
            if sigma > 0.0 {
                series["points"][0]["uncertainty"] = json!(sigma * exact);
            }
            series
        })
        .collect()
}

/// The fit of E_L and H on the continuum (or `law`) to `series`, from 2 GPa and 8 nm.
fn modulus_and_thickness(series: Vec<Value>, model: &str) -> Value {
    fit(json!({
        "layer": {"model": model, "elastic_modulus": "2 GPa", "thickness": "8 nm"},
        "series": series,
        "parameters": {"elastic_modulus": {"min": "0.1 GPa", "max": "100 GPa"},
                       "thickness": {"min": "0.5 nm", "max": "100 nm"}}}))
    .unwrap()
}

#[test]
fn noiseless_static_friction_gives_back_modulus_and_thickness_on_the_continuum() {
    let truth = thin();
    let series = static_friction(&truth, 0.0, &mut Noise(1));
    let answer = modulus_and_thickness(series.clone(), "continuum");
    for (name, expected) in [
        ("elastic_modulus", truth.elastic_modulus),
        ("thickness", truth.thickness),
    ] {
        let got = value(&answer, name);
        assert!(
            (got / expected - 1.0).abs() < 1e-4,
            "{name}: {got} vs {expected}"
        );
    }
    assert_eq!(answer["identifiability"]["identifiable"], true, "{answer}");
    assert_eq!(answer["meta"]["input"]["layer"]["model"], "continuum");
    assert!(answer["meta"]["references"].to_string().contains("Carbone"));
    // The local law at rest sees E_L·H alone: the same data leave it one combination.
    let local = modulus_and_thickness(series, "local");
    assert_eq!(local["identifiability"]["identifiable"], false, "{local}");
}

#[test]
fn the_truth_lies_in_the_95_percent_interval_90_to_99_percent_of_the_time_on_the_continuum() {
    let truth = thin();
    let fits: Vec<[bool; 2]> = std::thread::scope(|s| {
        let runs: Vec<_> = (0..2u64)
            .map(|thread| {
                s.spawn(move || {
                    (0..25u64)
                        .map(|i| {
                            let seed = 2 * i + thread;
                            let mut noise = Noise(0x2545_F491_4F6C_DD1D ^ (seed + 1));
                            let series = static_friction(&truth, 0.01, &mut noise);
                            let answer = modulus_and_thickness(series, "continuum");
                            [
                                ("elastic_modulus", truth.elastic_modulus),
                                ("thickness", truth.thickness),
                            ]
                            .map(|(name, t)| {
                                let interval = &answer["parameters"][name]["interval_95"];
                                let lo = interval[0].as_f64().unwrap();
                                let hi = interval[1].as_f64().unwrap();
                                lo <= t && t <= hi
                            })
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        runs.into_iter().flat_map(|r| r.join().unwrap()).collect()
    });
    assert_eq!(fits.len(), 50);
    let held = fits.iter().flatten().filter(|&&h| h).count();
    eprintln!("continuum coverage: {held} of 100 intervals");
    assert!((90..=99).contains(&held), "{held} of 100");
}

/// Rolling friction on the continuum (the grid, whose area moves in steps of up to 4e-3 as
/// T_σ moves, which leaves the minimum a few per cent wide): T_σ comes back from noiseless
/// μ(V) within 3 %.
#[test]
fn noiseless_rolling_friction_gives_back_the_relaxation_time_on_the_continuum() {
    let truth = Layer::default();
    let points = against_speed(&[2.0, 8.0], |speed| friction(&truth, 25.0, 1.0, speed));
    let answer = fit(json!({
        "layer": {"model": "continuum", "relaxation_time": "60 ms"},
        "series": [{"radius": "25 nm", "load": "1 nN", "points": points}],
        "parameters": {"relaxation_time": {"min": "10 ms", "max": "400 ms"}}}))
    .unwrap();
    let got = value(&answer, "relaxation_time");
    assert!((got / truth.relaxation_time - 1.0).abs() < 3e-2, "{got}");
}
