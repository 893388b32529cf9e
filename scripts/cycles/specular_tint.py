# Specular tint against Cycles (BENCHMARKS.md, "Specular colour against
# Cycles"): four dielectric balls on a grey floor before a wall, under a
# constant sky and a point light: a red one (roughness 0.3) untinted, the
# same with a gold specular tint, a black one with a strong green-blue tint
# (roughness 0.5) and a smooth blue one with an orange tint. Writes
# OUT/specular_tint.glb (Blender's glTF export: KHR_materials_specular's
# specularColorFactor), OUT/sky.exr and OUT/cycles.exr (Cycles, GGX, 64
# bounces of every kind).
#
#   SPP=512 python specular_tint.py -- OUT        (PyPI bpy and OpenEXR)
#   hikari render OUT/specular_tint.glb --environment OUT/sky.exr --renderer path \
#       --resolution 240x160 --spp 512 -o path.exr
#   python shared/relerr.py path.exr OUT/cycles.exr
import bpy, sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import balls_before_a_wall, constant_sky, export_and_render, principled_material
out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
def principled(name, color, roughness, tint=(1, 1, 1), specular=0.5):
    return principled_material(name, {"Base Color": (*color, 1), "Roughness": roughness,
                                      "Specular IOR Level": specular, "Specular Tint": (*tint, 1)})
grey = principled("grey", (0.6, 0.6, 0.6), 1.0, specular=0.0)
balls = [
    (-2.7, principled("plain red", (0.63, 0.07, 0.05), 0.3)),
    (-0.9, principled("gold-tinted red", (0.63, 0.07, 0.05), 0.3, tint=(1.0, 0.8, 0.3))),
    (0.9, principled("tinted black", (0.0, 0.0, 0.0), 0.5, tint=(0.2, 1.0, 0.8))),
    (2.7, principled("orange-tinted blue", (0.1, 0.2, 0.6), 0.1, tint=(1.0, 0.5, 0.1))),
]
balls_before_a_wall(scene, grey, balls)
constant_sky(scene, out, (0.5, 0.55, 0.6))
export_and_render(scene, out, "specular_tint")
