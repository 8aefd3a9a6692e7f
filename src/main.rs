//! The `thirdbody` command: solve a job file, print a figure of the paper, or serve the
//! HTTP API.

use std::io::{IsTerminal, Read, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Duration;

use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand, ValueEnum};

use thirdbody::check;
use thirdbody::engine::Engine;
use thirdbody::http::{self, AppState, Config, LogFormat, ServeArgs};
use thirdbody::job::registry;
use thirdbody::job::{Control, FigureJob, Job, JobError, Limits};
use thirdbody::model::text::{count, quantity};
use thirdbody::render::{Answer, Format};

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
    /// Solve a job and print the result as JSON (the help naming the kinds is made from the
    /// registry, in `cli_with_kinds`).
    Solve {
        /// The job file, or - for standard input.
        job: String,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Print the data of Figure N (3–9) of the paper.
    Figure {
        number: i64,
        #[command(flatten)]
        output: OutputArgs,
    },
    /// Run the checks of a file, for CI: prints a report; exits 0 when every check holds, 1
    /// when one fails, 2 when the file is not valid.
    Check {
        /// The checks file: {"checks": [{"name", "job", "expect": {...}, "golden": {...}}]}.
        checks: PathBuf,
        /// Also write the report as JUnit XML to this file.
        #[arg(long)]
        junit: Option<PathBuf>,
        /// Rewrite every golden answer file with today's answer.
        #[arg(long)]
        update: bool,
    },
    /// Serve the HTTP API (see /docs once it runs); every flag has a THIRDBODY_* variable.
    Serve(Box<ServeArgs>),
    /// Take work from the fleet's Redis stream, with no API (needs --redis-url; the other
    /// flags of `serve` that concern solving apply, those of HTTP are ignored).
    Worker(Box<WorkerArgs>),
    /// Print the OpenAPI description of the HTTP API.
    Openapi,
    /// Make an API key: prints the key on the first line (give it to its holder: it is kept
    /// nowhere) and, on the second, its entry for the keys file of `serve --api-keys` (or,
    /// with `--append FILE`, adds the entry to that file and prints the key alone).
    NewKey {
        /// The key's tenant: jobs submitted with it belong to this name (keys of one name
        /// share them: add a new key under the old name to rotate it).
        #[arg(long)]
        name: String,
        /// What it may do: a comma-separated list of submit, read, metrics and admin.
        #[arg(long, default_value = "submit,read")]
        scopes: String,
        /// When it stops being accepted (RFC 3339, e.g. 2027-06-30T00:00:00Z); never if absent.
        #[arg(long)]
        expires: Option<String>,
        /// The keys file to add the entry to (made if absent; a running `serve` reads it
        /// again within a second).
        #[arg(long, value_name = "FILE")]
        append: Option<std::path::PathBuf>,
    },
    /// Exit 0 if the service on THIRDBODY_BIND answers /healthz (a container's health check:
    /// the image has no curl).
    Healthcheck {
        /// The address the service listens on (0.0.0.0 is asked on 127.0.0.1).
        #[arg(long, env = "THIRDBODY_BIND", default_value = "127.0.0.1:8080")]
        bind: std::net::SocketAddr,
    },
}

/// `thirdbody worker`: the flags of `serve`, and where to serve its operations' routes.
#[derive(Args)]
struct WorkerArgs {
    /// Serve /metrics, /healthz and /readyz on this address (e.g. 0.0.0.0:9100), for
    /// Prometheus and probes, under the access rules of `serve`; nothing if absent.
    #[arg(long, env = "THIRDBODY_METRICS_BIND")]
    metrics_bind: Option<std::net::SocketAddr>,
    #[command(flatten)]
    serve: ServeArgs,
}

/// How an answer is printed.
#[derive(Args)]
struct OutputArgs {
    /// Output format.
    #[arg(long, value_enum, default_value_t = OutputFormat::Json)]
    format: OutputFormat,
    /// Say where the answer comes from (software version and git commit, model version,
    /// SHA-256 of the input) where the output still parses: a first `#` line of a CSV, an
    /// XML comment of an SVG; a JSON answer holds it already in `meta`.
    #[arg(long)]
    provenance: bool,
}

/// The forms of an answer on the command line (JSON is indented for people).
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum OutputFormat {
    Json,
    Csv,
    /// The answer's picture.
    Svg,
}

impl OutputFormat {
    fn format(self) -> Format {
        match self {
            OutputFormat::Json => Format::Json,
            OutputFormat::Csv => Format::Csv,
            OutputFormat::Svg => Format::Svg,
        }
    }
}

/// Exit status for a job that cannot be used: a job file that cannot be read, is not JSON or
/// is not a valid job (as distinct from a valid job that failed to solve, 1); and for a
/// `serve` setting that is not valid.
const INVALID_JOB: u8 = 2;

