//! Jobs solved in parts: a job whose answer is one row per point (a sweep, see
//! [`super::Kind::points`]) splits into ranges of points that any process can solve
//! ([`super::Job::run_points`]); each part is rendered at once, and the parts' renderings are
//! assembled into the bytes the whole job would have rendered. The parts travel as text
//! (through Redis), so nothing here needs an answer's types back.

use std::ops::Range;

use serde::{Deserialize, Serialize};
use serde_json::value::RawValue;

use super::sweep::{SweepMeta, SweepSummary};
use super::{JobError, Meta};
use crate::render::{Answer, Format};

/// A part solved and rendered: its rows as JSON and as CSV, and what the sweep's `meta`
/// says of them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RenderedPart {
    /// The rows as JSON values separated by commas (the inside of the `points` list).
    pub json: String,
    /// The rows as CSV, with the header line.
    pub csv: String,
    /// The counts, worst errors and validity of the part's rows, merged into the whole's.
    pub summary: SweepSummary,
}

/// The answer to a whole job, rendered.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Assembled {
    pub json: Vec<u8>,
    pub csv: Vec<u8>,
}

/// `points` split into ranges of at most `per_part` points, in order.
pub fn ranges(points: usize, per_part: usize) -> Vec<Range<usize>> {
    let per_part = per_part.max(1);
    (0..points.div_ceil(per_part))
        .map(|i| i * per_part..((i + 1) * per_part).min(points))
        .collect()
}

/// Renders the answer of a part (from [`super::Job::run_points`]).
pub fn render(answer: &Answer) -> Result<RenderedPart, JobError> {
    #[derive(Deserialize)]
    struct Rows<'a> {
        #[serde(borrow)]
        points: &'a RawValue,
        meta: SweepSummary,
    }
    let internal = |e: String| JobError::Internal(format!("cannot render a part: {e}"));
    let json = answer
        .render(Format::Json)
        .map_err(|e| internal(e.to_string()))?;
    let rows: Rows = serde_json::from_slice(&json).map_err(|e| internal(e.to_string()))?;
    let list = rows.points.get();
    let inside = list
        .strip_prefix('[')
        .and_then(|l| l.strip_suffix(']'))
        .ok_or_else(|| internal("`points` is not a list".to_string()))?;
    let csv = answer
        .render(Format::Csv)
        .map_err(|e| internal(e.to_string()))?;
    Ok(RenderedPart {
        json: inside.to_string(),
        csv: String::from_utf8(csv).map_err(|e| internal(e.to_string()))?,
        summary: rows.meta,
    })
}

