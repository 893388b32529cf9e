// G-buffer: world position, normal facing the eye, albedo and material kind,
// emitted radiance. One fragment per pixel centre, like a primary ray. The
// surface's textures are applied here (surface_point.wgsl, mip-mapped by
// the pixel's footprint); MASK cut-outs discard their fragments, and BLEND
// surfaces with probability 1 − alpha, afresh each pass; where a material
// mixes in glass (KHR_materials_transmission below 1) each pixel draws one
// of the two per pass.

struct GBufferParams {
    clip_from_world: mat4x4<f32>,
    camera_position: vec3<f32>,
    // Changes from pass to pass: BLEND fragments' `fragment_blend_threshold`.
    blend_seed: u32,
}


@group(0) @binding(0) var<uniform> params: GBufferParams;
@group(0) @binding(1) var<storage, read> surfaces: Surfaces;
@group(0) @binding(2) var<storage, read> texture_data: array<u32>;

// scene_upload::HAS_UV: the vertex's surface id carries whether `uv` is set.
const HAS_UV: u32 = 0x80000000u;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) geometric_normal: vec3<f32>,
    @location(3) surface: u32,
    @location(4) uv: vec2<f32>,
    // The vertex's stored tangent (scene_upload: Snorm16x4); zero where
    // its triangle has none.
    @location(5) tangent: vec4<f32>,
}

struct VertexOut {
    // Invariant: the storage path's two draws must give the same depths.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) geometric_normal: vec3<f32>,
    @location(3) @interpolate(flat) surface: u32,
    @location(4) uv: vec2<f32>,
    @location(5) tangent: vec3<f32>,
    // The side of the triangle's first corner's tangent, as the CPU takes it.
    @location(6) @interpolate(flat) tangent_side: f32,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = params.clip_from_world * vec4<f32>(v.position, 1.0);
    out.world = v.position;
    out.normal = v.normal;
    out.geometric_normal = v.geometric_normal;
    out.surface = v.surface;
    out.uv = v.uv;
    out.tangent = v.tangent.xyz;
    out.tangent_side = v.tangent.w;
    return out;
}

struct GBufferOut {
    // xyz: world position; w: 0 where no surface is seen (cleared), else
    // the geometric normal's code (pack_geometric_normal: 1 where it is
    // the shading normal).
    @location(0) position: vec4<f32>,
    // xyz: unit shading normal turned toward the eye; w: surface id.
    @location(1) normal: vec4<f32>,
    // rgb: diffuse albedo (mirror reflectance for mirrors); a: material kind
    // (as drawn where glass is mixed in; KIND_MIXED_INSIDE on its back faces)
    // and a normal-mapped point's smooth normal (`pack_kind`).
    @location(2) albedo: vec4<f32>,
    // rgb: radiance emitted toward the eye (area lights, emissive meshes);
    // w: metallic and roughness with textures applied (`pack_metal_rough`).
    @location(3) emission: vec4<f32>,
}

@fragment
fn fs_main(in: VertexOut) -> GBufferOut {
    return shade(in).g;
}

// LAYERED scenes' G-buffer: the four targets and the layer textures'
// texels (layer_texels.wgsl) in a fifth.
struct LayeredOut {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) albedo: vec4<f32>,
    @location(3) emission: vec4<f32>,
    @location(4) layers: vec4<u32>,
}

@fragment
fn fs_main_layered(in: VertexOut) -> LayeredOut {
    let s = shade(in);
    return LayeredOut(s.g.position, s.g.normal, s.g.albedo, s.g.emission, s.layers);
}

// What `shade` stores: the four targets, and where LAYERED the fifth.
struct Shaded {
    g: GBufferOut,
    layers: vec4<u32>,
}

// The surface at the fragment, textures applied; its footprint's change of
// texture coordinates is taken here, in uniform control flow.
fn fragment_point(in: VertexOut) -> SurfacePoint {
    let dx = dpdx(in.uv);
    let dy = dpdy(in.uv);
    let uv = vec3<f32>(in.uv, select(0.0, 1.0, (in.surface & HAS_UV) != 0u));
    return surface_point(surfaces.all[in.surface & ~HAS_UV], uv, dx, dy);
}

