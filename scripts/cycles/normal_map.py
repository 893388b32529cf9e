# Normal textures against Cycles (BENCHMARKS.md, "Normal textures against
# Cycles"): on a grey floor before a wall, under a constant sky and a point
# light, three upright tiles whose normal texture tilts every normal the
# same way (up and to the right of the image), one with plain texture
# coordinates, one mirrored left to right, one turned a quarter, and a
# smooth ball under a tiled bump pattern. What each shows depends on the
# tangent frame alone: hikari's must be Blender's (MikkTSpace, with the
# image's +Y up). Writes OUT/normal_map.glb (no TANGENT: tangents are the
# reader's to make), OUT/normal_map_tangents.glb (Blender's own tangents),
# OUT/sky.exr and OUT/cycles.exr.
#
#   SPP=512 python normal_map.py -- OUT        (PyPI bpy and OpenEXR)
#   hikari render OUT/normal_map.glb --environment OUT/sky.exr --renderer path \
#       --resolution 240x160 --spp 512 -o path.exr
#   python shared/relerr.py path.exr OUT/cycles.exr
import bpy, sys, os, math
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import (bump_normals, constant_sky, export_and_render, grey_floor_and_wall, normal_image,
                    point_light_and_camera, principled_material)
out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene


def normal_mapped(name, image, color):
    m = principled_material(name, {"Base Color": (*color, 1), "Roughness": 0.5})
    nodes, links = m.node_tree.nodes, m.node_tree.links
    tex = nodes.new("ShaderNodeTexImage"); tex.image = image; tex.interpolation = "Linear"
    nm = nodes.new("ShaderNodeNormalMap")
    links.new(tex.outputs["Color"], nm.inputs["Color"])
    links.new(nm.outputs["Normal"], nodes["Principled BSDF"].inputs["Normal"])
    return m


# Every normal tilted up and to the right of the image.
tilt = np.array([0.45, 0.35, 0.0]); tilt[2] = math.sqrt(1 - tilt[0] ** 2 - tilt[1] ** 2)
tilted = normal_image(out, "tilted", np.broadcast_to(tilt, (8, 8, 3)).copy())
# Bumps: h = 0.02·sin(2π·8u)·sin(2π·8v) over the image.
bumps = normal_image(out, "bumps", bump_normals(256, 8, 0.02))

grey_floor_and_wall()


def tile(x, uv_map):
    """An upright 1.4 m tile facing the camera, its corners' coordinates
    moved by `uv_map` ((u, v) → (u, v))."""
    bpy.ops.mesh.primitive_plane_add(size=1.4, location=(x, 0, 0.9), rotation=(math.radians(90), 0, 0))
    o = bpy.context.object
    for loop in o.data.uv_layers.active.data:
        loop.uv = uv_map(*loop.uv)
    o.data.materials.append(normal_mapped(f"tile {x}", tilted, (0.5, 0.5, 0.5)))


tile(-3.0, lambda u, v: (u, v))
tile(-1.4, lambda u, v: (1 - u, v))       # mirrored left to right
tile(0.2, lambda u, v: (v, 1 - u))        # turned a quarter
bpy.ops.mesh.primitive_uv_sphere_add(segments=96, ring_count=48, radius=0.8, location=(2.2, 0, 0.8))
o = bpy.context.object; bpy.ops.object.shade_smooth()
o.data.materials.append(normal_mapped("bumpy ball", bumps, (0.6, 0.45, 0.3)))

point_light_and_camera(scene, (-1.5, -3.0, 3.5), 300.0)
constant_sky(scene, out, (0.3, 0.33, 0.36))
scene.render.resolution_x, scene.render.resolution_y = 240, 160
bpy.ops.export_scene.gltf(filepath=os.path.join(out, "normal_map_tangents.glb"), export_format="GLB",
                          export_lights=True, export_cameras=True, export_tangents=True)
export_and_render(scene, out, "normal_map")
