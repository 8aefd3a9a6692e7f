//! Three-body systems on the layer as a continuum (docs/model.md §4 with §8): each particle's
//! contact is the single-particle continuum answer, through the layer's curve.

use thirdbody_model::continuum::{self, PenetrationCurve};
use thirdbody_model::counterface::UpperSurface;
use thirdbody_model::motion::{self, Mode};
use thirdbody_model::three_body::{
    self, squeeze, LayerContact, LayerCurves, LayerLaw, OperatingPoint, ThreeBody,
    ThreeBodyOptions, UpperLaw,
};
use thirdbody_model::{Layer, Rolling, SolveOptions, Stop};

/// The default system (docs/model.md §5) on the continuum at `velocity` and separation 45 nm.
fn system(velocity: f64) -> ThreeBody {
    ThreeBody {
        layer_contact: LayerContact::Continuum,
        velocity,
        ..ThreeBody::with_defaults(OperatingPoint::Separation(45e-9))
    }
}

/// Each particle of the system, squeezed through the curve, carries the force and has the
/// area of the single-particle continuum answer under that force, within the two errors.
fn particles_agree_with_single_answers(velocity: f64) {
    let system = system(velocity);
    let curves = LayerCurves::build(&system, Stop::NEVER).unwrap();
    let curve = if velocity > 0.0 {
        &curves.rolling
    } else {
        &curves.resting
    };
    let upper = UpperLaw::Elastic {
        modulus: 1.0 / ((1.0 - 0.3 * 0.3) / 210e9),
    };
    let layer = LayerLaw::Continuum {
        curve: curve.clone(),
    };
    for diameter in [46e-9, 50e-9, 57e-9, 65e-9] {
        let s = squeeze(&upper, &layer, diameter, diameter - 45e-9).unwrap();
        let single = continuum::solve(
            &Rolling {
                radius: 0.5 * diameter,
                load: s.force,
                velocity,
                layer: Layer::default(),
            },
            &SolveOptions::integrals_only(Default::default()),
            Stop::NEVER,
        )
        .unwrap();
        let e = single.verification.errors;
        let area_off = (s.layer_area / single.contact_area - 1.0).abs();
        let depth_off = (s.layer_penetration / single.penetration - 1.0).abs();
        assert!(
            area_off <= e.contact_area + s.layer_error,
            "x = {diameter:e}, V = {velocity:e}: A {} vs {} ({area_off:.2e} > {:.2e} + {:.2e})",
            s.layer_area,
            single.contact_area,
            e.contact_area,
            s.layer_error
        );
        assert!(
            depth_off <= e.penetration + s.layer_error,
            "x = {diameter:e}, V = {velocity:e}: δ {} vs {}",
            s.layer_penetration,
            single.penetration
        );
        assert!(s.layer_error > 0.0 && s.layer_error <= curve.error());
    }
}

#[test]
fn at_rest_each_particle_is_the_single_continuum_answer() {
    particles_agree_with_single_answers(0.0);
}

#[test]
fn rolling_each_particle_is_the_single_continuum_answer() {
    particles_agree_with_single_answers(4e-9);
}

