//! What a three-body solve answers: the system's state at the operating point, with rolling
//! and at rest, how its particles move, and how far it can be trusted.

use crate::motion::{Mode, Motion};

/// Real contact areas (m²).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Areas {
    /// A_s1s2, asperities of the upper surface on the layer.
    pub surface_surface: f64,
    /// A_s1a, particles on the upper surface.
    pub particle_upper: f64,
    /// A_s2a, particles on the layer.
    pub particle_layer: f64,
    /// A_total = A_s1s2 + A_s1a (eq. 6).
    pub total: f64,
}

/// Loads carried (N).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Loads {
    /// W_s1s2.
    pub asperities: f64,
    /// W_a.
    pub particles: f64,
    /// W = W_s1s2 + W_a.
    pub total: f64,
}

/// The system at one separation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactState {
    /// d (m).
    pub separation: f64,
    /// n_a (eq. 7).
    pub particles_in_contact: f64,
    pub areas: Areas,
    pub loads: Loads,
    /// ω₂ of the largest particle (m): must stay below the layer thickness.
    pub max_layer_penetration: f64,
    /// μ = (τ_a A_s2a + τ_s A_s1s2)/W (eq. 12 summed).
    pub friction_coefficient: f64,
    /// A bound on the relative error of A_s2a and W_a from the layer contacts' law at this
    /// separation: their errors ([`crate::three_body::Squeeze::layer_error`]) weighted by
    /// what each contact adds to the sums (0 for the closed-form laws).
    pub layer_error: f64,
    /// The same for W_a alone.
    pub layer_load_error: f64,
}

impl ContactState {
    /// A_total/n_a (eq. 8); `None` when no particle is in contact (the asperities carry
    /// the load alone).
    pub fn mean_area(&self) -> Option<f64> {
        self.per_particle(self.areas.total)
    }

    /// W/n_a; `None` when no particle is in contact.
    pub fn mean_load(&self) -> Option<f64> {
        self.per_particle(self.loads.total)
    }

    fn per_particle(&self, total: f64) -> Option<f64> {
        (self.particles_in_contact > 0.0).then(|| total / self.particles_in_contact)
    }
}

/// How far the answer can be trusted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThreeBodyVerification {
    pub diameter_nodes: usize,
    /// Iterations of the separation root (0 for a given separation).
    pub separation_iterations: u32,
    /// |W(d) − W|/W (or the same for the mean particle load) at the returned d.
    pub load_residual: f64,
    /// Largest relative change of the areas and loads when the diameter nodes are halved.
    pub quadrature_error_estimate: f64,
    /// Relative error of the `kelvin_layer` table against direct solves, when one is used.
    pub layer_table_error: Option<f64>,
    /// For the `continuum` layer contact: a bound on the relative error of A_s2a, W_a and
    /// the particles' Σ T from the continuum contacts (their curves' errors, weighted over
    /// the sizes; at a given load, the load's error added, which moves the separation), with
    /// and without rolling, the worse.
    pub layer_contact_error: Option<f64>,
    pub converged: bool,
}

/// How the particles in contact move at the job's speed (docs/model.md §11): each size at
/// its own load rolls, or slides at its weaker contact.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SystemMotion {
    /// (Σ T + τ_s A_s1s2)/W: the system's friction with each particle transmitting the
    /// tangential force its motion gives (eq. 12's μ assumes every particle slides on the
    /// layer).
    pub friction: f64,
    /// Σ T (N), the particles' tangential forces.
    pub particle_traction: f64,
    /// A bound on the relative error of Σ T from the layer contacts' law (0 for the closed
    /// forms; the continuum's force, area and centre of pressure, weighted over the sizes).
    pub traction_error: f64,
    /// Particles that roll.
    pub rolling: f64,
    /// Particles that slide on the layer.
    pub sliding_at_layer: f64,
    /// Particles that slide against the upper surface.
    pub sliding_at_upper: f64,
    /// Where the mode changes, in ascending diameter.
    pub changes: Vec<ModeChange>,
    /// The particle in contact furthest from rolling (the largest μ_roll over its weaker
    /// capacity); `None` with no particle in contact.
    pub furthest: Option<Motion>,
}

/// A diameter where the particles' mode changes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeChange {
    /// x (m).
    pub diameter: f64,
    /// The mode of the particles just smaller, and of those just larger.
    pub below: Mode,
    pub above: Mode,
}

impl SystemMotion {
    /// Particles that slide, at either contact.
    pub fn sliding(&self) -> f64 {
        self.sliding_at_layer + self.sliding_at_upper
    }
}

/// The three-body system with rolling (at the job's V) and without (V = 0).
#[derive(Clone, Debug, PartialEq)]
pub struct ThreeBodySolution {
    pub rolling: ContactState,
    pub static_state: ContactState,
    /// How the particles move with rolling.
    pub motion: SystemMotion,
    pub verification: ThreeBodyVerification,
}
