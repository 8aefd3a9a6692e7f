//! The API keys a service accepts (`--api-keys`): a JSON file of *hashed* keys, read again
//! when it changes, so that a key is added, rotated or revoked without a restart.
//!
//! ```json
//! {"keys": [
//!   {"name": "lab-a", "sha256": "<64 hex digits>", "scopes": ["submit", "read"],
//!    "expires": "2027-06-30T00:00:00Z"}
//! ]}
//! ```
//!
//! Only the SHA-256 of a key is kept (`printf %s "$KEY" | sha256sum`, or `thirdbody key
//! new`), so the file is no secret worth stealing. Several keys may share a name: they are
//! one tenant, which is how a key is rotated (add the new one, hand it out, remove the old).

use std::collections::HashMap;
use std::fmt;
use std::sync::{Arc, Mutex, RwLock};
use std::time::SystemTime;

use serde::Deserialize;
use sha2::{Digest, Sha256};

/// What a caller may do, as a set.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Scopes(u8);

impl Scopes {
    pub const NONE: Scopes = Scopes(0);
    /// Submit work: solves, sweeps, fits, checks, jobs; cancel and delete one's own jobs.
    pub const SUBMIT: Scopes = Scopes(1);
    /// Read jobs, results, figures, the history and the API's docs.
    pub const READ: Scopes = Scopes(2);
    /// Read `/metrics`.
    pub const METRICS: Scopes = Scopes(4);
    /// Everything, and every tenant's jobs.
    pub const ADMIN: Scopes = Scopes(8);

    /// Every scope by name, in the order they are listed.
    const NAMED: [(&'static str, Scopes); 4] = [
        ("submit", Scopes::SUBMIT),
        ("read", Scopes::READ),
        ("metrics", Scopes::METRICS),
        ("admin", Scopes::ADMIN),
    ];

    /// The scopes of a comma-separated list of names (`none` alone for the empty set).
    pub fn parse(list: &str) -> Result<Scopes, UnknownScope> {
        if list.trim() == "none" {
            return Ok(Scopes::NONE);
        }
        Scopes::of_names(
            list.split(',')
                .map(str::trim)
                .filter(|name| !name.is_empty()),
        )
    }

    /// The scopes named in `names`; an error names the first unknown one.
    fn of_names<'a>(names: impl IntoIterator<Item = &'a str>) -> Result<Scopes, UnknownScope> {
        names
            .into_iter()
            .try_fold(Scopes::NONE, |all, name| Ok(all.with(Scopes::named(name)?)))
    }

    fn named(name: &str) -> Result<Scopes, UnknownScope> {
        Scopes::NAMED
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, scope)| *scope)
            .ok_or_else(|| UnknownScope(name.to_string()))
    }

    fn with(self, other: Scopes) -> Scopes {
        Scopes(self.0 | other.0)
    }

    /// Whether these scopes allow what `needed` names (admin allows everything).
    pub fn allow(self, needed: Scopes) -> bool {
        self.0 & Scopes::ADMIN.0 != 0 || self.0 & needed.0 == needed.0
    }

    pub fn is_admin(self) -> bool {
        self.0 & Scopes::ADMIN.0 != 0
    }
}

impl fmt::Display for Scopes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = Scopes::NAMED
            .iter()
            .filter(|(_, scope)| self.0 & scope.0 != 0)
            .map(|(name, _)| *name)
            .collect();
        match names.as_slice() {
            [] => f.write_str("none"),
            names => f.write_str(&names.join(", ")),
        }
    }
}

/// One key, as the service knows it.
#[derive(Debug)]
pub struct Key {
    /// Its tenant: the jobs made with it belong to this name.
    pub name: String,
    pub scopes: Scopes,
    /// When it stops being accepted, if ever.
    pub expires: Option<SystemTime>,
}

/// The keys of one reading of the file, by their hash.
#[derive(Debug, Default)]
struct Ring(HashMap<[u8; 32], Arc<Key>>);

/// A key file as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    keys: Vec<Entry>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Entry {
    name: String,
    sha256: String,
    scopes: Vec<String>,
    #[serde(default)]
    expires: Option<String>,
}

