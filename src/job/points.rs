//! The rows of a sweep and what its `meta` says of them. Every point of a sweep has a row:
//! its conditions, then what became of it: answered (`ok` or `warn`, with its numbers and
//! the ratios of the model's assumptions), `refused` by the model (with the reason, its
//! values named), or `missing` (the job stopped before it: a cancel, the deadline). One
//! point the model refuses does not refuse the sweep, and a stopped sweep keeps the points
//! it finished.
//!
//! What is the same on every row is said once, in the sweep's `meta`
//! ([`super::sweep::SweepSummary`]): how many points are in each state, the worst numerical
//! error over the answered points, and the assumptions in words with how many points each
//! warns on.

use serde::ser::SerializeMap;
use serde::{Deserialize, Serialize, Serializer};
use utoipa::ToSchema;

use super::validity::{PointValidity, ValidityStatus};
use crate::render::Column;

/// What became of a point of a sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum PointStatus {
    /// Answered; every assumption of the model holds.
    Ok,
    /// Answered; an assumption is strained (`warn` names it).
    Warn,
    /// Not answered: the model refuses the point (`reason` says why).
    Refused,
    /// Not solved: the job stopped before it (`meta.stopped` says why).
    Missing,
}

impl PointStatus {
    pub fn as_str(self) -> &'static str {
        match self {
            PointStatus::Ok => "ok",
            PointStatus::Warn => "warn",
            PointStatus::Refused => "refused",
            PointStatus::Missing => "missing",
        }
    }
}

/// What a row says beyond its conditions and numbers.
#[derive(Clone, Debug, PartialEq)]
pub enum PointNotes {
    /// The ratios of the model's assumptions at the point.
    Answered(PointValidity),
    /// Why the model refuses the point.
    Refused(String),
    /// The job stopped before the point.
    Missing,
}

impl PointNotes {
    /// The row's status.
    pub fn status(&self) -> PointStatus {
        match self {
            PointNotes::Answered(v) => match v.status() {
                ValidityStatus::Ok => PointStatus::Ok,
                ValidityStatus::Warn => PointStatus::Warn,
            },
            PointNotes::Refused(_) => PointStatus::Refused,
            PointNotes::Missing => PointStatus::Missing,
        }
    }

    /// The CSV cell beside the status: the names of the assumptions that warn, or the
    /// reason of a refusal, appended to `text`.
    pub fn write_note(&self, text: &mut String) {
        match self {
            PointNotes::Answered(validity) => validity.write_warned(text),
            PointNotes::Refused(reason) => text.push_str(reason),
            PointNotes::Missing => text.push_str("not solved: the job stopped before this point"),
        }
    }
}

impl PointNotes {
    /// The path and unit of each number the notes put in a row (its `validity`).
    pub fn units() -> Vec<(String, &'static str)> {
        let ratios = PointValidity::units().into_iter();
        ratios
            .map(|(name, unit)| (format!("validity.{name}"), unit))
            .collect()
    }
}

/// Flattened into a row: `validity` (each assumption's ratio at the point's speed, by name)
/// and `warn` (the names of those that warn, at speed or at rest) for an answered point,
/// `reason` for a refused one, nothing for a missing one.
impl Serialize for PointNotes {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(None)?;
        match self {
            PointNotes::Answered(validity) => {
                map.serialize_entry("validity", validity)?;
                if validity.status() == ValidityStatus::Warn {
                    map.serialize_entry("warn", &Warned(validity))?;
                }
            }
            PointNotes::Refused(reason) => map.serialize_entry("reason", reason)?,
            PointNotes::Missing => {}
        }
        map.end()
    }
}

/// The names of the assumptions a point warns on, as a list.
struct Warned<'a>(&'a PointValidity);

impl Serialize for Warned<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.0.warned())
    }
}

/// The fields [`PointNotes`] adds to a row, for the OpenAPI description.
#[derive(ToSchema)]
#[allow(dead_code)]
pub struct PointNotesFields {
    /// Answered points: each assumption's ratio at the point's speed, by name (what each
    /// measures, and its rule, are in `meta.validity`).
    validity: Option<std::collections::BTreeMap<String, f64>>,
    /// Answered points that warn: the names of the assumptions strained, at the point's
    /// speed or at rest.
    warn: Option<Vec<String>>,
    /// Refused points: why, with the values named.
    reason: Option<String>,
}

/// The CSV columns of a kind of row: `fields`, the columns of its numbers, then its status
/// and the note beside it.
pub fn columns<R: Row>(mut fields: Vec<Column<R>>) -> Vec<Column<R>> {
    fields.push(Column::text("status", |r, text| {
        text.push_str(r.notes().status().as_str())
    }));
    fields.push(Column::text("note", |r, text| r.notes().write_note(text)));
    fields
}

/// A row of a sweep, of either kind.
pub trait Row: Sized {
    /// The point a row is made for.
    type Point;
    /// The numerical error of an answered point, as its kind measures it.
    type Verification;
    /// The row of `point` without numbers, with `notes` (refused or missing).
    fn unanswered(point: &Self::Point, notes: PointNotes) -> Self;
    fn notes(&self) -> &PointNotes;
    /// The numerical error of an answered point.
    fn verification(&self) -> Option<Self::Verification>;
}