/// One size of particle: the system's μ is the single particle's, τ_a A/P, and its means per
/// particle are that particle's force and area; the areas are the continuum's, several
/// times smaller than the local law's at these parameters (§8).
#[test]
fn particles_of_one_size_give_the_single_particle_friction() {
    let mut one_size = system(4e-9);
    one_size.diameters.std = 0.0;
    one_size.diameters.min = 50e-9;
    one_size.diameters.max = 50e-9;
    let s = three_body::solve(&one_size, &ThreeBodyOptions::default()).unwrap();
    let state = &s.rolling;
    let tau = Layer::default().interfacial_shear_strength();
    let mean_load = state.loads.particles / state.particles_in_contact;
    let mean_area = state.areas.particle_layer / state.particles_in_contact;
    assert!((state.friction_coefficient / (tau * mean_area / mean_load) - 1.0).abs() < 1e-12);
    let single = continuum::solve(
        &Rolling {
            radius: 25e-9,
            load: mean_load,
            velocity: 4e-9,
            layer: Layer::default(),
        },
        &SolveOptions::integrals_only(Default::default()),
        Stop::NEVER,
    )
    .unwrap();
    let error = s.verification.layer_contact_error.unwrap();
    let off = (state.friction_coefficient / single.friction_coefficient - 1.0).abs();
    assert!(
        off <= error + single.verification.errors.contact_area,
        "{off:.2e}"
    );
    // Its particles move as the single particle does (docs/model.md §11): on the
    // continuum they slide at the layer, with the single particle's friction.
    let m = motion::particle(
        25e-9,
        mean_load,
        single.rolling_resistance_coefficient,
        single.contact_area,
        tau,
        &UpperSurface::default(),
    );
    assert_eq!(m.mode, Mode::SlidesAtLayer);
    assert_eq!(s.motion.furthest.unwrap().mode, m.mode);
    let off = (s.motion.friction / m.friction - 1.0).abs();
    assert!(
        off <= error + single.verification.errors.contact_area,
        "{off:.2e}"
    );
    let local = three_body::solve(
        &ThreeBody {
            layer_contact: LayerContact::KelvinLayer,
            ..one_size
        },
        &ThreeBodyOptions::default(),
    )
    .unwrap();
    assert!(local.rolling.friction_coefficient > 3.0 * state.friction_coefficient);
}

/// The whole system: its layer-contact error is reported and bounded by the curves', μ
/// follows from the sums (eq. 12 summed), rolling lowers μ (docs/model.md §6), and a total
/// load is carried.
#[test]
fn the_system_reports_its_layer_error_and_follows_eq_12() {
    let system = system(4e-9);
    let curves = LayerCurves::build(&system, Stop::NEVER).unwrap();
    let s = three_body::solve_with(&system, &ThreeBodyOptions::default(), Some(&curves)).unwrap();
    let error = s.verification.layer_contact_error.unwrap();
    assert!(error > 0.0 && error <= curves.rolling.error().max(curves.resting.error()));
    let tau = Layer::default().interfacial_shear_strength();
    for state in [&s.rolling, &s.static_state] {
        let mu = tau * state.areas.particle_layer / state.loads.total;
        assert!((state.friction_coefficient / mu - 1.0).abs() < 1e-12);
    }
    assert!(s.rolling.friction_coefficient < s.static_state.friction_coefficient);
    let loaded = ThreeBody {
        operating: OperatingPoint::TotalLoad(0.5 * s.rolling.loads.total),
        ..system
    };
    let at_load =
        three_body::solve_with(&loaded, &ThreeBodyOptions::default(), Some(&curves)).unwrap();
    assert!((at_load.rolling.loads.total / (0.5 * s.rolling.loads.total) - 1.0).abs() < 1e-12);
    assert!(at_load.rolling.separation > 45e-9);
}

/// The curve's problems reach beyond the c asked for, and its interpolation between nodes
/// holds direct solves within the two errors.
#[test]
fn the_curve_interpolates_direct_solves() {
    let layer = Layer::default();
    let curve = PenetrationCurve::build(&layer, 4e-9, 40e-9).unwrap();
    assert!(curve.reach() >= 40e-9);
    for load in [3e-12, 7e-11, 2e-10, 1.3e-9, 6e-9] {
        let direct = continuum::solve(
            &Rolling {
                radius: 25e-9,
                load,
                velocity: 4e-9,
                layer,
            },
            &SolveOptions::integrals_only(Default::default()),
            Stop::NEVER,
        )
        .unwrap();
        let (force, area) = curve.contact(25e-9, direct.penetration);
        let bound =
            curve.error_at(25e-9, direct.penetration) + direct.verification.errors.relative();
        assert!((force / load - 1.0).abs() <= bound, "F at P = {load:e}");
        assert!(
            (area / direct.contact_area - 1.0).abs() <= bound,
            "A at P = {load:e}"
        );
        // The centre of pressure, which sets a particle's rolling resistance (§11).
        let e = direct.verification.errors;
        let shift = direct.pressure_centre_shift;
        let bound = curve.pressure_error_at(25e-9, direct.penetration)
            + e.pressure_centre_shift / shift
            + e.penetration;
        let off = (curve.pressure_centre(25e-9, direct.penetration) / shift - 1.0).abs();
        assert!(off <= bound, "x_p at P = {load:e}: {off:.2e} > {bound:.2e}");
    }
}
