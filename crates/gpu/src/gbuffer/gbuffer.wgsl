// G-buffer: world position, normal facing the eye, albedo and material kind,
// emitted radiance. One fragment per pixel centre, like a primary ray.

struct GBufferParams {
    clip_from_world: mat4x4<f32>,
    camera_position: vec3<f32>,
    _pad: f32,
}


@group(0) @binding(0) var<uniform> params: GBufferParams;
@group(0) @binding(1) var<storage, read> surfaces: array<Surface>;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) geometric_normal: vec3<f32>,
    @location(3) surface: u32,
}

struct VertexOut {
    // Invariant: the storage path's two draws must give the same depths.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) geometric_normal: vec3<f32>,
    @location(3) @interpolate(flat) surface: u32,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = params.clip_from_world * vec4<f32>(v.position, 1.0);
    out.world = v.position;
    out.normal = v.normal;
    out.geometric_normal = v.geometric_normal;
    out.surface = v.surface;
    return out;
}

struct GBufferOut {
    // xyz: world position; w: 1 where a surface is seen, 0 elsewhere (cleared).
    @location(0) position: vec4<f32>,
    // xyz: unit shading normal turned toward the eye; w: surface id.
    @location(1) normal: vec4<f32>,
    // rgb: diffuse albedo (mirror reflectance for mirrors); a: material kind.
    @location(2) albedo: vec4<f32>,
    // rgb: radiance emitted toward the eye (area lights, emissive meshes).
    @location(3) emission: vec4<f32>,
}

@fragment
fn fs_main(in: VertexOut) -> GBufferOut {
    return shade(in);
}

// What a pixel stores (fs_main's outputs; gbuffer_storage.wgsl stores the same).
fn shade(in: VertexOut) -> GBufferOut {
    let surface = surfaces[in.surface];
    let view = in.world - params.camera_position;
    let front = dot(in.geometric_normal, view) < 0.0;
    let side = select(-1.0, 1.0, front);
    var out: GBufferOut;
    out.position = vec4<f32>(in.world, 1.0);
    out.normal = vec4<f32>(normalize(in.normal) * side, f32(in.surface));
    out.albedo = vec4<f32>(surface.albedo, f32(surface.kind));
    out.emission = vec4<f32>(select(vec3<f32>(0.0), surface.emission, front || surface.two_sided != 0u), 0.0);
    return out;
}
