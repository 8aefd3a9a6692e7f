//! What a sweep's `meta` says of its rows ([`SweepSummary`]), made as its rows are: how
//! many points are in each state, the worst numerical error over the answered points, and
//! the assumptions in words with how many points each warns on. A row itself is said in
//! [`crate::job::points`], which each kind's row type shares.

use serde::ser::SerializeMap;
use serde::{Deserialize, Serialize, Serializer};
use utoipa::ToSchema;

use crate::described;
use crate::job::points::{PointNotes, PointStatus, Row};
use crate::job::rolling::ContactVerification;
use crate::job::three_body::ThreeBodyVerificationOutput;
use crate::job::validity::{Subject, SweepValidityOutput, ValidityTally};
use crate::job::{JobError, Swept};
use crate::render::{fields, Field, Fields};

/// The rows of `points`, the first of which is point `first` of the sweep, from what became
/// of them (`swept`: each row, or why it was refused), and the summary of the rows.
pub fn rows<R: Row>(
    points: &[R::Point],
    swept: Swept<R, JobError>,
    first: usize,
    subject: Subject,
) -> (Vec<R>, SweepSummary)
where
    R::Verification: Into<SweepVerification>,
{
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

impl From<ContactVerification> for SweepVerification {
    fn from(verification: ContactVerification) -> Self {
        SweepVerification::Rolling(verification)
    }
}

impl From<ThreeBodyVerificationOutput> for SweepVerification {
    fn from(verification: ThreeBodyVerificationOutput) -> Self {
        SweepVerification::ThreeBody(verification)
    }
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
    fn count<R: Row>(&mut self, index: usize, row: &R, subject: Subject)
    where
        R::Verification: Into<SweepVerification>,
    {
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
        if let Some(v) = row.verification().map(Into::into) {
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
