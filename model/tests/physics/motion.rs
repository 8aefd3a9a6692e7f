//! Roll or slide (docs/model.md §11): the anchors of the default particle on both laws, the
//! slow-rolling limit and the power balance, and three-body systems against direct sums of
//! single answers.

use proptest::prelude::*;
use thirdbody_model::continuum;
use thirdbody_model::counterface::UpperSurface;
use thirdbody_model::motion::{self, Mode, Motion};
use thirdbody_model::tables::{self, Use};
use thirdbody_model::three_body::{
    self, squeeze, LayerContact, LayerLaw, OperatingPoint, ThreeBody, ThreeBodyOptions,
};
use thirdbody_model::{solve, Layer, Rolling, RollingSolution, SolveOptions, Stop};

/// The motion of a single rigid particle between steel and the layer, from its answer.
fn particle<V>(rolling: &Rolling, s: &RollingSolution<V>) -> Motion {
    motion::particle(
        rolling.radius,
        rolling.load,
        s.rolling_resistance_coefficient,
        s.contact_area,
        rolling.layer.interfacial_shear_strength(),
        &UpperSurface::default(),
    )
}

fn close(a: f64, b: f64, tolerance: f64) -> bool {
    (a / b - 1.0).abs() <= tolerance
}

/// §11: on the local law the default particle rolls, μ_roll = 1.069151/25/2 = 0.0213830,
/// which is then its friction; its capacities are 0.0947 (eq. 12's μ) and 0.0476.
#[test]
fn the_default_particle_rolls_on_the_local_law() {
    let r = Rolling::default();
    let s = solve(&r, &SolveOptions::default()).unwrap();
    let m = particle(&r, &s);
    assert_eq!(m.mode, Mode::Rolls);
    assert!(close(
        m.friction,
        0.5 * s.rolling_resistance_coefficient,
        1e-12
    ));
    assert!((m.friction - 0.0213830).abs() < 5e-8, "{}", m.friction);
    // μ_roll = x_p/2R with x_p the pressure's own first moment: from the pressure map,
    // summed apart from the solver's strip integrals (a 401² midpoint sum, to 1e-4).
    let options = SolveOptions {
        pressure_grid: Some(401),
        ..SolveOptions::default()
    };
    let grid = solve(&r, &options).unwrap().pressure.unwrap();
    let (mut load, mut moment) = (0.0, 0.0);
    for row in &grid.values {
        for (x, p) in grid.x.iter().zip(row) {
            load += p;
            moment += x * p;
        }
    }
    let shift = moment / load;
    assert!(
        close(shift / (2.0 * r.radius), m.rolling_need, 1e-4),
        "{shift:e}"
    );
    assert_eq!(m.layer_capacity, s.friction_coefficient);
    assert!(
        (m.layer_capacity - 0.0947).abs() < 5e-5,
        "{}",
        m.layer_capacity
    );
    assert!(
        (m.upper_capacity - 0.0476).abs() < 5e-5,
        "{}",
        m.upper_capacity
    );
}

