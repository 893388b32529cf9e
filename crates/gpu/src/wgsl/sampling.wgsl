// Direction sampling, mirrored from hikari_core::sampling (and the phase
// functions' sampler from hikari_core::medium::phase), operation for
// operation, so the GPU photon tracer takes the CPU's paths.

// Rust's f32::signum and copysign(1, x): ±1 by the sign bit, so −0 gives −1
// (WGSL's sign() gives 0 for ±0).
fn sign_bit_signum(x: f32) -> f32 {
    return select(1.0, -1.0, (bitcast<u32>(x) & 0x80000000u) != 0u);
}

// (cos 2πu, sin 2πu) by the octant polynomials of sampling::unit_circle.
fn unit_circle(u: f32) -> vec2<f32> {
    let x = u * 4.0;
    let quadrant = i32(x + 0.5);
    let a = (x - f32(quadrant)) * (PI / 2.0);
    let a2 = a * a;
    let s = a * (1.0 + a2 * (-1.0 / 6.0 + a2 * (1.0 / 120.0 + a2 * (-1.0 / 5040.0 + a2 * (1.0 / 362880.0)))));
    let c = 1.0 + a2 * (-0.5 + a2 * (1.0 / 24.0 + a2 * (-1.0 / 720.0 + a2 * (1.0 / 40320.0))));
    switch (quadrant & 3) {
        case 0: {
            return vec2<f32>(c, s);
        }
        case 1: {
            return vec2<f32>(-s, c);
        }
        case 2: {
            return vec2<f32>(-c, -s);
        }
        default: {
            return vec2<f32>(s, -c);
        }
    }
}

// Two unit tangents completing unit n to an orthonormal frame
// (sampling::orthonormal_basis, Duff et al.).
struct Basis {
    t: vec3<f32>,
    b: vec3<f32>,
}

fn orthonormal_basis(n: vec3<f32>) -> Basis {
    let s = sign_bit_signum(n.z);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return Basis(vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x), vec3<f32>(b, s + n.y * n.y * a, -n.y));
}

// sampling::local_to_world.
fn local_to_world(local: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let basis = orthonormal_basis(n);
    return basis.t * local.x + basis.b * local.y + n * local.z;
}

fn uniform_sphere(u: vec2<f32>) -> vec3<f32> {
    let z = 1.0 - 2.0 * u.x;
    let r = sqrt(max(1.0 - z * z, 0.0));
    return vec3<f32>(unit_circle(u.y) * r, z);
}

fn cosine_hemisphere(u: vec2<f32>) -> vec3<f32> {
    let cos_theta = sqrt(1.0 - u.x);
    let sin_theta = sqrt(u.x);
    return vec3<f32>(unit_circle(u.y) * sin_theta, cos_theta);
}

fn uniform_cone(u: vec2<f32>, cos_max: f32) -> vec3<f32> {
    let cos_theta = 1.0 - u.x * (1.0 - cos_max);
    let sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    return vec3<f32>(unit_circle(u.y) * sin_theta, cos_theta);
}

// Phase::sample_mu: kind 0 Schlick (parameter k), 1 Henyey–Greenstein (g).
fn phase_sample_mu(kind: f32, parameter: f32, xi: f32) -> f32 {
    var mu: f32;
    if (kind == 0.0) {
        let k = parameter;
        mu = (2.0 * xi + k - 1.0) / (2.0 * k * xi - k + 1.0);
    } else if (abs(parameter) < 1.0e-4) {
        mu = 1.0 - 2.0 * xi;
    } else {
        let g = parameter;
        let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * xi);
        mu = (1.0 + g * g - s * s) / (2.0 * g);
    }
    return clamp(mu, -1.0, 1.0);
}

// Phase::sample: a new propagation direction for a photon travelling along `dir`.
fn phase_sample(kind: f32, parameter: f32, dir: vec3<f32>, u: vec2<f32>) -> vec3<f32> {
    let mu = phase_sample_mu(kind, parameter, u.x);
    let s = sqrt(max(1.0 - mu * mu, 0.0));
    return local_to_world(vec3<f32>(unit_circle(u.y) * s, mu), dir);
}
