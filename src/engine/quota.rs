//! Quotas of work: the points a tenant may ask to be computed in a minute (a sweep's points,
//! a figure's, one for a single contact or a fit), counted in fixed windows of a minute, in
//! this process's memory or, in a fleet, in the job store's Redis, so that every process of
//! the fleet counts the same. Who a tenant is and what it may use is the caller's to say.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, SystemTime};

use super::clock::unix_millis;
use super::fleet::Fleet;
use super::lock;
use crate::job::Cost;

const WINDOW: Duration = Duration::from_secs(60);

/// A charge refused: what the tenant used in the window, and when the window ends (none if
/// the charge alone is over the limit: waiting cannot help).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Exceeded {
    pub used: u64,
    pub retry_after: Option<Duration>,
}

/// Points charged to a tenant before its work, to true up after it ([`PointCounts::true_up`])
/// if they were a guess at its iterations, or to give back if the work is refused after all.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Charge {
    pub tenant: String,
    pub points: u64,
    pub window: u64,
    /// Whether the points guessed at an iterative job's work (a fit's), which its time then
    /// settles; else they are the work's own measure, the same whatever the machine.
    pub guessed: bool,
}

/// The points charged to each tenant in the current window.
pub struct PointCounts {
    /// Tenant → (window, points), without a fleet (or its Redis).
    local: Mutex<HashMap<String, (u64, u64)>>,
    fleet: Option<Arc<Fleet>>,
}

impl PointCounts {
    pub fn new(fleet: Option<Arc<Fleet>>) -> PointCounts {
        PointCounts {
            local: Mutex::new(HashMap::new()),
            fleet,
        }
    }

    /// Charges `points` to `tenant` in the window of `now` within `limit`; the window.
    pub async fn charge(
        &self,
        tenant: &str,
        points: u64,
        limit: u64,
        now: SystemTime,
    ) -> Result<u64, Exceeded> {
        let since = unix_millis(now) / 1000;
        let window = since / WINDOW.as_secs();
        let retry_after = Duration::from_secs(WINDOW.as_secs() - since % WINDOW.as_secs());
        if points > limit {
            return Err(Exceeded {
                used: 0,
                retry_after: None,
            });
        }
        let shared = match &self.fleet {
            Some(fleet) => charge_fleet(fleet, tenant, window, points, limit).await,
            None => None,
        };
        match shared.unwrap_or_else(|| self.charge_here(tenant, window, points, limit)) {
            Ok(()) => Ok(window),
            Err(used) => Err(Exceeded {
                used,
                retry_after: Some(retry_after),
            }),
        }
    }

    /// Trues up `charge`, if it was a guess, by what the work `took` ([`Cost::of_time`]).
    pub async fn true_up(&self, charge: &Charge, took: Duration) {
        if !charge.guessed {
            return;
        }
        let took = i64::try_from(Cost::of_time(took)).unwrap_or(i64::MAX);
        let charged = i64::try_from(charge.points).unwrap_or(i64::MAX);
        self.adjust(&charge.tenant, took - charged, charge.window)
            .await;
    }

    /// Gives back `charge`: its work was refused after all.
    pub async fn refund(&self, charge: &Charge) {
        let charged = i64::try_from(charge.points).unwrap_or(i64::MAX);
        self.adjust(&charge.tenant, -charged, charge.window).await;
    }

    /// Adds `delta` points (fewer, if negative) to `tenant`'s charge in `window`, whatever
    /// its limit (the work is done).
    pub async fn adjust(&self, tenant: &str, delta: i64, window: u64) {
        if delta == 0 {
            return;
        }
        if let Some(fleet) = &self.fleet {
            if add(fleet, &key(tenant, window), delta).await.is_some() {
                return;
            }
        }
        let mut counts = lock(&self.local);
        // A window gone by is not counted any more: nothing to true up there.
        if let Some(count) = counts.get_mut(tenant).filter(|c| c.0 == window) {
            count.1 = count.1.saturating_add_signed(delta);
        }
    }

