//! Fitting the layer to measurements (job kind `fit`): synthetic data from the forward model
//! with known parameters. Noiseless data give the truth back to 1e-6; with Gaussian noise of
//! known σ the truth lies in the 95 % interval in at least 90 of 100 seeded repetitions
//! (with the uncertainties given, and with them estimated from the scatter); combinations
//! the data cannot separate are reported as such; bounds hold; bad data get problems; a
//! cancel stops a running fit within 100 ms.

use std::sync::Arc;
use std::time::{Duration, Instant};

use serde_json::{json, Value};
use thirdbody::job::{Control, Job, JobError, Limits};
use thirdbody::model::counterface::UpperSurface;
use thirdbody::model::fit::{Law, Measured, Point, Setting};
use thirdbody::model::motion::{self, Mode};
use thirdbody::model::three_body::{OperatingPoint, ThreeBody, ThreeBodyOptions};
use thirdbody::model::{solve, Layer, Rolling, SolveOptions, Stop};
use thirdbody::render::Format;

/// The answer to the fit `input`, as JSON.
pub fn fit(input: Value) -> Result<Value, JobError> {
    let job = Job::from_value(json!({"kind": "fit", "input": input}), &Limits::default())?;
    let answer = job.run(job.meta(), &Control::default())?;
    Ok(serde_json::from_slice(&answer.render(Format::Json).unwrap()).unwrap())
}

/// The model's value on `layer` at R = `radius` nm, P = `load` nN, V = `speed` nm/s.
fn model(layer: &Layer, measured: Measured, radius: f64, load: f64, speed: f64) -> f64 {
    let point = Point {
        setting: Setting::Particle {
            radius: radius * 1e-9,
            load: load * 1e-9,
            upper: Default::default(),
        },
        velocity: speed * 1e-9,
        measured,
    };
    point.value(layer, Law::Local, Stop::NEVER).unwrap()
}

/// Normal deviates from a seeded xorshift generator (Box–Muller).
pub struct Noise(pub u64);

impl Noise {
    pub fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    pub fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}

const SPEEDS: [f64; 12] = [
    0.0, 0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0, 15.0, 20.0, 30.0,
];

/// μ(V) at R = 25 nm, P = `load` nN on `layer`, each value plus `sigma` × a normal deviate;
/// the points carry `sigma` as their uncertainty if `given`.
fn friction_series(layer: &Layer, load: f64, sigma: f64, noise: &mut Noise, given: bool) -> Value {
    let points: Vec<Value> = SPEEDS
        .iter()
        .map(|&v| {
            let value =
                model(layer, Measured::FrictionCoefficient, 25.0, load, v) + sigma * noise.normal();
            let mut point = json!({"velocity": format!("{v} nm/s"), "value": value});
            if given {
                point["uncertainty"] = json!(sigma);
            }
            point
        })
        .collect();
    json!({"radius": "25 nm", "load": format!("{load} nN"), "quantity": "friction_coefficient",
           "points": points})
}

pub fn value(answer: &Value, name: &str) -> f64 {
    answer["parameters"][name]["value"].as_f64().unwrap()
}

#[test]
fn noiseless_data_give_back_three_parameters_to_1e_6() {
    let truth = Layer::default();
    let mut silent = Noise(1);
    let series = [0.6, 1.4].map(|load| friction_series(&truth, load, 0.0, &mut silent, false));
    let answer = fit(json!({
        "layer": {"elastic_modulus": "1 GPa", "relaxation_time": "30 ms", "retardation_time": "1 s"},
        "series": series,
        "parameters": {"relaxation_time": {}, "retardation_time": {}, "elastic_modulus": {}}}))
    .unwrap();
    for (name, expected) in [
        ("relaxation_time", truth.relaxation_time),
        ("retardation_time", truth.retardation_time),
        ("elastic_modulus", truth.elastic_modulus),
    ] {
        let got = value(&answer, name);
        assert!(
            (got / expected - 1.0).abs() < 1e-6,
            "{name}: {got} vs {expected}"
        );
    }
    assert!(answer["chi_squared"].as_f64().unwrap() < 1e-20);
    assert_eq!(answer["dof"], 2 * SPEEDS.len() - 3);
    assert_eq!(answer["identifiability"]["identifiable"], true);
    assert_eq!(answer["uncertainties"], "from_scatter");
    assert_eq!(
        answer["parameter_names"],
        json!(["relaxation_time", "retardation_time", "elastic_modulus"])
    );
    let correlation = answer["correlation"].as_array().unwrap();
    assert_eq!(correlation.len(), 3);
    for (i, row) in correlation.iter().enumerate() {
        assert_eq!(row[i], 1.0);
    }
    // The fitted curve passes through every (noiseless) point.
    for r in answer["residuals"].as_array().unwrap() {
        let c = &r["friction_coefficient"];
        let (measured, fitted) = (
            c["measured"].as_f64().unwrap(),
            c["fitted"].as_f64().unwrap(),
        );
        assert!((fitted / measured - 1.0).abs() < 1e-9, "{r}");
    }
}

