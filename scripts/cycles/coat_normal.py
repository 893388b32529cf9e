# The clear coat's own normal against Cycles (BENCHMARKS.md, "The clear
# coat's normal texture against Cycles"): three balls on a grey floor before
# a wall, under a constant sky and a point light, each a red paint under a
# coat: the first with fine bumps on its Coat Normal only (orange peel: the
# coat's highlights ripple over a smooth base), the second a dark metal
# under a 0.15-rough coat with the same bumps on its Coat Normal, the third
# with the bumps on the base's Normal only (its smooth coat must stay
# smooth: glTF's coat takes no normal texture but its own, and Cycles' Coat
# Normal defaults to the surface's). Writes OUT/coat_normal.glb (Blender's
# glTF export: clearcoatNormalTexture, normalTexture), OUT/sky.exr and
# OUT/cycles.exr.
#
#   SPP=512 python coat_normal.py -- OUT        (PyPI bpy and OpenEXR)
#   hikari render OUT/coat_normal.glb --environment OUT/sky.exr \
#       --renderer path --resolution 240x160 --spp 512 -o path.exr
#   python shared/relerr.py path.exr OUT/cycles.exr
import bpy, sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import (balls_before_a_wall, bump_normals, constant_sky, export_and_render, exported_materials,
                    normal_image, principled_material)
out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene

# Bumps: h = 0.025·sin(2π·8u)·sin(2π·8v) over the image.
bumps = normal_image(out, "bumps", bump_normals(256, 8, 0.025))


def bumped(name, inputs, socket):
    """A Principled material of `inputs` whose `socket` (Normal or Coat
    Normal) reads the bumps through a Normal Map node."""
    m = principled_material(name, inputs)
    nodes, links = m.node_tree.nodes, m.node_tree.links
    tex = nodes.new("ShaderNodeTexImage"); tex.image = bumps; tex.interpolation = "Linear"
    nm = nodes.new("ShaderNodeNormalMap")
    links.new(tex.outputs["Color"], nm.inputs["Color"])
    links.new(nm.outputs["Normal"], nodes["Principled BSDF"].inputs[socket])
    return m


paint = {"Base Color": (0.63, 0.07, 0.05, 1), "Roughness": 0.6, "Specular IOR Level": 0.5,
         "Coat Weight": 1.0, "Coat Roughness": 0.0, "Coat IOR": 1.5}
metal = {"Base Color": (0.2, 0.22, 0.25, 1), "Metallic": 1.0, "Roughness": 0.5,
         "Coat Weight": 1.0, "Coat Roughness": 0.15, "Coat IOR": 1.5}
grey = principled_material("grey", {"Base Color": (0.6, 0.6, 0.6, 1), "Roughness": 1.0, "Specular IOR Level": 0.0})
balls = [
    (-2.0, bumped("orange peel", paint, "Coat Normal")),
    (0.0, bumped("bumpy coat on metal", metal, "Coat Normal")),
    (2.0, bumped("bumpy paint, smooth coat", paint, "Normal")),
]
balls_before_a_wall(scene, grey, balls)
constant_sky(scene, out, (0.5, 0.55, 0.6))
export_and_render(scene, out, "coat_normal")
for m in exported_materials(out, "coat_normal"):
    print(m.get("name"), m.get("normalTexture"), m.get("extensions"))
