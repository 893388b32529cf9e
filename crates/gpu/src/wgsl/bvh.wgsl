// Closest hits in the scene's flat BVH (hikari_core::geometry::FlatBvh),
// step for step as its CPU `intersect`: the specular pass and the photon
// tracer share this one copy. The includer declares the storage arrays
// `nodes` and `prims`, `loop_iteration()` (its loop accounting) and
// `prim_is_there(prim, barycentrics, origin, direction)`: false where a
// cut-out (alphaMode MASK) is cut or a BLEND surface absent for this ray,
// so the ray goes on (Accel's alpha test; CUT_OUTS).

struct FlatNode {
    min: vec3<f32>,
    prim_count: u32,
    max: vec3<f32>,
    first: u32,
}

struct FlatPrim {
    a: vec3<f32>,
    is_sphere: u32,
    b: vec3<f32>,
    surface: u32,
    c: vec3<f32>,
    // Its index in Accel's joint primitive space (a BLEND threshold's hash).
    source: u32,
}

const NO_HIT: f32 = 3.0e38;

// Zero components become ±1e-20 so the slab test never sees 0·∞
// (as hikari_core::geometry::FlatBvh::intersect).
fn safe_inverse(d: vec3<f32>) -> vec3<f32> {
    let s = select(d, sign(d + vec3<f32>(1.0e-30)) * 1.0e-20, abs(d) < vec3<f32>(1.0e-20));
    return 1.0 / s;
}

fn slab_hit(o: vec3<f32>, inv: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>, t_max: f32) -> bool {
    let t0 = (lo - o) * inv;
    let t1 = (hi - o) * inv;
    let near = max(max(max(min(t0.x, t1.x), min(t0.y, t1.y)), min(t0.z, t1.z)), 0.0);
    let far = min(min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z)), t_max);
    return near <= far;
}

// Nearest hit in (epsilon, t_max), as hikari_core's Triangle/Sphere::intersect:
// (t, b1, b2), t = NO_HIT for none; a triangle's barycentrics b1, b2 are
// the weights of its vertices 1 and 2 (zero for spheres).
fn intersect_prim(p: FlatPrim, o: vec3<f32>, d: vec3<f32>, t_max: f32, eps: f32) -> vec3<f32> {
    if (p.is_sphere != 0u) {
        let radius = p.b.x;
        let oc = o - p.a;
        let a = dot(d, d);
        let half_b = dot(oc, d);
        let closest = oc - d * (half_b / a);
        let disc = radius * radius - dot(closest, closest);
        if (disc < 0.0) {
            return vec3<f32>(NO_HIT, 0.0, 0.0);
        }
        let root = sqrt(a * disc);
        let q = -half_b - select(-root, root, half_b >= 0.0);
        var t0 = q / a;
        var t1 = select(q / a, (dot(oc, oc) - radius * radius) / q, q != 0.0);
        if (t0 > t1) {
            let tmp = t0;
            t0 = t1;
            t1 = tmp;
        }
        if (t0 > eps && t0 < t_max) {
            return vec3<f32>(t0, 0.0, 0.0);
        }
        if (t1 > eps && t1 < t_max) {
            return vec3<f32>(t1, 0.0, 0.0);
        }
        return vec3<f32>(NO_HIT, 0.0, 0.0);
    }
    let e1 = p.b;
    let e2 = p.c;
    let pv = cross(d, e2);
    let det = dot(e1, pv);
    if (abs(det) < 1.0e-12) {
        return vec3<f32>(NO_HIT, 0.0, 0.0);
    }
    let inv = 1.0 / det;
    let s = o - p.a;
    let b1 = dot(s, pv) * inv;
    if (b1 < 0.0 || b1 > 1.0) {
        return vec3<f32>(NO_HIT, 0.0, 0.0);
    }
    let qv = cross(s, e1);
    let b2 = dot(d, qv) * inv;
    if (b2 < 0.0 || b1 + b2 > 1.0) {
        return vec3<f32>(NO_HIT, 0.0, 0.0);
    }
    let t = dot(e2, qv) * inv;
    if (t > eps && t < t_max) {
        return vec3<f32>(t, b1, b2);
    }
    return vec3<f32>(NO_HIT, 0.0, 0.0);
}

struct Hit {
    t: f32,
    prim: u32,
    // Barycentrics (weights of vertices 1 and 2) of a triangle hit.
    b: vec2<f32>,
}

// Closest hit by stack traversal of the flat BVH (FlatBvh::intersect).
fn trace_bvh(o: vec3<f32>, d: vec3<f32>, eps: f32) -> Hit {
    var hit = Hit(NO_HIT, 0u, vec2<f32>(0.0));
    if (arrayLength(&nodes) == 0u) {
        return hit;
    }
    let inv = safe_inverse(d);
    var stack: array<u32, 64>;
    var top = 1u;
    stack[0] = 0u;
    while (top > 0u) {
        if (!loop_iteration()) {
            break;
        }
        top -= 1u;
        let node = nodes[stack[top]];
        if (!slab_hit(o, inv, node.min, node.max, hit.t)) {
            continue;
        }
        if (node.prim_count == 0u) {
            if (top + 2u <= 64u) {
                stack[top] = node.first;
                stack[top + 1u] = node.first + 1u;
                top += 2u;
            }
            continue;
        }
        for (var i = node.first; i < node.first + node.prim_count; i++) {
            if (!loop_iteration()) {
                break;
            }
            let r = intersect_prim(prims[i], o, d, hit.t, eps);
            if (r.x < hit.t && prim_is_there(i, r.yz, o, d)) {
                hit = Hit(r.x, i, r.yz);
            }
        }
    }
    return hit;
}
