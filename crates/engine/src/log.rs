//! Where the engine's one-line notes go: which renderer runs, a fallback
//! and why, what the photons and passes took. The CLI prints them to
//! stderr; other front ends (Python, the Blender add-on) keep or forward them.

use std::sync::{Arc, Mutex};

/// A sink for notes, cheap to clone and safe to send to a tracing thread.
#[derive(Clone)]
pub struct Log(Arc<dyn Fn(&str) + Send + Sync>);

impl Log {
    /// Each note as a line on stderr.
    pub fn stderr() -> Self {
        Log(Arc::new(|line| eprintln!("{line}")))
    }

    /// Notes handed to `f`.
    pub fn to(f: impl Fn(&str) + Send + Sync + 'static) -> Self {
        Log(Arc::new(f))
    }

    /// Notes kept in memory, and the list they are kept in.
    pub fn collected() -> (Self, Arc<Mutex<Vec<String>>>) {
        let lines = Arc::new(Mutex::new(Vec::new()));
        let kept = lines.clone();
        (Log::to(move |line| kept.lock().unwrap_or_else(|e| e.into_inner()).push(line.to_string())), lines)
    }

    pub fn note(&self, line: &str) {
        (self.0)(line)
    }
}

impl Default for Log {
    fn default() -> Self {
        Log::stderr()
    }
}

impl std::fmt::Debug for Log {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Log")
    }
}
