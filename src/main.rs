//! The `thirdbody` command: solve a job file, or print a figure of the paper.

use std::io::{Read, Write};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use thirdbody::engine::{self, Control, Output};
use thirdbody::job::{FigureJob, Job, JobError, Limits};

#[derive(Parser)]
#[command(
    name = "thirdbody",
    version,
    about = "Contact area and friction of particles rolling over a viscoelastic layer"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a job {"kind": "rolling" | "three_body" | "sweep" | "figure", "input": {...}} and print the result as JSON.
    Solve {
        /// The job file, or - for standard input.
        job: String,
        /// Output format (csv for sweeps and figures).
        #[arg(long, value_enum, default_value_t = Format::Json)]
        format: Format,
    },
    /// Print the data of Figure N (3–9) of the paper.
    Figure {
        number: i64,
        #[arg(long, value_enum, default_value_t = Format::Json)]
        format: Format,
    },
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Format {
    Json,
    Csv,
}

/// Exit status for a job that is not valid (as distinct from one that failed to solve).
const INVALID_JOB: u8 = 2;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let (job, format) = match cli.command {
        Command::Solve { job, format } => (read_job(&job), format),
        Command::Figure { number, format } => (FigureJob::new(number).map(Job::Figure), format),
    };
    let result = job.and_then(|job| {
        let output = engine::run(&job, &Control::default())?;
        render(&output, format)
    });
    match result {
        Ok(text) => {
            // A reader that stops early (`| head`) is not an error of ours.
            let mut out = std::io::stdout().lock();
            let newline = if text.ends_with('\n') { "" } else { "\n" };
            match write!(out, "{text}{newline}").and_then(|()| out.flush()) {
                Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
                    eprintln!("thirdbody: cannot write the result: {e}");
                    ExitCode::FAILURE
                }
                _ => ExitCode::SUCCESS,
            }
        }
        Err(e) => {
            eprintln!("thirdbody: {e}");
            match e {
                JobError::Syntax(_) | JobError::Schema { .. } | JobError::Invalid(_) => {
                    ExitCode::from(INVALID_JOB)
                }
                _ => ExitCode::FAILURE,
            }
        }
    }
}

fn read_job(path: &str) -> Result<Job, JobError> {
    let mut text = Vec::new();
    let read = if path == "-" {
        std::io::stdin().read_to_end(&mut text).map(|_| ())
    } else {
        std::fs::read(path).map(|t| text = t)
    };
    read.map_err(|e| JobError::Syntax(format!("cannot read {path}: {e}")))?;
    Job::from_json(&text, &Limits::default())
}

fn render(output: &Output, format: Format) -> Result<String, JobError> {
    match (format, output) {
        (Format::Json, _) => serde_json::to_string_pretty(output)
            .map_err(|e| JobError::Internal(format!("cannot write the result: {e}"))),
        (Format::Csv, Output::Sweep(s)) => Ok(s.to_csv()),
        (Format::Csv, Output::Figure(f)) => Ok(f.to_csv()),
        (Format::Csv, Output::Rolling(_) | Output::ThreeBody(_)) => Err(JobError::Schema {
            field: "--format".to_string(),
            message: "csv is available for sweeps and figures; use json for a single job"
                .to_string(),
        }),
    }
}
