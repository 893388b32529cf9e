# Clear-coat and specular textures against Cycles (BENCHMARKS.md, "Layer
# textures against Cycles"): three balls on a grey floor before a wall,
# under a constant sky and a point light, each with a stripe texture
# (black and white bands, 8 around) driving one Principled input: a red
# paint ball's Coat Weight, a dark ball's Specular IOR Level, and for
# contrast the same red paint coated all over. Writes OUT/layer_textures.glb
# (Blender's glTF export: clearcoatTexture, specularTexture), OUT/sky.exr
# and OUT/cycles.exr (Cycles, GGX, 64 bounces of every kind).
#
#   SPP=512 python layer_textures.py -- OUT        (PyPI bpy and OpenEXR)
#   hikari render OUT/layer_textures.glb --environment OUT/sky.exr \
#       --renderer path --resolution 240x160 --spp 512 -o path.exr
#   python shared/relerr.py path.exr OUT/cycles.exr
import bpy, sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import balls_before_a_wall, constant_sky, export_and_render, exported_materials, principled_material
out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene

# Eight vertical bands around a UV sphere (u), alternately white and black.
stripes = bpy.data.images.new("stripes", 64, 8)
stripes.colorspace_settings.name = "Non-Color"
# The same bands in the alpha channel, for the specular (glTF reads its A).
stripes.pixels[:] = [v for y in range(8) for x in range(64) for v in [float((x // 8) % 2 == 0)] * 4]
stripes.alpha_mode = "CHANNEL_PACKED"
stripes.pack()


def textured(name, inputs, socket, output="Color"):
    """A Principled material of `inputs` whose `socket` reads the stripes'
    `output` (Color, or Alpha)."""
    m = principled_material(name, inputs)
    nodes, links = m.node_tree.nodes, m.node_tree.links
    image = nodes.new("ShaderNodeTexImage"); image.image = stripes; image.interpolation = "Closest"
    links.new(image.outputs[output], nodes["Principled BSDF"].inputs[socket])
    return m


paint = {"Base Color": (0.63, 0.07, 0.05, 1), "Roughness": 0.6, "Specular IOR Level": 0.5,
         "Coat Weight": 1.0, "Coat Roughness": 0.0, "Coat IOR": 1.5}
dark = {"Base Color": (0.05, 0.05, 0.06, 1), "Roughness": 0.25, "Specular IOR Level": 1.0}
grey = principled_material("grey", {"Base Color": (0.6, 0.6, 0.6, 1), "Roughness": 1.0, "Specular IOR Level": 0.0})
balls = [
    (-2.0, textured("striped coat", paint, "Coat Weight")),
    (0.0, textured("striped specular", dark, "Specular IOR Level", "Alpha")),
    (2.0, principled_material("coated paint", paint)),
]
balls_before_a_wall(scene, grey, balls)
constant_sky(scene, out, (0.5, 0.55, 0.6))
export_and_render(scene, out, "layer_textures")
for m in exported_materials(out, "layer_textures"):
    print(m.get("name"), m.get("extensions"))
