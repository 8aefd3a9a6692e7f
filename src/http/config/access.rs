//! Who may call the service: API keys, what anonymous callers may do, the quotas every
//! tenant (the anonymous callers one of them) draws on, and the browser origins allowed.

use axum::http::HeaderValue;

use super::{check_all, Bounded, ConfigError, MAX_COUNT};
use crate::http::access::{Access, Keys, Quota, Scopes, Source};

/// Keys, anonymous callers, quotas and browser origins.
#[derive(Clone, Debug, clap::Args)]
pub struct AccessArgs {
    /// Origins allowed to call the API from a browser, comma-separated (`*` for any);
    /// none by default.
    #[arg(
        long = "cors-origin",
        env = "THIRDBODY_CORS_ORIGINS",
        value_delimiter = ','
    )]
    pub cors_origins: Vec<String>,

    /// API keys: a JSON file of hashed keys, each with a name, scopes and an optional
    /// expiry, read again within a second when it changes (or the JSON itself, e.g. in an
    /// environment variable: then changed by a restart). See README, "API keys". Absent:
    /// no key is accepted, and every caller is anonymous.
    #[arg(long, env = "THIRDBODY_API_KEYS")]
    pub api_keys: Option<String>,

    /// What a caller without an API key may do: a comma-separated list of submit, read and
    /// metrics, or `none` (then everything but the dashboard's files and the probes needs a
    /// key).
    #[arg(
        long,
        env = "THIRDBODY_ANONYMOUS",
        default_value = "submit,read,metrics"
    )]
    pub anonymous: String,

    /// Points (about ten microseconds of a solver thread each: a local-law answer is one, a
    /// continuum answer what its grid costs, 7,000 on the default grid) each tenant may ask
    /// to be computed in a minute, fleet-wide; more are refused with 429 until the minute
    /// ends (0: no limit). Each API key's name is a tenant, and the callers without a key
    /// together are one. An answer already cached costs nothing.
    #[arg(long, env = "THIRDBODY_QUOTA_POINTS", default_value_t = 0)]
    pub quota_points: u64,

    /// Unfinished asynchronous jobs each tenant may have at once (0: no limit); the callers
    /// without a key together are one tenant.
    #[arg(long, env = "THIRDBODY_QUOTA_JOBS", default_value_t = 0)]
    pub quota_jobs: usize,
}

/// Which browser origins may call the API.
#[derive(Clone, Debug, PartialEq)]
pub enum CorsOrigins {
    /// No CORS headers: browsers on other origins cannot read answers.
    None,
    Any,
    List(Vec<HeaderValue>),
}

impl CorsOrigins {
    /// Why a page at `origin` may not call the service, naming the flag that would allow it;
    /// `None` if it may.
    pub fn refusal(&self, origin: &HeaderValue) -> Option<String> {
        let shown = String::from_utf8_lossy(origin.as_bytes());
        match self {
            CorsOrigins::Any => None,
            CorsOrigins::List(list) if list.contains(origin) => None,
            CorsOrigins::None => Some(format!(
                "a page at {shown} may not call this service: it was started without \
                 --cors-origin (THIRDBODY_CORS_ORIGINS). Start it with --cors-origin {shown} to \
                 allow that origin"
            )),
            CorsOrigins::List(list) => Some(format!(
                "a page at {shown} may not call this service: its --cors-origin \
                 (THIRDBODY_CORS_ORIGINS) allows {}. Add {shown} to allow that origin",
                list.iter()
                    .map(|o| String::from_utf8_lossy(o.as_bytes()).into_owned())
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        }
    }
}

/// The access rules as checked.
pub struct Checked {
    pub access: Access,
    pub cors_origins: CorsOrigins,
}

impl AccessArgs {
    /// Reads the keys (a file that cannot be used fails the start), and checks the scopes of
    /// `--anonymous`, the quotas and the origins.
    pub fn validate(self) -> Result<Checked, ConfigError> {
        let no_limit = "no limit";
        check_all([
            Bounded::or_zero("--quota-points", self.quota_points, MAX_COUNT, no_limit),
            Bounded::or_zero("--quota-jobs", self.quota_jobs, MAX_COUNT, no_limit),
        ])?;
        let mut access = access(self.api_keys.as_deref(), &self.anonymous)?;
        access.quota = Quota {
            points_per_minute: self.quota_points,
            jobs: self.quota_jobs,
        };
        Ok(Checked {
            access,
            cors_origins: cors_origins(&self.cors_origins)?,
        })
    }
}

/// The keys of `--api-keys` and the scopes of `--anonymous`.
fn access(api_keys: Option<&str>, anonymous: &str) -> Result<Access, ConfigError> {
    let anonymous =
        Scopes::parse(anonymous).map_err(|e| ConfigError::Invalid(format!("--anonymous: {e}")))?;
    if anonymous.is_admin() {
        return Err(ConfigError::Invalid(
            "--anonymous admin: an admin needs a key (allowed submit, read, metrics, or none)"
                .to_string(),
        ));
    }
    if anonymous == Scopes::NONE && api_keys.is_none() {
        return Err(ConfigError::Invalid(
            "--anonymous none without --api-keys: nobody could use the service".to_string(),
        ));
    }
    let keys =
        Keys::load(api_keys.map(Source::of)).map_err(|e| ConfigError::Invalid(e.to_string()))?;
    Ok(Access::new(keys, anonymous))
}

/// Origins are `scheme://host[:port]` exactly as browsers send them, or `*` alone.
fn cors_origins(origins: &[String]) -> Result<CorsOrigins, ConfigError> {
    let origins: Vec<&str> = origins
        .iter()
        .map(|o| o.trim())
        .filter(|o| !o.is_empty())
        .collect();
    match origins.as_slice() {
        [] => return Ok(CorsOrigins::None),
        ["*"] => return Ok(CorsOrigins::Any),
        _ => {}
    }
    origins
        .iter()
        .map(|&origin| {
            let valid = origin.split_once("://").is_some_and(|(scheme, host)| {
                matches!(scheme, "http" | "https") && !host.is_empty() && !host.contains('/')
            });
            match HeaderValue::from_str(origin) {
                Ok(value) if valid => Ok(value),
                _ => Err(ConfigError::Invalid(format!(
                    "--cors-origin {origin:?}: expected an origin such as \
                     https://dashboard.example.org or http://localhost:3000 (no path), or * alone"
                ))),
            }
        })
        .collect::<Result<_, _>>()
        .map(CorsOrigins::List)
}
