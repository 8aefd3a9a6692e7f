//! Times as the engine stores and shares them, in whole milliseconds (since the Unix epoch):
//! one way for the database, the fleet's Redis and the memory store.

use std::time::{Duration, SystemTime};

/// `time` in milliseconds since the Unix epoch: how times are stored and shared.
pub fn unix_millis(time: SystemTime) -> u64 {
    let since = age(std::time::UNIX_EPOCH, time);
    u64::try_from(since.as_millis()).unwrap_or(u64::MAX)
}

/// The time `unix_ms` milliseconds after the Unix epoch.
pub fn from_unix_millis(unix_ms: u64) -> SystemTime {
    std::time::UNIX_EPOCH + Duration::from_millis(unix_ms)
}

/// How long before `now` the time `then` was (none if it is not before).
pub fn age(then: SystemTime, now: SystemTime) -> Duration {
    now.duration_since(then).unwrap_or_default()
}

/// `duration` in whole milliseconds, at least one.
pub fn millis(duration: Duration) -> u64 {
    u64::try_from(duration.as_millis())
        .unwrap_or(u64::MAX)
        .max(1)
}
