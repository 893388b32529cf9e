// Texture lookups in the packed texture buffer (textures/mod.rs has the
// layout): hikari_core::texture::Image::sample's bilinear filter and wrap
// modes operation for operation, and a mip-mapped variant for the G-buffer.
// The includer declares `texture_data: array<u32>` (storage, read).

const NO_TEXTURE: u32 = 0xffffffffu;
const TEXTURE_HEADER_WORDS: u32 = 4u;
const TEXTURE_VIEW_WORDS: u32 = 26u;
const TEXTURE_TRANSFORM_WORDS: u32 = 6u;

// hikari_core::texture::srgb_to_linear.
fn srgb_to_linear(c: f32) -> f32 {
    if (c <= 0.04045) {
        return c / 12.92;
    }
    return pow((c + 0.055) / 1.055, 2.4);
}

// Wrap::bounded: a coordinate brought into a range that wraps the same.
fn wrap_bounded(u: f32, wrap: u32) -> f32 {
    if (wrap == 1u) {
        return clamp(u, -1.0, 2.0);
    }
    // rem_euclid(u, 2).
    return u - 2.0 * floor(u * 0.5);
}

// Wrap::texel: texel index i of a row of n, wrapped.
fn wrap_texel(i: i32, n: i32, wrap: u32) -> i32 {
    if (wrap == 1u) {
        return clamp(i, 0, n - 1);
    }
    let period = select(n, 2 * n, wrap == 2u);
    // i ≥ −1 after wrap_bounded, so i + 2·period ≥ 0: a modulo of
    // non-negative numbers (GLSL leaves % of negative ones undefined).
    let m = i32(u32(i + 2 * period) % u32(period));
    if (wrap == 2u && m >= n) {
        return 2 * n - 1 - m;
    }
    return m;
}

// Texel (x, y) of a level starting at word `offset`, `width` wide.
fn load_texel(offset: u32, width: u32, x: i32, y: i32, srgb: bool) -> vec4<f32> {
    let v = unpack4x8unorm(texture_data[offset + u32(y) * width + u32(x)]);
    if (!srgb) {
        return v;
    }
    return vec4<f32>(srgb_to_linear(v.x), srgb_to_linear(v.y), srgb_to_linear(v.z), v.w);
}

// The header of the view texture `t` reads.
fn texture_header(t: u32) -> u32 {
    return TEXTURE_HEADER_WORDS + TEXTURE_VIEW_WORDS * (t & 0x00ffffffu);
}

// The linear part of the view's KHR_texture_transform (TextureRef::transform).
fn texture_linear(header: u32) -> mat2x2<f32> {
    let m = header + 4u;
    return mat2x2<f32>(
        vec2<f32>(bitcast<f32>(texture_data[m]), bitcast<f32>(texture_data[m + 1u])),
        vec2<f32>(bitcast<f32>(texture_data[m + 2u]), bitcast<f32>(texture_data[m + 3u])),
    );
}

// Header word 3: bit 0 the image is sRGB-encoded, bit 1 the view has a
// transform (without one its coordinates are the surface's: a branch that
// a scene without transforms takes the same way everywhere).
const TEXTURE_SRGB: u32 = 1u;
const TEXTURE_TRANSFORMED: u32 = 2u;

// Surface coordinates to the image's (TextureRef::image_uv).
fn texture_image_uv(header: u32, uv: vec2<f32>) -> vec2<f32> {
    if ((texture_data[header + 3u] & TEXTURE_TRANSFORMED) == 0u) {
        return uv;
    }
    let m = header + 4u;
    let offset = vec2<f32>(bitcast<f32>(texture_data[m + 4u]), bitcast<f32>(texture_data[m + 5u]));
    return texture_linear(header) * uv + offset;
}

// Level `level` of the image texture `t` refers to, at surface
// coordinates `uv_in` (TextureRef::image_uv, then Image::sample).
fn sample_level(t: u32, uv_in: vec2<f32>, level: u32) -> vec4<f32> {
    let header = texture_header(t);
    let wrap_s = (t >> 24u) & 3u;
    let wrap_t = (t >> 26u) & 3u;
    let width = max(texture_data[header] >> level, 1u);
    let height = max(texture_data[header + 1u] >> level, 1u);
    let srgb = (texture_data[header + 3u] & TEXTURE_SRGB) != 0u;
    let offset = texture_data[header + 4u + TEXTURE_TRANSFORM_WORDS + level];
    var uv = texture_image_uv(header, uv_in);
    // Non-finite coordinates read (0, 0), as on the CPU.
    if (!(abs(uv.x) <= 3.4e38) || !(abs(uv.y) <= 3.4e38)) {
        uv = vec2<f32>(0.0);
    }
    uv = vec2<f32>(wrap_bounded(uv.x, wrap_s), wrap_bounded(uv.y, wrap_t));
    let x = uv.x * f32(width) - 0.5;
    let y = uv.y * f32(height) - 0.5;
    let x0 = floor(x);
    let y0 = floor(y);
    let fx = x - x0;
    let fy = y - y0;
    let w = i32(width);
    let h = i32(height);
    let xa = wrap_texel(i32(x0), w, wrap_s);
    let xb = wrap_texel(i32(x0) + 1, w, wrap_s);
    let ya = wrap_texel(i32(y0), h, wrap_t);
    let yb = wrap_texel(i32(y0) + 1, h, wrap_t);
    let row_a = mix(load_texel(offset, width, xa, ya, srgb), load_texel(offset, width, xb, ya, srgb), fx);
    let row_b = mix(load_texel(offset, width, xa, yb, srgb), load_texel(offset, width, xb, yb, srgb), fx);
    return mix(row_a, row_b, fy);
}

