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
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import box, constant_sky, export_and_render
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
box((0, 0, -0.05), (8, 6, 0.1), grey)       # floor
box((0, 2.0, 1.5), (8, 0.2, 3), grey)       # back wall
for x, mat in ((-1.1, glass("rough", (0.9, 0.6, 0.3), 0.3)), (1.1, glass("smooth", (0.5, 0.8, 0.9), 0.0))):
    bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=64, radius=0.9, location=(x, 0, 0.9))
    o = bpy.context.object; bpy.ops.object.shade_smooth(); o.data.materials.append(mat)
bpy.ops.object.camera_add(location=(0, -6, 1.6)); cam = bpy.context.object
cam.rotation_euler = (math.radians(83), 0, 0); cam.data.lens = 35
scene.camera = cam
constant_sky(scene, out, (0.8, 0.85, 1.0))
export_and_render(scene, out, "glass")
