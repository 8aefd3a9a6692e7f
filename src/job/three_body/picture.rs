//! The picture of a three-body answer: the distribution of particle diameters, the
//! particles in contact (larger than the separation) shaded, and how the real contact area
//! splits.

use serde::Deserialize;

use super::{SystemMotionOutput, ThreeBodyJob, ThreeBodyResult};
use crate::job::picture::{shown, Asked, PictureError};
use crate::job::rolling::MotionMode;
use crate::model::text::count;
use crate::model::three_body::LayerContact;
use crate::render::svg::{Axis, Chart, Layer};
use crate::render::Picture;

/// What the picture shows of a three-body answer.
#[derive(Deserialize)]
pub struct ThreeBodyPicture {
    #[serde(flatten)]
    result: ThreeBodyResult,
    meta: Asked,
}

impl Picture for ThreeBodyPicture {
    fn chart(self) -> Result<Chart, PictureError> {
        let system = self.meta.job::<ThreeBodyJob>()?.system;
        let d = system.diameters;
        let state = &self.result.state;
        let separation = state.separation;
        let density = |x: f64| {
            if d.std > 0.0 {
                // Per nm, as read on the axis.
                (-(x - d.mean).powi(2) / (2.0 * d.std * d.std)).exp()
                    / (d.std * (2.0 * std::f64::consts::PI).sqrt())
                    * 1e-9
            } else {
                0.0
            }
        };
        let curve: Vec<(f64, f64)> = (0..=200)
            .map(|i| d.min + (d.max - d.min) * f64::from(i) / 200.0)
            .map(|x| (x, density(x)))
            .collect();
        let top = curve.iter().map(|p| p.1).fold(0.0, f64::max);
        let areas = &state.areas;
        let share = |name: &str, a: f64| {
            let percent = if areas.total > 0.0 {
                100.0 * a / areas.total
            } else {
                0.0
            };
            format!("{name}: {percent:.1} %")
        };
        let mut layers = vec![Layer::Line {
            name: "diameters".to_string(),
            group: "diameters".to_string(),
            points: curve.clone(),
            dashed: false,
        }];
        // The particles in contact (x > d), shaded by how they move (docs/model.md §11).
        let motion = &self.result.motion;
        for (from, to, mode) in populations(motion, separation.max(d.min), d.max) {
            let inside = |x: f64| (from..=to).contains(&x);
            let mut outline = vec![(from, 0.0), (from, density(from))];
            outline.extend(curve.iter().copied().filter(|p| inside(p.0)));
            outline.extend([(to, density(to)), (to, 0.0)]);
            if to > from {
                layers.push(Layer::Area {
                    name: format!("in contact: {}", mode.words()),
                    outline,
                });
            }
        }
        layers.push(Layer::Line {
            name: format!("separation d = {}", shown(separation, "m")),
            group: "separation".to_string(),
            points: vec![(separation, 0.0), (separation, top * 1.05)],
            dashed: true,
        });
        Ok(Chart {
            title: format!(
                "Three-body system: {} in contact",
                count(state.particles_in_contact, "particle", "particles")
            ),
            x: Axis::new("particle diameter", "m"),
            y: Axis::new("probability density per nm", ""),
            layers,
            equal_aspect: false,
            notes: vec![
                format!(
                    "{} roll, {} slide",
                    count(motion.rolling, "", "").trim_end(),
                    count(motion.sliding_at_layer + motion.sliding_at_upper, "", "").trim_end(),
                ),
                format!(
                    "friction {} (eq. 12: {})",
                    shown(motion.friction, ""),
                    shown(self.result.friction_coefficient.rolling, ""),
                ),
                format!("real contact area {}", shown(areas.total, "m^2")),
                share("particle–upper", areas.particle_upper),
                share("surface–surface", areas.surface_surface),
                format!("particle–layer: {}", shown(areas.particle_layer, "m^2")),
                format!("layer: {}", law_name(system.layer_contact)),
            ],
        })
    }
}

/// The diameters in contact, from `from` to `to`, in pieces of one mode each: split where
/// the mode changes; without a change, of the mode that has particles.
fn populations(motion: &SystemMotionOutput, from: f64, to: f64) -> Vec<(f64, f64, MotionMode)> {
    let only = if motion.rolling > 0.0 {
        MotionMode::Rolls
    } else if motion.sliding_at_layer > 0.0 {
        MotionMode::SlidesAtLayer
    } else {
        MotionMode::SlidesAtUpper
    };
    let first = motion.changes.first().map_or(only, |c| c.below);
    let mut pieces = Vec::new();
    let (mut start, mut mode) = (from, first);
    for change in &motion.changes {
        pieces.push((start, change.diameter, mode));
        (start, mode) = (change.diameter, change.above);
    }
    pieces.push((start, to, mode));
    pieces
}

/// The layer contact law, in a user's words.
fn law_name(law: LayerContact) -> &'static str {
    match law {
        LayerContact::KelvinLayer => "local law (the paper's)",
        LayerContact::Hertz => "Hertz (eq. 6)",
        LayerContact::Continuum => "continuum",
    }
}
