//! The model's domain of validity (docs/model.md §7): each assumption the model rests on, measured
//! on a solved contact as a ratio, with its status. The verification block of an answer says
//! how exact the numbers are; this says how far the model itself can be trusted there.

use std::f64::consts::PI;

use super::continuum::{static_area, ContinuumVerification};
use super::motion::Motion;
use super::three_body::{LayerContact, ThreeBody, ThreeBodySolution};
use super::{Rolling, RollingSolution};

/// Where a ratio stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    Ok,
    /// The answer is given; the assumption is strained there.
    Warn,
    /// The assumption fails: no answer.
    Violated,
}

/// An assumption of the model and how it is measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Assumption {
    /// The sphere stays inside the layer (the rigid base is never reached): δ/H (three-body:
    /// the largest ω₂/H). Warn above 0.1 (the linear layer law assumes small strain);
    /// violated at 1.
    InsideLayer,
    /// The sphere is a paraboloid: a_max/R with a_max the largest extent of the contact;
    /// the profile's error is about (a_max/R)²/4. Warn when that passes 0.05; violated at 1.
    Parabolic,
    /// The layer is local (Winkler): A_local/A_continuum at rest, the static contact area
    /// under the local law over that of the layer as a continuum (docs/model.md §7, §8, by
    /// its table). Warn when off by more than 5 % either way: a thick layer spreads the
    /// load (the local law overstates the area), a thin nearly incompressible one squeezes
    /// out sideways (it understates it).
    LocalLayer,
    /// Adhesive friction is meaningful: μ of eq. 12. Warn above 1.
    AdhesiveFriction,
    /// Three-body: the surfaces stay apart: d/x_max. Violated at or below 0.
    SurfacesApart,
    /// Three-body with asperities: d/σ_s. Warn below 3 (the asperities touch: outside the
    /// paper's always-a-gap regime, their contact is in the answer).
    AsperityGap,
    /// Three-body: particles in contact, n_a. Warn below 1 (a fraction of a particle).
    ParticlesInContact,
    /// The layer as a continuum: pixels across the contact on the fine grid, 2√(A/π)/h
    /// (docs/model.md §8). Warn below 24.
    Resolution,
    /// The layer as a continuum: the answer's reported error against §8's tolerances, the
    /// larger of A's error over 1 % and δ's over 0.5 %. Warn above 1: the numbers are
    /// given, less exact than §8 asks, and `meta.verification` says by how much.
    Numerical,
    /// The particle rolls, as the paper assumes (docs/model.md §11): μ_roll over the weaker
    /// contact's capacity (three-body: the largest over the sizes in contact). Warn above
    /// 1: the particle slides there, and its friction is that capacity.
    PureRolling,
}

impl Assumption {
    /// Every assumption.
    pub const ALL: [Assumption; 10] = [
        Assumption::InsideLayer,
        Assumption::Parabolic,
        Assumption::LocalLayer,
        Assumption::AdhesiveFriction,
        Assumption::SurfacesApart,
        Assumption::AsperityGap,
        Assumption::ParticlesInContact,
        Assumption::Resolution,
        Assumption::Numerical,
        Assumption::PureRolling,
    ];

    /// The status of `ratio`.
    pub fn status(self, ratio: f64) -> Status {
        use Assumption::*;
        let (warn, violated) = match self {
            InsideLayer => (ratio > 0.1, ratio >= 1.0),
            Parabolic => (ratio * ratio / 4.0 > 0.05, ratio >= 1.0),
            LocalLayer => ((ratio - 1.0).abs() > 0.05, false),
            AdhesiveFriction => (ratio > 1.0, false),
            SurfacesApart => (false, ratio <= 0.0),
            AsperityGap => (ratio < 3.0, false),
            ParticlesInContact => (ratio < 1.0, false),
            Resolution => (ratio < 24.0, false),
            Numerical | PureRolling => (ratio > 1.0, false),
        };
        if violated {
            Status::Violated
        } else if warn {
            Status::Warn
        } else {
            Status::Ok
        }
    }
}

/// One assumption measured on an answer: the ratio (its numerator and denominator, for
/// messages) in the moving contact and in its V = 0 companion, which the answer also gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Check {
    pub assumption: Assumption,
    /// (numerator, denominator) at the job's speed.
    pub rolling: (f64, f64),
    /// The same for the V = 0 companion.
    pub at_rest: (f64, f64),
    /// For [`Assumption::PureRolling`]: how the particles move, for the words of a warning.
    pub motion: Option<Sliding>,
}

/// How the particles of a pure-rolling check move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sliding {
    /// The particle's (three-body: the one furthest from rolling).
    pub motion: Motion,
    /// Three-body: the particles that slide and those in contact.
    pub particles: Option<(f64, f64)>,
    /// The friction then transmitted: the particle's, or the system's Σ T/W.
    pub friction: f64,
}

