# Glass against Cycles (BENCHMARKS.md, "Glass against Cycles"): a rough
# tinted glass ball and a smooth tinted one on a grey floor before a wall,
# under a constant sky. Writes OUT/glass.glb (Blender's glTF export), OUT/sky.exr
# (the sky as an 8x4 EXR for hikari's --environment) and OUT/cycles.exr
# (Cycles, single-scatter GGX as hikari's, 64 bounces of every kind).
#
#   SPP=512 python glass.py -- OUT        (PyPI bpy and OpenEXR)
#   hikari render OUT/glass.glb --environment OUT/sky.exr --renderer path \
#       --resolution 240x160 --spp 512 -o path.exr
#   python shared/relerr.py path.exr OUT/cycles.exr
import bpy, sys, math, os
import numpy as np, OpenEXR, Imath
out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
grey = bpy.data.materials.new("grey"); grey.use_nodes = True
b = grey.node_tree.nodes["Principled BSDF"]
b.inputs["Base Color"].default_value = (0.6, 0.6, 0.6, 1)
b.inputs["Roughness"].default_value = 1.0
b.inputs["Specular IOR Level"].default_value = 0.0
def glass(name, color, roughness):
    m = bpy.data.materials.new(name); m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    p.distribution = "GGX"
    p.inputs["Base Color"].default_value = (*color, 1)
    p.inputs["Roughness"].default_value = roughness
    p.inputs["Transmission Weight"].default_value = 1.0
    p.inputs["IOR"].default_value = 1.5
    return m
def box(loc, size):
    bpy.ops.mesh.primitive_cube_add(location=loc)
    o = bpy.context.object; o.scale = (size[0] / 2, size[1] / 2, size[2] / 2)
    bpy.ops.object.transform_apply(scale=True)
    o.data.materials.append(grey)
box((0, 0, -0.05), (8, 6, 0.1))       # floor
box((0, 2.0, 1.5), (8, 0.2, 3))       # back wall
for x, mat in ((-1.1, glass("rough", (0.9, 0.6, 0.3), 0.3)), (1.1, glass("smooth", (0.5, 0.8, 0.9), 0.0))):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=64, radius=0.9, location=(x, 0, 0.9))
    o = bpy.context.object; bpy.ops.object.shade_smooth(); o.data.materials.append(mat)
bpy.ops.object.camera_add(location=(0, -6, 1.6)); cam = bpy.context.object
cam.rotation_euler = (math.radians(83), 0, 0); cam.data.lens = 35
scene.camera = cam
sky = (0.8, 0.85, 1.0)
world = bpy.data.worlds.new("w"); scene.world = world; world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (*sky, 1)
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
# Written directly: a Blender image saved as EXR goes through its colour
# management (0.8 came out as 0.906).
header = OpenEXR.Header(8, 4)
header["channels"] = {c: Imath.Channel(Imath.PixelType(Imath.PixelType.FLOAT)) for c in "RGB"}
exr = OpenEXR.OutputFile(os.path.join(out, "sky.exr"), header)
exr.writePixels({c: np.full(32, v, np.float32).tobytes() for c, v in zip("RGB", sky)})
exr.close()
scene.render.resolution_x = 240; scene.render.resolution_y = 160
bpy.ops.export_scene.gltf(filepath=os.path.join(out, "glass.glb"), export_format="GLB", export_lights=True, export_cameras=True)
scene.render.engine = "CYCLES"; scene.cycles.samples = int(os.environ.get("SPP", "1024")); scene.cycles.device = "CPU"
scene.cycles.use_denoising = False
for attr in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces", "transparent_max_bounces"):
    setattr(scene.cycles, attr, 64)
scene.cycles.blur_glossy = 0.0
scene.render.image_settings.file_format = "OPEN_EXR"; scene.render.image_settings.color_depth = "32"
scene.view_settings.view_transform = "Standard"
scene.render.filepath = os.path.join(out, "cycles.exr")
bpy.ops.render.render(write_still=True)
