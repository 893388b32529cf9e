//! The viewer's photon tracer: a background thread that traces photon sets
//! on request (all cores, through rayon), so a frame never waits for
//! tracing. A request names a pose of the scene (time and edits), a photon
//! count and a seed; the thread always takes the newest request waiting,
//! poses the scene (rebuilding its BVH) and traces it. Results come back
//! with the posed scene they were traced in, so the window always draws a
//! scene and photons that belong together.

use anyhow::{Result, anyhow};
use hikari_core::photon::TraceSettings;
use hikari_core::scene::{Pose, Scene};
use hikari_engine::tracer::PhotonTracer;
pub use hikari_viewer::photon_set::{Job, PhotonSet};
use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender, TryRecvError, channel};
use std::time::Instant;

pub struct PhotonSets {
    /// None once dropping (closing it ends the thread).
    jobs: Option<Sender<(u64, Job)>>,
    /// Joined on drop: a GPU tracer's device must be released before the
    /// process exits (lavapipe crashes tearing down a device another
    /// thread still holds).
    thread: Option<std::thread::JoinHandle<()>>,
    results: Receiver<PhotonSet>,
    /// Requests made so far (the newest has number `requested - 1`).
    requested: u64,
    /// Sets that came back, including those too old to draw.
    pub received: u64,
}

impl PhotonSets {
    /// A tracing thread for poses of `scene` (as loaded), tracing with
    /// `tracer` (chosen for `scene`). It ends when this is dropped (its
    /// channels close).
    pub fn start(scene: Arc<Scene>, mut tracer: PhotonTracer) -> Result<Self> {
        let (jobs, job_receiver) = channel::<(u64, Job)>();
        let (sender, results) = channel();
        let thread = std::thread::Builder::new()
            .name("photon sets".into())
            .spawn(move || {
                let mut posed: Option<(Pose, Arc<Scene>)> = None;
                while let Ok(mut job) = job_receiver.recv() {
                    // Only the newest request matters: older ones are stale.
                    while let Ok(newer) = job_receiver.try_recv() {
                        job = newer;
                    }
                    let (id, Job { pose, photons, seed }) = job;
                    let start = Instant::now();
                    let mut pose_seconds = 0.0;
                    let scene = match &posed {
                        Some((p, s)) if *p == pose => s.clone(),
                        _ => {
                            let s = Arc::new(scene.posed_for_frame(&pose));
                            pose_seconds = start.elapsed().as_secs_f64();
                            posed = Some((pose.clone(), s.clone()));
                            tracer.set_scene(&s);
                            s
                        }
                    };
                    let settings = TraceSettings { photons, seed, ..Default::default() };
                    let traced = tracer.trace(&scene, &settings, &hikari_core::progress::Silent);
                    let seconds = start.elapsed().as_secs_f64();
                    let set = PhotonSet { id, pose, scene, traced, seconds, pose_seconds, photons };
                    if sender.send(set).is_err() {
                        return; // the window closed, or the scene was reloaded
                    }
                }
            })
            .map_err(|e| anyhow!("cannot start the photon-tracing thread: {e}"))?;
        Ok(PhotonSets { jobs: Some(jobs), thread: Some(thread), results, requested: 0, received: 0 })
    }

    /// Asks for a set; returns its number. Requests are numbered from 0 in
    /// the order made, so the same requests give the same numbers.
    pub fn request(&mut self, job: Job) -> Result<u64> {
        let id = self.requested;
        let stopped = || anyhow!("the photon-tracing thread stopped");
        self.jobs.as_ref().ok_or_else(stopped)?.send((id, job)).map_err(|_| stopped())?;
        self.requested += 1;
        Ok(id)
    }

    /// The number of the newest request, if any.
    pub fn newest(&self) -> Option<u64> {
        self.requested.checked_sub(1)
    }

