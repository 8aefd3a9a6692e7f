//! The picture of each kind's answer, drawn from the answer's JSON (so that an answer
//! solved in another process, or assembled from parts, is drawn the same): the contact
//! region of a rolling contact (the paper's Fig. 3), a sweep's curves, a three-body
//! system's diameter distribution, a figure of the paper.

use serde_json::Value;

use crate::model::text::{count, quantity_to};
use crate::render::svg::{Axis, Chart, Layer};

/// Why an answer cannot be drawn: it is not the answer of the kind asked (a fault of ours).
pub type PictureError = String;

fn number(value: &Value, what: &str) -> Result<f64, PictureError> {
    value
        .as_f64()
        .ok_or_else(|| format!("the answer has no number at {what}"))
}

fn list<'a>(value: &'a Value, what: &str) -> Result<&'a Vec<Value>, PictureError> {
    value
        .as_array()
        .ok_or_else(|| format!("the answer has no list at {what}"))
}

/// `value` (SI) in the unit a person reads, with it: `25 nm`; to four digits, so that the
/// labels of close values in a legend differ.
fn shown(value: f64, unit: &str) -> String {
    quantity_to(value, unit, 4)
}

/// A rolling contact as in the paper's Fig. 3: the contact region a(y) ≤ x ≤ b(y), the
/// circle of the same sphere at rest, the pressure centre and the centroid; the pressure
/// map under it when the answer has one.
pub fn rolling(answer: &Value) -> Result<Chart, PictureError> {
    let input = &answer["meta"]["input"];
    let mut layers = Vec::new();
    if let Some(grid) = answer.get("pressure") {
        let axis = |name: &str| -> Result<Vec<f64>, PictureError> {
            list(&grid[name], name)?
                .iter()
                .map(|v| number(v, name))
                .collect()
        };
        let values = list(&grid["values"], "pressure.values")?
            .iter()
            .map(|row| {
                list(row, "pressure.values[]")?
                    .iter()
                    .map(|v| number(v, "pressure.values[][]"))
                    .collect::<Result<Vec<f64>, _>>()
            })
            .collect::<Result<Vec<_>, _>>()?;
        layers.push(Layer::Heatmap {
            name: "pressure".to_string(),
            x: axis("x")?,
            y: axis("y")?,
            values,
            unit: "Pa".to_string(),
        });
    }
    let boundary = list(&answer["boundary"], "boundary")?;
    let edge = |side: &str| -> Result<Vec<(f64, f64)>, PictureError> {
        boundary
            .iter()
            .map(|p| Ok((number(&p[side], side)?, number(&p["y"], "y")?)))
            .collect()
    };
    let mut outline = edge("entry")?;
    outline.extend(edge("exit")?.into_iter().rev());
    let velocity = number(&input["velocity"], "meta.input.velocity")?;
    layers.push(Layer::Area {
        name: format!("contact, V = {}", shown(velocity, "m/s")),
        outline,
    });
    let at_rest = number(&answer["static"]["contact_area"], "static.contact_area")?;
    layers.push(Layer::Circle {
        name: "at rest, V = 0".to_string(),
        centre: (0.0, 0.0),
        radius: (at_rest / std::f64::consts::PI).sqrt(),
    });
    layers.push(Layer::Markers {
        name: "pressure centre".to_string(),
        points: vec![(
            number(&answer["pressure_centre_shift"], "pressure_centre_shift")?,
            0.0,
        )],
        hollow: false,
    });
    layers.push(Layer::Markers {
        name: "centroid".to_string(),
        points: vec![(number(&answer["centroid_shift"], "centroid_shift")?, 0.0)],
        hollow: true,
    });
    let title = format!(
        "Contact region, R = {}, P = {}, μ = {}",
        shown(number(&input["radius"], "meta.input.radius")?, "m"),
        shown(number(&input["load"], "meta.input.load")?, "N"),
        shown(
            number(&answer["friction_coefficient"], "friction_coefficient")?,
            ""
        )
    );
    Ok(Chart {
        title,
        x: Axis::new("x (rolling direction)", "m"),
        y: Axis::new("y", "m"),
        layers,
        equal_aspect: true,
        notes: Vec::new(),
    })
}

