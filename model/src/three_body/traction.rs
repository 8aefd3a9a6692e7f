//! The particles' tangential forces summed over the sizes in contact (docs/model.md §11).
//! Each size, at its own load, rolls or slides at its weaker contact; its tangential force
//! F·min(μ_roll, μ_cap,u, μ_cap,l) is continuous in the diameter but kinks where the mode
//! changes. So the size sum is split there: each piece is smooth for Gauss–Legendre, and the
//! particles of each mode are exact integrals of the distribution between the changes.

use super::distribution::Diameters;
use super::solver::EDGE_POWER;
use super::state::{ModeChange, SystemMotion};
use crate::motion::{Mode, Motion};
use crate::quadrature::GaussRule;
use crate::roots::brent;
use crate::ModelError;

/// Samples of the sizes in contact between which a change of mode is looked for (the
/// middles of as many cells in τ, and both ends of the range): a change and its return
/// within one cell (1/64 of the range in τ) would be missed.
const SCAN: usize = 64;

/// One particle of a given diameter: its balance, the normal force it carries (N), and a
/// bound on the relative error of its tangential force from the layer's law.
pub(super) type Particle = (Motion, f64, f64);

/// The sizes in contact at a separation, and where each particle's balance comes from.
pub(super) struct Population<'a, F> {
    pub diameters: &'a Diameters,
    pub separation: f64,
    /// Particles in the system, A_n η_a.
    pub count: f64,
    /// The particle of a diameter (> separation) at this separation.
    pub particle: F,
}

impl<F> Population<'_, F>
where
    F: Fn(f64) -> Result<Particle, ModelError>,
{
    /// Σ T and the particles of each mode, the size sum split where the mode changes, each
    /// piece under `nodes`; the friction is left for the caller (it adds the asperities).
    /// Also Σ T under `coarse` over the same pieces: the size sum's error estimate.
    pub fn motion(
        &self,
        nodes: &GaussRule,
        coarse: &GaussRule,
    ) -> Result<(SystemMotion, f64), ModelError> {
        let d = self.diameters;
        let mut motion = SystemMotion::default();
        if d.is_single_size() {
            if d.mean > self.separation {
                let (m, force, error) = (self.particle)(d.mean)?;
                self.tally(&mut motion, m.mode, 1.0);
                motion.particle_traction = self.count * force * m.friction;
                motion.traction_error = error;
                motion.furthest = Some(m);
            }
            return Ok((motion.clone(), motion.particle_traction));
        }
        let lo = self.separation.max(d.min);
        if lo >= d.max {
            return Ok((motion, 0.0));
        }
        let span = d.max - self.separation;
        let tau_lo = ((lo - self.separation) / span).powf(1.0 / f64::from(EDGE_POWER));
        let diameter = |tau: f64| self.separation + span * tau.powi(EDGE_POWER);
        // The mode at the middle of each of SCAN cells in τ and at the range's ends (its
        // lower end only where a particle there is squeezed: above the separation), and
        // where it changes, refined to the root of the balance that decides it.
        let width = (1.0 - tau_lo) / SCAN as f64;
        let middles = (0..SCAN).map(|k| tau_lo + (k as f64 + 0.5) * width);
        let samples = (tau_lo > 0.0)
            .then_some(tau_lo)
            .into_iter()
            .chain(middles)
            .chain([1.0]);
        let mut breaks = vec![tau_lo];
        let mut modes = Vec::new();
        let mut previous: Option<(f64, Motion)> = None;
        for tau in samples {
            let (m, ..) = (self.particle)(diameter(tau))?;
            keep_furthest(&mut motion, m);
            if let Some((before, was)) = previous.filter(|(_, was)| was.mode != m.mode) {
                let at = self.change(before, tau, was.mode, m.mode, &diameter)?;
                motion.changes.push(ModeChange {
                    diameter: diameter(at),
                    below: was.mode,
                    above: m.mode,
                });
                breaks.push(at);
            }
            if previous.map_or(true, |(_, was)| was.mode != m.mode) {
                modes.push(m.mode);
            }
            previous = Some((tau, m));
        }
        breaks.push(1.0);
        let above = |tau: f64| d.fraction_above(if tau == tau_lo { lo } else { diameter(tau) });
        for (piece, &mode) in breaks.windows(2).zip(&modes) {
            self.tally(&mut motion, mode, above(piece[0]) - above(piece[1]));
        }
        // Σ T and Σ T ε (ε each particle's error) under `rule`, piece by piece.
        let sum = |rule: &GaussRule, motion: &mut SystemMotion| {
            let (x, w) = &**rule;
            let (mut traction, mut error) = (0.0, 0.0);
            for piece in breaks.windows(2) {
                let (a, b) = (piece[0], piece[1]);
                for (t, w) in x.iter().zip(w) {
                    let tau = a + (b - a) * 0.5 * (t + 1.0);
                    let x = diameter(tau);
                    let weight = w
                        * 0.5
                        * (b - a)
                        * f64::from(EDGE_POWER)
                        * span
                        * tau.powi(EDGE_POWER - 1)
                        * d.density(x);
                    let (m, force, e) = (self.particle)(x)?;
                    keep_furthest(motion, m);
                    let t = self.count * weight * force * m.friction;
                    traction += t;
                    error += t * e;
                }
            }
            Ok::<_, ModelError>((traction, error))
        };
        let (traction, error) = sum(nodes, &mut motion)?;
        motion.particle_traction = traction;
        if traction > 0.0 {
            motion.traction_error = error / traction;
        }
        let (coarse_traction, _) = sum(coarse, &mut motion)?;
        Ok((motion, coarse_traction))
    }

    /// Counts a `share` of the particles in `mode`.
    fn tally(&self, motion: &mut SystemMotion, mode: Mode, share: f64) {
        let particles = self.count * share;
        match mode {
            Mode::Rolls => motion.rolling += particles,
            Mode::SlidesAtLayer => motion.sliding_at_layer += particles,
            Mode::SlidesAtUpper => motion.sliding_at_upper += particles,
        }
    }

    /// The τ between `before` (mode `was`) and `after` (mode `is`) where the mode changes:
    /// where rolling's need meets the weaker capacity, or where the two capacities cross.
    fn change(
        &self,
        before: f64,
        after: f64,
        was: Mode,
        is: Mode,
        diameter: &impl Fn(f64) -> f64,
    ) -> Result<f64, ModelError> {
        let between_slides = was != Mode::Rolls && is != Mode::Rolls;
        let mut failure = None;
        let mut balance = |tau: f64| match (self.particle)(diameter(tau)) {
            Ok((m, ..)) if between_slides => (m.upper_capacity / m.layer_capacity).ln(),
            Ok((m, ..)) => m.margin().ln(),
            Err(e) => {
                failure.get_or_insert(e);
                f64::NAN
            }
        };
        let ends = ((before, balance(before)), (after, balance(after)));
        let root = brent(
            &mut balance,
            ends.0,
            ends.1,
            1e-12 * (after - before),
            "diameter where the particles change from rolling to sliding",
        );
        match failure {
            Some(e) => Err(e),
            None => Ok(root?.x),
        }
    }
}

/// Keeps in `motion` the particle furthest from rolling.
fn keep_furthest(motion: &mut SystemMotion, m: Motion) {
    if motion.furthest.map_or(true, |f| m.margin() < f.margin()) {
        motion.furthest = Some(m);
    }
}
