//! Where an engine keeps answers and job records: in this process (memory and its database),
//! or in a fleet's Redis ([`super::fleet::storage`]).

use std::sync::Arc;

use super::archive::{Archive, ArchiveError};
use super::budget::Budget;
use super::cache::{MemoryCache, ResultCache};
use super::config::EngineConfig;
use super::fleet::Shared;
use super::local::LocalJobStore;
use super::store::{JobStore, MemoryJobStore};

/// Where an engine keeps answers and job records.
#[derive(Clone)]
pub struct Storage {
    pub cache: Arc<dyn ResultCache>,
    pub jobs: Arc<dyn JobStore>,
    /// The fleet the engine works in, if any ([`super::fleet`]): its jobs then run on the
    /// fleet's work stream, not in this process's tasks.
    pub fleet: Option<Arc<Shared>>,
}

impl Storage {
    /// In this process's memory, within `config`'s bounds, and its database of saved
    /// analyses (which keeps the results beyond the memory budget too, if it is a file): the
    /// default. Fails if the database cannot be opened.
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
}
