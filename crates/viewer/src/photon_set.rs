//! What a viewer asks its photon tracer for and gets back (the window's
//! tracing thread, the web page's tracing task).

use hikari_core::photon::TracedPhotons;
use hikari_core::scene::{Pose, Scene};
use std::sync::Arc;

/// One request: a pose of the scene, photon paths and a seed.
#[derive(Clone, Debug)]
pub struct Job {
    pub pose: Pose,
    pub photons: u64,
    pub seed: u64,
}

/// A traced set: the request's number, the posed scene and its photons.
pub struct PhotonSet {
    pub id: u64,
    pub pose: Pose,
    pub scene: Arc<Scene>,
    pub traced: TracedPhotons,
    /// Seconds spent posing and tracing, and the photon paths traced.
    pub seconds: f64,
    /// Of `seconds`, those spent posing the scene (`Scene::posed`: moving
    /// and deforming meshes, rebuilding the BVH); 0 where the pose was
    /// traced before.
    pub pose_seconds: f64,
    pub photons: u64,
}