/// The name, unit and point field of each list a sweep can vary, in the order a curve is
/// preferred along (speed first).
const VARIED: [(&str, &str, &str); 6] = [
    ("velocity", "m/s", "velocity"),
    ("load", "N", "load"),
    ("radius", "m", "radius"),
    ("mean_diameter", "m", "mean_diameter"),
    ("total_load", "N", "operating.total_load"),
    ("separation", "m", "operating.separation"),
];

fn field<'a>(point: &'a Value, path: &str) -> &'a Value {
    path.split('.').fold(point, |v, key| &v[key])
}

/// A sweep: the friction coefficient against the longest varied list, one curve per
/// combination of the others; points at rest (V = 0) hollow, rolling ones filled.
pub fn sweep(answer: &Value) -> Result<Chart, PictureError> {
    let points = list(&answer["points"], "points")?;
    let first = points.first().ok_or("the sweep has no point")?;
    let three_body = first.get("operating").is_some();
    let varied: Vec<_> = VARIED
        .iter()
        .filter(|(_, _, path)| field(first, path).is_number())
        .filter(|(_, _, path)| {
            let values: Vec<String> = points.iter().map(|p| field(p, path).to_string()).collect();
            values.iter().any(|v| *v != values[0])
        })
        .collect();
    let count = |path: &str| {
        let mut seen: Vec<String> = points.iter().map(|p| field(p, path).to_string()).collect();
        seen.sort();
        seen.dedup();
        seen.len()
    };
    // The longest list; of equal ones, the first in `VARIED` (`max_by_key` keeps the last).
    let along = varied
        .iter()
        .rev()
        .max_by_key(|(_, _, path)| count(path))
        .copied()
        .unwrap_or(&VARIED[0]);
    let mu = |p: &Value| {
        if three_body {
            number(
                &p["friction_coefficient"]["rolling"],
                "friction_coefficient.rolling",
            )
        } else {
            number(&p["friction_coefficient"], "friction_coefficient")
        }
    };
    // Curves by the values of the other varied lists, in order of first appearance; points
    // without numbers (refused, or not solved) are counted in a note.
    let mut curves: Vec<Curve> = Vec::new();
    let mut unanswered = 0;
    for point in points {
        if matches!(point["status"].as_str(), Some("refused" | "missing")) {
            unanswered += 1;
            continue;
        }
        let label: Vec<String> = varied
            .iter()
            .filter(|v| v.2 != along.2)
            .map(|(name, unit, path)| {
                let value = field(point, path).as_f64().unwrap_or(f64::NAN);
                format!("{} = {}", symbol(name), shown(value, unit))
            })
            .collect();
        let label = if label.is_empty() {
            "sweep".to_string()
        } else {
            label.join(", ")
        };
        let x = number(field(point, along.2), along.2)?;
        let y = mu(point)?;
        let at_rest = number(&point["velocity"], "velocity")? == 0.0;
        let index = match curves.iter().position(|c| c.0 == label) {
            Some(i) => i,
            None => {
                curves.push((label, Vec::new(), Vec::new()));
                curves.len() - 1
            }
        };
        curves[index].1.push((x, y));
        if at_rest {
            curves[index].2.push((x, y));
        }
    }
    let mut layers = Vec::new();
    let mut rest = Vec::new();
    for (name, line, at_rest) in curves {
        layers.push(Layer::Line {
            group: name.clone(),
            name,
            points: line,
            dashed: false,
        });
        rest.extend(at_rest);
    }
    if !rest.is_empty() {
        layers.push(Layer::Markers {
            name: "at rest, V = 0".to_string(),
            points: rest,
            hollow: true,
        });
    }
    let y_name = if three_body {
        "rolling friction coefficient"
    } else {
        "friction coefficient"
    };
    // Short lines: they stand under the legend.
    let notes = match unanswered {
        0 => Vec::new(),
        n => vec![
            format!("{n} of {} points not drawn:", points.len()),
            "refused, or not solved".to_string(),
        ],
    };
    Ok(Chart {
        title: format!("Sweep: {y_name} against {}", along.0.replace('_', " ")),
        x: Axis::new(along.0, along.1),
        y: Axis::new(y_name, ""),
        layers,
        equal_aspect: false,
        notes,
    })
}

