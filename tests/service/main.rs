//! The service without HTTP: the command line, the job kinds through the library, pictures,
//! the fleet's processes on a real Redis, and the deployment files. One test binary, a
//! module per concern (the HTTP service end to end is the `api` binary).

mod access;
mod cli;
#[path = "../shared/clock.rs"]
mod clock;
mod deploy;
mod fit;
mod fit_continuum;
mod fleet;
mod fleet_faults;
mod history;
mod honest_answers;
mod jobs;
#[path = "../shared/json.rs"]
mod json;
mod kinds;
mod pictures;
mod processes;
mod storage;
mod three_body;
mod tls;