/// In how many of 100 noisy repetitions each parameter's 95 % interval holds the truth.
fn coverage(given: bool) -> [usize; 2] {
    let truth = Layer::default();
    let mut hits = [0, 0];
    for seed in 0..100 {
        let mut noise = Noise(0x9E37_79B9_7F4A_7C15 ^ (seed + 1));
        let series = friction_series(&truth, 1.0, 0.002, &mut noise, given);
        let answer = fit(json!({
            "series": [series],
            "parameters": {"relaxation_time": {"start": "50 ms"}, "retardation_time": {"start": "1 s"}}}))
        .unwrap();
        for (i, (name, t)) in [
            ("relaxation_time", truth.relaxation_time),
            ("retardation_time", truth.retardation_time),
        ]
        .into_iter()
        .enumerate()
        {
            let interval = &answer["parameters"][name]["interval_95"];
            let (lo, hi) = (interval[0].as_f64().unwrap(), interval[1].as_f64().unwrap());
            if lo <= t && t <= hi {
                hits[i] += 1;
            }
        }
    }
    hits
}

#[test]
fn the_truth_lies_in_the_95_percent_interval_in_at_least_90_of_100_noisy_fits() {
    let given = coverage(true);
    let scatter = coverage(false);
    eprintln!("coverage: uncertainties given {given:?}, from the scatter {scatter:?}");
    assert!(given.iter().all(|&n| n >= 90), "{given:?}");
    assert!(scatter.iter().all(|&n| n >= 90), "{scatter:?}");
}

#[test]
fn modulus_and_thickness_from_friction_at_rest_are_reported_as_one_combination() {
    // At rest μ₀ = √(π R H E_L / P)/(1000(1 + ν)): only E_L·H shows.
    let truth = Layer::default();
    let points: Vec<Value> = [0.8, 1.0, 1.2, 1.4]
        .iter()
        .map(|&p| {
            let mu = model(&truth, Measured::FrictionCoefficient, 25.0, p, 0.0);
            json!({"load": format!("{p} nN"), "value": mu, "uncertainty": 1e-3})
        })
        .collect();
    let answer = fit(json!({
        "series": [{"velocity": 0, "points": points}],
        "parameters": {"elastic_modulus": {"start": "1 GPa"}, "thickness": {"start": "50 nm"}}}))
    .unwrap();
    let id = &answer["identifiability"];
    assert_eq!(id["identifiable"], false, "{id}");
    assert_eq!(id["determined"], json!([]));
    let combination = &id["undetermined"][0];
    assert_eq!(
        combination["parameters"],
        json!(["elastic_modulus", "thickness"])
    );
    let direction = &combination["direction"];
    assert_eq!(direction["elastic_modulus"].as_f64().unwrap().abs(), 1.0);
    assert_eq!(direction["thickness"].as_f64().unwrap().abs(), 1.0);
    assert!(
        direction["elastic_modulus"].as_f64().unwrap() * direction["thickness"].as_f64().unwrap()
            < 0.0
    );
    assert!(
        combination["message"]
            .as_str()
            .unwrap()
            .contains("Only elastic_modulus · thickness is determined"),
        "{combination}"
    );
    for name in ["elastic_modulus", "thickness"] {
        let estimate = &answer["parameters"][name];
        assert_eq!(estimate["determined"], false);
        assert!(estimate.get("standard_error").is_none() && estimate.get("interval_95").is_none());
    }
    // The product is fitted exactly.
    let product = value(&answer, "elastic_modulus") * value(&answer, "thickness");
    assert!((product / (truth.elastic_modulus * truth.thickness) - 1.0).abs() < 1e-6);
}

