//! One memory budget for everything the service keeps between requests (cached answers, the
//! results of finished jobs, the input memo and the solved points of sweeps) and for what
//! its solves hold while they run. Each part is bounded in bytes (estimated, with a fixed
//! overhead per entry), so the process stays within the budget plus a fixed overhead
//! whatever the traffic.

/// The budget's shares, in bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Budget {
    /// Cached answers (9/16).
    pub answers: u64,
    /// The working memory of the solves running (3/16), set aside before they allocate.
    pub solves: u64,
    /// Results kept by finished asynchronous jobs beyond the cache (3/16).
    pub job_results: u64,
    /// The input memo: input text → cache key (1/32).
    pub inputs: u64,
    /// Solved points of sweeps, kept for a retry after a deadline (1/32).
    pub points: u64,
}

impl Budget {
    pub fn split(total: u64) -> Budget {
        let part = |numerator: u64, denominator: u64| total / denominator * numerator;
        Budget {
            answers: part(9, 16),
            solves: part(3, 16),
            job_results: part(3, 16),
            inputs: part(1, 32),
            points: part(1, 32),
        }
    }
}

/// Bytes an entry of a map costs beyond its key and value: the map's own bookkeeping, the
/// allocations' headers, the eviction policy's records (measured for moka at ~200 bytes, and
/// kept as an upper bound for the maps of [`super::bounded`]).
pub const ENTRY_OVERHEAD: u64 = 256;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shares_add_up_to_the_budget() {
        let b = Budget::split(256 << 20);
        assert_eq!(
            b.answers + b.solves + b.job_results + b.inputs + b.points,
            256 << 20
        );
    }
}
