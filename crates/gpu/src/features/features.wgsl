// What the scene's surfaces and lights use (features/mod.rs, `SceneFeatures`), fixed
// per pipeline: a pass tests these before the per-surface field, so code
// for a feature no surface has folds away when the pipeline is compiled.
// A software rasterizer (llvmpipe) runs both sides of every branch under a
// mask; a real GPU skips them, but pays for their registers. The defaults
// (everything on) are correct for any scene.

// Some surface has a texture (base colour, metallic–roughness, emissive).
override TEXTURED: bool = true;
// Some surface is a cut-out (alphaMode MASK) or stochastically transparent
// (BLEND).
override CUT_OUTS: bool = true;
// Some surface reflects by the glTF BRDF's specular lobe (`Surface::glossy`).
override GLOSSY: bool = true;
// Some glossy surface has a clear coat (`Surface::clearcoat`; bsdf.wgsl's coat).
override COATED: bool = true;
// Some glossy surface has a sheen (`Surface::sheen_color`; bsdf.wgsl's sheen).
override SHEENED: bool = true;
// Some light is a sky or an emissive mesh (light_eval.wgsl's `sampled_radiance`).
override SAMPLED_LIGHTS: bool = true;
// The sky is an image (environment.wgsl).
override SKY_IMAGE: bool = true;
// Some medium fills the scene or a region (media.wgsl, view_depth.wgsl).
override MEDIA: bool = true;
// Some glTF surface lets a share of its light through as glass
// (`Surface::transmission`; surface_point.wgsl's `draw_layer`).
override MIXED: bool = true;
// Some glTF surface reads clear-coat, sheen, specular or clear-coat normal
// textures per point (`Surface::layer_textures`; surface_point.wgsl's
// `layer_texels` and `coat_normal`), and the G-buffer keeps their texels
// and the coat's normal in its fifth target (`gbuffer_layers`).
override LAYERED: bool = true;
// Some diffuse surface shades with a normal off its facets' (smooth vertex
// normals, spheres, normal textures): the G-buffer keeps its geometric
// normal and the photon gathers weigh shading_normal_factor
// (gbuffer/geometric_normal.wgsl).
override BENT: bool = true;

// Some diffuse surface has a normal texture: only then is the diffuse
// lobes' bump shadowing (bsdf.wgsl's `bump_term`) compiled in.
fn bump_mapped() -> bool {
    return TEXTURED && BENT;
}