#[test]
fn all_four_from_friction_at_one_load_leave_one_direction_free() {
    // μ = τ_a A₀ α(ξ, κ)/P with τ_a A₀ ∝ √(E_L H) and ξ ∝ V T_σ (E_L/H)^{1/4}: along
    // ln E_L +1, ln H −1, ln T_σ −1/2 at fixed κ, neither changes. So T_σ is not determined
    // alone either, only T_σ (E_L/H)^{1/4}; κ is.
    let truth = Layer::default();
    let mut silent = Noise(1);
    let answer = fit(json!({
        "series": [friction_series(&truth, 1.0, 0.0, &mut silent, false)],
        "layer": {"relaxation_time": "50 ms", "retardation_time": "400 ms"},
        "parameters": {"relaxation_time": {}, "kappa": {}, "elastic_modulus": {}, "thickness": {}}}))
    .unwrap();
    let id = &answer["identifiability"];
    assert_eq!(id["identifiable"], false, "{id}");
    assert_eq!(id["determined"], json!(["kappa"]), "{id}");
    let kappa = value(&answer, "kappa");
    assert!((kappa / truth.kappa() - 1.0).abs() < 1e-6, "{kappa}");
    let combination = &id["undetermined"][0];
    assert_eq!(
        combination["parameters"],
        json!(["relaxation_time", "elastic_modulus", "thickness"])
    );
    let d = |name: &str| combination["direction"][name].as_f64().unwrap();
    let sign = d("elastic_modulus").signum();
    assert!(
        (d("elastic_modulus") * sign - 1.0).abs() < 1e-3,
        "{combination}"
    );
    assert!((d("thickness") * sign + 1.0).abs() < 1e-3, "{combination}");
    assert!(
        (d("relaxation_time") * sign + 0.5).abs() < 1e-3,
        "{combination}"
    );
}

/// The system friction coefficient of the default three-body system on `layer` at total
/// load W = `total_load` mN and V = `speed` nm/s.
fn system_friction(layer: &Layer, total_load: f64, speed: f64) -> f64 {
    let w = total_load * 1e-3;
    let point = Point {
        setting: Setting::System {
            system: ThreeBody::with_defaults(OperatingPoint::TotalLoad(w)),
            options: ThreeBodyOptions::default(),
            total_load: w,
        },
        velocity: speed * 1e-9,
        measured: Measured::FrictionCoefficient,
    };
    point.value(layer, Law::Local, Stop::NEVER).unwrap()
}

/// A series' points against speed: at each of `speeds` (nm/s), the value `at` gives there.
pub(crate) fn against_speed(speeds: &[f64], at: impl Fn(f64) -> f64) -> Vec<Value> {
    speeds
        .iter()
        .map(|&v| json!({"velocity": format!("{v} nm/s"), "value": at(v)}))
        .collect()
}

