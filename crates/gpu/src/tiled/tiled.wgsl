// The tiled estimator (Mara, Luebke and McGuire 2013's tiled gather): the
// same sum as the raster splat (splat.wgsl), computed without the
// rasterizer. Each surviving photon is binned into the 16×16-pixel screen
// tiles its footprint covers (count → scan → fill); then one workgroup per
// tile gathers, each invocation summing its pixel's photons from the
// tile's list with the splat's test (estimate.wgsl).
//
// The sum is kept in 64-bit fixed point (2^-24 power units, as two u32),
// which adds exactly in any order: the fill's atomic order changes nothing
// and the frame is the same on every run. A gather may be split into
// slices of each tile's list (dispatches adding to `accum`), so no
// invocation runs past the adapter's loop budget.
// Composed with estimate.wgsl, footprint_rect.wgsl, prefix_sum.wgsl,
// lod_photon.wgsl, view_depth.wgsl and volume_chord.wgsl.

struct TiledParams {
    clip_from_world: mat4x4<f32>,
    radius: f32,
    // Watts per unit of stored photon power.
    power_unit: f32,
    normal_test: u32,
    width: u32,
    height: u32,
    tiles_x: u32,
    tiles_y: u32,
    // Entries `tile_lists` holds.
    list_capacity: u32,
    // Workgroups of the tile scan dispatches.
    scan_workgroups: u32,
    // This gather dispatch reads entries [slice_start, slice_start + slice_length) of each list.
    slice_start: u32,
    slice_length: u32,
    last_slice: u32,
    // Tiles one photon may cover (the adapter's loop budget); a photon
    // covering more is counted in status[2] and the frame is refused.
    loop_budget: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}


@group(0) @binding(0) var<uniform> params: TiledParams;
@group(0) @binding(1) var<storage, read> survivors: array<LodPhoton>;
// The LOD pass's indirect draw: [1] is the number of survivors.
@group(0) @binding(2) var<storage, read> draw: array<u32, 4>;
// Photons per tile (counted, then used as the fill cursor).
@group(0) @binding(3) var<storage, read_write> tile_counts: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read_write> group_sums: array<u32>;
@group(0) @binding(5) var<storage, read_write> tile_starts: array<u32>;
@group(0) @binding(6) var<storage, read_write> tile_lists: array<u32>;
// Per pixel: the fixed-point sums (low, high word per channel) and the photon count.
@group(0) @binding(7) var<storage, read_write> accum: array<u32>;
// [list entries needed, longest tile list, photons over the loop budget, unused].
@group(0) @binding(8) var<storage, read_write> status: array<atomic<u32>, 4>;
@group(0) @binding(9) var gbuffer_position: texture_2d<f32>;
@group(0) @binding(10) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(11) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(12) var output: texture_storage_2d<RADIANCE_FORMAT, write>;
// The media, for the volume map's gather (media.wgsl, view_depth.wgsl).
@group(0) @binding(13) var<uniform> media: MediaParams;
@group(0) @binding(14) var<storage, read> regions: array<RegionTriangle>;
@group(0) @binding(15) var slices_tex: texture_2d_array<f32>;
@group(0) @binding(16) var<storage, read> surfaces: Surfaces;
@group(0) @binding(17) var gbuffer_emission: texture_2d<f32>;
// The layer textures' texels (read where LAYERED; layer_texels.wgsl).
@group(0) @binding(18) var gbuffer_layers: texture_2d<u32>;

const TILE: u32 = 16u;

fn survivor_count() -> u32 {
    return draw[1];
}

// The tiles (x0, y0, x1, y1), inclusive, that photon i's footprint covers;
// x0 > x1 when none.
fn tile_range(i: u32) -> vec4<u32> {
    let p = survivors[i];
    let f = photon_footprint(vec3<f32>(p.position_x, p.position_y, p.position_z));
    if (f.x > f.z) {
        return vec4<u32>(1u, 1u, 0u, 0u);
    }
    let size = vec2<f32>(f32(params.width), f32(params.height));
    // NDC to pixels, y down: every pixel whose centre the quad covers.
    let a = vec2<f32>((f.x * 0.5 + 0.5) * size.x, (0.5 - f.w * 0.5) * size.y);
    let b = vec2<f32>((f.z * 0.5 + 0.5) * size.x, (0.5 - f.y * 0.5) * size.y);
    let last = vec2<i32>(i32(params.width) - 1, i32(params.height) - 1);
    let lo = clamp(vec2<i32>(floor(a)), vec2<i32>(0), last);
    let hi = clamp(vec2<i32>(ceil(b)), vec2<i32>(0), last);
    return vec4<u32>(vec2<u32>(lo) / TILE, vec2<u32>(hi) / TILE);
}