/// A scope name that is not one.
#[derive(Debug, PartialEq, thiserror::Error)]
#[error("unknown scope {0:?}: allowed submit, read, metrics, admin")]
pub struct UnknownScope(String);

/// Why the keys cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum KeysError {
    /// Not the JSON of a keys file.
    #[error("{0} (expected {{\"keys\": [{{\"name\", \"sha256\", \"scopes\", \"expires\"?}}]}})")]
    Json(serde_json::Error),
    /// Entry `index`, named `name`, is wrong in what `what` says.
    #[error("keys[{index}] ({name:?}): {what}")]
    Entry {
        index: usize,
        name: String,
        what: String,
    },
    /// The file cannot be read.
    #[error("--api-keys {path}: {source}")]
    Unreadable {
        path: String,
        source: std::io::Error,
    },
    /// The file cannot be written (`new-key --append`).
    #[error("cannot write {path}: {source}")]
    Unwritable {
        path: String,
        source: std::io::Error,
    },
}

impl Ring {
    /// The keys of `text`; an error names the entry and what is wrong with it.
    fn parse(text: &str) -> Result<Ring, KeysError> {
        let file: File = serde_json::from_str(text).map_err(KeysError::Json)?;
        let mut ring = HashMap::new();
        for (i, entry) in file.keys.into_iter().enumerate() {
            let at = |what: String| KeysError::Entry {
                index: i,
                name: entry.name.clone(),
                what,
            };
            if !is_tenant_name(&entry.name) {
                return Err(at(
                    "name: allowed 1 to 64 characters of A-Z, a-z, 0-9, '-', '_' and '.'".into(),
                ));
            }
            let hash = hex32(&entry.sha256).ok_or_else(|| {
                at("sha256: allowed 64 hexadecimal digits, the SHA-256 of the key".into())
            })?;
            let scopes = Scopes::of_names(entry.scopes.iter().map(String::as_str))
                .map_err(|e| at(e.to_string()))?;
            if scopes == Scopes::NONE {
                return Err(at(
                    "scopes: allowed a list of submit, read, metrics, admin".into()
                ));
            }
            let expires = entry
                .expires
                .as_deref()
                .map(|text| {
                    humantime::parse_rfc3339_weak(text).map_err(|e| {
                        at(format!(
                            "expires {text:?}: {e} (write e.g. 2027-06-30T00:00:00Z)"
                        ))
                    })
                })
                .transpose()?;
            let key = Key {
                name: entry.name.clone(),
                scopes,
                expires,
            };
            if ring.insert(hash, Arc::new(key)).is_some() {
                return Err(at("sha256: the same key is listed twice".into()));
            }
        }
        Ok(Ring(ring))
    }
}

/// Whether `name` may name a tenant: 1 to 64 characters of A-Z, a-z, 0-9, '-', '_' and '.'
/// (it is part of keys in Redis and of URLs, unescaped).
pub fn is_tenant_name(name: &str) -> bool {
    (1..=64).contains(&name.len())
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"-_.".contains(&b))
}

/// 32 bytes from 64 hexadecimal digits.
fn hex32(text: &str) -> Option<[u8; 32]> {
    let text = text.trim().as_bytes();
    if text.len() != 64 {
        return None;
    }
    let mut out = [0u8; 32];
    for (byte, pair) in out.iter_mut().zip(text.chunks(2)) {
        *byte = u8::from_str_radix(std::str::from_utf8(pair).ok()?, 16).ok()?;
    }
    Some(out)
}

