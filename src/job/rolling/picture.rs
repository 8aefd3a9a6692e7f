//! The picture of a rolling answer, as in the paper's Fig. 3: the contact region
//! a(y) ≤ x ≤ b(y), the circle of the same sphere at rest, the pressure centre and the
//! centroid; the pressure map under it when the answer has one.

use serde::Deserialize;

use super::{BoundaryOutput, ContactOutput, PressureOutput, RollingJob};
use crate::job::input::LayerModel;
use crate::job::picture::{shown, Asked, PictureError};
use crate::render::svg::{Axis, Chart, Layer};
use crate::render::Picture;

/// What the picture shows of a rolling answer.
#[derive(Deserialize)]
pub struct RollingPicture {
    #[serde(flatten)]
    contact: ContactOutput,
    boundary: Vec<BoundaryOutput>,
    pressure: Option<PressureOutput>,
    meta: Asked,
}

impl Picture for RollingPicture {
    fn chart(self) -> Result<Chart, PictureError> {
        let job = self.meta.job::<RollingJob>()?;
        let rolling = job.rolling;
        let contact = &self.contact;
        let mut layers = Vec::new();
        let mut outline: Vec<(f64, f64)> = self.boundary.iter().map(|p| (p.entry, p.y)).collect();
        outline.extend(self.boundary.iter().rev().map(|p| (p.exit, p.y)));
        if let Some(grid) = self.pressure {
            layers.push(Layer::Heatmap {
                name: "pressure".to_string(),
                x: grid.x,
                y: grid.y,
                values: grid.values,
                unit: "Pa".to_string(),
                // The pressure is zero outside the contact: no cell past its edge.
                clip: outline.clone(),
            });
        }
        layers.push(Layer::Area {
            name: format!("contact, V = {}", shown(rolling.velocity, "m/s")),
            outline,
        });
        layers.push(Layer::Circle {
            name: "at rest, V = 0".to_string(),
            centre: (0.0, 0.0),
            radius: (contact.r#static.contact_area / std::f64::consts::PI).sqrt(),
        });
        layers.push(Layer::Markers {
            name: "pressure centre".to_string(),
            points: vec![(contact.pressure_centre_shift, 0.0)],
            hollow: false,
        });
        layers.push(Layer::Markers {
            name: "centroid".to_string(),
            points: vec![(contact.centroid_shift, 0.0)],
            hollow: true,
        });
        let law = match job.law {
            LayerModel::Local => "",
            LayerModel::Continuum => " (layer as a continuum)",
        };
        let title = format!(
            "Contact region{law}, R = {}, P = {}, μ = {}",
            shown(rolling.radius, "m"),
            shown(rolling.load, "N"),
            shown(contact.friction_coefficient, "")
        );
        let motion = &contact.motion;
        let notes = vec![
            format!("particle: {}", motion.mode.words()),
            format!("friction {}", shown(motion.friction, "")),
            format!("rolling needs {}", shown(motion.rolling_need, "")),
            format!("layer holds {} (μ)", shown(motion.layer_capacity, "")),
            format!("upper holds {}", shown(motion.upper_capacity, "")),
        ];
        Ok(Chart {
            title,
            x: Axis::new("x (rolling direction)", "m"),
            y: Axis::new("y", "m"),
            layers,
            equal_aspect: true,
            notes,
        })
    }
}
