//! The data behind the paper's Figures 3–9 (docs/model.md §5): which contacts to solve and
//! which of their quantities each figure plots. Solving is left to the caller (the engine
//! runs the points in parallel), so this module stays pure.

use super::rolling::RollingSolution;
use super::{Layer, Rolling, SolveOptions};

/// The figures of the paper this service reproduces.
pub const FIGURES: std::ops::RangeInclusive<u8> = 3..=9;

/// Loads of Figs. 4–9 (N): 1.0 … 1.4 nN.
const LOADS: [f64; 5] = [1.0e-9, 1.1e-9, 1.2e-9, 1.3e-9, 1.4e-9];
/// Radii of Figs. 4 and 6 (m).
const RADII: [f64; 5] = [25e-9, 50e-9, 150e-9, 250e-9, 350e-9];
/// Speeds of Figs. 5 and 7 (m/s).
const SPEEDS: [f64; 5] = [0.0, 4e-9, 6e-9, 8e-9, 10e-9];
/// Speeds of Fig. 3 (m/s).
const CONTOUR_SPEEDS: [f64; 4] = [0.0, 2e-9, 3e-9, 4e-9];
/// Speeds compared in Figs. 4, 6, 8, 9: without and with rolling (m/s).
const STATIC_AND_ROLLING: [f64; 2] = [0.0, 4e-9];
/// Boundary points per contour of Fig. 3.
const CONTOUR_POINTS: usize = 101;

/// An axis: the quantity and its SI unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Axis {
    pub quantity: &'static str,
    pub unit: &'static str,
}

impl Axis {
    const fn new(quantity: &'static str, unit: &'static str) -> Axis {
        Axis { quantity, unit }
    }
}

/// One curve of a figure.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub label: String,
    /// R (m), when the series holds it fixed.
    pub radius: Option<f64>,
    /// P (N), when the series holds it fixed.
    pub load: Option<f64>,
    /// V (m/s).
    pub velocity: f64,
    /// (x, y) in the units of the axes.
    pub points: Vec<[f64; 2]>,
}

/// A figure's data.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    pub number: u8,
    pub title: &'static str,
    pub x: Axis,
    pub y: Axis,
    pub series: Vec<Series>,
}

/// The contacts a figure needs and how to read it off their solutions.
#[derive(Clone, Debug)]
pub struct Plan {
    pub number: u8,
    /// Every contact to solve, series after series.
    pub contacts: Vec<Rolling>,
    pub options: SolveOptions,
    layout: Layout,
}

const LOAD_AXIS: Axis = Axis::new("load", "N");
const RADIUS_AXIS: Axis = Axis::new("radius", "m");
const AREA_AXIS: Axis = Axis::new("contact_area", "m²");
const FRICTION_AXIS: Axis = Axis::new("friction_coefficient", "");

/// What a figure plots against what, and over which series.
#[derive(Clone, Debug)]
struct Layout {
    title: &'static str,
    x: Axis,
    y: Axis,
    series: Vec<Curve>,
}

/// A series before it is solved: what it holds fixed, and its contacts along x.
#[derive(Clone, Debug)]
struct Curve {
    radius: Option<f64>,
    load: Option<f64>,
    velocity: f64,
    contacts: Vec<Rolling>,
}

/// One contact of the figures: on the paper's default layer (docs/model.md §5).
fn at(radius: f64, load: f64, velocity: f64) -> Rolling {
    Rolling {
        radius,
        load,
        velocity,
        layer: Layer::default(),
    }
}

impl Curve {
    /// Along the loads of Figs. 4–7, at a fixed radius.
    fn along_load(radius: f64, velocity: f64) -> Curve {
        Curve {
            radius: Some(radius),
            load: None,
            velocity,
            contacts: LOADS.iter().map(|&p| at(radius, p, velocity)).collect(),
        }
    }

    /// Along the radii of Figs. 8–9 (25 … 350 nm), at a fixed load.
    fn along_radius(load: f64, velocity: f64) -> Curve {
        Curve {
            radius: None,
            load: Some(load),
            velocity,
            contacts: (1..=14)
                .map(|i| at(25e-9 * f64::from(i), load, velocity))
                .collect(),
        }
    }

    /// Fig. 3's one contact at speed `velocity`, whose boundary is the curve.
    fn contour(velocity: f64) -> Curve {
        Curve {
            radius: Some(25e-9),
            load: Some(1e-9),
            velocity,
            contacts: vec![at(25e-9, 1e-9, velocity)],
        }
    }

    /// Along the load, static and rolling for each radius (Figs. 4 and 6).
    fn by_radius() -> Vec<Curve> {
        RADII
            .iter()
            .flat_map(|&r| STATIC_AND_ROLLING.map(|v| Curve::along_load(r, v)))
            .collect()
    }

