//! One admission at a time per tenant: a quota of unfinished jobs is a count and then an
//! insert, and two submissions between them both pass it (20 concurrent submissions under
//! `--quota-jobs 2` let 5 in). The count and the insert are made under a lock of the
//! tenant's: in this process an async mutex, and in a fleet also a lock in the job store's
//! Redis (`SET NX` with a lease, freed by its holder), so that processes take turns too.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use tokio::sync::OwnedMutexGuard;

use super::error::EngineError;
use super::fleet::Fleet;
use super::lock;

/// The longest a fleet's lock is held if its holder dies: far longer than a count and an
/// insert take.
const LEASE: Duration = Duration::from_secs(10);

/// How long an admission waits for another process's turn before it is refused.
const PATIENCE: Duration = Duration::from_secs(5);

#[derive(Default)]
pub struct Admissions {
    local: Mutex<HashMap<String, Arc<tokio::sync::Mutex<()>>>>,
}

/// A tenant's turn to admit a job: held until the job is in the store, or refused.
pub struct Turn {
    _local: OwnedMutexGuard<()>,
    fleet: Option<(Arc<Fleet>, String, String)>,
}

impl Drop for Turn {
    fn drop(&mut self) {
        // Outside a runtime (none to free it on) the lease runs out by itself.
        let runtime = tokio::runtime::Handle::try_current();
        let (Ok(runtime), Some((fleet, key, token))) = (runtime, self.fleet.take()) else {
            return;
        };
        runtime.spawn(async move {
            if let Err(e) = fleet.jobs.delete_if_held(&key, &token).await {
                tracing::warn!(error = %e.why, "a tenant's admission lock waits out its lease");
            }
        });
    }
}

impl Admissions {
    /// `tenant`'s turn: after the admissions of its before it, here and in `fleet`.
    pub async fn turn(
        &self,
        tenant: &str,
        fleet: Option<&Arc<Fleet>>,
    ) -> Result<Turn, EngineError> {
        let mutex = lock(&self.local)
            .entry(tenant.to_string())
            .or_default()
            .clone();
        let mut turn = Turn {
            _local: mutex.lock_owned().await,
            fleet: None,
        };
        forget_idle(&mut lock(&self.local));
        let Some(fleet) = fleet else {
            return Ok(turn);
        };
        let key = format!("thirdbody:admitting:{tenant}");
        let token = uuid::Uuid::new_v4().to_string();
        let mut set = redis::cmd("SET");
        set.arg(&key)
            .arg(&token)
            .arg("NX")
            .arg("PX")
            .arg(LEASE.as_millis() as u64);
        let start = Instant::now();
        loop {
            let taken: Option<String> = fleet
                .jobs
                .query(&set)
                .await
                .map_err(|e| EngineError::Unavailable(e.why))?;
            if taken.is_some() {
                turn.fleet = Some((fleet.clone(), key, token));
                return Ok(turn);
            }
            if start.elapsed() > PATIENCE {
                return Err(EngineError::Unavailable(format!(
                    "another process of the fleet has been admitting this tenant's jobs for \
                     {} s: try again",
                    PATIENCE.as_secs()
                )));
            }
            tokio::time::sleep(Duration::from_millis(5)).await;
        }
    }
}

/// Forgets the locks nobody holds or waits for, so that the map stays as small as the
/// tenants admitting now.
fn forget_idle(locks: &mut HashMap<String, Arc<tokio::sync::Mutex<()>>>) {
    if locks.len() > 64 {
        locks.retain(|_, mutex| Arc::strong_count(mutex) > 1);
    }
}
