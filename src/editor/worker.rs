//! Rig builds (trace, mesh, weights) on a background thread, so the editor never blocks.
//!
//! In: the document's [`RigInputs`]. Out: progress (parts done of total), a cancel switch, and
//! the built [`Scene`] with the key of the inputs it was built from, for
//! [`crate::document::Command::SetRig`].

use crate::document::{compute_rig, DocumentError, RigInputs, RigInputsKey};
use crate::pipeline::Scene;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{self, Receiver, TryRecvError};
use std::sync::Arc;

/// A rig build under way.
pub struct Worker {
    cancel: Arc<AtomicBool>,
    done: Arc<AtomicUsize>,
    total: usize,
    result: Receiver<Result<Scene, DocumentError>>,
    /// The inputs being built from.
    pub key: RigInputsKey,
}

impl Worker {
    /// Starts building; `wake` is called from the worker thread after each part and at the end
    /// (the editor asks egui for a repaint there).
    pub fn start(inputs: RigInputs, dir: PathBuf, wake: impl Fn() + Send + 'static) -> Self {
        let cancel = Arc::new(AtomicBool::new(false));
        let done = Arc::new(AtomicUsize::new(0));
        let (send, result) = mpsc::channel();
        let key = inputs.key();
        let total = inputs.layers.len();
        let (thread_cancel, thread_done) = (cancel.clone(), done.clone());
        std::thread::spawn(move || {
            let built = compute_rig(&inputs, &dir, &thread_cancel, &mut |parts_done, _| {
                thread_done.store(parts_done, Ordering::Relaxed);
                wake();
            });
            // The editor may have been closed meanwhile; then nobody wants the result.
            let _ = send.send(built);
            wake();
        });
        Worker {
            cancel,
            done,
            total,
            result,
            key,
        }
    }

    /// Asks the build to stop before its next part.
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// Parts done and parts in all; does not take the result.
    pub fn progress(&self) -> (usize, usize) {
        (self.done.load(Ordering::Relaxed), self.total)
    }

    /// Takes the result once the build has finished; `None` while it runs.
    pub fn poll(&self) -> Option<Result<Scene, DocumentError>> {
        match self.result.try_recv() {
            Ok(result) => Some(result),
            Err(TryRecvError::Empty) => None,
            // The thread ended without a word: it can only have been torn down.
            Err(TryRecvError::Disconnected) => Some(Err(DocumentError::Cancelled)),
        }
    }
}
