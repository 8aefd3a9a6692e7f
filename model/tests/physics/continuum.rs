//! The layer as a continuum at rest (docs/model.md §8) against its exact anchors: Hertz on
//! a layer much thicker than the contact, the local law of §3 on one much thinner, and the
//! paper's own parameters, where the two laws part by the factor §7 and §8 state.

use std::f64::consts::PI;

use thirdbody_model::continuum::{contact_modulus, static_contact};
use thirdbody_model::Layer;

/// The local law's static area (docs/model.md §3): A_0 = 2√(πRP/k), k = E_L/H.
fn local_area(radius: f64, load: f64, layer: &Layer) -> f64 {
    let k = layer.elastic_modulus / layer.thickness;
    2.0 * (PI * radius * load / k).sqrt()
}

/// Hertz with E* = E/(1 − ν²): a³ = 3PR/(4E*), δ = a²/R.
fn hertz(radius: f64, load: f64, layer: &Layer) -> (f64, f64) {
    let a = (3.0 * load * radius / (4.0 * contact_modulus(layer))).cbrt();
    (a, a * a / radius)
}

#[test]
fn on_a_layer_fifty_contacts_thick_the_contact_is_hertz() {
    for (radius, load, nu) in [
        (25e-9, 1e-9, 0.35),
        (350e-9, 1.4e-9, 0.3),
        (1e-6, 5e-9, 0.45),
    ] {
        let layer = Layer {
            thickness: 5e-6,
            poisson_ratio: nu,
            ..Layer::default()
        };
        let (a, delta) = hertz(radius, load, &layer);
        assert!(layer.thickness / a >= 50.0);
        let c = static_contact(radius, load, &layer).unwrap();
        let area_error = c.contact_area / (PI * a * a) - 1.0;
        let delta_error = c.penetration / delta - 1.0;
        // Within its own estimate (and the half-space's remaining 1/50 of layer effect),
        // and within §8's 1 % in A and 0.5 % in δ.
        assert!(c.relative_error < 0.01, "{c:?}");
        assert!(
            area_error.abs() < 0.01,
            "R = {radius}: A off by {area_error:e}"
        );
        assert!(
            delta_error.abs() < 0.005,
            "R = {radius}: δ off by {delta_error:e}"
        );
    }
}

/// The local law is the thin-layer limit: the continuum's area tends to §3's as H/r_0 → 0,
/// the difference shrinking in proportion to H/r_0 (an edge layer about H wide) for every
/// ν ≤ 0.4. (§8's "within 0.4 % in A where r_0/H ≥ 20" holds near ν = 0.35 only: at
/// r_0/H = 27 the difference is −1.3 % at ν = 0 and +0.9 % at ν = 0.4.)
#[test]
fn on_a_layer_much_thinner_than_the_contact_the_continuum_tends_to_the_local_law() {
    let (radius, load) = (10e-6, 1e-6);
    for nu in [0.0, 0.2, 0.35, 0.4] {
        let off = |thickness: f64| {
            let layer = Layer {
                thickness,
                poisson_ratio: nu,
                ..Layer::default()
            };
            let c = static_contact(radius, load, &layer).unwrap();
            c.contact_area / local_area(radius, load, &layer) - 1.0
        };
        // r_0/H ≈ 16 and 45.
        let (thick, thin) = (off(4e-9), off(1e-9));
        assert!(thin.abs() < 0.01, "ν = {nu}: {thin:e}");
        assert!(
            thin.abs() < 0.6 * thick.abs(),
            "ν = {nu}: {thick:e} then {thin:e}"
        );
    }
}

/// At the paper's parameters the local law overstates the static area 4.7–7.6× (§7, §8):
/// R = 25 nm, P = 1 nN gives A = 13.4 nm² against the local law's 102.3 nm².
#[test]
fn at_the_papers_parameters_the_local_law_overstates_the_area_as_stated() {
    let layer = Layer::default();
    let c = static_contact(25e-9, 1e-9, &layer).unwrap();
    assert!(
        (c.contact_area * 1e18 - 13.4).abs() < 0.1,
        "{:e}",
        c.contact_area
    );
    let ratio = local_area(25e-9, 1e-9, &layer) / c.contact_area;
    assert!((ratio - 7.6).abs() < 0.1, "{ratio}");
    let far = static_contact(350e-9, 1.4e-9, &layer).unwrap();
    let ratio = local_area(350e-9, 1.4e-9, &layer) / far.contact_area;
    assert!((ratio - 4.7).abs() < 0.1, "{ratio}");
}

/// A bonded layer is stiffer than the half-space (its base holds it: C(qH) < 1), so its
/// contact is never wider than Hertz's. It is not always narrower than the local law's: a
/// thin, nearly incompressible layer squeezes out sideways, which the local law's
/// oedometric springs cannot (docs/model.md §8), and there the continuum's contact is the
/// wider one.
#[test]
fn the_continuum_contact_is_never_wider_than_hertz() {
    for thickness in [1e-9, 5e-9, 20e-9, 100e-9, 1e-6] {
        for nu in [0.1, 0.35, 0.45] {
            let layer = Layer {
                thickness,
                poisson_ratio: nu,
                ..Layer::default()
            };
            let (radius, load) = (100e-9, 2e-9);
            let c = static_contact(radius, load, &layer).unwrap();
            let (a, _) = hertz(radius, load, &layer);
            let bound = PI * a * a;
            assert!(
                c.contact_area <= bound * (1.0 + c.relative_error),
                "H = {thickness}, ν = {nu}: {:e} > {bound:e}",
                c.contact_area
            );
        }
    }
}