/// A sweep's curve: its label, its points, and those of them at rest.
type Curve = (String, Vec<(f64, f64)>, Vec<(f64, f64)>);

fn symbol(name: &str) -> &str {
    match name {
        "velocity" => "V",
        "load" => "P",
        "radius" => "R",
        "mean_diameter" => "x_a",
        "total_load" => "W",
        "separation" => "d",
        other => other,
    }
}

/// A three-body system: the distribution of particle diameters, the particles in contact
/// (larger than the separation) shaded, and how the real contact area splits.
pub fn three_body(answer: &Value) -> Result<Chart, PictureError> {
    let input = &answer["meta"]["input"]["distribution"];
    let mean = number(
        &input["mean_diameter"],
        "meta.input.distribution.mean_diameter",
    )?;
    let std = number(
        &input["std_diameter"],
        "meta.input.distribution.std_diameter",
    )?;
    let lo = number(
        &input["min_diameter"],
        "meta.input.distribution.min_diameter",
    )?;
    let hi = number(
        &input["max_diameter"],
        "meta.input.distribution.max_diameter",
    )?;
    let separation = number(&answer["separation"], "separation")?;
    let density = |d: f64| {
        if std > 0.0 {
            // Per nm, as read on the axis.
            (-(d - mean).powi(2) / (2.0 * std * std)).exp()
                / (std * (2.0 * std::f64::consts::PI).sqrt())
                * 1e-9
        } else {
            0.0
        }
    };
    let curve: Vec<(f64, f64)> = (0..=200)
        .map(|i| lo + (hi - lo) * f64::from(i) / 200.0)
        .map(|d| (d, density(d)))
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
    let areas = &answer["areas"];
    let total = number(&areas["total"], "areas.total")?;
    let share = |name: &str| -> Result<String, PictureError> {
        let a = number(&areas[name], name)?;
        let percent = if total > 0.0 { 100.0 * a / total } else { 0.0 };
        Ok(format!("{}: {percent:.1} %", name.replace('_', "–")))
    };
    let particles = number(&answer["particles_in_contact"], "particles_in_contact")?;
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
            count(particles, "particle", "particles")
        ),
        x: Axis::new("particle diameter", "m"),
        y: Axis::new("probability density per nm", ""),
        layers,
        equal_aspect: false,
        notes: vec![
            format!("real contact area {}", shown(total, "m^2")),
            share("particle_upper")?,
            share("surface_surface")?,
            format!(
                "particle–layer: {}",
                shown(number(&areas["particle_layer"], "particle_layer")?, "m^2")
            ),
        ],
    })
}