    /// Along the load, R = 25 nm, one series a speed (Figs. 5 and 7).
    fn by_speed() -> Vec<Curve> {
        SPEEDS
            .iter()
            .map(|&v| Curve::along_load(25e-9, v))
            .collect()
    }

    /// Along the radius, static and rolling for each load (Figs. 8 and 9).
    fn by_load() -> Vec<Curve> {
        LOADS
            .iter()
            .flat_map(|&p| STATIC_AND_ROLLING.map(|v| Curve::along_radius(p, v)))
            .collect()
    }
}

impl Layout {
    fn new(number: u8) -> Option<Layout> {
        let (title, x, y, series) = match number {
            3 => (
                "Contact region a(y) ≤ x ≤ b(y), R = 25 nm, P = 1 nN, V = 0, 2, 3, 4 nm/s",
                Axis::new("x", "m"),
                Axis::new("y", "m"),
                CONTOUR_SPEEDS.iter().map(|&v| Curve::contour(v)).collect(),
            ),
            4 => (
                "Contact area vs load, R = 25–350 nm, V = 0 and 4 nm/s",
                LOAD_AXIS,
                AREA_AXIS,
                Curve::by_radius(),
            ),
            5 => (
                "Contact area vs load, R = 25 nm, V = 0–10 nm/s",
                LOAD_AXIS,
                AREA_AXIS,
                Curve::by_speed(),
            ),
            6 => (
                "Friction coefficient vs load, R = 25–350 nm, V = 0 and 4 nm/s",
                LOAD_AXIS,
                FRICTION_AXIS,
                Curve::by_radius(),
            ),
            7 => (
                "Friction coefficient vs load, R = 25 nm, V = 0–10 nm/s",
                LOAD_AXIS,
                FRICTION_AXIS,
                Curve::by_speed(),
            ),
            8 => (
                "Contact area vs radius, P = 1–1.4 nN, V = 0 and 4 nm/s",
                RADIUS_AXIS,
                AREA_AXIS,
                Curve::by_load(),
            ),
            9 => (
                "Friction coefficient vs radius, P = 1–1.4 nN, V = 0 and 4 nm/s",
                RADIUS_AXIS,
                FRICTION_AXIS,
                Curve::by_load(),
            ),
            _ => return None,
        };
        Some(Layout {
            title,
            x,
            y,
            series,
        })
    }
}

impl Plan {
    /// The plan of figure `number`, if it is one of [`FIGURES`].
    pub fn new(number: u8) -> Option<Plan> {
        let layout = Layout::new(number)?;
        let boundary_points = if number == 3 { CONTOUR_POINTS } else { 0 };
        Some(Plan {
            number,
            contacts: layout
                .series
                .iter()
                .flat_map(|c| c.contacts.clone())
                .collect(),
            options: SolveOptions {
                boundary_points,
                ..SolveOptions::default()
            },
            layout,
        })
    }

    /// Assembles the figure from the solutions of [`Plan::contacts`], in order.
    pub fn assemble(&self, solutions: &[RollingSolution]) -> Figure {
        let layout = &self.layout;
        let mut solutions = solutions.iter();
        let series = layout
            .series
            .iter()
            .map(|curve| {
                let points = curve
                    .contacts
                    .iter()
                    .zip(solutions.by_ref())
                    .flat_map(|(contact, solution)| point(self.number, contact, solution))
                    .collect();
                Series {
                    label: label(curve.radius, curve.load, curve.velocity),
                    radius: curve.radius,
                    load: curve.load,
                    velocity: curve.velocity,
                    points,
                }
            })
            .collect();
        Figure {
            number: self.number,
            title: layout.title,
            x: layout.x,
            y: layout.y,
            series,
        }
    }
}

/// The plotted point(s) of one solution: a closed contour for Fig. 3, else one (x, y).
fn point(number: u8, contact: &Rolling, s: &RollingSolution) -> Vec<[f64; 2]> {
    match number {
        3 => {
            let entry = s.boundary.iter().map(|p| [p.entry, p.y]);
            let exit = s.boundary.iter().rev().map(|p| [p.exit, p.y]);
            entry.chain(exit).collect()
        }
        4 | 5 => vec![[contact.load, s.contact_area]],
        6 | 7 => vec![[contact.load, s.friction_coefficient]],
        8 => vec![[contact.radius, s.contact_area]],
        _ => vec![[contact.radius, s.friction_coefficient]],
    }
}

fn label(radius: Option<f64>, load: Option<f64>, velocity: f64) -> String {
    let mut parts = Vec::new();
    if let Some(r) = radius {
        parts.push(format!("R = {} nm", round(r * 1e9)));
    }
    if let Some(p) = load {
        parts.push(format!("P = {} nN", round(p * 1e9)));
    }
    parts.push(format!("V = {} nm/s", round(velocity * 1e9)));
    parts.join(", ")
}

/// Rounds away the binary noise of nm-scale products (25e-9 · 1e9 = 25.000000000000004).
fn round(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}
