//! Notices when the viewer's scene file is saved (its modification time,
//! looked at four times a second at most). Built-in scenes are not watched.

use hikari_core::scene::builtin;
use std::time::{Duration, Instant, SystemTime};

const INTERVAL: Duration = Duration::from_millis(250);

pub struct SceneWatch {
    spec: String,
    stamp: Option<SystemTime>,
    last_look: Option<Instant>,
}

impl SceneWatch {
    pub fn new(spec: &str) -> Self {
        SceneWatch { spec: spec.to_string(), stamp: modified(spec), last_look: None }
    }

    /// True once per save (a new modification time).
    pub fn changed(&mut self) -> bool {
        let now = Instant::now();
        if self.stamp.is_none() || self.last_look.is_some_and(|t| now - t < INTERVAL) {
            return false;
        }
        self.last_look = Some(now);
        let stamp = modified(&self.spec);
        if stamp.is_none() || stamp == self.stamp {
            return false;
        }
        self.stamp = stamp;
        true
    }
}

/// The modification time of the scene file `spec` (None for built-ins).
fn modified(spec: &str) -> Option<SystemTime> {
    if builtin::source(spec).is_some() {
        return None;
    }
    std::fs::metadata(spec).and_then(|m| m.modified()).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_save_is_seen_once_and_builtins_never() {
        let path = std::env::temp_dir().join(format!("hikari-watch-{}.toml", std::process::id()));
        std::fs::write(&path, "a").unwrap();
        let mut watch = SceneWatch::new(path.to_str().unwrap());
        assert!(!watch.changed());
        let later = SystemTime::now() + Duration::from_secs(5);
        std::fs::File::options().write(true).open(&path).unwrap().set_modified(later).unwrap();
        watch.last_look = None;
        assert!(watch.changed());
        watch.last_look = None;
        assert!(!watch.changed(), "the same save twice");
        let _ = std::fs::remove_file(&path);
        let mut builtin = SceneWatch::new("cornell-box");
        assert!(!builtin.changed());
    }
}
