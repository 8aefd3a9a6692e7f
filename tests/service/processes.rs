//! `thirdbody` as a test's child process. Each is started from [`thirdbody`], so that none
//! uses the working directory's database, and most with [`spawn_logged`], whose log the test
//! reads and a failed wait shows. Waits are bounded by [`PATIENCE`] (something that takes
//! milliseconds on an idle machine) or by a job's progress ([`STALL`]), never by a guess at
//! how fast the machine is: `cargo test` runs beside a server started as README says and on
//! a machine busy with other builds.

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// The longest a test waits for what takes milliseconds on an idle machine (a process to
/// start, a link to be seen down or back, a file read again, a part taken): reached only
/// when it never happens, however loaded the machine.
pub(crate) const PATIENCE: Duration = Duration::from_secs(120);

/// The longest a job may go without progress (its status, or its count of points done)
/// before a test gives up on it: more than one part of a sweep (100 points of the
/// continuum's ≈ 50 ms each) on a loaded two-core machine. A job that keeps moving is waited
/// for however long it takes; its own deadline still ends it.
pub(crate) const STALL: Duration = Duration::from_secs(180);

/// A fresh directory for files a test writes: `thirdbody-{name}-{pid}` in the system's
/// temporary directory, emptied of what an earlier run left.
pub(crate) fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("thirdbody-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A child process, killed when dropped.
pub(crate) struct Process(pub Child);

impl Process {
    /// Sends SIGTERM (the signal that starts a drain), checking that `kill` delivered it.
    pub(crate) fn sigterm(&self) {
        let pid = self.0.id().to_string();
        assert!(Command::new("kill")
            .args(["-TERM", &pid])
            .status()
            .unwrap()
            .success());
    }
}

impl Drop for Process {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
        let pid = self.0.id();
        LOGS.lock().unwrap().retain(|logged| logged.pid != pid);
    }
}

/// The `thirdbody` binary, with its database of saved analyses in memory unless the test
/// names one (`--database`, or `THIRDBODY_DATABASE` set on the command, either overrides
/// this): never the working directory's `thirdbody.db`, which a server started as README
/// says holds locked, and which tests running side by side would share. Settings of the
/// shell that runs the tests (`THIRDBODY_*`) are not passed on: a test says what it runs.
pub(crate) fn thirdbody() -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_thirdbody"));
    for (name, _) in std::env::vars_os() {
        if name.to_string_lossy().starts_with("THIRDBODY_") {
            cmd.env_remove(name);
        }
    }
    cmd.env("THIRDBODY_DATABASE", thirdbody::engine::archive::IN_MEMORY);
    cmd
}

/// The lines a process wrote on its standard error, as they come.
pub(crate) type Log = Arc<Mutex<Vec<String>>>;

/// A process whose log a failed wait shows: named, found by the port it serves on, and with
/// the others on its Redis (`group`: the processes of one fleet).
struct Logged {
    pid: u32,
    name: String,
    port: Option<u16>,
    group: Option<u16>,
    lines: Log,
    /// Its standard error closed: it exited.
    closed: Arc<AtomicBool>,
}

static LOGS: Mutex<Vec<Logged>> = Mutex::new(Vec::new());

/// Spawns `cmd` (named `name` in failures) with its standard error collected line by line;
/// `port` is where it serves, `group` the Redis port of its fleet. Its log is kept until the
/// process is dropped.
pub(crate) fn spawn_logged(
    cmd: &mut Command,
    name: &str,
    port: Option<u16>,
    group: Option<u16>,
) -> (Process, Log) {
    let mut child = cmd
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("thirdbody starts");
    let lines = Log::default();
    let closed = Arc::new(AtomicBool::new(false));
    let stderr = child.stderr.take().unwrap();
    let (sink, end) = (lines.clone(), closed.clone());
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            sink.lock().unwrap().push(line);
        }
        end.store(true, Ordering::SeqCst);
    });
    LOGS.lock().unwrap().push(Logged {
        pid: child.id(),
        name: name.to_string(),
        port,
        group,
        lines: lines.clone(),
        closed,
    });
    (Process(child), lines)
}

/// The port of a URL (`http://127.0.0.1:PORT/...`).
fn port_of(url: &str) -> Option<u16> {
    let authority = url.split("://").nth(1)?.split('/').next()?;
    authority.rsplit(':').next()?.parse().ok()
}

/// Whether the process serving on `port` (started by [`spawn_logged`]) has exited.
pub(crate) fn exited(port: u16) -> bool {
    let logs = LOGS.lock().unwrap();
    logs.iter()
        .any(|l| l.port == Some(port) && l.closed.load(Ordering::SeqCst))
}

/// The last lines of the log of the process serving `url` and of the others of its fleet,
/// for a failure to show ("no log kept" for a process not started by [`spawn_logged`]).
pub(crate) fn logs_near(url: &str) -> String {
    const TAIL: usize = 30;
    let port = port_of(url);
    let logs = LOGS.lock().unwrap();
    let Some(this) = logs.iter().find(|l| port.is_some() && l.port == port) else {
        return format!("(no log kept of the process serving {url})");
    };
    let mut text = String::new();
    let near = logs
        .iter()
        .filter(|l| std::ptr::eq(*l, this) || (this.group.is_some() && l.group == this.group));
    for logged in near {
        let lines = logged.lines.lock().unwrap();
        let exited = if logged.closed.load(Ordering::SeqCst) {
            ", exited"
        } else {
            ""
        };
        text.push_str(&format!(
            "--- {} (pid {}{exited}): last {} of {} log lines ---\n",
            logged.name,
            logged.pid,
            TAIL.min(lines.len()),
            lines.len()
        ));
        for line in &lines[lines.len().saturating_sub(TAIL)..] {
            text.push_str(line);
            text.push('\n');
        }
    }
    text
}

/// The last lines of `log`, for a failure to show.
pub(crate) fn tail(log: &Log) -> String {
    let lines = log.lock().unwrap();
    lines[lines.len().saturating_sub(30)..].join("\n")
}

/// Every test starts the binary through [`thirdbody`], so that none can use the working
/// directory's database: a test that spawns it otherwise fails here, naming its file.
#[test]
fn every_test_starts_the_binary_through_this_module() {
    fn sources(dir: &std::path::Path, found: &mut Vec<std::path::PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap().map(Result::unwrap) {
            let path = entry.path();
            if path.is_dir() {
                sources(&path, found);
            } else if path.extension().is_some_and(|e| e == "rs") {
                found.push(path);
            }
        }
    }
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    sources(&root.join("tests"), &mut files);
    let this = root.join(file!());
    let binary = concat!("CARGO_BIN_EXE", "_thirdbody");
    let elsewhere: Vec<_> = files
        .iter()
        .filter(|f| **f != this && std::fs::read_to_string(f).unwrap().contains(binary))
        .collect();
    assert!(
        files.contains(&this),
        "{} is not among {files:?}",
        this.display()
    );
    assert!(
        elsewhere.is_empty(),
        "{elsewhere:?} start the binary without tests/service/processes.rs's `thirdbody()`"
    );
}
