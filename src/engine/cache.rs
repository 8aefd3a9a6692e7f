//! Solved jobs, kept in memory bounded in bytes and in time, keyed by the job's cache key
//! (hash of the canonical input and the model version: equal keys, equal answers).

use std::future::Future;
use std::sync::Arc;
use std::time::Duration;

use bytes::Bytes;
use moka::future::Cache;

use super::Output;
use crate::job::JobError;

/// A solved job as it is kept and sent: the answer, and its JSON rendered once, so that a
/// cache hit costs no serialization.
#[derive(Debug)]
pub struct Solved {
    /// The job's cache key.
    pub key: String,
    pub output: Output,
    /// `output` as JSON.
    pub json: Bytes,
}

impl Solved {
    /// Renders `output`. The wire types never write `null` (absent options are skipped), and
    /// serde_json writes a non-finite float as `null`: a `null` value in the text can only
    /// be such a float, which the model promises never to return. It is an internal error
    /// here rather than a silent `null` for the client.
    pub fn new(key: String, output: Output) -> Result<Solved, JobError> {
        let json = serde_json::to_vec(&output)
            .map_err(|e| JobError::Internal(format!("cannot write the result: {e}")))?;
        if has_null_value(&json) {
            return Err(JobError::Internal(
                "the result holds a non-finite number".to_string(),
            ));
        }
        Ok(Solved {
            key,
            output,
            json: json.into(),
        })
    }

    /// The CSV form, for the answers that have one (sweeps and figures).
    pub fn csv(&self) -> Option<String> {
        match &self.output {
            Output::Sweep(s) => Some(s.to_csv()),
            Output::Figure(f) => Some(f.to_csv()),
            Output::Rolling(_) | Output::ThreeBody(_) => None,
        }
    }

    /// Bytes held in memory, roughly: the JSON text and the decoded answer, which is of the
    /// same size.
    fn weight(&self) -> u32 {
        u32::try_from(2 * self.json.len() + self.key.len()).unwrap_or(u32::MAX)
    }
}

/// Whether compact JSON text holds a `null` value (after `:`, `,` or `[`).
fn has_null_value(json: &[u8]) -> bool {
    json.windows(5)
        .any(|w| matches!(w[0], b':' | b',' | b'[') && &w[1..] == b"null")
}

/// The cache of solved jobs.
#[derive(Clone)]
pub struct ResultCache {
    cache: Cache<String, Arc<Solved>>,
}

impl ResultCache {
    /// Holds at most about `max_bytes` of answers, each for at most `ttl`.
    pub fn new(max_bytes: u64, ttl: Duration) -> Self {
        ResultCache {
            cache: Cache::builder()
                .max_capacity(max_bytes)
                .weigher(|_, solved: &Arc<Solved>| solved.weight())
                .time_to_live(ttl)
                .build(),
        }
    }

    pub async fn get(&self, key: &str) -> Option<Arc<Solved>> {
        self.cache.get(key).await
    }

    pub async fn insert(&self, solved: Arc<Solved>) {
        self.cache.insert(solved.key.clone(), solved).await;
    }

    /// The answer under `key`, solved by `solve` if absent. Concurrent calls for the same
    /// absent key run one `solve` and all get its answer or its error; errors are not kept.
    /// The flag says whether this call ran `solve`.
    pub async fn get_or_solve<E, F>(&self, key: String, solve: F) -> Result<(Arc<Solved>, bool), E>
    where
        E: Clone + Send + Sync + 'static,
        F: Future<Output = Result<Arc<Solved>, E>>,
    {
        // A plain lookup first: most calls are hits, and it costs less than the entry API.
        if let Some(solved) = self.cache.get(&key).await {
            return Ok((solved, false));
        }
        let entry = self
            .cache
            .entry(key)
            .or_try_insert_with(solve)
            .await
            .map_err(|e| (*e).clone())?;
        let fresh = entry.is_fresh();
        Ok((entry.into_value(), fresh))
    }
}

#[cfg(test)]
mod tests {
    use super::has_null_value;

    #[test]
    fn a_null_value_is_found_and_a_null_inside_a_string_is_not() {
        assert!(has_null_value(br#"{"a":null}"#));
        assert!(has_null_value(br#"{"a":[1,null]}"#));
        assert!(has_null_value(br#"[null]"#));
        assert!(!has_null_value(br#"{"a":"nullable","b":1}"#));
        assert!(!has_null_value(br#"{"a":"x null"}"#));
    }
}
