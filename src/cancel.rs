//! Stopping a call its caller no longer wants: Ctrl-C in Python (the
//! bindings poll the interpreter's signals while the core runs, and cancel
//! the call's token), or any Rust caller's own reason.
//!
//! A call runs under one `Token` (`with`). Its long parallel loops (the
//! shadow rays, the gather kernels, PCSS, the BVH build's parallel nodes)
//! read the token once on the thread that starts them (`current`: it is
//! thread-local, and rayon's workers do not inherit it) and skip every chunk
//! that starts after it was cancelled; chunks are a few milliseconds of
//! work, so a cancelled call ends within about that. What the skipped chunks
//! leave is never returned: `threads::run_capped`, which every entry of
//! `api.rs` runs its work in, checks the token when the work returns and
//! gives `Error::Interrupted` instead of the result.
//!
//! Nothing is shared between calls: cancelling one call's token stops that
//! call only, and the next call starts clean.

use crate::error::{Error, Result};
use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// One call's cancellation flag; clones share it.
#[derive(Clone, Debug, Default)]
pub struct Token(Option<Arc<AtomicBool>>);

impl Token {
    /// A token that can be cancelled.
    pub fn new() -> Token {
        Token(Some(Arc::new(AtomicBool::new(false))))
    }

    /// Asks the call running under this token to stop.
    pub fn cancel(&self) {
        if let Some(f) = &self.0 {
            f.store(true, Ordering::Relaxed);
        }
    }

    /// Whether the call was asked to stop (never for the default token).
    #[inline]
    pub fn is_cancelled(&self) -> bool {
        self.0.as_ref().is_some_and(|f| f.load(Ordering::Relaxed))
    }

    /// `Error::Interrupted` once cancelled.
    pub fn check(&self) -> Result<()> {
        if self.is_cancelled() {
            Err(Error::Interrupted)
        } else {
            Ok(())
        }
    }
}

thread_local! {
    static CURRENT: RefCell<Token> = RefCell::new(Token::default());
}

/// The token of the call running on this thread (the default, never
/// cancelled, outside `with`).
pub fn current() -> Token {
    CURRENT.with(|c| c.borrow().clone())
}

/// Runs `f` under `token` on this thread, restoring the previous token after
/// (also when `f` panics: the guard's drop restores it).
pub fn with<T>(token: Token, f: impl FnOnce() -> T) -> T {
    struct Restore(Option<Token>);
    impl Drop for Restore {
        fn drop(&mut self) {
            if let Some(t) = self.0.take() {
                CURRENT.with(|c| *c.borrow_mut() = t);
            }
        }
    }
    let previous = CURRENT.with(|c| std::mem::replace(&mut *c.borrow_mut(), token));
    let _restore = Restore(Some(previous));
    f()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    #[test]
    fn a_cancelled_call_skips_its_chunks_and_says_so() {
        let t = Token::new();
        let done = std::sync::atomic::AtomicUsize::new(0);
        let r = with(t.clone(), || {
            let stop = current();
            (0..1000).into_par_iter().for_each(|i| {
                if i == 10 {
                    stop.cancel();
                }
                if !stop.is_cancelled() {
                    done.fetch_add(1, Ordering::Relaxed);
                }
            });
            current().check()
        });
        assert_eq!(r, Err(Error::Interrupted));
        assert!(done.load(Ordering::Relaxed) < 1000);
        // The thread's token is back to the default, never cancelled.
        assert_eq!(current().check(), Ok(()));
        // Another call's token is its own.
        assert_eq!(with(Token::new(), || current().check()), Ok(()));
    }
}
