//! Where an engine keeps answers and job records: in this process (memory and its database),
//! or in a fleet's Redis ([`Storage::in_fleet`]).

use std::sync::Arc;

use super::archive::{Archive, ArchiveError};
use super::budget::Budget;
use super::cache::{MemoryCache, ResultCache};
use super::config::EngineConfig;
use super::fleet::{Fleet, FleetConfig, LinkError, RedisJobStore, Shared, TieredCache};
use super::local::LocalJobStore;
use super::store::{JobStore, MemoryJobStore};

/// Where an engine keeps answers and job records.
#[derive(Clone)]
pub struct Storage {
    pub cache: Arc<dyn ResultCache>,
    pub jobs: Arc<dyn JobStore>,
    /// The fleet, if any: jobs then run on its work stream, not in this process's tasks.
    pub fleet: Option<Arc<Shared>>,
}

impl Storage {
    /// In this process's memory and its database of saved analyses: the default.
    pub fn in_process(config: &EngineConfig) -> Result<Storage, ArchiveError> {
        let budget = Budget::split(config.memory_budget);
        let archive = Archive::open(&config.database, config.history_retention)?;
        let memory = MemoryJobStore::new(
            config.job_retention,
            config.max_jobs,
            budget.job_results,
            archive.durable(),
        );
        Ok(Storage {
            cache: Arc::new(MemoryCache::for_engine(config)),
            jobs: Arc::new(LocalJobStore::new(memory, archive)),
            fleet: None,
        })
    }

    /// In `fleet`: this process's memory in front of Redis for answers, Redis for jobs.
    pub fn in_fleet(config: &EngineConfig, fleet: FleetConfig) -> Result<Storage, LinkError> {
        let fleet = Arc::new(Fleet::open(fleet)?);
        let l1 = MemoryCache::for_engine(config);
        // A fleet's finished jobs are its history: kept in Redis for the history's retention.
        let store = Arc::new(RedisJobStore::new(
            fleet.clone(),
            config.history_retention,
            config.job_deadline,
        ));
        Ok(Storage {
            cache: Arc::new(TieredCache::new(l1, fleet.clone(), config.cache_ttl)),
            jobs: store.clone(),
            fleet: Some(Arc::new(Shared::new(fleet, store))),
        })
    }
}
