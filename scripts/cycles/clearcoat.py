# Clear coat against Cycles (BENCHMARKS.md, "Clear coat against Cycles"):
# three coated balls on a grey floor before a wall, under a constant sky
# and a point light: car paint (a rough red dielectric under a smooth
# coat), gold under a glossy coat (0.2) and a blue matte under a rough coat
# (0.5), with an uncoated red ball beside for contrast. Writes
# OUT/clearcoat.glb (Blender's glTF export: KHR_materials_clearcoat),
# OUT/sky.exr (the sky as an 8x4 EXR for hikari's --environment) and
# OUT/cycles.exr (Cycles, GGX, 64 bounces of every kind).
#
#   SPP=512 python clearcoat.py -- OUT        (PyPI bpy and OpenEXR)
#   hikari render OUT/clearcoat.glb --environment OUT/sky.exr --renderer path \
#       --resolution 240x160 --spp 512 -o path.exr
#   python shared/relerr.py path.exr OUT/cycles.exr
import bpy, sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import balls_before_a_wall, constant_sky, export_and_render, principled_material
out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
def principled(name, color, roughness, metallic=0.0, coat=0.0, coat_roughness=0.0, specular=0.5):
    return principled_material(name, {"Base Color": (*color, 1), "Roughness": roughness, "Metallic": metallic,
                                      "Specular IOR Level": specular, "Coat Weight": coat,
                                      "Coat Roughness": coat_roughness, "Coat IOR": 1.5})
grey = principled("grey", (0.6, 0.6, 0.6), 1.0, specular=0.0)
balls = [
    (-2.7, principled("plain red", (0.63, 0.07, 0.05), 0.6)),
    (-0.9, principled("car paint", (0.63, 0.07, 0.05), 0.6, coat=1.0, coat_roughness=0.0)),
    (0.9, principled("coated gold", (0.9, 0.75, 0.45), 0.4, metallic=1.0, coat=1.0, coat_roughness=0.2)),
    (2.7, principled("coated matte", (0.1, 0.2, 0.6), 1.0, specular=0.0, coat=1.0, coat_roughness=0.5)),
]
balls_before_a_wall(scene, grey, balls)
constant_sky(scene, out, (0.5, 0.55, 0.6))
export_and_render(scene, out, "clearcoat")