/// §11: on the continuum μ_roll = 0.0262/2 = 0.0131 exceeds the layer's capacity 0.00913:
/// the default particle slides at the layer, and its friction is that capacity.
#[test]
fn on_the_continuum_the_default_particle_slides_at_the_layer() {
    let r = Rolling::default();
    let s = continuum::solve(&r, &SolveOptions::default(), Stop::NEVER).unwrap();
    let m = particle(&r, &s);
    assert_eq!(m.mode, Mode::SlidesAtLayer);
    assert_eq!(m.friction, m.layer_capacity);
    assert_eq!(m.layer_capacity, s.friction_coefficient);
    let e = s.verification.errors;
    let need_error = e.pressure_centre_shift / s.pressure_centre_shift;
    assert!(
        close(m.rolling_need, 0.0131, 0.005 + need_error),
        "{}",
        m.rolling_need
    );
    assert!(
        close(m.layer_capacity, 0.00913, 0.002 + e.contact_area),
        "{}",
        m.layer_capacity
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Whatever the particle: its friction is the least of μ_roll and the two capacities,
    /// it rolls iff μ_roll is the least, and then the power the upper surface puts in,
    /// T·2V, is what the contacts dissipate, P·V(μ_r,u + μ_r,l), to 1e-12. Slow enough
    /// (V → 0, where x_p → 0), every particle rolls.
    #[test]
    fn the_friction_is_the_least_of_need_and_capacities(
        radius in 10e-9..400e-9f64,
        load in 0.2e-9..20e-9f64,
        velocity in 0.5e-9..40e-9f64,
    ) {
        let at = |velocity: f64| {
            let r = Rolling { radius, load, velocity, layer: Layer::default() };
            let s = solve(&r, &SolveOptions::integrals_only(Default::default())).unwrap();
            (particle(&r, &s), s.rolling_resistance_coefficient)
        };
        let (m, layer_resistance) = at(velocity);
        let least = m.rolling_need.min(m.upper_capacity).min(m.layer_capacity);
        prop_assert_eq!(m.friction, least);
        prop_assert_eq!(m.mode == Mode::Rolls, m.rolling_need == least);
        if m.mode == Mode::Rolls {
            let tangential = m.friction * load;
            let power = tangential * 2.0 * velocity;
            let dissipated = load * velocity * (0.0 + layer_resistance);
            prop_assert!(close(power, dissipated, 1e-12));
        }
        let (slowest, _) = at(velocity * 1e-6);
        prop_assert_eq!(slowest.mode, Mode::Rolls);
        prop_assert!(slowest.rolling_need < 1e-4, "{}", slowest.rolling_need);
    }
}

/// The default system (docs/model.md §5) on the local law at `operating`.
fn system(operating: OperatingPoint) -> ThreeBody {
    ThreeBody::with_defaults(operating)
}

/// Particles of one size: the system's friction Σ T/W is the single particle's, solved
/// through the same similarity table at the load each particle carries, to 1e-9; so is
/// its mode.
#[test]
fn a_system_of_one_size_is_its_single_particle() {
    for separation in [40e-9, 47e-9, 49.5e-9] {
        let mut one = system(OperatingPoint::Separation(separation));
        (one.diameters.std, one.diameters.min, one.diameters.max) = (0.0, 50e-9, 50e-9);
        let s = three_body::solve(&one, &ThreeBodyOptions::default()).unwrap();
        let load = s.rolling.loads.particles / s.rolling.particles_in_contact;
        let r = Rolling {
            radius: 25e-9,
            load,
            velocity: one.velocity,
            layer: one.layer,
        };
        let single = tables::solve(&r, &SolveOptions::default(), Use::Build).unwrap();
        let m = particle(&r, &single);
        let furthest = s.motion.furthest.unwrap();
        assert_eq!(furthest.mode, m.mode, "d = {separation:e}");
        assert!(
            close(s.motion.friction, m.friction, 1e-9),
            "d = {separation:e}: {} vs {}",
            s.motion.friction,
            m.friction
        );
        let counted = s.motion.rolling + s.motion.sliding();
        assert!(close(counted, s.rolling.particles_in_contact, 1e-12));
    }
}

/// The default system at the paper's operating point W = 1 mN against a direct sum over
/// 4000 sizes of single answers (strip sums, at the load each size carries there): Σ T/W,
/// the particles that roll and that slide at each contact, and the diameters where the
/// mode changes.
#[test]
fn the_default_system_is_a_sum_of_single_answers() {
    let sys = system(OperatingPoint::TotalLoad(1e-3));
    let s = three_body::solve(&sys, &ThreeBodyOptions::default()).unwrap();
    let d = s.rolling.separation;
    let upper_law = UpperSurface::default().law(0.0);
    // The load a particle of diameter x carries at d, by the system's own split of its
    // interference between the two contacts.
    let table = tables::get_or_build(sys.layer.kappa(), Default::default()).unwrap();
    let rolling_law = LayerLaw::Kelvin {
        stiffness: sys.layer.stiffness(),
        relaxation_length: sys.velocity * sys.layer.relaxation_time,
        table: Some(table),
    };
    let single = |x: f64| {
        let f = squeeze(&upper_law, &rolling_law, x, x - d).unwrap().force;
        let r = Rolling {
            radius: 0.5 * x,
            load: f,
            velocity: sys.velocity,
            layer: sys.layer,
        };
        let answer = solve(&r, &SolveOptions::integrals_only(Default::default())).unwrap();
        (particle(&r, &answer), f)
    };
    let dist = &sys.diameters;
    let (lo, hi) = (d.max(dist.min), dist.max);
    let cells = 4000;
    let h = (hi - lo) / cells as f64;
    let count = sys.nominal_area * sys.areal_density;
    let (mut traction, mut modes) = (0.0, [0.0; 3]);
    for i in 0..cells {
        let x = lo + (i as f64 + 0.5) * h;
        let (m, f) = single(x);
        let n = count * dist.density(x) * h;
        traction += n * f * m.friction;
        modes[m.mode as usize] += n;
    }
    let friction = traction / s.rolling.loads.total;
    let motion = &s.motion;
    assert!(
        close(motion.friction, friction, 2e-4),
        "{} vs {friction}",
        motion.friction
    );
    for (got, direct) in [
        (motion.rolling, modes[0]),
        (motion.sliding_at_layer, modes[1]),
        (motion.sliding_at_upper, modes[2]),
    ] {
        assert!(
            (got - direct).abs() <= 1e-3 * s.rolling.particles_in_contact,
            "{got} vs {direct}"
        );
    }
    // Each change of mode where the single answers change theirs, by bisection.
    assert!(!motion.changes.is_empty());
    for change in &motion.changes {
        let (x, mode) = (change.diameter, change.above);
        let (mut below, mut above) = (x * (1.0 - 1e-3), x * (1.0 + 1e-3));
        assert_eq!(single(below).0.mode, change.below);
        assert_eq!(single(above).0.mode, mode);
        while above - below > 1e-9 * x {
            let middle = 0.5 * (below + above);
            if single(middle).0.mode == mode {
                above = middle;
            } else {
                below = middle;
            }
        }
        assert!(close(x, below, 1e-6), "{x:e} vs {below:e}");
    }
}

/// The Hertz layer contact is elastic and symmetric: rolling costs nothing, every
/// particle rolls, and without asperities the system transmits no tangential force.
#[test]
fn on_the_hertz_layer_every_particle_rolls() {
    let sys = ThreeBody {
        layer_contact: LayerContact::Hertz,
        ..system(OperatingPoint::TotalLoad(1e-3))
    };
    let s = three_body::solve(&sys, &ThreeBodyOptions::default()).unwrap();
    assert!(close(
        s.motion.rolling,
        s.rolling.particles_in_contact,
        1e-12
    ));
    assert_eq!(s.motion.friction, 0.0);
    assert!(s.motion.changes.is_empty());
}
