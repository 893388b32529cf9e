//! A render on a thread of its own, so that Python keeps its GIL free and
//! Ctrl-C raises `KeyboardInterrupt` at once: the caller waits in slices of
//! 100 ms, checking Python's signals between them. An interrupted render's
//! thread stops after the pass under way and is dropped.

use crate::settings::Request;
use hikari_core::progress::Silent;
use hikari_core::render::Image;
use hikari_core::render::aov::Aovs;
use hikari_core::scene::Scene;
use hikari_engine::{Log, PassReport, Session};
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender, sync_channel};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// What the thread sends: a pass (with the mean so far where asked), the
/// end, or a failure.
pub enum Message {
    Pass(PassReport, Option<Image>, Option<f64>),
    /// The image, and its AOVs where asked for.
    Done(Image, Option<Aovs>),
    Failed(String),
}

pub struct Worker {
    /// Behind a lock only because waiting without the GIL needs it Sync.
    receiver: Mutex<Receiver<Message>>,
    stop: Arc<AtomicBool>,
    notes: Arc<Mutex<Vec<String>>>,
}

impl Worker {
    /// Starts rendering `scene` (posed and checked: `scene::posed`) as `request` says; `each_image`: send the
    /// mean after every pass (an iterator of passes), else only at the end.
    pub fn start(scene: Arc<Scene>, request: Request, each_image: bool) -> Worker {
        // One pass ahead at most: a consumer that stops reading stops the passes.
        let (sender, receiver) = sync_channel(1);
        let stop = Arc::new(AtomicBool::new(false));
        let (log, notes) = Log::collected();
        let flag = stop.clone();
        std::thread::spawn(move || {
            let run = || render(&scene, request, each_image, log, flag, &sender);
            if let Err(e) = run() {
                let _ = sender.send(Message::Failed(format!("{e:#}")));
            }
        });
        Worker { receiver: Mutex::new(receiver), stop, notes }
    }

    /// The next message, waiting without the GIL; Ctrl-C (any pending
    /// Python signal) stops the render and raises.
    pub fn next(&self, py: Python<'_>) -> PyResult<Option<Message>> {
        loop {
            let got = py.detach(|| {
                let receiver = self.receiver.lock().unwrap_or_else(|e| e.into_inner());
                receiver.recv_timeout(Duration::from_millis(100))
            });
            match got {
                Ok(message) => return Ok(Some(message)),
                Err(RecvTimeoutError::Disconnected) => return Ok(None),
                Err(RecvTimeoutError::Timeout) => {
                    if let Err(e) = py.check_signals() {
                        self.stop.store(true, Ordering::SeqCst);
                        return Err(e);
                    }
                }
            }
        }
    }

    /// The engine's notes so far (which renderer, fallbacks and why), taken.
    pub fn take_notes(&self) -> Vec<String> {
        std::mem::take(&mut *self.notes.lock().unwrap_or_else(|e| e.into_inner()))
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
    }
}

fn render(
    scene: &Scene,
    request: Request,
    each_image: bool,
    log: Log,
    stop: Arc<AtomicBool>,
    sender: &SyncSender<Message>,
) -> anyhow::Result<()> {
    let go = || -> anyhow::Result<()> {
        let mut session = Session::new(scene, request.settings, request.plan, log, &Silent)?.interrupt_on(stop);
        while let Some(report) = session.next_pass()? {
            if each_image {
                let image = session.image()?;
                let noise = report.noise;
                if sender.send(Message::Pass(report, Some(image), noise)).is_err() {
                    return Ok(());
                }
            }
        }
        let outcome = session.finish()?;
        let aovs = request.aovs.then(|| hikari_core::render::aov::render_aovs(scene));
        let _ = sender.send(Message::Done(outcome.image, aovs));
        Ok(())
    };
    match request.threads {
        None => go(),
        Some(n) => rayon::ThreadPoolBuilder::new().num_threads(n).build()?.install(go),
    }
}