impl Check {
    fn new(assumption: Assumption, rolling: (f64, f64), at_rest: (f64, f64)) -> Check {
        Check {
            assumption,
            rolling,
            at_rest,
            motion: None,
        }
    }

    /// Whether the particle of `motion` rolls (docs/model.md §11): μ_roll over the weaker
    /// capacity; at rest rolling needs nothing.
    pub fn pure_rolling(motion: &Motion) -> Check {
        Check::rolling_of(Sliding {
            motion: *motion,
            particles: None,
            friction: motion.friction,
        })
    }

    /// The pure-rolling check of `sliding`'s particle.
    fn rolling_of(sliding: Sliding) -> Check {
        let worst = sliding.motion;
        let weaker = worst.upper_capacity.min(worst.layer_capacity);
        Check {
            motion: Some(sliding),
            ..Check::new(
                Assumption::PureRolling,
                (worst.rolling_need, weaker),
                (0.0, weaker),
            )
        }
    }

    /// The ratio at the job's speed.
    pub fn ratio(&self) -> f64 {
        self.rolling.0 / self.rolling.1
    }

    /// The ratio at rest.
    pub fn ratio_at_rest(&self) -> f64 {
        self.at_rest.0 / self.at_rest.1
    }

    /// The worse of the two states.
    pub fn status(&self) -> Status {
        let status = |r: f64| self.assumption.status(r);
        status(self.ratio()).max(status(self.ratio_at_rest()))
    }

    /// Whether only the V = 0 companion makes the status what it is.
    pub fn caused_at_rest(&self) -> bool {
        self.assumption.status(self.ratio_at_rest()) > self.assumption.status(self.ratio())
    }
}

/// The assumptions of docs/model.md §7 on one rolling contact.
pub fn rolling<V>(rolling: &Rolling, s: &RollingSolution<V>) -> Vec<Check> {
    let rest = &s.static_contact;
    // b(0) is the half-width and |a(0)| < b(0) (docs/model.md §3): the half-width is a_max.
    let mut checks = contact_checks(rolling, s, s.half_width);
    let local = local_layer(
        rest.contact_area,
        rolling.radius,
        rolling.load,
        &rolling.layer,
    );
    checks.insert(2, local);
    checks
}

/// The assumptions of docs/model.md §8 on one rolling contact on the layer as a continuum:
/// §7's, less the local layer's (the continuum is what it is measured against), the grid's
/// resolution of the contact, and the answer's error against §8's tolerances.
pub fn continuum(rolling: &Rolling, s: &RollingSolution<ContinuumVerification>) -> Vec<Check> {
    let mut checks = contact_checks(rolling, s, s.verification.extent);
    if let Some(grid) = s.verification.grid {
        checks.push(Check::new(
            Assumption::Resolution,
            (grid.across, 1.0),
            (grid.across_at_rest, 1.0),
        ));
    }
    let (rolling_share, at_rest) = s.verification.errors.tolerance_shares();
    checks.push(Check::new(
        Assumption::Numerical,
        (rolling_share, 1.0),
        (at_rest, 1.0),
    ));
    checks
}

/// The rows every rolling contact has, whatever the layer's law: inside the layer, the
/// parabolic sphere (its contact reaching `extent` from the centre), adhesive friction.
fn contact_checks<V>(rolling: &Rolling, s: &RollingSolution<V>, extent: f64) -> Vec<Check> {
    let (h, r) = (rolling.layer.thickness, rolling.radius);
    let rest = &s.static_contact;
    vec![
        Check::new(
            Assumption::InsideLayer,
            (s.penetration, h),
            (rest.penetration, h),
        ),
        Check::new(Assumption::Parabolic, (extent, r), (rest.half_width, r)),
        Check::new(
            Assumption::AdhesiveFriction,
            (s.friction_coefficient, 1.0),
            (rest.friction_coefficient, 1.0),
        ),
    ]
}

/// The local-layer check of a sphere of radius `radius` under `load` at rest, whose contact
/// area under the local law is `local_area`: measured at rest, for the answer and its V = 0
/// companion alike.
fn local_layer(local_area: f64, radius: f64, load: f64, layer: &crate::Layer) -> Check {
    let areas = (local_area, static_area(radius, load, layer));
    Check::new(Assumption::LocalLayer, areas, areas)
}

