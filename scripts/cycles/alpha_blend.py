# Alpha blending against Cycles (BENCHMARKS.md, "alphaMode BLEND against
# Cycles"): on a grey floor before a wall, under a constant sky and a point
# light, a red pane of Alpha 0.5 (Blender writes alphaMode BLEND with the
# factor), a pane whose Alpha is a texture fading from 0 at its left edge
# to 1 at its right (BLEND, the texture's alpha) and an orange ball half
# behind the panes. Cycles draws Alpha as a mix with a transparent BSDF
# for camera, shadow and bounce rays alike; hikari's stochastic
# transparency should converge to the same. Writes OUT/alpha_blend.glb,
# OUT/sky.exr and OUT/cycles.exr.
#
#   SPP=512 python alpha_blend.py -- OUT        (PyPI bpy and OpenEXR)
#   hikari render OUT/alpha_blend.glb --environment OUT/sky.exr --renderer path \
#       --resolution 240x160 --spp 512 -o path.exr
#   python shared/relerr.py path.exr OUT/cycles.exr
import bpy, sys, os, math
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import (box, constant_sky, export_and_render, exported_materials, grey_floor_and_wall,
                    point_light_and_camera, principled_material, smooth_ball)
out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene

grey_floor_and_wall()


def pane(x, material):
    """An upright 1.6 m pane facing the camera at x, 0.6 m before the ball."""
    bpy.ops.mesh.primitive_plane_add(size=1.6, location=(x, -0.6, 0.9), rotation=(math.radians(90), 0, 0))
    bpy.context.object.data.materials.append(material)


half = principled_material("half red", {"Base Color": (0.8, 0.1, 0.1, 1), "Alpha": 0.5, "Roughness": 1.0,
                                        "Specular IOR Level": 0.0})
pane(-1.2, half)

# Alpha fading from 0 (left) to 1 (right), a blue-green colour.
w, h = 64, 4
img = bpy.data.images.new("fade", w, h, alpha=True)
a = np.broadcast_to((np.arange(w) + 0.5) / w, (h, w))
rgba = np.stack([np.full((h, w), 0.1), np.full((h, w), 0.5), np.full((h, w), 0.6), a], axis=2)
img.pixels.foreach_set(rgba.astype(np.float32).ravel())
img.filepath_raw = os.path.join(out, "fade.png"); img.file_format = "PNG"; img.save()
fade = principled_material("fade", {"Roughness": 1.0, "Specular IOR Level": 0.0})
nodes, links = fade.node_tree.nodes, fade.node_tree.links
tex = nodes.new("ShaderNodeTexImage"); tex.image = img; tex.interpolation = "Linear"
links.new(tex.outputs["Color"], nodes["Principled BSDF"].inputs["Base Color"])
links.new(tex.outputs["Alpha"], nodes["Principled BSDF"].inputs["Alpha"])
pane(1.2, fade)

ball = principled_material("orange", {"Base Color": (0.8, 0.4, 0.1, 1), "Roughness": 0.5})
smooth_ball((0, 0.6, 0.7), 0.7, ball)

point_light_and_camera(scene, (-1.5, -3.0, 3.5), 300.0)
constant_sky(scene, out, (0.3, 0.33, 0.36))
export_and_render(scene, out, "alpha_blend")

# What the exporter wrote: both panes must be BLEND for the comparison to mean anything.
for m in exported_materials(out, "alpha_blend"):
    print(m["name"], m.get("alphaMode", "OPAQUE"), m.get("pbrMetallicRoughness", {}).get("baseColorFactor"))