// What a pixel stores (fs_main's outputs; gbuffer_storage.wgsl stores the
// same); a cut-out's fragment is discarded.
fn shade(in: VertexOut) -> Shaded {
    // Derivatives in uniform control flow (the normal texture's frame),
    // taken only by pipelines of textured scenes.
    var px = vec3<f32>(0.0);
    var py = vec3<f32>(0.0);
    var dx = vec2<f32>(0.0);
    var dy = vec2<f32>(0.0);
    if (TEXTURED) {
        px = dpdx(in.world);
        py = dpdy(in.world);
        dx = dpdx(in.uv);
        dy = dpdy(in.uv);
    }
    var point = fragment_point(in);
    let id = in.surface & ~HAS_UV;
    var surface = surfaces.all[id];
    if (CUT_OUTS && !is_there_for_fragment(surface, point.alpha, in.clip, params.blend_seed)) {
        discard;
    }
    // Which face of the triangle the eye sees.
    let view = in.world - params.camera_position;
    let front = dot(in.geometric_normal, view) < 0.0;
    // Glass mixed into the material: the pixel draws one of the two afresh
    // each pass, and stores it as drawn (its kind, its metallic), which every
    // pass reading the pixel then shades.
    var kind = surface.kind;
    if (MIXED && surface.transmission > 0.0) {
        let drawn = draw_layer(surface, point, fragment_mix_threshold(in.clip, params.blend_seed));
        surface = drawn.surface;
        point = drawn.point;
        kind = select(surface.kind, KIND_MIXED_INSIDE, surface.kind == 0u && !front);
    }
    let side = select(-1.0, 1.0, front);
    var out: GBufferOut;
    let uv = vec3<f32>(in.uv, select(0.0, 1.0, (in.surface & HAS_UV) != 0u));
    let tangent = vec4<f32>(in.tangent, in.tangent_side);
    // The shading normal on the geometric normal's side, as Accel::intersect
    // and hit_normals keep it (a mesh's normals may disagree with its winding).
    let interpolated = normalize(in.normal);
    let shading = select(interpolated, -interpolated, dot(interpolated, in.geometric_normal) < 0.0);
    let n = bent_normal(surface, uv, dx, dy, px, py, tangent, shading, in.geometric_normal, normalize(view));
    // Both normals turned toward the eye, as the gathers read them.
    var geometric = 1.0;
    if (BENT) {
        geometric = pack_geometric_normal(n * side, normalize(in.geometric_normal) * side);
    }
    out.position = vec4<f32>(in.world, geometric);
    out.normal = vec4<f32>(n * side, f32(id));
    // Where a normal texture bent the normal, the smooth one beside the
    // kind (pack_kind): the diffuse lobes' bump shadowing reads it.
    let bumped = BENT && reads_normal_texture(surface, uv) && any(n != shading);
    out.albedo = vec4<f32>(point.base, pack_kind(kind, shading * side, bumped));
    let emitted = select(vec3<f32>(0.0), point.emission, front || surface.two_sided != 0u);
    out.emission = vec4<f32>(emitted, pack_metal_rough(point.metallic, point.roughness));
    // The layer textures at the pixel's footprint, as the raster passes
    // multiply the surface's factors by them, and the coat's own normal in
    // the frame of the normal stored (Scene::coat_tilted).
    var layers = vec4<u32>(0u);
    if (LAYERED) {
        var texels = layer_texels(surface, uv, dx, dy);
        if (coat_apart(surface, uv)) {
            let coat = coat_normal(surface, uv, dx, dy, px, py, tangent, shading, in.geometric_normal, normalize(view));
            texels.coat_normal = to_shading(coat * side, n * side);
            texels.coat_unbent = coat_normal_texture(surface) == NO_TEXTURE;
        }
        layers = pack_layer_texels(texels);
    }
    return Shaded(out, layers);
}

// The depth-only draw of the storage path: cut-outs leave no depth, and
// a BLEND fragment decides as `shade` does.
@fragment
fn fs_depth(in: VertexOut) {
    let surface = surfaces.all[in.surface & ~HAS_UV];
    if (CUT_OUTS && !is_there_for_fragment(surface, fragment_point(in).alpha, in.clip, params.blend_seed)) {
        discard;
    }
}
