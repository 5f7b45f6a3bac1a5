//! How many worker threads a call may use. rayon's global pool takes every
//! core; a dataset worker on a shared machine must not. `threads=` caps one
//! call, `SOFTSHADOW_THREADS` every call of the process that gives none; with
//! neither, the global pool runs it. Results do not depend on the count (no
//! kernel splits a sum across threads), so a cap changes time, not bits.
//!
//! Pools are built once per count and kept: building one costs a thread
//! spawn per worker, too much per call.

use crate::cancel;
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// The environment variable that caps the threads of every call.
pub const ENV_THREADS: &str = "SOFTSHADOW_THREADS";
/// The most threads one call may ask for.
pub const MAX_THREADS: usize = 1024;

/// `threads=` checked: 1 to MAX_THREADS.
pub fn check_threads(arg: &str, n: i64) -> Result<usize> {
    if (1..=MAX_THREADS as i64).contains(&n) {
        Ok(n as usize)
    } else {
        Err(Error::invalid(
            arg,
            format!("must be in [1, {MAX_THREADS}] worker threads, got {n}"),
        ))
    }
}

/// The cap for a call: `threads`, else `SOFTSHADOW_THREADS`, else none.
pub fn resolve(threads: Option<i64>) -> Result<Option<usize>> {
    if let Some(n) = threads {
        return check_threads("threads", n).map(Some);
    }
    match std::env::var(ENV_THREADS) {
        Err(_) => Ok(None),
        Ok(s) if s.trim().is_empty() => Ok(None),
        Ok(s) => match s.trim().parse::<i64>() {
            Ok(n) => check_threads(ENV_THREADS, n).map(Some),
            Err(_) => Err(Error::invalid(
                ENV_THREADS,
                format!("must be a whole number of threads, got {s:?}"),
            )),
        },
    }
}

fn pool(n: usize) -> Result<Arc<rayon::ThreadPool>> {
    static POOLS: OnceLock<Mutex<HashMap<usize, Arc<rayon::ThreadPool>>>> = OnceLock::new();
    let mut pools = POOLS
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    if let Some(p) = pools.get(&n) {
        return Ok(p.clone());
    }
    let p = rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .thread_name(|i| format!("softshadow-{i}"))
        .build()
        .map_err(|e| Error::invalid("threads", format!("cannot start {n} threads: {e}")))?;
    let p = Arc::new(p);
    pools.insert(n, p.clone());
    Ok(p)
}

/// Runs `f` on at most `cap` worker threads (the global pool for `None`) and
/// returns its result with the number of threads it could use, or
/// `Error::Interrupted` where the call's `cancel::Token` was cancelled
/// while `f` ran (what `f` returns then may be partial: its loops skipped
/// their chunks). The token goes with `f` onto the pool's thread.
pub fn run_capped<T: Send>(
    cap: Option<usize>,
    f: impl FnOnce() -> Result<T> + Send,
) -> Result<(T, usize)> {
    let token = cancel::current();
    let out = match cap {
        None => (f()?, rayon::current_num_threads()),
        Some(n) => {
            let p = pool(n)?;
            let t = token.clone();
            p.install(|| cancel::with(t, || Ok::<_, Error>((f()?, rayon::current_num_threads()))))?
        }
    };
    token.check()?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cap_runs_on_that_many_threads() {
        let ((), n) = run_capped(Some(1), || Ok(())).unwrap();
        assert_eq!(n, 1);
        let (seen, n) = run_capped(Some(3), || Ok(rayon::current_num_threads())).unwrap();
        assert_eq!((seen, n), (3, 3));
        assert!(check_threads("threads", 0).is_err());
        assert!(check_threads("threads", MAX_THREADS as i64 + 1).is_err());
    }
}
