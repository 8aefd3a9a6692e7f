//! The picture of a fit: each series' measured points, the fitted curve through them, and
//! each residual as a dashed segment from the point to the curve; all in one colour per
//! series. Series of the other quantity than the first series' are left out, and a note
//! says so.

use serde::Deserialize;

use super::output::{Conditions, Curve, Residual};
use crate::job::picture::{shown, symbol, Picture, PictureError};
use crate::render::svg::{Axis, Chart, Layer};

/// What the picture shows of a fit.
#[derive(Deserialize)]
pub struct FitPicture {
    curves: Vec<Curve>,
    residuals: Vec<Residual>,
    chi_squared: f64,
    dof: usize,
}

impl Picture for FitPicture {
    fn chart(self) -> Result<Chart, PictureError> {
        let first = self.curves.first().ok_or("the fit has no curve")?;
        let (quantity, along) = (first.quantity, first.along.clone());
        // The condition along the curves, with its unit, at a point.
        let x = |at: &Conditions| -> Result<(f64, &'static str), PictureError> {
            let given = at.given().into_iter().find(|c| c.0 == along);
            given
                .map(|c| (c.2, c.1))
                .ok_or_else(|| format!("a point has no {along}"))
        };
        let mut layers = Vec::new();
        let mut left_out = 0;
        let mut all_x = Vec::new();
        let mut x_unit = "";
        for curve in &self.curves {
            if curve.quantity != quantity {
                left_out += 1;
                continue;
            }
            // Named by the conditions the curve holds: `R = 25 nm, P = 1 nN`.
            let held = curve.points.first().map(|p| {
                let held = p.at.given().into_iter().filter(|c| c.0 != along);
                let named = held.map(|(name, unit, value)| {
                    format!("{} = {}", symbol(&name), shown(value, unit))
                });
                named.collect::<Vec<_>>().join(", ")
            });
            let group = held.unwrap_or_else(|| format!("series {}", curve.series));
            let line = curve
                .points
                .iter()
                .map(|p| {
                    let (x, unit) = x(&p.at)?;
                    x_unit = unit;
                    let y = p.value(quantity).ok_or("a curve point has no value")?;
                    Ok((x, y))
                })
                .collect::<Result<Vec<_>, PictureError>>()?;
            let mut measured = Vec::new();
            let mut segments = Vec::new();
            for r in self.residuals.iter().filter(|r| r.series == curve.series) {
                let compared = r
                    .comparison(quantity)
                    .ok_or("a residual has no comparison")?;
                let (x, _) = x(&r.at)?;
                measured.push((x, compared.measured));
                segments.push(Layer::Line {
                    name: String::new(),
                    group: group.clone(),
                    points: vec![(x, compared.measured), (x, compared.fitted)],
                    dashed: true,
                });
            }
            all_x.extend(measured.iter().map(|p| p.0));
            // Markers first: they take the colour the series' lines then share.
            layers.push(Layer::Markers {
                name: format!("{group}, measured"),
                points: measured,
                hollow: false,
            });
            layers.push(Layer::Line {
                name: format!("{group}, fitted"),
                group: group.clone(),
                points: line,
                dashed: false,
            });
            layers.extend(segments);
        }
        let (lo, hi) = all_x.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
        let mut x = Axis::new(&along, x_unit);
        if lo > 0.0 && hi / lo > 20.0 {
            x = x.log();
        }
        let mut notes = vec![
            format!("χ² = {} for {} dof", shown(self.chi_squared, ""), self.dof),
            "dashed: residuals".to_string(),
        ];
        if left_out > 0 {
            notes.push(format!("{left_out} series of the other quantity not drawn"));
        }
        let name = quantity.name();
        Ok(Chart {
            title: format!("Fit: {} against {along}", name.replace('_', " ")),
            x,
            y: Axis::new(&name.replace('_', " "), quantity.parameter().unit()),
            layers,
            equal_aspect: false,
            notes,
        })
    }
}
