# Partly transmissive materials against Cycles (BENCHMARKS.md,
# "Transmission below 1 against Cycles"): Principled BSDFs of Transmission
# Weight 0.5 (rough, tinted) and 0.25 (smooth, tinted), one of weight 0.6
# and metallic 0.5, on a grey floor before a wall under a constant sky.
# Writes OUT/mix.glb (Blender's glTF export: KHR_materials_transmission
# below 1), OUT/sky.exr and OUT/cycles.exr.
#
#   SPP=512 python transmission_mix.py -- OUT        (PyPI bpy and OpenEXR)
#   hikari render OUT/mix.glb --environment OUT/sky.exr --renderer path \
#       --resolution 240x160 --spp 512 -o path.exr
#   python shared/relerr.py path.exr OUT/cycles.exr
import bpy, sys, math, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import constant_sky, export_and_render, grey_floor_and_wall, principled_material, smooth_ball
out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
grey_floor_and_wall()
for x, inputs in (
    (-2.2, {"Base Color": (0.9, 0.6, 0.3, 1), "Roughness": 0.3, "Transmission Weight": 0.5, "IOR": 1.5}),
    (0.0, {"Base Color": (0.5, 0.8, 0.9, 1), "Roughness": 0.0, "Transmission Weight": 0.25, "IOR": 1.5}),
    (2.2, {"Base Color": (0.8, 0.8, 0.8, 1), "Roughness": 0.2, "Transmission Weight": 0.6, "Metallic": 0.5,
           "IOR": 1.5}),
):
    smooth_ball((x, 0, 0.9), 0.9, principled_material(f"mix{x}", inputs))
bpy.ops.object.camera_add(location=(0, -7, 1.6)); cam = bpy.context.object
cam.rotation_euler = (math.radians(83), 0, 0); cam.data.lens = 30
scene.camera = cam
constant_sky(scene, out, (0.8, 0.85, 1.0))
export_and_render(scene, out, "mix")