// The texture at `uv`, level 0: what the CPU renderers read at a point.
fn sample_texture(t: u32, uv: vec2<f32>) -> vec4<f32> {
    return sample_level(t, uv, 0u);
}

// The texture over a pixel whose coordinates change by `dx` and `dy` from
// one pixel to the next: trilinear between the two mip levels around the
// footprint's larger side (the CPU averages a minified texture over its
// many samples per pixel instead).
fn sample_texture_footprint(t: u32, uv: vec2<f32>, dx: vec2<f32>, dy: vec2<f32>) -> vec4<f32> {
    let header = texture_header(t);
    let size = vec2<f32>(f32(texture_data[header]), f32(texture_data[header + 1u]));
    let levels = texture_data[header + 2u];
    // The footprint in the image: a transform scales it too.
    var footprint = max(length(dx * size), length(dy * size));
    if ((texture_data[header + 3u] & TEXTURE_TRANSFORMED) != 0u) {
        let linear = texture_linear(header);
        footprint = max(length(linear * dx * size), length(linear * dy * size));
    }
    let lod = clamp(log2(max(footprint, 1.0)), 0.0, f32(levels - 1u));
    if (!(lod > 0.0)) {
        return sample_level(t, uv, 0u);
    }
    let lo = u32(floor(lod));
    let hi = min(lo + 1u, levels - 1u);
    return mix(sample_level(t, uv, lo), sample_level(t, uv, hi), lod - floor(lod));
}

// The texture coordinates of BVH primitive `prim`'s three corners
// (TexCoords::triangle); `present` false where it has none.
struct CornerUvs {
    present: bool,
    u0: vec2<f32>,
    u1: vec2<f32>,
    u2: vec2<f32>,
}

fn primitive_corner_uvs(prim: u32) -> CornerUvs {
    let table = texture_data[1];
    if (table == 0u) {
        return CornerUvs(false, vec2<f32>(0.0), vec2<f32>(0.0), vec2<f32>(0.0));
    }
    let base = table + 6u * prim;
    if (texture_data[base] == NO_TEXTURE) {
        return CornerUvs(false, vec2<f32>(0.0), vec2<f32>(0.0), vec2<f32>(0.0));
    }
    let u0 = vec2<f32>(bitcast<f32>(texture_data[base]), bitcast<f32>(texture_data[base + 1u]));
    let u1 = vec2<f32>(bitcast<f32>(texture_data[base + 2u]), bitcast<f32>(texture_data[base + 3u]));
    let u2 = vec2<f32>(bitcast<f32>(texture_data[base + 4u]), bitcast<f32>(texture_data[base + 5u]));
    return CornerUvs(true, u0, u1, u2);
}

// hikari_core::texture::Texturing::tangents of BVH primitive `prim`'s
// corners (PackedTangent::decode is unpack2x16snorm's conversion); zero
// where it has none (header word 3 gives the table, 0: no table).
struct CornerTangents {
    t0: vec4<f32>,
    t1: vec4<f32>,
    t2: vec4<f32>,
}

fn primitive_corner_tangents(prim: u32) -> CornerTangents {
    let table = texture_data[3];
    if (table == 0u) {
        return CornerTangents(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    }
    let w = table + 6u * prim;
    return CornerTangents(
        vec4<f32>(unpack2x16snorm(texture_data[w]), unpack2x16snorm(texture_data[w + 1u])),
        vec4<f32>(unpack2x16snorm(texture_data[w + 2u]), unpack2x16snorm(texture_data[w + 3u])),
        vec4<f32>(unpack2x16snorm(texture_data[w + 4u]), unpack2x16snorm(texture_data[w + 5u])),
    );
}

// The texture coordinates (xy) at barycentrics b (weights of vertices 1
// and 2) of BVH primitive `prim` (TexCoords::at), and z = 1; z = 0 where the
// primitive has none (its textures then leave the factors alone).
fn primitive_uv(prim: u32, b: vec2<f32>) -> vec3<f32> {
    let c = primitive_corner_uvs(prim);
    if (!c.present) {
        return vec3<f32>(0.0);
    }
    return vec3<f32>(c.u0 * (1.0 - b.x - b.y) + c.u1 * b.x + c.u2 * b.y, 1.0);
}

// The coordinates' changes along BVH triangle `prim`'s edges (corner 1 −
// corner 0, corner 2 − corner 0; FlatPrim's b and c), as xy and zw; zero
// where it has no coordinates.
fn primitive_uv_edges(prim: u32) -> vec4<f32> {
    let c = primitive_corner_uvs(prim);
    return vec4<f32>(c.u1 - c.u0, c.u2 - c.u0);
}
