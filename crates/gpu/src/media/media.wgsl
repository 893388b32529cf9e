// Participating media on the GPU (METHOD.md §5), mirrored from
// hikari_core::medium: phase functions, the view ray of a pixel, the
// optical depth along any segment, and the transmittance light_eval.wgsl
// asks for (light reaching a surface).
// Prepended to the shaders that use media; the includer declares `media`
// and defines `region_triangle(i)` (from a `regions` array: REGION_ARRAY)
// (view_depth.wgsl adds the optical depth along view rays).

struct MediaParams {
    // σ_t of the media filling the whole scene. First, as values that stay
    // from frame to frame (media/mod.rs: lavapipe bakes the first word in).
    global_sigma_t: vec3<f32>,
    region_triangles: u32,
    // The camera basis of hikari_core::camera::Camera::ray.
    forward: vec3<f32>,
    tan_half_fov: f32,
    right: vec3<f32>,
    aspect: f32,
    up: vec3<f32>,
    // Optical-depth slices along each view ray (0: no region meshes).
    slices: u32,
    camera_position: vec3<f32>,
    // Length of view rays that hit nothing (photon-cpu's: twice the scene diagonal).
    max_distance: f32,
    // Per phase slot: x = kind (0 Schlick, 1 Henyey–Greenstein), y = k or g.
    phases: array<vec4<f32>, 4>,
    image_size: vec2<f32>,
    // The camera's sub-pixel jitter (hikari_core::camera::Camera::jitter).
    jitter: vec2<f32>,
    // The disc distant lights' photons start from: xyz its centre, w its
    // radius (0 without distant lights).
    distant_disc: vec4<f32>,
}

// How far a ray from o along unit d that hits nothing crosses the media
// (hikari_core::scene::Scene::escape_distance, photon-cpu's eye rays): to
// the plane of the distant lights' disc, else `max_distance`.
fn escape_distance(o: vec3<f32>, d: vec3<f32>) -> f32 {
    let disc = media.distant_disc;
    if (disc.w > 0.0) {
        return max(disc.w - dot(o - disc.xyz, d), 0.0);
    }
    return media.max_distance;
}

// A triangle of a region mesh, wound with its normal out of the medium, and
// that medium's σ_t.
struct RegionTriangle {
    a: vec4<f32>,
    b: vec4<f32>,
    c: vec4<f32>,
    sigma_t: vec4<f32>,
}

// hikari_core::medium::Phase::eval, μ the cosine between propagation directions.
fn phase_eval(slot: u32, mu: f32) -> f32 {
    let p = media.phases[slot];
    if (p.x == 0.0) {
        let k = p.y;
        let d = 1.0 - k * mu;
        return (1.0 - k * k) / (4.0 * PI * d * d);
    }
    let g = p.y;
    let d = 1.0 + g * g - 2.0 * g * mu;
    return (1.0 - g * g) / (4.0 * PI * d * sqrt(d));
}

// The view ray through a pixel: unit direction (xyz) and the distance to the
// visible surface (w), or `escape_distance` where the pixel sees no surface.
fn view_ray(gbuffer_pos: vec4<f32>, frag_xy: vec2<f32>) -> vec4<f32> {
    if (gbuffer_pos.w != 0.0) {
        let d = gbuffer_pos.xyz - media.camera_position;
        let l = length(d);
        return vec4<f32>(d / l, l);
    }
    let size = media.image_size;
    let p = frag_xy + media.jitter;
    let x = (2.0 * p.x / size.x - 1.0) * media.tan_half_fov * media.aspect;
    let y = (1.0 - 2.0 * p.y / size.y) * media.tan_half_fov;
    let dir = normalize(media.forward + media.right * x + media.up * y);
    return vec4<f32>(dir, escape_distance(media.camera_position, dir));
}

// ∫ σ_t along origin + t·dir, t in [0, len]: Σ over region crossings ahead of
// sign · σ_t · min(t, len), + leaving and − entering (the identity of
// hikari_core::medium::region), plus the media filling the scene.
fn segment_optical_depth(origin: vec3<f32>, dir: vec3<f32>, len: f32) -> vec3<f32> {
    var tau = media.global_sigma_t * len;
    for (var i = 0u; i < media.region_triangles; i++) {
        if (!loop_iteration()) {
            break;
        }
        let tri = region_triangle(i);
        let t = region_crossing(origin, dir, tri.a.xyz, tri.b.xyz, tri.c.xyz);
        if (t <= 0.0) {
            continue;
        }
        let leaving = dot(cross(tri.b.xyz - tri.a.xyz, tri.c.xyz - tri.a.xyz), dir) > 0.0;
        tau += select(-1.0, 1.0, leaving) * tri.sigma_t.xyz * min(t, len);
    }
    return max(tau, vec3<f32>(0.0));
}

// Light reaching x from a light sample through the media (eq. 5.8, 5.26).
fn light_transmittance(x: vec3<f32>, light_position: vec3<f32>) -> vec3<f32> {
    if (!MEDIA) {
        return vec3<f32>(1.0);
    }
    let d = light_position - x;
    let len = length(d);
    return exp(-segment_optical_depth(x, d / len, len));
}
