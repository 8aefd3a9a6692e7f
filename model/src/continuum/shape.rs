//! The shape of a contact solved on the grid, as an answer gives it: its lateral half-width,
//! its boundary at chosen lateral positions, and its pressure on a chosen grid.

use std::f64::consts::{FRAC_PI_2, PI};

use super::grid::Grid;
use super::pressed::GridContact;
use crate::rolling::{BoundaryPoint, PressureGrid};

/// The contact's half-width across the rolling direction (m): beyond the outermost row in
/// contact on each side, where an elliptic tip through that row's and the next row's
/// chords closes (chord² linear in y²), averaged over the two sides.
pub(super) fn lateral_half_width(contact: &GridContact) -> f64 {
    let rows: Vec<(f64, f64)> = chords(contact)
        .into_iter()
        .map(|(y, exit, entry)| (y, entry - exit))
        .collect();
    if rows.is_empty() {
        return 0.0;
    }
    let half_pixel = 0.5 * contact.grid.pixel;
    let tip = |outer: (f64, f64), inner: Option<&(f64, f64)>| {
        let (y1, l1) = outer;
        match inner {
            Some(&(y2, l2)) if l2 > l1 => {
                let (a, b) = (l1 * l1, l2 * l2);
                ((a * y2 * y2 - b * y1 * y1) / (a - b)).sqrt()
            }
            _ => y1.abs() + half_pixel,
        }
    };
    let last = rows.len() - 1;
    let low = tip(rows[0], rows.get(1));
    let high = tip(rows[last], last.checked_sub(1).map(|k| &rows[k]));
    0.5 * (low + high)
}

/// Each row in contact: its y and its exit and entry edges' x from the sphere's centre.
pub(super) fn chords(contact: &GridContact) -> Vec<(f64, f64, f64)> {
    let grid = contact.grid;
    (0..grid.ny)
        .filter_map(|j| {
            let (exit, entry) = contact.edges[j]?;
            Some((grid.y(j), contact.middle + exit, contact.middle + entry))
        })
        .collect()
}

/// `n` points of the contact boundary at y = w sin θ (θ evenly over [−π/2, π/2], as the
/// local law's), the edges interpolated between the grid's rows; at the tips both edges
/// are the outermost row's middle.
pub(super) fn boundary(contact: &GridContact, half_width: f64, n: usize) -> Vec<BoundaryPoint> {
    let rows = chords(contact);
    if rows.is_empty() {
        return Vec::new();
    }
    let at = |y: f64| -> (f64, f64) {
        let (first, last) = (rows[0], rows[rows.len() - 1]);
        let middle = |r: (f64, f64, f64)| 0.5 * (r.1 + r.2);
        if y <= first.0 {
            // Between the tip and the outermost row: the chord closes elliptically.
            let share = closing(y, first.0, -half_width);
            let m = middle(first);
            return (m + share * (first.1 - m), m + share * (first.2 - m));
        }
        if y >= last.0 {
            let share = closing(y, last.0, half_width);
            let m = middle(last);
            return (m + share * (last.1 - m), m + share * (last.2 - m));
        }
        let k = rows.partition_point(|r| r.0 <= y).clamp(1, rows.len() - 1);
        let (a, b) = (rows[k - 1], rows[k]);
        let u = (y - a.0) / (b.0 - a.0);
        (a.1 + u * (b.1 - a.1), a.2 + u * (b.2 - a.2))
    };
    (0..n)
        .map(|j| {
            let theta = if n == 1 {
                0.0
            } else {
                -FRAC_PI_2 + PI * j as f64 / (n - 1) as f64
            };
            let y = half_width * theta.sin();
            let (exit, entry) = at(y);
            BoundaryPoint { y, exit, entry }
        })
        .collect()
}

/// The share of the outermost row's chord left at `y`, between that row (at `row`) and
/// the tip (at `tip`), for a chord that closes as √(tip² − y²).
fn closing(y: f64, row: f64, tip: f64) -> f64 {
    let chord = |y: f64| (tip * tip - y * y).max(0.0).sqrt();
    let at_row = chord(row);
    if at_row > 0.0 {
        (chord(y) / at_row).min(1.0)
    } else {
        0.0
    }
}

/// p on an n × n grid over [−e, e]², e the contact's largest extent from the centre (the
/// local law's map spans its half-width, which is its extent).
pub(super) fn pressure_grid(contact: &GridContact, extent: f64, n: usize) -> PressureGrid {
    let axis: Vec<f64> = (0..n)
        .map(|i| {
            if n == 1 {
                0.0
            } else {
                -extent + 2.0 * extent * i as f64 / (n - 1) as f64
            }
        })
        .collect();
    PressureGrid {
        values: axis
            .iter()
            .map(|&y| axis.iter().map(|&x| pressure_at(contact, x, y)).collect())
            .collect(),
        x: axis.clone(),
        y: axis,
    }
}

/// `contact`'s pressure on the pixels of `grid` whose middle is at x = `middle`: a coarser
/// grid's steady contact as the start of a finer grid's march.
pub(super) fn resampled(contact: &GridContact, grid: &Grid, middle: f64) -> Vec<f64> {
    (0..grid.pixels())
        .map(|k| pressure_at(contact, middle + grid.x(k / grid.ny), grid.y(k % grid.ny)))
        .collect()
}

/// The pressure at (x, y) from the sphere's centre: bilinear between the pixels' centres,
/// zero outside them.
fn pressure_at(contact: &GridContact, x: f64, y: f64) -> f64 {
    let Grid { nx, ny, pixel } = contact.grid;
    // Fractional pixel index of a coordinate (pixel centres at integers).
    let index = |offset: f64, count: usize| offset / pixel - 0.5 + 0.5 * count as f64;
    let (u, v) = (index(x - contact.middle, nx), index(y, ny));
    if u < 0.0 || v < 0.0 || u > (nx - 1) as f64 || v > (ny - 1) as f64 {
        return 0.0;
    }
    let (i, j) = ((u as usize).min(nx - 2), (v as usize).min(ny - 2));
    let (s, t) = (u - i as f64, v - j as f64);
    let p = |i: usize, j: usize| contact.pressure[i * ny + j];
    (1.0 - s) * ((1.0 - t) * p(i, j) + t * p(i, j + 1))
        + s * ((1.0 - t) * p(i + 1, j) + t * p(i + 1, j + 1))
}