@compute @workgroup_size(256)
fn count_tiles(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = gid.y * groups.x * 256u + gid.x;
    if (i >= survivor_count()) {
        return;
    }
    let r = tile_range(i);
    if (r.x <= r.z && (r.z - r.x + 1u) * (r.w - r.y + 1u) > params.loop_budget) {
        atomicAdd(&status[2], 1u);
        return;
    }
    for (var ty = r.y; ty <= r.w; ty++) {
        for (var tx = r.x; tx <= r.z; tx++) {
            atomicAdd(&tile_counts[ty * params.tiles_x + tx], 1u);
        }
    }
}

fn tile_count(t: u32) -> u32 {
    return select(0u, atomicLoad(&tile_counts[t]), t < params.tiles_x * params.tiles_y);
}

@compute @workgroup_size(256)
fn sum_groups(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let g = wid.x;
    workgroup_exclusive_prefix(lid, tile_count(g * SCAN_WORKGROUP + lid));
    if (lid == 0u) {
        group_sums[g] = shared_sums[SCAN_WORKGROUP - 1u];
    }
}

@compute @workgroup_size(256)
fn scan_groups(@builtin(local_invocation_index) lid: u32) {
    let total = scan_group_sums(lid, params.scan_workgroups);
    if (lid == 0u) {
        atomicStore(&status[0], total);
    }
}

// Each tile's first list entry; the counts become fill cursors (zeroed).
@compute @workgroup_size(256)
fn write_starts(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let t = wid.x * SCAN_WORKGROUP + lid;
    let count = tile_count(t);
    let first = group_sums[wid.x] + workgroup_exclusive_prefix(lid, count);
    if (t < params.tiles_x * params.tiles_y) {
        tile_starts[t] = first;
        atomicMax(&status[1], count);
        atomicStore(&tile_counts[t], 0u);
    }
}

@compute @workgroup_size(256)
fn fill_tiles(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = gid.y * groups.x * 256u + gid.x;
    if (i >= survivor_count()) {
        return;
    }
    let r = tile_range(i);
    if (r.x <= r.z && (r.z - r.x + 1u) * (r.w - r.y + 1u) > params.loop_budget) {
        return;
    }
    for (var ty = r.y; ty <= r.w; ty++) {
        for (var tx = r.x; tx <= r.z; tx++) {
            let t = ty * params.tiles_x + tx;
            let slot = tile_starts[t] + atomicAdd(&tile_counts[t], 1u);
            if (slot < params.list_capacity) {
                tile_lists[slot] = i;
            }
        }
    }
}

// v ≥ 0 power units added to the fixed-point sum (low, high) at 2^-24 units:
// v · 2^24 split exactly into its high and low 32 bits (truncating below
// 2^-24), then an integer add with carry.
fn add_fixed(sum: vec2<u32>, v: f32) -> vec2<u32> {
    let scaled = v * 16777216.0;
    let high = floor(scaled / 4294967296.0);
    let low = u32(scaled - high * 4294967296.0);
    let l = sum.x + low;
    return vec2<u32>(l, sum.y + u32(high) + select(0u, 1u, l < sum.x));
}

fn fixed_value(sum: vec2<u32>) -> f32 {
    return f32(sum.y) * 256.0 + f32(sum.x) * (1.0 / 16777216.0);
}

// A pixel's fixed-point sum across gather slices.
struct FixedSum {
    r: vec2<u32>,
    g: vec2<u32>,
    b: vec2<u32>,
    count: u32,
}

fn load_sum(index: u32) -> FixedSum {
    if (params.slice_start == 0u) {
        return FixedSum(vec2<u32>(0u), vec2<u32>(0u), vec2<u32>(0u), 0u);
    }
    return FixedSum(
        vec2<u32>(accum[index], accum[index + 1u]),
        vec2<u32>(accum[index + 2u], accum[index + 3u]),
        vec2<u32>(accum[index + 4u], accum[index + 5u]),
        accum[index + 6u],
    );
}

fn add_to_sum(sum: ptr<function, FixedSum>, v: vec3<f32>) {
    (*sum).r = add_fixed((*sum).r, v.x);
    (*sum).g = add_fixed((*sum).g, v.y);
    (*sum).b = add_fixed((*sum).b, v.z);
    (*sum).count += 1u;
}

// Keeps the sum for the next slice, or (last slice) stores factor × sum.
fn finish_sum(pixel: vec2<i32>, index: u32, sum: FixedSum, factor: vec3<f32>) {
    if (params.last_slice == 0u) {
        accum[index] = sum.r.x;
        accum[index + 1u] = sum.r.y;
        accum[index + 2u] = sum.g.x;
        accum[index + 3u] = sum.g.y;
        accum[index + 4u] = sum.b.x;
        accum[index + 5u] = sum.b.y;
        accum[index + 6u] = sum.count;
        return;
    }
    let value = vec3<f32>(fixed_value(sum.r), fixed_value(sum.g), fixed_value(sum.b));
    // Alpha counts the photons that reached the pixel, as the splat's does.
    textureStore(output, pixel, vec4<f32>(factor * value, f32(sum.count)));
}