/// What `thirdbody solve` exits with, under its first line in `solve --help`.
const SOLVE_EXITS: &str = "Exits 0 with an answer, 1 when a valid job cannot be solved, 2 when \
                           the job cannot be used (the file cannot be read, is not JSON, or is \
                           not a valid job).";

/// The command line, its help naming the job kinds from the registry (the one list of
/// kinds).
fn cli_with_kinds() -> clap::Command {
    let about = format!(
        "Solve a job {{\"kind\": {}, \"input\": {{...}}}} and print the result as JSON.",
        registry::quoted_names(" | ")
    );
    let long_about = format!("{about}\n\n{SOLVE_EXITS}");
    Cli::command().mut_subcommand("solve", |solve| solve.about(about).long_about(long_about))
}

fn main() -> ExitCode {
    let cli = Cli::from_arg_matches(&cli_with_kinds().get_matches()).unwrap_or_else(|e| e.exit());
    let (job, output) = match cli.command {
        Command::Solve { job, output } => match read_input(&job) {
            Ok(text) => (Job::from_json(&text, &Limits::default()), output),
            Err(why) => {
                eprintln!("thirdbody: {why}");
                return ExitCode::from(INVALID_JOB);
            }
        },
        Command::Figure { number, output } => (FigureJob::new(number).map(Job::new), output),
        Command::Check {
            checks,
            junit,
            update,
        } => return check(&checks, junit.as_deref(), update),
        Command::Serve(args) => return serve(*args),
        Command::Worker(args) => return worker(*args),
        Command::Openapi => return print(&http::openapi::spec_json()),
        Command::NewKey {
            name,
            scopes,
            expires,
            append,
        } => return new_key(&name, &scopes, expires.as_deref(), append.as_deref()),
        Command::Healthcheck { bind } => return healthcheck(bind),
    };
    let result = job.and_then(|job| {
        for warning in job.warnings() {
            eprintln!("thirdbody: warning: {}", warning.message);
        }
        let meta = job.meta();
        let provenance = output.provenance.then(|| meta.provenance());
        let answer = job.run(meta, &Control::default())?;
        if let Some(notice) = answer.notice() {
            eprintln!("thirdbody: warning: {notice}");
        }
        let format = output.format.format();
        let text = render(&answer, format)?;
        Ok(match provenance {
            Some(line) => format.with_provenance(text, &line),
            None => text,
        })
    });
    match result {
        Ok(text) => print(&text),
        Err(e) => {
            let e = e.cut();
            eprintln!("thirdbody: {e}");
            match e {
                JobError::Syntax(_)
                | JobError::Schema { .. }
                | JobError::Invalid(_)
                | JobError::OutOfDomain(_) => ExitCode::from(INVALID_JOB),
                _ => ExitCode::FAILURE,
            }
        }
    }
}

/// `thirdbody check`: the report on standard output (and in JUnit XML if asked).
fn check(path: &Path, junit: Option<&Path>, update: bool) -> ExitCode {
    let report = match check::run_file(path, update) {
        Ok(report) => report,
        Err(e) => {
            eprintln!("thirdbody check: {e}");
            return ExitCode::from(INVALID_JOB);
        }
    };
    if let Some(junit) = junit {
        if let Err(e) = std::fs::write(junit, report.to_junit()) {
            eprintln!("thirdbody check: cannot write {}: {e}", junit.display());
            return ExitCode::from(INVALID_JOB);
        }
    }
    let printed = print(&report.to_text());
    if report.passed {
        printed
    } else {
        ExitCode::FAILURE
    }
}

