# Sheen against Cycles (BENCHMARKS.md, "Sheen against Cycles"): three
# balls with a sheen on a grey floor before a wall, under a constant sky
# and a point light: red velvet (a white sheen of roughness 0.3 over a dark
# red Lambertian), a blue cloth with a blue sheen of roughness 0.6 and a
# smooth sheen (0.1) over a grey satin, with an unsheened red ball beside
# for contrast. Writes OUT/sheen.glb (Blender's glTF export:
# KHR_materials_sheen), OUT/sky.exr (the sky as an 8x4 EXR for hikari's
# --environment) and OUT/cycles.exr (Cycles, GGX, 64 bounces of every kind).
#
# Cycles draws Blender's own sheen (Zeltner et al. 2022's microfibre model,
# fitted by linearly transformed cosines); the glTF export maps it onto the
# extension's Charlie sheen, which hikari draws: the two models differ.
#
#   SPP=512 python sheen.py -- OUT        (PyPI bpy and OpenEXR)
#   hikari render OUT/sheen.glb --environment OUT/sky.exr --renderer path \
#       --resolution 240x160 --spp 512 -o path.exr
#   python shared/relerr.py path.exr OUT/cycles.exr
import bpy, sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import balls_before_a_wall, constant_sky, export_and_render, principled_material
out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
def principled(name, color, roughness, sheen=0.0, tint=(1, 1, 1), sheen_roughness=0.5, specular=0.5):
    return principled_material(name, {"Base Color": (*color, 1), "Roughness": roughness,
                                      "Specular IOR Level": specular, "Sheen Weight": sheen,
                                      "Sheen Tint": (*tint, 1), "Sheen Roughness": sheen_roughness})
grey = principled("grey", (0.6, 0.6, 0.6), 1.0, specular=0.0)
balls = [
    (-2.7, principled("plain red", (0.3, 0.02, 0.03), 1.0, specular=0.0)),
    (-0.9, principled("red velvet", (0.3, 0.02, 0.03), 1.0, specular=0.0, sheen=1.0, sheen_roughness=0.3)),
    (0.9, principled("blue cloth", (0.05, 0.1, 0.4), 1.0, specular=0.0, sheen=1.0, tint=(0.5, 0.6, 1.0),
                     sheen_roughness=0.6)),
    (2.7, principled("grey satin", (0.4, 0.4, 0.4), 0.5, sheen=1.0, sheen_roughness=0.1)),
]
balls_before_a_wall(scene, grey, balls)
constant_sky(scene, out, (0.5, 0.55, 0.6))
export_and_render(scene, out, "sheen")
