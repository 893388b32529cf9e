//! Fresh photon sets for the viewer's running mean, traced on a background
//! thread (all cores, through rayon) so a frame never waits for tracing.

use anyhow::{Result, anyhow};
use hikari_core::photon::{TraceSettings, TracedPhotons, trace_photons};
use hikari_core::scene::Scene;
use std::sync::mpsc::{Receiver, TryRecvError, sync_channel};

/// Sets k = 1, 2, … of a scene, traced with seed + k, at most one ahead of
/// the window. The thread ends when this is dropped (its next send fails).
pub struct PhotonSets {
    receiver: Receiver<TracedPhotons>,
}

impl PhotonSets {
    pub fn start(scene: Scene, photons: u64, seed: u64) -> Result<Self> {
        let (sender, receiver) = sync_channel(1);
        std::thread::Builder::new()
            .name("photon sets".into())
            .spawn(move || {
                for k in 1.. {
                    let settings = TraceSettings { photons, seed: seed.wrapping_add(k), ..Default::default() };
                    let traced = trace_photons(&scene, &settings, &hikari_core::progress::Silent);
                    if sender.send(traced).is_err() {
                        return; // the window closed, or the scene was reloaded
                    }
                }
            })
            .map_err(|e| anyhow!("cannot start the photon-tracing thread: {e}"))?;
        Ok(PhotonSets { receiver })
    }

    /// The next set: waited for when `wait`, else only if it is ready.
    pub fn next(&self, wait: bool) -> Result<Option<TracedPhotons>> {
        let stopped = || anyhow!("the photon-tracing thread stopped");
        if wait {
            return self.receiver.recv().map(Some).map_err(|_| stopped());
        }
        match self.receiver.try_recv() {
            Ok(traced) => Ok(Some(traced)),
            Err(TryRecvError::Empty) => Ok(None),
            Err(TryRecvError::Disconnected) => Err(stopped()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_follow_the_seeds_in_order() {
        let scene = || Scene::load("cornell-box").unwrap();
        let sets = PhotonSets::start(scene(), 500, 7).unwrap();
        for k in 1..=3u64 {
            let got = sets.next(true).unwrap().unwrap();
            let want = trace_photons(
                &scene(),
                &TraceSettings { photons: 500, seed: 7 + k, ..Default::default() },
                &hikari_core::progress::Silent,
            );
            let bits = |t: &TracedPhotons| t.global.iter().map(|p| p.position.map(f32::to_bits)).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&want), "set {k}");
        }
    }
}
