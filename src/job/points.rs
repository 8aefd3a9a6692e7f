//! The rows of a sweep and what its `meta` says of them. Every point of a sweep has a row:
//! its conditions, then what became of it: answered (`ok` or `warn`, with its numbers and
//! the ratios of the model's assumptions), `refused` by the model (with the reason, its
//! values named), or `missing` (the job stopped before it: a cancel, the deadline). One
//! point the model refuses does not refuse the sweep, and a stopped sweep keeps the points
//! it finished.
//!
//! What is the same on every row is said once, in the sweep's `meta` ([`SweepSummary`]):
//! how many points are in each state, the worst numerical error over the answered points,
//! and the assumptions in words with how many points each warns on.

use serde::ser::SerializeMap;
use serde::{Deserialize, Serialize, Serializer};
use utoipa::ToSchema;

use super::rolling::ContactVerification;
use super::three_body::ThreeBodyVerificationOutput;
use super::validity::{PointValidity, Subject, SweepValidityOutput, ValidityStatus, ValidityTally};
use super::{JobError, Swept};
use crate::described;
use crate::render::{fields, Column, Field, Fields};

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
    /// The row of `point` without numbers, with `notes` (refused or missing).
    fn unanswered(point: &Self::Point, notes: PointNotes) -> Self;
    fn notes(&self) -> &PointNotes;
    /// The numerical error of an answered point.
    fn verification(&self) -> Option<SweepVerification>;
}

/// The rows of `points`, the first of which is point `first` of the sweep, from what became
/// of them (`swept`: each row, or why it was refused), and the summary of the rows.
pub fn rows<R: Row>(
    points: &[R::Point],
    swept: Swept<R, JobError>,
    first: usize,
    subject: Subject,
) -> (Vec<R>, SweepSummary) {
    let mut summary = SweepSummary {
        counts: PointCounts::default(),
        complete: swept.stopped.is_none(),
        stopped: swept.stopped.map(|e| e.to_string()),
        verification: None,
        validity: ValidityTally::default(),
    };
    let rows: Vec<R> = points
        .iter()
        .zip(swept.outcomes)
        .map(|(point, outcome)| match outcome {
            Some(Ok(row)) => row,
            Some(Err(e)) => R::unanswered(point, PointNotes::Refused(reason(e))),
            None => R::unanswered(point, PointNotes::Missing),
        })
        .collect();
    for (i, row) in rows.iter().enumerate() {
        summary.count(first + i, row, subject);
    }
    (rows, summary)
}

/// Why a point is refused, in words: the model's own sentence.
fn reason(e: JobError) -> String {
    match e {
        JobError::OutOfDomain(m) | JobError::Unsolvable(m) => m,
        other => other.to_string(),
    }
}

described! {
    /// How many points of a sweep are in each state.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
    pub struct PointCounts {
        /// Points of the sweep (count).
        pub total: usize => [unit ""],
        /// Answered, every assumption holding (count).
        pub ok: usize => [unit ""],
        /// Answered with a warning (count).
        pub warn: usize => [unit ""],
        /// Refused by the model (count).
        pub refused: usize => [unit ""],
        /// Not solved: the job stopped before them (count).
        pub missing: usize => [unit ""],
    }
}

impl PointCounts {
    fn add(&mut self, other: PointCounts) {
        self.total += other.total;
        self.ok += other.ok;
        self.warn += other.warn;
        self.refused += other.refused;
        self.missing += other.missing;
    }
}

/// The worst numerical error over a sweep's answered points.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(untagged)]
pub enum SweepVerification {
    Rolling(ContactVerification),
    ThreeBody(ThreeBodyVerificationOutput),
}

/// The fields of either kind's verification (the union: a sweep's is one of them).
impl Fields for SweepVerification {
    fn fields() -> Vec<Field<Self>> {
        let mut fields = Field::nested::<ContactVerification>("", None, |_| None);
        fields.extend(Field::nested::<ThreeBodyVerificationOutput>(
            "",
            None,
            |_| None,
        ));
        fields
    }
}

impl SweepVerification {
    /// The worse of the two, field by field.
    fn worst(self, other: SweepVerification) -> SweepVerification {
        match (self, other) {
            (SweepVerification::Rolling(a), SweepVerification::Rolling(b)) => {
                SweepVerification::Rolling(a.worst(&b))
            }
            (SweepVerification::ThreeBody(a), SweepVerification::ThreeBody(b)) => {
                SweepVerification::ThreeBody(a.worst(&b))
            }
            // A sweep's points are all of one kind.
            (a, _) => a,
        }
    }
}

described! {
    /// What a sweep's `meta` says of its rows.
    #[derive(Clone, Debug, PartialEq, Deserialize, ToSchema)]
    pub struct SweepSummary {
        /// How many points are in each state.
        pub counts: PointCounts => [nested],
        /// Whether every point was reached (false: the job stopped; see `stopped`).
        pub complete: bool => [],
        /// Why the sweep stopped before its end (a cancel, the deadline): its unsolved points
        /// are `missing`. Absent for a whole sweep.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub stopped: Option<String> => [],
        /// The worst numerical error over the answered points, field by field (each point's
        /// own is not repeated on its row). Absent when no point was answered.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub verification: Option<SweepVerification> => [optional nested],
        #[schema(value_type = SweepValidityOutput)]
        pub validity: ValidityTally => [by fields::units::<SweepValidityOutput>()],
    }
}

/// Written as derived, but for the validity's status, which refused points make `warn`.
impl Serialize for SweepSummary {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(None)?;
        map.serialize_entry("counts", &self.counts)?;
        map.serialize_entry("complete", &self.complete)?;
        if let Some(stopped) = &self.stopped {
            map.serialize_entry("stopped", stopped)?;
        }
        if let Some(verification) = &self.verification {
            map.serialize_entry("verification", verification)?;
        }
        let validity = self.validity.output(self.counts.refused > 0);
        map.serialize_entry("validity", &validity)?;
        map.end()
    }
}

impl SweepSummary {
    /// Counts row `index` of the sweep.
    fn count<R: Row>(&mut self, index: usize, row: &R, subject: Subject) {
        let counts = &mut self.counts;
        counts.total += 1;
        match row.notes().status() {
            PointStatus::Ok => counts.ok += 1,
            PointStatus::Warn => counts.warn += 1,
            PointStatus::Refused => counts.refused += 1,
            PointStatus::Missing => counts.missing += 1,
        }
        if let PointNotes::Answered(validity) = row.notes() {
            self.validity.count(index, validity, subject);
        }
        if let Some(v) = row.verification() {
            self.verification = Some(match self.verification.take() {
                Some(worst) => worst.worst(v),
                None => v,
            });
        }
    }

    /// The summary of the points of `self` followed by those of `other`.
    pub fn merge(mut self, other: SweepSummary) -> SweepSummary {
        self.counts.add(other.counts);
        self.complete &= other.complete;
        self.stopped = self.stopped.or(other.stopped);
        self.verification = match (self.verification, other.verification) {
            (Some(a), Some(b)) => Some(a.worst(b)),
            (a, b) => a.or(b),
        };
        self.validity.merge(other.validity);
        self
    }
}