/// The squeeze: on a layer 1 nm thick under a contact ten times wider, at ν = 0.45 the
/// continuum's contact is wider than the local law's, at ν = 0.2 it is not.
#[test]
fn a_thin_nearly_incompressible_layer_is_softer_than_its_local_law() {
    let area = |nu: f64| {
        let layer = Layer {
            thickness: 1e-9,
            poisson_ratio: nu,
            ..Layer::default()
        };
        let c = static_contact(100e-9, 2e-9, &layer).unwrap();
        c.contact_area / local_area(100e-9, 2e-9, &layer)
    };
    assert!(area(0.45) > 1.1, "{}", area(0.45));
    assert!(area(0.2) < 1.0, "{}", area(0.2));
}

/// A thin, nearly incompressible layer (ν → 0.5, a ≫ H) is never local: it squeezes out
/// sideways, and tends to p = 3G(a² − r²)²/(32RH³), δ = a²/(4R), P = πGa⁶/(32RH³)
/// (docs/model.md §8; Johnson §5.9), with an error ∝ H/a. At ν = 0.49999 the area falls
/// short of it by 2.8 H/a: linearly extrapolated from H/a = 0.05 and 0.025 to H/a = 0, it
/// is the limit within 1 %; δ is within 1.5 % at H/a = 0.05 and 0.1 % at 0.025.
#[test]
fn a_thin_incompressible_layer_tends_to_its_squeeze_film_limit() {
    let (radius, load, shear, nu) = (1e-6, 5e-5, 1e9, 0.49999);
    let young = 2.0 * shear * (1.0 + nu);
    let off = |thickness: f64| {
        let layer = Layer {
            thickness,
            poisson_ratio: nu,
            // E_L for this E (docs/model.md §8: E = E_L (1 + ν)(1 − 2ν)/(1 − ν)).
            elastic_modulus: young * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            ..Layer::default()
        };
        let a = (32.0 * radius * thickness.powi(3) * load / (PI * shear)).powf(1.0 / 6.0);
        let c = static_contact(radius, load, &layer).unwrap();
        let delta = c.penetration / (a * a / (4.0 * radius)) - 1.0;
        (thickness / a, c.contact_area / (PI * a * a) - 1.0, delta)
    };
    let ((thick, area_thick, delta_thick), (thin, area_thin, delta_thin)) =
        (off(2e-9), off(0.5e-9));
    assert!((thick - 0.05).abs() < 1e-3 && (thin - 0.025).abs() < 1e-3);
    let limit = (thick * area_thin - thin * area_thick) / (thick - thin);
    assert!(limit.abs() < 0.01, "A at H/a → 0 off by {limit:e}");
    assert!(area_thin < 0.0 && area_thin.abs() < 0.6 * area_thick.abs());
    assert!(delta_thick.abs() < 0.015 && delta_thin.abs() < 1e-3);
}

/// Issue 47: where the layer is about as thin as the contact (H/a 0.2 to 2.4), the grid's δ
/// carries a bias that its two grids share; the reported penetration error bounds it
/// against the axisymmetric solver (whose own δ is exact to 1e-4), at rest. These are the
/// cases where the two grids' change alone claimed 1.0 to 6.2 times too little.
#[test]
fn where_the_layer_is_as_thin_as_the_contact_the_depth_error_bounds_the_grids_bias() {
    use thirdbody_model::{continuum, Rolling, SolveOptions, Stop};
    for (nu, thickness, load) in [
        (0.3, 10e-9, 20e-9),
        (0.3, 10e-9, 40e-9),
        (0.3, 5e-9, 80e-9),
        (0.3, 3e-9, 80e-9),
        (0.45, 10e-9, 5e-9),
        (0.45, 5e-9, 80e-9),
        (0.45, 3e-9, 200e-9),
        (0.45, 20e-9, 80e-9),
        (0.45, 15e-9, 40e-9),
        (0.49, 10e-9, 1e-9),
        (0.49, 10e-9, 20e-9),
        (0.49, 5e-9, 40e-9),
        (0.49, 30e-9, 80e-9),
        (0.49, 3e-9, 200e-9),
    ] {
        let layer = Layer {
            poisson_ratio: nu,
            thickness,
            ..Layer::default()
        };
        let at_rest = Rolling {
            radius: 25e-9,
            load,
            velocity: 0.0,
            layer,
        };
        let options = SolveOptions::integrals_only(Default::default());
        let grid = continuum::solve(&at_rest, &options, Stop::NEVER).unwrap();
        let exact = static_contact(25e-9, load, &layer).unwrap();
        let off = (grid.penetration / exact.penetration - 1.0).abs();
        let claimed = grid.verification.errors.penetration;
        assert!(
            off <= claimed + 1e-4,
            "ν {nu}, H {thickness:e}, P {load:e} (H/a {:.2}): δ off by {off:.2e}, claimed \
             {claimed:.2e}",
            thickness / exact.contact_radius
        );
        assert!(claimed < 0.005, "within §8's tolerance of δ: {claimed:.2e}");
    }
}