/// The assumptions of docs/model.md §7 on a three-body system, measured on its largest particle
/// in contact (the deepest and widest contact) and on the whole system.
pub fn three_body(system: &ThreeBody, s: &ThreeBodySolution) -> Vec<Check> {
    let h = system.layer.thickness;
    let x_max = system.diameters.max;
    let radius = 0.5 * x_max;
    // Contact half-width of the largest particle on the layer: √(2Rω₂) in the Kelvin layer
    // (docs/model.md §3), √(Rω₂) for Hertz and, as its scale, for the continuum (whose
    // contact radius is √(Φ_A) times that, Φ_A within a factor 1.5 of 1 wherever δ < H).
    let half_width = |omega: f64| match system.layer_contact {
        LayerContact::KelvinLayer => (2.0 * radius * omega).sqrt(),
        LayerContact::Hertz | LayerContact::Continuum => (radius * omega).sqrt(),
    };
    let (moving, rest) = (&s.rolling, &s.static_state);
    let (w_moving, w_rest) = (moving.max_layer_penetration, rest.max_layer_penetration);
    let mut checks = vec![
        Check::new(Assumption::InsideLayer, (w_moving, h), (w_rest, h)),
        Check::new(
            Assumption::Parabolic,
            (half_width(w_moving), radius),
            (half_width(w_rest), radius),
        ),
        Check::new(
            Assumption::AdhesiveFriction,
            (moving.friction_coefficient, 1.0),
            (rest.friction_coefficient, 1.0),
        ),
        Check::new(
            Assumption::SurfacesApart,
            (moving.separation, x_max),
            (rest.separation, x_max),
        ),
        Check::new(
            Assumption::ParticlesInContact,
            (moving.particles_in_contact, 1.0),
            (rest.particles_in_contact, 1.0),
        ),
    ];
    // The local law takes the particles only in the Kelvin-layer contact (Hertz's treats
    // the layer as a half-space), and at rest its largest particle carries P = πkRω²
    // (docs/model.md §3) on the area 2πRω.
    if system.layer_contact == LayerContact::KelvinLayer && w_rest > 0.0 {
        let k = system.layer.elastic_modulus / h;
        let load = PI * k * radius * w_rest * w_rest;
        let area = 2.0 * PI * radius * w_rest;
        checks.insert(2, local_layer(area, radius, load, &system.layer));
    }
    if let Some(a) = &system.asperities {
        checks.push(Check::new(
            Assumption::AsperityGap,
            (moving.separation, a.height_std),
            (rest.separation, a.height_std),
        ));
    }
    let motion = &s.motion;
    if let Some(worst) = motion.furthest {
        checks.push(Check::rolling_of(Sliding {
            motion: worst,
            particles: Some((motion.sliding(), moving.particles_in_contact)),
            friction: motion.friction,
        }));
    }
    checks
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{solve, SolveOptions};

    #[test]
    fn the_thresholds_are_those_of_model_section_7() {
        use Assumption::*;
        for (assumption, ratio, status) in [
            (InsideLayer, 0.1, Status::Ok),
            (InsideLayer, 0.11, Status::Warn),
            (InsideLayer, 1.0, Status::Violated),
            (Parabolic, 0.2_f64.sqrt() * 0.999, Status::Ok),
            (Parabolic, 0.2_f64.sqrt() * 1.001, Status::Warn),
            (Parabolic, 1.0, Status::Violated),
            (LocalLayer, 1.06, Status::Warn),
            (LocalLayer, 0.94, Status::Warn),
            (LocalLayer, 1.04, Status::Ok),
            (LocalLayer, 0.96, Status::Ok),
            (AdhesiveFriction, 1.01, Status::Warn),
            (SurfacesApart, 0.0, Status::Violated),
            (SurfacesApart, 1e-9, Status::Ok),
            (AsperityGap, 2.9, Status::Warn),
            (ParticlesInContact, 0.5, Status::Warn),
        ] {
            assert_eq!(assumption.status(ratio), status, "{assumption:?} {ratio}");
        }
    }

    #[test]
    fn the_default_particle_warns_only_on_the_local_layer() {
        let r = Rolling::default();
        let s = solve(&r, &SolveOptions::default()).unwrap();
        let checks = rolling(&r, &s);
        let warned: Vec<Assumption> = checks
            .iter()
            .filter(|c| c.status() != Status::Ok)
            .map(|c| c.assumption)
            .collect();
        assert_eq!(warned, [Assumption::LocalLayer]);
        // δ/H and a_max/R of the reference row (docs/model.md §3: δ = 0.6237 nm, b(0) = 5.5842 nm).
        assert!((checks[0].ratio() - 0.6237e-2).abs() < 1e-6);
        assert!((checks[1].ratio() * 25.0 - 5.5842).abs() < 1e-4);
        // The local law's 102.333 nm² at rest against the continuum's 13.39 nm² (§8).
        let local = &checks[2];
        assert!(
            (local.ratio() / 7.643 - 1.0).abs() < 0.01,
            "{}",
            local.ratio()
        );
        assert_eq!(local.ratio(), local.ratio_at_rest());
    }
}
