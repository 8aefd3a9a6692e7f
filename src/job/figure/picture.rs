//! The picture of a figure of the paper: its curves on its axes (contact regions at equal
//! scale, curves at rest dashed).

use serde::Deserialize;

use super::{AxisOutput, SeriesOutput};
use crate::job::picture::PictureError;
use crate::render::svg::{Axis, Chart, Layer};
use crate::render::Picture;

/// What the picture shows of a figure: all of it but its `meta`.
#[derive(Deserialize)]
pub struct FigurePicture {
    figure: u8,
    title: String,
    x: AxisOutput,
    y: AxisOutput,
    series: Vec<SeriesOutput>,
}

impl Picture for FigurePicture {
    fn chart(self) -> Result<Chart, PictureError> {
        let axis = |a: &AxisOutput| Axis::new(&a.quantity, &a.unit);
        let (x, y) = (axis(&self.x), axis(&self.y));
        let labels: Vec<&str> = self.series.iter().map(|s| s.label.as_str()).collect();
        let common = common_prefix(&labels);
        // Curves of one sphere and load share a colour (at rest dashed) when there are just
        // two of them, at rest and rolling (Figs. 4–9); else each has its own (Fig. 3).
        let sphere = |label: &str| label.rfind(", V =").map_or(label.len(), |i| i);
        let pairs = labels.iter().all(|l| {
            labels
                .iter()
                .filter(|m| m[..sphere(m)] == l[..sphere(l)])
                .count()
                <= 2
        });
        let layers = self
            .series
            .iter()
            .map(|series| {
                let label = series.label.as_str();
                let group = if pairs {
                    &label[..sphere(label)]
                } else {
                    label
                };
                Layer::Line {
                    name: label[common..].to_string(),
                    group: group.to_string(),
                    points: series.points.iter().map(|p| (p[0], p[1])).collect(),
                    dashed: series.velocity == 0.0,
                }
            })
            .collect();
        let equal_aspect = x.unit == "m" && y.unit == "m";
        Ok(Chart {
            title: format!("Fig. {}: {}", self.figure, self.title),
            x,
            y,
            layers,
            equal_aspect,
            notes: Vec::new(),
        })
    }
}

/// The length of the part ending in ", " that every label starts with (said once, in the
/// title, rather than on every legend entry).
fn common_prefix(labels: &[&str]) -> usize {
    let Some(first) = labels.first() else {
        return 0;
    };
    if labels.len() < 2 {
        return 0;
    }
    let mut end = 0;
    for (i, _) in first.match_indices(", ") {
        let prefix = &first[..i + 2];
        if labels.iter().all(|l| l.starts_with(prefix)) {
            end = i + 2;
        }
    }
    end
}
