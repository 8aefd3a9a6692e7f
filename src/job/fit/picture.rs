//! The picture of a fit: each series' measured points with their error bars (± the
//! uncertainty given), the fitted curve through them, and each residual as a dashed segment
//! from the point to the curve; all in one colour per series. The notes state each fitted
//! value with its 95 % interval. Series of the other quantity than the first series' are
//! left out, and a note says so.

use std::collections::BTreeMap;

use serde::Deserialize;

use super::input::MeasuredQuantity;
use super::output::{Conditions, Curve, Residual};
use crate::job::picture::{shown, symbol, PictureError};
use crate::model::fit::FitParameter;
use crate::render::svg::{Axis, Chart, Layer};
use crate::render::Picture;

/// What the picture shows of a fit.
#[derive(Deserialize)]
pub struct FitPicture {
    curves: Vec<Curve>,
    residuals: Vec<Residual>,
    parameters: BTreeMap<String, Fitted>,
    chi_squared: f64,
    dof: usize,
}

/// What the notes say of a fitted parameter.
#[derive(Deserialize)]
struct Fitted {
    value: f64,
    interval_95: Option<[f64; 2]>,
}

impl Fitted {
    /// `E_L = 2.533 GPa` and `95 %: 2.476 GPa to 2.59 GPa` (two lines: the notes are narrow),
    /// or why there is no interval.
    fn note(&self, name: &str) -> [String; 2] {
        let unit = FitParameter::ALL
            .iter()
            .find(|p| p.name() == name)
            .map_or("", |p| p.parameter().unit());
        let value = format!("{} = {}", symbol(name), shown(self.value, unit));
        match self.interval_95 {
            Some([lo, hi]) => [
                value,
                format!("95 %: {} to {}", shown(lo, unit), shown(hi, unit)),
            ],
            None => [value, "not determined alone".to_string()],
        }
    }
}

/// A curve's name: the conditions it holds, `R = 25 nm, P = 1 nN`, or its series' number.
fn group_name(curve: &Curve, along: &str) -> String {
    let held = curve.points.first().map(|p| {
        let held = p.at.given().into_iter().filter(|c| c.0 != along);
        let named =
            held.map(|(name, unit, value)| format!("{} = {}", symbol(&name), shown(value, unit)));
        named.collect::<Vec<_>>().join(", ")
    });
    held.unwrap_or_else(|| format!("series {}", curve.series))
}

/// A series' measured points, and the segments from them to the curve and their bars.
type Residuals = (Vec<(f64, f64)>, Vec<Layer>);

/// Where a point is along the curves, and the unit there.
type Along<'a> = dyn Fn(&Conditions) -> Result<(f64, &'static str), PictureError> + 'a;

impl FitPicture {
    /// The measured points of `series` and the segments to their fitted values (dashed),
    /// with their uncertainty bars.
    fn residuals(
        &self,
        series: usize,
        quantity: MeasuredQuantity,
        group: &str,
        x: &Along<'_>,
    ) -> Result<Residuals, PictureError> {
        let mut measured = Vec::new();
        let mut segments = Vec::new();
        for r in self.residuals.iter().filter(|r| r.series == series) {
            let compared = r
                .comparison(quantity)
                .ok_or_else(|| PictureError::new("a residual has no comparison"))?;
            let (x, _) = x(&r.at)?;
            measured.push((x, compared.measured));
            segments.push(Layer::Line {
                name: String::new(),
                group: group.to_string(),
                points: vec![(x, compared.measured), (x, compared.fitted)],
                dashed: true,
            });
            if let Some(u) = compared.uncertainty {
                segments.push(Layer::Line {
                    name: String::new(),
                    group: group.to_string(),
                    points: vec![(x, compared.measured - u), (x, compared.measured + u)],
                    dashed: false,
                });
            }
        }
        Ok((measured, segments))
    }

    /// The notes under the chart: each parameter fitted, χ², how to read it, and the series
    /// `left_out`.
    fn notes(&self, left_out: usize) -> Vec<String> {
        let mut notes: Vec<String> = self
            .parameters
            .iter()
            .flat_map(|(name, fitted)| fitted.note(name))
            .collect();
        notes.push(format!(
            "χ² = {} for {} dof",
            shown(self.chi_squared, ""),
            self.dof
        ));
        notes.push("bars: ± the uncertainty given".to_string());
        notes.push("dashed: residuals".to_string());
        if left_out > 0 {
            notes.push(format!("{left_out} series of the other quantity not drawn"));
        }
        notes
    }
}

impl Picture for FitPicture {
    fn chart(self) -> Result<Chart, PictureError> {
        let first = self
            .curves
            .first()
            .ok_or_else(|| PictureError::new("the fit has no curve"))?;
        let (quantity, along) = (first.quantity, first.along.clone());
        // The condition along the curves, with its unit, at a point.
        let x = |at: &Conditions| -> Result<(f64, &'static str), PictureError> {
            let given = at.given().into_iter().find(|c| c.0 == along);
            given
                .map(|c| (c.2, c.1))
                .ok_or_else(|| PictureError::new(format!("a point has no {along}")))
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
            let group = group_name(curve, &along);
            let line = curve
                .points
                .iter()
                .map(|p| {
                    let (x, unit) = x(&p.at)?;
                    x_unit = unit;
                    let y = p
                        .value(quantity)
                        .ok_or_else(|| PictureError::new("a curve point has no value"))?;
                    Ok((x, y))
                })
                .collect::<Result<Vec<_>, PictureError>>()?;
            let (measured, segments) = self.residuals(curve.series, quantity, &group, &x)?;
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
        let notes = self.notes(left_out);
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