/// The whole answer from its parts, in order, and its `meta`: the bytes
/// `Answer::render` gives for the job solved whole.
pub fn assemble(meta: &Meta, parts: &[RenderedPart]) -> Result<Assembled, JobError> {
    let summary = parts
        .iter()
        .map(|p| p.summary.clone())
        .reduce(SweepSummary::merge)
        .ok_or_else(|| JobError::Internal("a job of no part".to_string()))?;
    let meta = SweepMeta {
        meta: meta.clone(),
        summary,
    };
    let meta = serde_json::to_string(&meta)
        .map_err(|e| JobError::Internal(format!("cannot render meta: {e}")))?;
    let rows: Vec<&str> = parts
        .iter()
        .map(|p| p.json.as_str())
        .filter(|rows| !rows.is_empty())
        .collect();
    let json = format!(r#"{{"points":[{}],"meta":{meta}}}"#, rows.join(","));
    let mut csv = String::new();
    for (i, part) in parts.iter().enumerate() {
        let body = if i == 0 {
            part.csv.as_str()
        } else {
            part.csv.split_once('\n').map_or("", |(_, rows)| rows)
        };
        csv.push_str(body);
    }
    Ok(Assembled {
        json: json.into_bytes(),
        csv: csv.into_bytes(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::job::{Control, Job, Limits};

    #[test]
    fn ranges_cover_every_point_once_in_order() {
        assert_eq!(ranges(0, 3), Vec::<Range<usize>>::new());
        assert_eq!(ranges(7, 3), vec![0..3, 3..6, 6..7]);
        assert_eq!(ranges(6, 3), vec![0..3, 3..6]);
        assert_eq!(ranges(2, 0), vec![0..1, 1..2]);
    }

    /// A sweep solved in parts and assembled is, byte for byte, the sweep solved whole.
    fn assembled_equals_whole(envelope: &str, per_part: usize) {
        let job = Job::from_json(envelope.as_bytes(), &Limits::default()).unwrap();
        let meta = job.meta();
        let whole = job.run(meta.clone(), &Control::default()).unwrap();
        let points = job.points().unwrap();
        let parts: Vec<RenderedPart> = ranges(points, per_part)
            .into_iter()
            .map(|r| {
                let answer = job.run_points(meta.clone(), r, &Control::default());
                render(&answer.unwrap()).unwrap()
            })
            .collect();
        let assembled = assemble(&meta, &parts).unwrap();
        assert_eq!(
            String::from_utf8(assembled.json).unwrap(),
            String::from_utf8(whole.render(Format::Json).unwrap()).unwrap()
        );
        assert_eq!(
            String::from_utf8(assembled.csv).unwrap(),
            String::from_utf8(whole.render(Format::Csv).unwrap()).unwrap()
        );
    }

    #[test]
    fn a_rolling_sweep_in_parts_is_the_sweep_whole() {
        let sweep = r#"{"kind": "sweep", "input": {"vary": {
            "load": ["0.5 nN", "1 nN", "2 nN"], "velocity": ["0 nm/s", "1 nm/s", "10 nm/s"]}}}"#;
        for per_part in [1, 2, 4, 9, 100] {
            assembled_equals_whole(sweep, per_part);
        }
    }

    #[test]
    fn a_three_body_sweep_in_parts_is_the_sweep_whole() {
        let sweep = r#"{"kind": "sweep", "input": {"kind": "three_body",
            "base": {"operating": {"total_load": "1 mN"}}, "vary": {
            "velocity": ["0 nm/s", "1 nm/s", "10 nm/s"]}}}"#;
        assembled_equals_whole(sweep, 2);
    }

    #[test]
    fn a_point_out_of_the_domain_is_a_refused_row_or_with_on_refusal_fail_named_by_its_index() {
        let sweep = r#"{"kind": "sweep", "input": {"vary": {"load": ["1 nN", "1 mN"]}}}"#;
        let job = Job::from_json(sweep.as_bytes(), &Limits::default()).unwrap();
        let part = render(
            &job.run_points(job.meta(), 1..2, &Control::default())
                .unwrap(),
        )
        .unwrap();
        assert!(
            part.json
                .contains(r#""status":"refused","reason":"the penetration"#),
            "{}",
            part.json
        );
        assert_eq!(part.summary.counts.refused, 1);
        let failing = r#"{"kind": "sweep", "input": {"on_refusal": "fail",
            "vary": {"load": ["1 nN", "1 mN"]}}}"#;
        let job = Job::from_json(failing.as_bytes(), &Limits::default()).unwrap();
        let error = job
            .run_points(job.meta(), 1..2, &Control::default())
            .unwrap_err();
        assert!(
            error
                .to_string()
                .starts_with("points[1] (R = 25 nm, P = 1 mN, V = 4 nm/s): "),
            "{error}"
        );
    }

    #[test]
    fn a_sweep_with_refused_points_in_parts_is_the_sweep_whole() {
        let sweep = r#"{"kind": "sweep", "input": {"vary": {
            "load": ["1 nN", "1 mN", "2 nN"], "velocity": ["0 nm/s", "4 nm/s"]}}}"#;
        for per_part in [1, 2, 5] {
            assembled_equals_whole(sweep, per_part);
        }
    }
}