    /// In this process; the points used before, if refused.
    fn charge_here(&self, tenant: &str, window: u64, points: u64, limit: u64) -> Result<(), u64> {
        let mut counts = lock(&self.local);
        let count = counts.entry(tenant.to_string()).or_insert((window, 0));
        if count.0 != window {
            *count = (window, 0);
        }
        if count.1 + points > limit {
            return Err(count.1);
        }
        count.1 += points;
        Ok(())
    }
}

/// In the fleet's Redis (added, then taken back if over the limit); `None` if it cannot be
/// reached (this process then counts alone: a quota is not a reason to refuse work).
async fn charge_fleet(
    fleet: &Fleet,
    tenant: &str,
    window: u64,
    points: u64,
    limit: u64,
) -> Option<Result<(), u64>> {
    let key = key(tenant, window);
    let used = add(fleet, &key, i64::try_from(points).unwrap_or(i64::MAX)).await?;
    // A count trued up below nought (a refund that passed a later charge) is nought.
    let used = u64::try_from(used).unwrap_or(0);
    if used <= limit {
        return Some(Ok(()));
    }
    let give_back = redis::Cmd::decr(&key, points);
    let _ = fleet.jobs.query::<i64>(&give_back).await;
    Some(Err(used - points))
}

fn key(tenant: &str, window: u64) -> String {
    format!("thirdbody:quota:{tenant}:{window}")
}

/// Adds `delta` to the count under `key` in the fleet's Redis, which keeps it two windows:
/// the count then, or `None` if Redis cannot be reached.
async fn add(fleet: &Fleet, key: &str, delta: i64) -> Option<i64> {
    let mut pipe = redis::pipe();
    pipe.atomic()
        .incr(key, delta)
        .expire(key, 2 * WINDOW.as_secs() as i64)
        .ignore();
    let (count,): (i64,) = fleet.jobs.pipe(&pipe).await.ok()?;
    Some(count)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A charge is trued up in the window it was charged in: a refund makes room, work beyond
    /// the estimate takes it (past the limit, even: the work is done); a window gone by is
    /// not counted any more.
    #[tokio::test]
    async fn a_tenant_gets_its_points_per_window_and_a_charge_is_trued_up_in_it() {
        let counts = PointCounts::new(None);
        let at = |s: u64| std::time::UNIX_EPOCH + Duration::from_secs(s);
        // 60 000 s is the start of a window; 10 points a window.
        assert_eq!(counts.charge("a", 6, 10, at(60_000)).await, Ok(1000));
        assert_eq!(counts.charge("a", 4, 10, at(60_010)).await, Ok(1000));
        assert_eq!(
            counts.charge("a", 1, 10, at(60_015)).await,
            Err(Exceeded {
                used: 10,
                retry_after: Some(Duration::from_secs(45))
            })
        );
        // Another tenant counts apart; the next window starts afresh.
        assert_eq!(counts.charge("b", 10, 10, at(60_015)).await, Ok(1000));
        assert_eq!(counts.charge("a", 10, 10, at(60_060)).await, Ok(1001));
        // More than the limit at once: waiting cannot help.
        let alone = counts.charge("c", 11, 10, at(60_000)).await;
        assert_eq!(alone.unwrap_err().retry_after, None);

        let window = counts.charge("d", 8, 10, at(60_000)).await.unwrap();
        counts.adjust("d", -6, window).await;
        assert_eq!(counts.charge("d", 8, 10, at(60_002)).await, Ok(window));
        counts.adjust("d", 5, window).await;
        let over = counts.charge("d", 1, 10, at(60_004)).await.unwrap_err();
        assert_eq!(over.used, 15);
        counts.adjust("d", -100, window - 1).await;
        let over = counts.charge("d", 1, 10, at(60_005)).await.unwrap_err();
        assert_eq!(over.used, 15);
        counts.adjust("e", -5, window).await;
        assert_eq!(counts.charge("e", 10, 10, at(60_006)).await, Ok(window));
    }
}
