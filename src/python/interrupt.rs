//! Long calls that Ctrl-C stops: the core runs on a thread of its own
//! while the calling thread waits without the GIL and, every
//! `POLL`, takes it to run the interpreter's signal handlers
//! (`PyErr_CheckSignals`). A handler's exception (KeyboardInterrupt for
//! Ctrl-C) cancels the call's `cancel::Token`; the core skips the rest of
//! its work within milliseconds, the thread is joined, and the handler's
//! exception is raised: nothing is left running and the module stays
//! usable.
//!
//! Signal handlers run on the main thread only: a call made from another
//! Python thread waits the same way and is stopped by nothing but its own
//! end (as any Python code there).

use crate::cancel::{self, Token};
use crate::error::Result;
use pyo3::prelude::*;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::Duration;

/// How often the waiting thread looks at the signals: well under the
/// 100 ms a user waits for Ctrl-C to act.
const POLL: Duration = Duration::from_millis(20);

/// Runs `f` without the GIL, stopping it when a signal handler raises.
pub fn run<T: Send>(py: Python<'_>, f: impl FnOnce() -> Result<T> + Send) -> PyResult<T> {
    let token = Token::new();
    let (done_tx, done_rx) = mpsc::channel::<()>();
    std::thread::scope(|s| {
        let t = token.clone();
        let worker = s.spawn(move || {
            // A panic is carried to the calling thread by `join` (the
            // bindings' `errors::guard` turns it into a RuntimeError
            // there); the channel closes either way.
            let r = catch_unwind(AssertUnwindSafe(|| cancel::with(t, f)));
            drop(done_tx);
            r
        });
        let mut raised = None;
        // (The receiver is Send but not Sync: it goes into each wait and
        // comes back.)
        let mut rx = done_rx;
        loop {
            let (got, back) = py.detach(move || (rx.recv_timeout(POLL), rx));
            rx = back;
            match got {
                Err(RecvTimeoutError::Timeout) => {}
                Ok(()) | Err(RecvTimeoutError::Disconnected) => break,
            }
            if raised.is_none() {
                if let Err(e) = py.check_signals() {
                    token.cancel();
                    raised = Some(e);
                }
            }
        }
        let out = match worker.join() {
            Ok(Ok(r)) => r,
            Ok(Err(panic)) | Err(panic) => resume_unwind(panic),
        };
        match raised {
            Some(e) => Err(e),
            None => out.map_err(PyErr::from),
        }
    })
}