/// The SHA-256 of a key, as the file lists it.
pub fn hash_hex(key: &str) -> String {
    Sha256::digest(key.as_bytes())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// A new key for the tenant `name` with `scopes` (comma-separated), expiring at `expires`
/// (RFC 3339) if given: the key itself (244 random bits; shown once, kept nowhere) and its
/// entry for the keys file, checked as the service will read it.
pub fn issue(
    name: &str,
    scopes: &str,
    expires: Option<&str>,
) -> Result<(String, String), KeysError> {
    let random = || uuid::Uuid::new_v4().simple().to_string();
    let key = format!("tb_{}{}", random(), random());
    let scopes: Vec<&str> = scopes
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect();
    let mut entry = serde_json::json!({"name": name, "sha256": hash_hex(&key), "scopes": scopes});
    if let Some(expires) = expires {
        entry["expires"] = expires.into();
    }
    let entry = entry.to_string();
    Ring::parse(&format!("{{\"keys\": [{entry}]}}"))?;
    Ok((key, entry))
}

/// Adds `entry` (as [`issue`] made it) to the keys file at `path`, made if it does not exist:
/// the file with it is checked as `serve` reads it, then written beside it and renamed over it,
/// so that a running service never reads half of it.
pub fn append(path: &std::path::Path, entry: &str) -> Result<(), KeysError> {
    let shown = path.display().to_string();
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => "{\"keys\": []}".to_string(),
        Err(source) => {
            return Err(KeysError::Unreadable {
                path: shown,
                source,
            })
        }
    };
    // Checked whole once the entry is in: a file `serve` refuses stays refused, untouched.
    let mut file: serde_json::Value = serde_json::from_str(&text).map_err(KeysError::Json)?;
    let entry: serde_json::Value = serde_json::from_str(entry).map_err(KeysError::Json)?;
    if let Some(keys) = file["keys"].as_array_mut() {
        keys.push(entry);
    }
    let text = serde_json::to_string_pretty(&file).map_err(KeysError::Json)?;
    Ring::parse(&text)?;
    let partial = path.with_extension("partial");
    let unwritable = |source| KeysError::Unwritable {
        path: shown.clone(),
        source,
    };
    std::fs::write(&partial, text + "\n").map_err(unwritable)?;
    std::fs::rename(&partial, path).map_err(unwritable)
}

/// Where the keys come from: a file (read again when it changes) or the JSON itself (an
/// environment variable's value: changed by a restart only).
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    File(std::path::PathBuf),
    Inline(String),
}

impl Source {
    /// `--api-keys`'s value: JSON if it starts with `{`, else a file's path.
    pub fn of(value: &str) -> Source {
        if value.trim_start().starts_with('{') {
            Source::Inline(value.to_string())
        } else {
            Source::File(value.into())
        }
    }

    fn read(&self) -> Result<String, KeysError> {
        match self {
            Source::Inline(text) => Ok(text.clone()),
            Source::File(path) => {
                std::fs::read_to_string(path).map_err(|source| KeysError::Unreadable {
                    path: path.display().to_string(),
                    source,
                })
            }
        }
    }
}

/// The keys the service accepts now.
pub struct Keys {
    source: Option<Source>,
    ring: RwLock<Arc<Ring>>,
    /// The text the ring was read from (or why it could not be): a file is parsed again
    /// only when it changes.
    text: Mutex<String>,
    /// What is wrong with the file now, if anything.
    problem: Mutex<Option<String>>,
}

impl fmt::Debug for Keys {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let described = match &self.source {
            None => "none".to_string(),
            Some(Source::File(path)) => path.display().to_string(),
            Some(Source::Inline(_)) => "(inline)".to_string(),
        };
        f.debug_struct("Keys").field("source", &described).finish()
    }
}

/// Why `--api-keys` cannot be used: a file that cannot be read names itself; keys that are
/// not valid are told under the flag's name.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    #[error(transparent)]
    Unreadable(KeysError),
    #[error("--api-keys: {0}")]
    Invalid(KeysError),
}

/// What a presented key turns out to be.
pub enum Lookup {
    Valid(Arc<Key>),
    Expired(Arc<Key>),
    Unknown,
}

impl Keys {
    /// The keys of `source` (none: no key is accepted); an error if they cannot be read.
    pub fn load(source: Option<Source>) -> Result<Keys, LoadError> {
        let (text, ring) = match &source {
            Some(source) => {
                let text = source.read().map_err(LoadError::Unreadable)?;
                let ring = Ring::parse(&text).map_err(LoadError::Invalid)?;
                (text, ring)
            }
            None => (String::new(), Ring::default()),
        };
        Ok(Keys {
            source,
            ring: RwLock::new(Arc::new(ring)),
            text: Mutex::new(text),
            problem: Mutex::new(None),
        })
    }

    /// Whether any key may be accepted at all.
    pub fn configured(&self) -> bool {
        self.source.is_some()
    }

