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
/// (1 024 samples, 512² maps) most tile visits end there; charged in full
/// they counted 2.0e8 for a 1.7 s call, counted so 6.0e7. The prediction
/// (`work::visits_bound`) decides how fine a fitted map may be; this
/// decides whether a call finishes. A call's count does not depend on the
/// order its groups run in (each group's visits are its own), so whether
/// the total passes the limit, and hence the refusal, is the same on every
/// run and thread count; once it has passed, the remaining groups are
/// skipped (how many ran first is not deterministic, so nothing but the
/// refusal is read from them).
pub struct Meter {
    done: AtomicU64,
    limit: u64,
}

impl Meter {
    /// Adds a group's visits.
    #[inline]
    pub(super) fn charge(&self, visits: u64) {
        self.done.fetch_add(visits, Ordering::Relaxed);
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
pub fn metered<T>(limit: u64, f: impl FnOnce() -> T) -> (T, u64) {
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
    });
    let previous = METER.with(|c| c.borrow_mut().replace(meter.clone()));
    let restore = Restore(Some(previous));
    let out = f();
    drop(restore);
    (out, meter.done.load(Ordering::Relaxed))
}