#[test]
fn a_three_body_series_gives_back_the_layer_its_friction_came_from() {
    // The system's friction coefficient against speed at two total loads (docs/model.md §4
    // defaults: 50 ± 5 nm particles, 1e12 m⁻², 1 mm², steel above).
    let truth = Layer::default();
    let series: Vec<Value> = [0.5, 1.0]
        .iter()
        .map(|&w| {
            let speeds = [0.0, 1.0, 2.0, 4.0, 8.0, 16.0];
            let points = against_speed(&speeds, |v| system_friction(&truth, w, v));
            json!({"system": {}, "total_load": format!("{w} mN"), "points": points})
        })
        .collect();
    let answer = fit(
        json!({"series": series, "layer": {"relaxation_time": "40 ms", "retardation_time": "1 s"},
        "parameters": {"relaxation_time": {}, "retardation_time": {}}}),
    )
    .unwrap();
    for (name, expected) in [("relaxation_time", 0.1), ("retardation_time", 0.5)] {
        let got = value(&answer, name);
        assert!((got / expected - 1.0).abs() < 1e-6, "{name}: {got}");
    }
    let residual = &answer["residuals"][7];
    assert_eq!(residual["total_load"], 1e-3);
    assert!(residual.get("radius").is_none() && residual.get("load").is_none());
    assert_eq!(answer["curves"][0]["along"], "velocity");
    assert_eq!(answer["curves"][0]["points"][0]["total_load"], 5e-4);
    // A system's series may not give what the fit sets, nor one particle's conditions.
    let errors = refused(
        json!({"series": [{"system": {"layer": {}, "operating": {"total_load": "1 mN"}},
        "radius": "25 nm", "quantity": "contact_area", "points": [{"velocity": 0, "value": 0.1}]}],
        "parameters": {"elastic_modulus": {}}}),
    );
    let fields: Vec<&str> = errors.iter().map(|e| e.0.as_str()).collect();
    for field in [
        "series[0].system.layer",
        "series[0].system.operating",
        "series[0].radius",
        "series[0].quantity",
        "series[0].points[0].total_load",
    ] {
        assert!(fields.contains(&field), "{field} not in {errors:?}");
    }
}

#[test]
fn bounds_hold() {
    let truth = Layer::default();
    let mut noise = Noise(7);
    let answer = fit(json!({
        "series": [friction_series(&truth, 1.0, 0.001, &mut noise, true)],
        "parameters": {"relaxation_time": {"start": "20 ms", "min": "10 ms", "max": "60 ms"},
                       "retardation_time": {"start": "400 ms", "min": "300 ms", "max": "2 s"}}}))
    .unwrap();
    let t = &answer["parameters"]["relaxation_time"];
    assert_eq!(t["value"].as_f64().unwrap(), 0.06, "{t}");
    assert_eq!(t["at_bound"], true);
    assert_eq!(t["bounds"], json!([0.01, 0.06]));
    let r = value(&answer, "retardation_time");
    assert!((0.3..=2.0).contains(&r), "{r}");
    // Without a start, bounds that exclude the layer's value start from their middle.
    let job = Job::from_value(
        json!({"kind": "fit", "input": {"series": [friction_series(&truth, 1.0, 0.001, &mut noise, true)],
            "parameters": {"retardation_time": {"min": "1 s", "max": "100 s"}}}}),
        &Limits::default(),
    )
    .unwrap();
    let start = &job.canonical()["parameters"]["retardation_time"]["start"];
    assert!(
        (start.as_f64().unwrap() / 10.0 - 1.0).abs() < 1e-12,
        "{start}"
    );
}

