//! The continuum layer's penetration curves a system needs, built from continuum solves that
//! the caller may run as it likes (in parallel, from a memo, one after another).

use std::sync::Arc;

use super::system::ThreeBody;
use crate::continuum::{ContinuumVerification, PenetrationCurve};
use crate::{ModelError, Rolling, RollingSolution, Stop};

/// The continuum layer's contacts a system with the `continuum` layer contact needs: at its
/// speed and at rest (one curve when it is at rest), each up to the largest c = √(Rδ) a
/// particle can reach, √((x_max/2)·max(H, x_max)): δ ≤ ω ≤ x_max for every separation
/// the operating point's root may try, and H keeps a layer thicker than the particles
/// covered to its thickness.
#[derive(Clone, Debug)]
pub struct LayerCurves {
    pub rolling: Arc<PenetrationCurve>,
    pub resting: Arc<PenetrationCurve>,
}

impl LayerCurves {
    /// The continuum problems whose answers make the curves of `system`, the rolling
    /// curve's first ([`PenetrationCurve::problems`]).
    pub fn problems(system: &ThreeBody) -> Vec<Rolling> {
        let (layer, reach) = (&system.layer, Self::reach(system));
        let mut problems = PenetrationCurve::problems(layer, system.velocity, reach);
        if system.velocity > 0.0 {
            problems.extend(PenetrationCurve::problems(layer, 0.0, reach));
        }
        problems
    }

    /// The curves of `system` from `solve_all`, which answers [`LayerCurves::problems`] in
    /// their order (in parallel, from a memo, or one after another, as the caller has it).
    pub fn solved_by<E>(
        system: &ThreeBody,
        solve_all: impl FnOnce(&[Rolling]) -> Result<Vec<RollingSolution<ContinuumVerification>>, E>,
    ) -> Result<LayerCurves, E> {
        let problems = Self::problems(system);
        let answers = solve_all(&problems)?;
        Ok(Self::from_answers(system, &problems, &answers))
    }

    /// The curves of `system`, solved here one problem after another, stopped when `stop`
    /// says so.
    pub fn build(system: &ThreeBody, stop: Stop) -> Result<LayerCurves, ModelError> {
        Self::solved_by(system, |problems| {
            problems
                .iter()
                .map(|p| PenetrationCurve::solve(p, stop))
                .collect()
        })
    }

    /// The curves from the answers to [`LayerCurves::problems`], in their order.
    fn from_answers(
        system: &ThreeBody,
        problems: &[Rolling],
        answers: &[RollingSolution<ContinuumVerification>],
    ) -> LayerCurves {
        let layer = &system.layer;
        let split = problems
            .iter()
            .position(|p| p.velocity != system.velocity)
            .unwrap_or(problems.len());
        let curve = |range: std::ops::Range<usize>, velocity: f64| {
            Arc::new(PenetrationCurve::from_answers(
                layer,
                velocity,
                &problems[range.clone()],
                &answers[range],
            ))
        };
        let rolling = curve(0..split, system.velocity);
        let resting = if split < problems.len() {
            curve(split..problems.len(), 0.0)
        } else {
            rolling.clone()
        };
        LayerCurves { rolling, resting }
    }

    fn reach(system: &ThreeBody) -> f64 {
        let x_max = system.diameters.max;
        (0.5 * x_max * system.layer.thickness.max(x_max)).sqrt()
    }
}