    /// The newest set that came back, if any (older ones are dropped).
    /// With `wait`, waits for the set of the newest request instead.
    pub fn next(&mut self, wait: bool) -> Result<Option<PhotonSet>> {
        let stopped = || anyhow!("the photon-tracing thread stopped");
        let mut newest = None;
        loop {
            match self.results.try_recv() {
                Ok(set) => {
                    self.received += 1;
                    newest = Some(set);
                }
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => return Err(stopped()),
            }
        }
        if wait {
            let target = self.newest();
            while newest.as_ref().map(|s| s.id) != target {
                newest = Some(self.results.recv().map_err(|_| stopped())?);
                self.received += 1;
            }
        }
        Ok(newest)
    }
}

impl Drop for PhotonSets {
    /// Closes the request channel and waits for the thread to finish the
    /// set under way (results go to an unbounded channel, so it never blocks).
    fn drop(&mut self) {
        self.jobs = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hikari_core::photon::{TracedPhotons, trace_photons};

    fn bits(t: &TracedPhotons) -> Vec<[u32; 3]> {
        t.global.iter().map(|p| p.position.map(f32::to_bits)).collect()
    }

    #[test]
    fn a_set_is_the_trace_of_its_request() {
        let scene = Arc::new(Scene::load("cornell-orbit").unwrap());
        let mut sets = PhotonSets::start(scene.clone(), PhotonTracer::cpu(hikari_engine::Log::stderr())).unwrap();
        for (k, time) in [(1u64, 0.0f32), (2, 1.7)] {
            let pose = Pose { time, ..scene.rest_pose() };
            let id = sets.request(Job { pose: pose.clone(), photons: 500, seed: 7 + k }).unwrap();
            let got = sets.next(true).unwrap().unwrap();
            assert_eq!(got.id, id);
            assert_eq!(got.pose, pose);
            let want = trace_photons(
                &scene.posed(&pose),
                &TraceSettings { photons: 500, seed: 7 + k, ..Default::default() },
                &hikari_core::progress::Silent,
            );
            assert_eq!(bits(&got.traced), bits(&want), "set {k}");
        }
    }

    /// On the GPU tracer, each set is traced in its own pose: the thread
    /// hands every newly posed scene to the tracer.
    #[test]
    fn gpu_sets_follow_the_pose() {
        use hikari_engine::tracer::TraceDevice;
        let scene = Arc::new(Scene::load("cornell-orbit").unwrap());
        let ctx = hikari_gpu::GpuContext::new().expect("an adapter (scripts/test.sh installs lavapipe)");
        let tracer = PhotonTracer::choose(TraceDevice::Gpu, Some(&ctx), &scene, hikari_engine::Log::stderr());
        assert_eq!(tracer.device(), "gpu");
        let mut sets = PhotonSets::start(scene.clone(), tracer).unwrap();
        let mut previous = None;
        for time in [0.0f32, 1.7] {
            let pose = Pose { time, ..scene.rest_pose() };
            sets.request(Job { pose: pose.clone(), photons: 500, seed: 3 }).unwrap();
            let got = sets.next(true).unwrap().unwrap();
            let settings = TraceSettings { photons: 500, seed: 3, ..Default::default() };
            let mut fresh = hikari_gpu::trace::GpuTracer::new(&ctx, &scene.posed(&pose)).unwrap();
            let want = fresh.trace(&ctx, &settings).unwrap().0;
            assert_eq!(bits(&got.traced), bits(&want), "time {time}");
            assert_ne!(previous, Some(bits(&got.traced)), "the light moved, the photons did not");
            previous = Some(bits(&got.traced));
        }
    }

    #[test]
    fn waiting_skips_to_the_newest_request() {
        let scene = Arc::new(Scene::load("cornell-box").unwrap());
        let mut sets = PhotonSets::start(scene.clone(), PhotonTracer::cpu(hikari_engine::Log::stderr())).unwrap();
        for seed in 0..5 {
            sets.request(Job { pose: scene.rest_pose(), photons: 2000, seed }).unwrap();
        }
        let got = sets.next(true).unwrap().unwrap();
        assert_eq!(got.id, 4);
        assert!(sets.received <= 5);
    }
}
