//! Checks from a file, as `thirdbody check` runs them: golden answers are read from the files
//! the checks name (relative to the checks file) or, with `update`, written there.

use std::path::{Path, PathBuf};

use serde_json::Value;

use super::{Report, Suite};
use crate::job::input::parse;
use crate::job::{Control, JobError, Limits};
use crate::render::Format;

/// Why a checks file could not be run: its own fault, not a check's.
fn bad(message: String) -> JobError {
    JobError::Schema {
        field: String::new(),
        message,
    }
}

/// Runs the checks of the file at `path` in this process; with `update`, first writes each
/// check's answer to its golden file.
pub fn run_file(path: &Path, update: bool) -> Result<Report, JobError> {
    let text =
        std::fs::read(path).map_err(|e| bad(format!("cannot read {}: {e}", path.display())))?;
    let mut value = parse(&text)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    if !update {
        if let Err(missing) = read_goldens(&mut value, dir) {
            // A malformed check is said before a golden file to write: `--update` would
            // only run into it.
            Suite::from_value(value, &Limits::default())?;
            return Err(missing);
        }
    }
    let suite = Suite::from_value(value, &Limits::default())?;
    let mut reports = Vec::new();
    // Each answer is judged, then dropped before the next job runs: a file of large sweeps
    // holds one answer at a time.
    for mut spec in suite.checks {
        let started = std::time::Instant::now();
        let json = spec
            .job
            .run(spec.job.meta(), &Control::default())
            .and_then(|answer| {
                answer
                    .render(Format::Json)
                    .map_err(|e| JobError::Internal(e.to_string()))
            });
        if let (true, Ok(json), Some(golden)) = (update, &json, &mut spec.golden) {
            let answer = serde_json::from_slice::<Value>(json)
                .map_err(|e| JobError::Internal(e.to_string()))?;
            if let Some(file) = &golden.file {
                write_golden(&dir.join(file), &answer)?;
            }
            golden.answer = Some(answer);
        }
        reports.push(spec.judge(json.as_deref()).timed(started));
    }
    Ok(Report::new(reports))
}

/// Puts the answer of every `golden.file` into its `golden.answer`.
fn read_goldens(value: &mut Value, dir: &Path) -> Result<(), JobError> {
    let checks = value.get_mut("checks").and_then(Value::as_array_mut);
    for golden in checks
        .into_iter()
        .flatten()
        .filter_map(|c| c.get_mut("golden"))
    {
        let Some(file) = golden.get("file").and_then(Value::as_str) else {
            continue;
        };
        let path: PathBuf = dir.join(file);
        let text = std::fs::read(&path).map_err(|e| {
            bad(format!(
                "golden answer {}: {e} (run `thirdbody check --update` to write it)",
                path.display()
            ))
        })?;
        golden["answer"] = parse(&text)?;
    }
    Ok(())
}

fn write_golden(path: &Path, answer: &Value) -> Result<(), JobError> {
    let text =
        serde_json::to_string_pretty(answer).map_err(|e| JobError::Internal(e.to_string()))?;
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)
            .map_err(|e| bad(format!("cannot create {}: {e}", dir.display())))?;
    }
    std::fs::write(path, text + "\n")
        .map_err(|e| bad(format!("cannot write {}: {e}", path.display())))
}