/// The particle's own friction (docs/model.md §11) measured at eleven speeds and two loads,
/// noiseless, against a glass counterface: the particle rolls at some and slides on the
/// glass at others, and the fit gives back both times to 1e-6 (with its counterface in the
/// forward model: against steel the same data fit other times).
#[test]
fn noiseless_particle_friction_gives_back_both_times() {
    let truth = Layer::default();
    let glass = UpperSurface {
        elastic_modulus: 70e9,
        poisson_ratio: 0.22,
        shear_strength: Some(10e6),
        ..UpperSurface::default()
    };
    let mut modes = Vec::new();
    let series: Vec<Value> = [0.6, 1.4]
        .iter()
        .map(|&load| {
            let points: Vec<Value> = SPEEDS[1..]
                .iter()
                .map(|&v| {
                    let point = Point {
                        setting: Setting::Particle {
                            radius: 25e-9,
                            load: load * 1e-9,
                            upper: glass,
                        },
                        velocity: v * 1e-9,
                        measured: Measured::ParticleFriction,
                    };
                    let value = point.value(&truth, Law::Local, Stop::NEVER).unwrap();
                    let rolling = Rolling {
                        radius: 25e-9,
                        load: load * 1e-9,
                        velocity: v * 1e-9,
                        layer: truth,
                    };
                    let s = solve(&rolling, &SolveOptions::default()).unwrap();
                    let tau = truth.interfacial_shear_strength();
                    let resistance = s.rolling_resistance_coefficient;
                    let m = motion::particle(
                        25e-9,
                        load * 1e-9,
                        resistance,
                        s.contact_area,
                        tau,
                        &glass,
                    );
                    modes.push(m.mode == Mode::Rolls);
                    json!({"velocity": format!("{v} nm/s"), "value": value})
                })
                .collect();
            json!({"radius": "25 nm", "load": format!("{load} nN"), "quantity": "particle_friction",
                   "upper_surface": {"elastic_modulus": "70 GPa", "poisson_ratio": 0.22,
                                     "shear_strength": "10 MPa"},
                   "points": points})
        })
        .collect();
    assert!(modes.contains(&true) && modes.contains(&false), "{modes:?}");
    let input = json!({
        "layer": {"relaxation_time": "30 ms", "retardation_time": "1 s"},
        "series": series,
        "parameters": {"relaxation_time": {}, "retardation_time": {}}});
    let answer = fit(input.clone()).unwrap();
    for (name, expected) in [
        ("relaxation_time", truth.relaxation_time),
        ("retardation_time", truth.retardation_time),
    ] {
        let got = value(&answer, name);
        assert!(
            (got / expected - 1.0).abs() < 1e-6,
            "{name}: {got} vs {expected}"
        );
    }
    let residual = &answer["residuals"][0]["particle_friction"];
    assert!(residual["measured"].is_number(), "{residual}");
    // The counterface is part of the input: without it (steel) the same data fit worse.
    let mut on_steel = input;
    for s in on_steel["series"].as_array_mut().unwrap() {
        s.as_object_mut().unwrap().remove("upper_surface");
    }
    let steel = fit(on_steel).unwrap();
    assert!(
        steel["chi_squared"].as_f64().unwrap() > 1e-6,
        "{}",
        steel["chi_squared"]
    );
}

