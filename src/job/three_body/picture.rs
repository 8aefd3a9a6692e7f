//! The picture of a three-body answer: the distribution of particle diameters, the
//! particles in contact (larger than the separation) shaded, and how the real contact area
//! splits.

use serde::Deserialize;

use super::{ThreeBodyJob, ThreeBodyResult};
use crate::job::picture::{shown, Asked, PictureError};
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
        let mut shaded: Vec<(f64, f64)> = curve
            .iter()
            .copied()
            .filter(|p| p.0 >= separation)
            .collect();
        if let (Some(&(first, _)), Some(&(last, _))) = (shaded.first(), shaded.last()) {
            shaded.insert(0, (first, 0.0));
            shaded.push((last, 0.0));
        }
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
            points: curve,
            dashed: false,
        }];
        if shaded.len() > 2 {
            layers.push(Layer::Area {
                name: "in contact (x > d)".to_string(),
                outline: shaded,
            });
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
                format!("real contact area {}", shown(areas.total, "m^2")),
                share("particle–upper", areas.particle_upper),
                share("surface–surface", areas.surface_surface),
                format!("particle–layer: {}", shown(areas.particle_layer, "m^2")),
                format!("layer: {}", law_name(system.layer_contact)),
            ],
        })
    }
}

/// The layer contact law, in a user's words.
fn law_name(law: LayerContact) -> &'static str {
    match law {
        LayerContact::KelvinLayer => "local law (the paper's)",
        LayerContact::Hertz => "Hertz (eq. 6)",
        LayerContact::Continuum => "continuum",
    }
}