/// A figure of the paper: its curves on its axes (contact regions at equal scale, curves
/// at rest dashed).
pub fn figure(answer: &Value) -> Result<Chart, PictureError> {
    let axis = |name: &str| -> Result<Axis, PictureError> {
        let a = &answer[name];
        Ok(Axis::new(
            a["quantity"]
                .as_str()
                .ok_or("the figure has no axis quantity")?,
            a["unit"].as_str().unwrap_or(""),
        ))
    };
    let (x, y) = (axis("x")?, axis("y")?);
    let series = list(&answer["series"], "series")?;
    let labels: Vec<&str> = series
        .iter()
        .map(|s| s["label"].as_str().unwrap_or(""))
        .collect();
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
    let layers = series
        .iter()
        .map(|series| {
            let label = series["label"].as_str().unwrap_or("");
            let group = if pairs {
                &label[..sphere(label)]
            } else {
                label
            };
            let points = list(&series["points"], "series[].points")?
                .iter()
                .map(|p| Ok((number(&p[0], "points[][0]")?, number(&p[1], "points[][1]")?)))
                .collect::<Result<Vec<_>, PictureError>>()?;
            Ok(Layer::Line {
                name: label[common..].to_string(),
                group: group.to_string(),
                points,
                dashed: series["velocity"].as_f64() == Some(0.0),
            })
        })
        .collect::<Result<Vec<_>, PictureError>>()?;
    let equal_aspect = x.unit == "m" && y.unit == "m";
    Ok(Chart {
        title: format!(
            "Fig. {}: {}",
            answer["figure"],
            answer["title"].as_str().unwrap_or("")
        ),
        x,
        y,
        layers,
        equal_aspect,
        notes: Vec::new(),
    })
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

/// A fit: each series' measured points, the fitted curve through them, and each residual as
/// a dashed segment from the point to the curve; all in one colour per series. Series of the
/// other quantity than the first series' are left out, and a note says so.
pub fn fit(answer: &Value) -> Result<Chart, PictureError> {
    let curves = list(&answer["curves"], "curves")?;
    let residuals = list(&answer["residuals"], "residuals")?;
    let first = curves.first().ok_or("the fit has no curve")?;
    let quantity = first["quantity"]
        .as_str()
        .ok_or("the curve has no quantity")?;
    let along = first["along"].as_str().ok_or("the curve has no `along`")?;
    let mut layers = Vec::new();
    let mut left_out = 0;
    let mut all_x = Vec::new();
    for curve in curves {
        if curve["quantity"] != first["quantity"] {
            left_out += 1;
            continue;
        }
        let series = number(&curve["series"], "curves[].series")?;
        // Named by the conditions the curve holds: `R = 25 nm, P = 1 nN`.
        let held = list(&curve["points"], "curves[].points")?.first().map(|p| {
            [
                ("R", "radius", "m"),
                ("P", "load", "N"),
                ("W", "total_load", "N"),
                ("V", "velocity", "m/s"),
            ]
            .iter()
            .filter(|c| c.1 != along)
            .filter_map(|(symbol, name, unit)| {
                Some(format!("{symbol} = {}", shown(p[*name].as_f64()?, unit)))
            })
            .collect::<Vec<_>>()
            .join(", ")
        });
        let group = held.unwrap_or_else(|| format!("series {series}"));
        let xy = |p: &Value, y: &Value| {
            Ok::<_, PictureError>((number(&p[along], along)?, number(y, quantity)?))
        };
        let line = list(&curve["points"], "curves[].points")?
            .iter()
            .map(|p| xy(p, &p[quantity]))
            .collect::<Result<Vec<_>, _>>()?;
        let mine: Vec<&Value> = residuals
            .iter()
            .filter(|r| r["series"].as_f64() == Some(series))
            .collect();
        let mut measured = Vec::new();
        let mut segments = Vec::new();
        for r in mine {
            let (x, y) = xy(r, &r[quantity]["measured"])?;
            let (_, fitted) = xy(r, &r[quantity]["fitted"])?;
            measured.push((x, y));
            segments.push(Layer::Line {
                name: String::new(),
                group: group.clone(),
                points: vec![(x, y), (x, fitted)],
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
    let unit = if quantity == "contact_area" {
        "m^2"
    } else {
        ""
    };
    let x_unit = match along {
        "velocity" => "m/s",
        "load" | "total_load" => "N",
        _ => "m",
    };
    let (lo, hi) = all_x.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), &x| {
        (lo.min(x), hi.max(x))
    });
    let mut x = Axis::new(along, x_unit);
    if lo > 0.0 && hi / lo > 20.0 {
        x = x.log();
    }
    let chi = number(&answer["chi_squared"], "chi_squared")?;
    let dof = number(&answer["dof"], "dof")?;
    let mut notes = vec![
        format!("χ² = {} for {dof} dof", shown(chi, "")),
        "dashed: residuals".to_string(),
    ];
    if left_out > 0 {
        notes.push(format!("{left_out} series of the other quantity not drawn"));
    }
    Ok(Chart {
        title: format!("Fit: {} against {along}", quantity.replace('_', " ")),
        x,
        y: Axis::new(&quantity.replace('_', " "), unit),
        layers,
        equal_aspect: false,
        notes,
    })
}