    /// Reads the file again; if it changed, its keys replace the old ones. A file gone
    /// leaves no key accepted (a key revoked by removing the file stays revoked); a file
    /// that cannot be read or parsed leaves the keys as they were. Either is logged, and
    /// told by [`Keys::problem`] (in `/readyz`) until the file is right again.
    pub fn reload(&self) {
        let Some(Source::File(path)) = &self.source else {
            return;
        };
        let read = std::fs::read_to_string(path)
            .map_err(|e| (e.kind(), format!("--api-keys {}: {e}", path.display())));
        let seen = match &read {
            Ok(text) => text.clone(),
            Err((_, why)) => why.clone(),
        };
        let mut last = self.text.lock().unwrap_or_else(|p| p.into_inner());
        if *last == seen {
            return;
        }
        *last = seen;
        let problem = match read.map(|text| Ring::parse(&text)) {
            Ok(Ok(ring)) => {
                tracing::info!(keys = ring.0.len(), "API keys read again");
                self.replace(ring);
                None
            }
            Ok(Err(e)) => Some(format!(
                "the API keys file {} is not valid ({e}): the keys read before stay",
                path.display()
            )),
            Err((std::io::ErrorKind::NotFound, why)) => {
                self.replace(Ring::default());
                Some(format!("{why}: no API key is accepted until it is back"))
            }
            Err((_, why)) => Some(format!("{why}: the keys read before stay")),
        };
        if let Some(problem) = &problem {
            tracing::error!("{problem}");
        }
        *self.problem.lock().unwrap_or_else(|p| p.into_inner()) = problem;
    }

    fn replace(&self, ring: Ring) {
        *self.ring.write().unwrap_or_else(|p| p.into_inner()) = Arc::new(ring);
    }

    /// What is wrong with the keys file now, if anything.
    pub fn problem(&self) -> Option<String> {
        self.problem
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .clone()
    }