/// Writes `text` to standard output; a reader that stops early (`| head`) is not an error
/// of ours.
fn print(text: &str) -> ExitCode {
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

/// `thirdbody healthcheck`: one GET /healthz, answered 200 within two seconds.
fn healthcheck(mut bind: std::net::SocketAddr) -> ExitCode {
    if bind.ip().is_unspecified() {
        bind.set_ip(std::net::Ipv4Addr::LOCALHOST.into());
    }
    let timeout = Duration::from_secs(2);
    let answered = (|| -> std::io::Result<String> {
        let mut stream = std::net::TcpStream::connect_timeout(&bind, timeout)?;
        stream.set_read_timeout(Some(timeout))?;
        stream.write_all(b"GET /healthz HTTP/1.0\r\nAccept: application/json\r\n\r\n")?;
        let mut answer = String::new();
        stream.read_to_string(&mut answer)?;
        Ok(answer)
    })();
    match answered {
        Ok(answer) if answer.starts_with("HTTP/1.1 200") || answer.starts_with("HTTP/1.0 200") => {
            ExitCode::SUCCESS
        }
        Ok(answer) => {
            eprintln!(
                "thirdbody healthcheck: {}",
                answer.lines().next().unwrap_or("")
            );
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("thirdbody healthcheck: {bind}: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `thirdbody new-key`: a key and its entry (or the entry added to the keys file `append`),
/// or why not (exit 2).
fn new_key(name: &str, scopes: &str, expires: Option<&str>, append: Option<&Path>) -> ExitCode {
    use http::access::keys;
    let issued = keys::issue(name, scopes, expires).and_then(|(key, entry)| match append {
        Some(file) => keys::append(file, &entry).map(|()| {
            eprintln!(
                "thirdbody new-key: its entry is added to {}",
                file.display()
            );
            format!("{key}\n")
        }),
        None => Ok(format!("{key}\n{entry}\n")),
    });
    match issued {
        Ok(text) => print(&text),
        Err(e) => {
            eprintln!("thirdbody new-key: {e}");
            ExitCode::from(INVALID_JOB)
        }
    }
}

/// The settings of `command` and a runtime to run it on; or the exit code saying why not.
fn start(command: &str, args: ServeArgs) -> Result<(Config, tokio::runtime::Runtime), ExitCode> {
    let config = args.validate().map_err(|e| {
        eprintln!("thirdbody {command}: invalid setting: {e}");
        ExitCode::from(INVALID_JOB)
    })?;
    init_logging(config.log_format);
    let runtime = tokio::runtime::Runtime::new().map_err(|e| {
        eprintln!("thirdbody {command}: cannot start the runtime: {e}");
        ExitCode::FAILURE
    })?;
    Ok((config, runtime))
}

/// `thirdbody worker`: works the fleet's stream until SIGTERM or Ctrl-C, then finishes the
/// part it holds (within the shutdown timeout; what it cannot finish, another process takes
/// over). With `--metrics-bind`, serves its operations' routes meanwhile.
fn worker(args: WorkerArgs) -> ExitCode {
    if args.serve.fleet.redis_url.is_none() {
        eprintln!(
            "thirdbody worker: invalid setting: --redis-url (or THIRDBODY_REDIS_URL) is required"
        );
        return ExitCode::from(INVALID_JOB);
    }
    let (config, runtime) = match start("worker", args.serve) {
        Ok(started) => started,
        Err(code) => return code,
    };
    let worked = runtime.block_on(async {
        let timeout = config.shutdown_timeout;
        let pool_size = config.engine.pool_size;
        let state = AppState::new(config).map_err(|e| e.to_string())?;
        let operations = match args.metrics_bind {
            Some(bind) => Some(
                tokio::net::TcpListener::bind(bind)
                    .await
                    .map_err(|e| format!("cannot listen on {bind} (--metrics-bind): {e}"))?,
            ),
            None => None,
        };
        let engine = state.engine().clone();
        engine.jobs.start_workers(pool_size, false);
        tracing::info!(workers = pool_size, "taking work from Redis");
        let _served = operations.map(|listener| http::serve_operations(listener, state.clone()));
        let _chores = http::chores(&state);
        Signals::new().next().await;
        engine.jobs.begin_drain();
        engine
            .jobs
            .finish_jobs(tokio::time::Instant::now() + timeout)
            .await;
        Ok::<_, String>(())
    });
    match worked {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("thirdbody worker: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `thirdbody serve`: validates the settings, then serves until SIGTERM or Ctrl-C, and drains
/// (a second Ctrl-C or SIGTERM exits at once, with status 130 or 143).
fn serve(args: ServeArgs) -> ExitCode {
    let (config, runtime) = match start("serve", args) {
        Ok(started) => started,
        Err(code) => return code,
    };
    let served = runtime.block_on(async {
        let signals = Signals::new();
        let (bind, timeout) = (config.bind, config.shutdown_timeout);
        // The service first (its database may be another process's): then the port.
        let state = AppState::new(config).map_err(|e| e.to_string())?;
        let listener = tokio::net::TcpListener::bind(bind)
            .await
            .map_err(|e| format!("cannot listen on {bind}: {e}"))?;
        // The address bound (the port the system chose, for `--bind 127.0.0.1:0`).
        let address = listener.local_addr().unwrap_or(bind);
        tracing::info!(%address, "listening; dashboard at /, API docs at /docs");
        let shutdown = shut_down_on(signals, state.engine().clone(), timeout);
        http::run(listener, state, shutdown)
            .await
            .map_err(|e| format!("the server failed: {e}"))
    });
    match served {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("thirdbody serve: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Log lines on standard error, filtered by `RUST_LOG` (default `info`).
fn init_logging(format: LogFormat) {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    let logs = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_ansi(std::io::stderr().is_terminal())
        .with_writer(std::io::stderr);
    match format {
        LogFormat::Json => logs.json().flatten_event(true).init(),
        LogFormat::Text => logs.init(),
    }
}

/// Resolves on the first of `signals`, saying at once what the drain will wait for and for
/// how long at most (`timeout`): a person who pressed Ctrl-C learns why the prompt does not
/// come back. The second signal exits at once, saying what it abandons.
async fn shut_down_on(mut signals: Signals, engine: Arc<Engine>, timeout: Duration) {
    signals.next().await;
    let unfinished = engine.jobs.unfinished_jobs() as f64;
    let unread = engine.jobs.unread_jobs() as f64;
    let mut waited = Vec::new();
    if unfinished > 0.0 {
        waited.push(count(unfinished, "unfinished job", "unfinished jobs"));
    }
    if unread > 0.0 {
        waited.push(count(
            unread,
            "finished job whose client has not read it",
            "finished jobs whose clients have not read them",
        ));
    }
    if waited.is_empty() {
        waited.push("the requests in flight".to_string());
    }
    tracing::info!(
        "shutting down: waiting up to {} for {}; press Ctrl-C again to exit now",
        quantity(timeout.as_secs_f64(), "s"),
        waited.join(" and ")
    );
    tokio::spawn(async move {
        let status = signals.next().await;
        let mut abandoned = Vec::new();
        let unfinished = engine.jobs.unfinished_jobs() as f64;
        if unfinished > 0.0 {
            let jobs = count(unfinished, "unfinished job", "unfinished jobs");
            abandoned.push(format!("{jobs} interrupted"));
        }
        let unread = engine.jobs.unread_jobs() as f64;
        if unread > 0.0 {
            let results = count(unread, "unread result", "unread results");
            abandoned.push(format!("{results} dropped"));
        }
        if abandoned.is_empty() {
            abandoned.push("nothing was left to wait for".to_string());
        }
        tracing::warn!("exiting now: {}", abandoned.join(", "));
        std::process::exit(i32::from(status));
    });
}

/// Ctrl-C (SIGINT) and SIGTERM, listened for from start-up on, so that a second one is not
/// missed while the first is handled.
struct Signals {
    #[cfg(unix)]
    interrupt: Option<tokio::signal::unix::Signal>,
    #[cfg(unix)]
    terminate: Option<tokio::signal::unix::Signal>,
}

impl Signals {
    /// Starts listening (within a runtime); a signal that cannot be listened for never comes.
    fn new() -> Signals {
        #[cfg(unix)]
        {
            use tokio::signal::unix::{signal, SignalKind};
            Signals {
                interrupt: signal(SignalKind::interrupt()).ok(),
                terminate: signal(SignalKind::terminate()).ok(),
            }
        }
        #[cfg(not(unix))]
        Signals {}
    }

    /// Waits for the next signal; returns the conventional status of a process it ends
    /// (128 + its number: 130 for Ctrl-C, 143 for SIGTERM).
    async fn next(&mut self) -> u8 {
        #[cfg(unix)]
        {
            async fn recv(signal: &mut Option<tokio::signal::unix::Signal>) {
                let received = match signal {
                    Some(signal) => signal.recv().await,
                    None => None,
                };
                if received.is_none() {
                    std::future::pending::<()>().await;
                }
            }
            tokio::select! {
                () = recv(&mut self.interrupt) => 130,
                () = recv(&mut self.terminate) => 143,
            }
        }
        #[cfg(not(unix))]
        {
            if tokio::signal::ctrl_c().await.is_err() {
                std::future::pending::<()>().await;
            }
            130
        }
    }
}

/// A job file that cannot be read.
#[derive(Debug, thiserror::Error)]
#[error("cannot read {path}: {source}")]
struct Unread {
    /// The file, or "standard input".
    path: String,
    source: std::io::Error,
}

/// The text of the job file at `path` (`-`: standard input), or why it cannot be read.
fn read_input(path: &str) -> Result<Vec<u8>, Unread> {
    let unread = |source, path: &str| Unread {
        path: path.to_string(),
        source,
    };
    if path == "-" {
        let mut text = Vec::new();
        std::io::stdin()
            .read_to_end(&mut text)
            .map(|_| text)
            .map_err(|e| unread(e, "standard input"))
    } else {
        std::fs::read(path).map_err(|e| unread(e, path))
    }
}

/// The answer as text in `format`; failing to render it is a fault of ours, not the job's.
fn render(answer: &Answer, format: Format) -> Result<String, JobError> {
    let text = match format {
        Format::Json => answer.to_pretty_json(),
        _ => answer
            .render(format)
            .map(|bytes| String::from_utf8_lossy(&bytes).into_owned()),
    };
    text.map_err(|e| JobError::Internal(e.to_string()))
}