// The list entries of tile t this slice reads: [first slot, end slot).
fn slice_slots(t: u32) -> vec2<u32> {
    let start = tile_starts[t];
    let end = min(atomicLoad(&tile_counts[t]), params.slice_start + params.slice_length);
    return vec2<u32>(start + params.slice_start, min(start + end, params.list_capacity));
}

// The photons of `slots` within reach of x (shading normal n): their
// powers, weighted by the BRDF at a glossy point and, where `bent`, by
// shading_normal_factor across the geometric normal ng (as photon-cpu) and
// the bump shadowing `bump` of the photon's side at a normal-mapped point.
fn gather_slots(sum: ptr<function, FixedSum>, slots: vec2<u32>, x: vec3<f32>, n: vec3<f32>, ng: vec3<f32>, bent: bool, bump: BumpShadow, glossy: bool, b: Bsdf, eye: vec3<f32>) {
    for (var slot = slots.x; slot < slots.y; slot++) {
        let p = survivors[tile_lists[slot]];
        let d = x - vec3<f32>(p.position_x, p.position_y, p.position_z);
        let direction = decode_octahedral_15(p.direction_and_class & 0x3fffffffu);
        if (photon_accepted(dot(d, d), direction, n, params.radius, params.normal_test != 0u)) {
            let power = decode_rgb9e5(p.power_rgb9e5) * p.scale;
            add_to_sum(sum, gathered_power(power, direction, n, ng, bent, bump, glossy, b, eye));
        }
    }
}

// Surface maps: the splat's estimate (splat.wgsl) at the pixel's surface point.
@compute @workgroup_size(16, 16)
fn gather(@builtin(workgroup_id) wid: vec3<u32>, @builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let pixel = vec2<i32>(gid.xy);
    let index = 8u * (gid.y * params.width + gid.x);
    var sum = load_sum(index);
    let position = textureLoad(gbuffer_position, pixel, 0);
    let g = textureLoad(gbuffer_normal, pixel, 0);
    let normal = g.xyz;
    let albedo = textureLoad(gbuffer_albedo, pixel, 0);
    // A glossy surface weights each photon by its BRDF (photon_brdf) in
    // the sum; a Lambertian one applies ρ/(π² r²) to the sum of powers.
    var surface = surfaces.all[u32(g.w)];
    var layers = vec4<u32>(0u);
    if (LAYERED) {
        layers = textureLoad(gbuffer_layers, pixel, 0);
        surface = pixel_surface(surface, layers);
    }
    let glossy = GLOSSY && surface.glossy != 0u;
    let b = pixel_coat(pixel_bsdf(surface, albedo.rgb, textureLoad(gbuffer_emission, pixel, 0).w), surface, layers);
    let eye = unit(media.camera_position - position.xyz);
    // Only visible diffuse surfaces (kind 0) take photon light.
    if (position.w != 0.0 && pixel_kind(albedo.a) == 0u) {
        let slots = slice_slots(wid.y * params.tiles_x + wid.x);
        // `bent` a literal in each call, so the test folds out of the loop.
        if (BENT && position.w < 0.0) {
            let ng = unpack_geometric_normal(position.w, normal);
            let bump = pixel_bump(albedo.a, normal);
            gather_slots(&sum, slots, position.xyz, normal, ng, true, bump, glossy, b, eye);
        } else {
            gather_slots(&sum, slots, position.xyz, normal, normal, false, no_bump(), glossy, b, eye);
        }
    }
    var factor = radiance_per_power(albedo.rgb, params.radius);
    if (glossy) {
        factor = vec3<f32>(radiance_per_weighted_power(params.radius));
    }
    finish_sum(pixel, index, sum, factor * params.power_unit);
}

// The volume map: the volume splat's chords (volume.wgsl) along the pixel's view ray.
@compute @workgroup_size(16, 16)
fn gather_volume(@builtin(workgroup_id) wid: vec3<u32>, @builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.width || gid.y >= params.height) {
        return;
    }
    let pixel = vec2<i32>(gid.xy);
    let index = 8u * (gid.y * params.width + gid.x);
    var sum = load_sum(index);
    // The fragment position the splat shades: the pixel centre.
    let ray = view_ray(textureLoad(gbuffer_position, pixel, 0), vec2<f32>(gid.xy) + 0.5);
    let r2 = params.radius * params.radius;
    let slots = slice_slots(wid.y * params.tiles_x + wid.x);
    for (var slot = slots.x; slot < slots.y; slot++) {
        let p = survivors[tile_lists[slot]];
        let chord = volume_chord(media.camera_position, ray.xyz, ray.w, vec3<f32>(p.position_x, p.position_y, p.position_z), r2);
        if (chord.y <= chord.x) {
            continue;
        }
        let transmittance = exp(-view_optical_depth(pixel, chord.z, ray.w));
        add_to_sum(&sum, transmittance * chord_scattering(p.power_rgb9e5, p.direction_and_class, ray.xyz, chord) * p.scale);
    }
    finish_sum(pixel, index, sum, vec3<f32>(volume_kernel(params.radius) * params.power_unit));
}