    /// What `key` is, at `now`.
    pub fn look_up(&self, key: &str, now: SystemTime) -> Lookup {
        let hash: [u8; 32] = Sha256::digest(key.as_bytes()).into();
        let ring = self.ring.read().unwrap_or_else(|p| p.into_inner()).clone();
        match ring.0.get(&hash) {
            None => Lookup::Unknown,
            Some(key) if key.expires.is_some_and(|at| at <= now) => Lookup::Expired(key.clone()),
            Some(key) => Lookup::Valid(key.clone()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn file(entries: &str) -> String {
        format!("{{\"keys\": [{entries}]}}")
    }

    #[test]
    fn a_key_is_known_by_its_hash_until_it_expires() {
        let text = file(&format!(
            r#"{{"name": "lab-a", "sha256": "{}", "scopes": ["submit", "read"], "expires": "2030-01-01T00:00:00Z"}}"#,
            hash_hex("secret-a")
        ));
        let keys = Keys::load(Some(Source::of(&text))).unwrap();
        let before = humantime::parse_rfc3339("2029-12-31T23:59:59Z").unwrap();
        let Lookup::Valid(key) = keys.look_up("secret-a", before) else {
            panic!("a listed key is valid before it expires");
        };
        assert_eq!(key.name, "lab-a");
        assert!(key.scopes.allow(Scopes::SUBMIT) && key.scopes.allow(Scopes::READ));
        assert!(!key.scopes.allow(Scopes::METRICS));
        let after = before + Duration::from_secs(1);
        assert!(matches!(
            keys.look_up("secret-a", after),
            Lookup::Expired(_)
        ));
        assert!(matches!(keys.look_up("secret-b", before), Lookup::Unknown));
    }

    #[test]
    fn an_issued_key_is_accepted_by_its_entry() {
        let (key, entry) = issue("lab-b", "read,metrics", Some("2031-01-01T00:00:00Z")).unwrap();
        assert!(key.starts_with("tb_") && key.len() == 67, "{key}");
        let keys = Keys::load(Some(Source::of(&file(&entry)))).unwrap();
        let Lookup::Valid(found) = keys.look_up(&key, SystemTime::now()) else {
            panic!("the issued key is accepted");
        };
        assert_eq!(
            (found.name.as_str(), found.scopes.to_string().as_str()),
            ("lab-b", "read, metrics")
        );
        assert!(issue("a b", "read", None)
            .unwrap_err()
            .to_string()
            .contains("name"));
        assert!(issue("a", "fly", None)
            .unwrap_err()
            .to_string()
            .contains("\"fly\""));
    }

    #[test]
    fn scopes_read_as_lists_and_admin_allows_all() {
        assert_eq!(Scopes::parse("none").unwrap(), Scopes::NONE);
        let some = Scopes::parse("submit, read").unwrap();
        assert_eq!(some.to_string(), "submit, read");
        assert!(!some.allow(Scopes::METRICS));
        assert!(Scopes::ADMIN.allow(Scopes::METRICS.with(Scopes::SUBMIT)));
        assert!(Scopes::parse("submit,write")
            .unwrap_err()
            .to_string()
            .contains("\"write\""));
    }

    #[test]
    fn a_bad_file_names_the_entry_and_the_field() {
        let hash = hash_hex("k");
        for (entries, needle) in [
            (
                r#"{"name": "a b", "sha256": "00", "scopes": ["read"]}"#.to_string(),
                "keys[0] (\"a b\"): name",
            ),
            (
                r#"{"name": "a", "sha256": "xyz", "scopes": ["read"]}"#.to_string(),
                "sha256: allowed 64",
            ),
            (
                format!(r#"{{"name": "a", "sha256": "{hash}", "scopes": []}}"#),
                "scopes: allowed",
            ),
            (
                format!(r#"{{"name": "a", "sha256": "{hash}", "scopes": ["root"]}}"#),
                "\"root\"",
            ),
            (
                format!(
                    r#"{{"name": "a", "sha256": "{hash}", "scopes": ["read"], "expires": "soon"}}"#
                ),
                "expires \"soon\"",
            ),
            (
                format!(
                    r#"{{"name": "a", "sha256": "{hash}", "scopes": ["read"]}}, {{"name": "b", "sha256": "{hash}", "scopes": ["read"]}}"#
                ),
                "keys[1] (\"b\"): sha256: the same key",
            ),
            (
                format!(r#"{{"name": "a", "hash": "{hash}", "scopes": ["read"]}}"#),
                "unknown field",
            ),
        ] {
            let error = Keys::load(Some(Source::of(&file(&entries))))
                .unwrap_err()
                .to_string();
            assert!(error.contains(needle), "{entries}: {error}");
        }
    }

    #[test]
    fn a_changed_file_replaces_the_keys_a_broken_one_does_not_and_a_removed_one_leaves_none() {
        let path = std::env::temp_dir().join(format!("thirdbody-keys-{}.json", std::process::id()));
        let entry = |key: &str| {
            file(&format!(
                r#"{{"name": "lab", "sha256": "{}", "scopes": ["read"]}}"#,
                hash_hex(key)
            ))
        };
        std::fs::write(&path, entry("old")).unwrap();
        let keys = Keys::load(Some(Source::of(path.to_str().unwrap()))).unwrap();
        let now = SystemTime::now();
        assert!(matches!(keys.look_up("old", now), Lookup::Valid(_)));
        std::fs::write(&path, entry("new")).unwrap();
        keys.reload();
        assert!(matches!(keys.look_up("old", now), Lookup::Unknown));
        assert!(matches!(keys.look_up("new", now), Lookup::Valid(_)));
        std::fs::write(&path, "{\"keys\": [").unwrap();
        keys.reload();
        assert!(matches!(keys.look_up("new", now), Lookup::Valid(_)));
        assert!(keys.problem().unwrap().contains("is not valid"));
        std::fs::remove_file(&path).unwrap();
        keys.reload();
        assert!(matches!(keys.look_up("new", now), Lookup::Unknown));
        assert!(keys.problem().unwrap().contains("no API key is accepted"));
        std::fs::write(&path, entry("back")).unwrap();
        keys.reload();
        assert!(matches!(keys.look_up("back", now), Lookup::Valid(_)));
        assert_eq!(keys.problem(), None);
        std::fs::remove_file(&path).unwrap();
    }
}
