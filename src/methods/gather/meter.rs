//! Counting a gather kernel's visits as it makes them, against a limit
//! (`metered`): what stops a call whose cost no answer needs
//! (`methods::bounded`, with the limit of `work::visit_limit`).

use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// The visits a running kernel has made, counted where it makes them
/// (`traverse.rs` `add_row`: one a row, one a texel shaded lane by lane or
/// shaded for a whole tile where the method did its work, an eighth where
/// it found early that the micro-patch reaches no lane), against the most
/// it may make. Counting that early exit matters: on the fence's light view
/// (1 024 samples, 512² maps) most tile visits end there, and charged in
/// full they counted 3.3x the visits that cost the time. The prediction (`work::visits_bound`)
/// decides how fine a fitted map may be; this decides whether a call
/// finishes. The
/// count of a call does not depend on the order its groups run in (each
/// group's visits are its own), so whether the total passes the limit, and
/// hence the refusal, is the same on every run and thread count; once it
/// has passed, the kernel's remaining groups are skipped.
pub struct Meter {
    done: AtomicU64,
    limit: u64,
    /// Groups of receivers shaded, and to shade (the kernels' own counts):
    /// what the total of a stopped call is estimated from.
    groups: AtomicU64,
    groups_planned: AtomicU64,
}

/// What `metered` counted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Count {
    pub visits: u64,
    /// The visits the whole call would have made, estimated from the
    /// groups shaded where it was stopped (`visits` where it finished).
    pub estimated: f64,
}

impl Meter {
    /// Adds a group's visits.
    #[inline]
    pub(super) fn charge(&self, visits: u64) {
        self.done.fetch_add(visits, Ordering::Relaxed);
        self.groups.fetch_add(1, Ordering::Relaxed);
    }

    /// Adds the groups a kernel is about to shade.
    pub(super) fn plan(&self, groups: usize) {
        self.groups_planned
            .fetch_add(groups as u64, Ordering::Relaxed);
    }

    /// Whether the visits so far passed the limit.
    #[inline]
    pub(super) fn over(&self) -> bool {
        self.done.load(Ordering::Relaxed) > self.limit
    }
}

thread_local! {
    static METER: RefCell<Option<Arc<Meter>>> = const { RefCell::new(None) };
}

/// The meter of the `metered` call running on this thread, read where a
/// kernel is made (rayon's workers do not inherit it, as `cancel::current`).
pub(crate) fn current_meter() -> Option<Arc<Meter>> {
    METER.with(|m| m.borrow().clone())
}

/// Runs `f` with every gather kernel it makes on this thread counting its
/// visits against `limit`; returns what `f` returns and the visits counted
/// (over `limit` when the kernels stopped early: the result is partial).
pub fn metered<T>(limit: u64, f: impl FnOnce() -> T) -> (T, Count) {
    struct Restore(Option<Option<Arc<Meter>>>);
    impl Drop for Restore {
        fn drop(&mut self) {
            if let Some(m) = self.0.take() {
                METER.with(|c| *c.borrow_mut() = m);
            }
        }
    }
    let meter = Arc::new(Meter {
        done: AtomicU64::new(0),
        limit,
        groups: AtomicU64::new(0),
        groups_planned: AtomicU64::new(0),
    });
    let previous = METER.with(|c| c.borrow_mut().replace(meter.clone()));
    let restore = Restore(Some(previous));
    let out = f();
    drop(restore);
    let visits = meter.done.load(Ordering::Relaxed);
    let groups = meter.groups.load(Ordering::Relaxed).max(1) as f64;
    let planned = meter.groups_planned.load(Ordering::Relaxed) as f64;
    let estimated = if visits > limit {
        visits as f64 * (planned / groups).max(1.0)
    } else {
        visits as f64
    };
    (out, Count { visits, estimated })
}