/// The field errors of a fit refused as invalid.
fn refused(input: Value) -> Vec<(String, String)> {
    match fit(input) {
        Err(JobError::Invalid(errors)) => {
            errors.into_iter().map(|e| (e.field, e.message)).collect()
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
}

#[test]
fn bad_data_get_problems_that_name_the_field() {
    let at_rest = json!([{"velocity": 0, "points": [
        {"load": "1 nN", "value": 0.11}, {"load": "1.2 nN", "value": 0.10},
        {"load": "1.4 nN", "value": 0.095}]}]);
    // A time has no effect on points at rest.
    let errors = refused(json!({"series": at_rest, "parameters": {"relaxation_time": {}}}));
    assert_eq!(errors[0].0, "parameters.relaxation_time", "{errors:?}");
    assert!(
        errors[0]
            .1
            .contains("no measured point depends on relaxation_time"),
        "{errors:?}"
    );
    // Fewer points than parameters (plus one, without uncertainties).
    let two = json!([{"points": [{"velocity": "1 nm/s", "value": 0.11}, {"velocity": "2 nm/s", "value": 0.10}]}]);
    let errors = refused(json!({"series": two,
        "parameters": {"relaxation_time": {}, "retardation_time": {}}}));
    assert_eq!(errors[0].0, "series", "{errors:?}");
    assert!(
        errors[0]
            .1
            .contains("at least 3 points to fit 2 parameters"),
        "{errors:?}"
    );
    // All points at one condition.
    let same = json!([{"velocity": "4 nm/s", "points": [{"value": 0.09}, {"value": 0.095}, {"value": 0.1}]}]);
    let errors = refused(json!({"series": same,
        "parameters": {"relaxation_time": {}, "retardation_time": {}}}));
    assert_eq!(errors[0].0, "series", "{errors:?}");
    assert!(errors[0].1.contains("distinct conditions"), "{errors:?}");
    // Each bad value is named with its path.
    let errors = refused(json!({
        "series": [{"points": [{"velocity": "-1 nm/s", "value": 0.1}, {"value": "3 nm"},
                               {"velocity": "2 nm/s"}]}],
        "parameters": {"relaxation_time": {"start": "1 s", "max": "100 ms"}, "retardation_time": {}, "kappa": {}}}));
    let fields: Vec<&str> = errors.iter().map(|e| e.0.as_str()).collect();
    for field in [
        "series[0].points[0].velocity",
        "series[0].points[1].value",
        "series[0].points[2].value",
        "parameters.relaxation_time.start",
        "parameters.kappa",
    ] {
        assert!(fields.contains(&field), "{field} not in {errors:?}");
    }
    // Uncertainties for some points only.
    let errors = refused(json!({"series": [{"points": [
        {"velocity": "1 nm/s", "value": 0.1, "uncertainty": 0.001},
        {"velocity": "2 nm/s", "value": 0.1}, {"velocity": "3 nm/s", "value": 0.1}]}],
        "parameters": {"relaxation_time": {}}}));
    assert!(
        errors[0].1.contains("for every point or for none"),
        "{errors:?}"
    );
    // The particle's own friction at rest: it transmits none there.
    let errors = refused(
        json!({"series": [{"quantity": "particle_friction", "points": [
        {"velocity": 0, "value": 0.02}, {"velocity": "2 nm/s", "value": 0.02},
        {"velocity": "3 nm/s", "value": 0.02}]}], "parameters": {"relaxation_time": {}}}),
    );
    assert_eq!(errors[0].0, "series[0].points[0].velocity", "{errors:?}");
    assert!(errors[0].1.contains("particle_friction"), "{errors:?}");
    // A system's area, and a counterface beside a system that has its own.
    let errors = refused(json!({"series": [{"system": {}, "quantity": "contact_area",
        "upper_surface": {}, "points": [{"total_load": "1 mN", "value": 1e-12}]}],
        "parameters": {"relaxation_time": {}}}));
    let fields: Vec<&str> = errors.iter().map(|e| e.0.as_str()).collect();
    for field in ["series[0].quantity", "series[0].upper_surface"] {
        assert!(fields.contains(&field), "{field} not in {errors:?}");
    }
    // The particles' own friction on the hertz contact: nothing to fit there.
    let errors = refused(json!({"series": [{"system": {"layer_contact": "hertz"},
        "quantity": "particle_friction", "points": [{"total_load": "1 mN", "value": 0.01}]}],
        "parameters": {"relaxation_time": {}}}));
    assert_eq!(errors[0].0, "series[0].quantity", "{errors:?}");
    assert!(errors[0].1.contains("hertz"), "{errors:?}");
    // No series, no parameter.
    let errors = refused(json!({"parameters": {}}));
    let fields: Vec<&str> = errors.iter().map(|e| e.0.as_str()).collect();
    assert!(
        fields.contains(&"series") && fields.contains(&"parameters"),
        "{errors:?}"
    );
}

#[test]
fn a_cancel_stops_a_running_fit_within_100_ms() {
    let truth = Layer::default();
    let points: Vec<Value> = (0..3000)
        .map(|i| {
            let v = 0.01 * (i + 1) as f64;
            json!({"velocity": format!("{v} nm/s"),
                   "value": model(&truth, Measured::FrictionCoefficient, 25.0, 1.0, v)})
        })
        .collect();
    let input = json!({"kind": "fit", "input": {"series": [{"points": points}],
        "parameters": {"relaxation_time": {"start": "30 ms"}, "retardation_time": {}, "elastic_modulus": {}}}});
    let job = Job::from_value(input, &Limits::default()).unwrap();
    let control = Arc::new(Control::default());
    let running = {
        let control = control.clone();
        std::thread::spawn(move || {
            let outcome = job.run(job.meta(), &control);
            (outcome.map(|_| ()), Instant::now())
        })
    };
    while control.done() < 100 {
        std::thread::sleep(Duration::from_millis(1));
    }
    std::thread::sleep(Duration::from_millis(50));
    let cancelled_at = Instant::now();
    control.cancel();
    let (outcome, stopped_at) = running.join().unwrap();
    assert_eq!(outcome, Err(JobError::Cancelled));
    let delay = stopped_at - cancelled_at;
    assert!(delay < Duration::from_millis(100), "{delay:?}");
}
