//! Heavy work (solving, parsing large bodies, drawing, reading and writing the database) runs on
//! tokio's blocking threads, and at a lower scheduling priority than the async threads
//! that accept connections and answer `/healthz`. On a machine with few cores the two
//! compete: under a burst of 100 clients each sending a 70 kB sweep, two threads parsing
//! at equal priority delayed a `/healthz` probe by up to 75 ms; below the async threads,
//! the heavy work still gets every core nobody else wants, but yields to the light work
//! that keeps the service answering.

use tokio::task::JoinError;

/// How much lower than the async threads heavy work runs (a nice value: 10 gives the async
/// threads about ten times the heavy threads' share when both want a core).
#[cfg_attr(not(target_os = "linux"), allow(dead_code))]
const NICENESS: i32 = 10;

/// Runs `work` on a blocking thread below the async threads' priority.
pub async fn run<T: Send + 'static>(
    work: impl FnOnce() -> T + Send + 'static,
) -> Result<T, JoinError> {
    tokio::task::spawn_blocking(move || {
        lower_priority();
        work()
    })
    .await
}

/// Puts the calling thread in the idle class (`SCHED_IDLE`): a thread lent to a running
/// job ([`crate::job::Control::with_lent_threads`]) beside the solver threads the pool
/// counts, which takes a core only when no other thread wants it, and gives it up at once
/// when one does.
pub fn lent_thread() {
    // SAFETY: gettid takes nothing; sched_setscheduler reads the parameter it is given for
    // the call's duration; a failure only leaves the thread as it was.
    #[cfg(target_os = "linux")]
    unsafe {
        let idle = libc::sched_param { sched_priority: 0 };
        libc::sched_setscheduler(libc::gettid(), libc::SCHED_IDLE, &idle);
    }
}

/// Lowers the calling thread's priority, once per thread (a thread cannot raise it again
/// without privileges, and need not). On Linux the nice value is the calling thread's own
/// (NPTL), not the process's; a thread starts with its creator's.
fn lower_priority() {
    thread_local! {
        static LOWERED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    }
    if LOWERED.with(|lowered| lowered.replace(true)) {
        return;
    }
    // SAFETY: gettid, getpriority and setpriority take no pointers; a failure only leaves
    // the priority as it was.
    #[cfg(target_os = "linux")]
    unsafe {
        let thread = libc::gettid() as libc::id_t;
        let now = libc::getpriority(libc::PRIO_PROCESS, thread);
        libc::setpriority(libc::PRIO_PROCESS, thread, (now + NICENESS).min(19));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(target_os = "linux")]
    fn own_niceness() -> i32 {
        // SAFETY: as in lower_priority.
        unsafe { libc::getpriority(libc::PRIO_PROCESS, libc::gettid() as libc::id_t) }
    }

    #[cfg(target_os = "linux")]
    #[tokio::test]
    async fn heavy_work_runs_below_the_async_threads() {
        let caller = own_niceness();
        let heavy = run(own_niceness).await.expect("the work ran");
        assert_eq!(heavy, (caller + NICENESS).min(19));
        assert_eq!(
            own_niceness(),
            caller,
            "the async thread keeps its priority"
        );
    }
}
