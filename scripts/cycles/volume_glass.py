# Coloured glass against Cycles (BENCHMARKS.md, "KHR_materials_volume
# against Cycles"): on a grey floor before a wall, under a constant sky and
# a point light, a clear glass cube 1.2 m wide and a slab 0.25 m thick, both
# of one material whose inside absorbs (a Volume Absorption node, colour
# (0.9, 0.5, 0.2) and density 1.5, and a "glTF Material Output" node with
# Thickness 1, which is how Blender's exporter writes KHR_materials_volume),
# and a plain glass ball for reference. Thick parts of the glass are darker
# than thin ones. Writes OUT/volume_glass.glb, OUT/sky.exr, OUT/cycles.exr.
#
#   SPP=512 python volume_glass.py -- OUT        (PyPI bpy and OpenEXR)
#   hikari render OUT/volume_glass.glb --environment OUT/sky.exr --renderer path \
#       --resolution 240x160 --spp 512 -o path.exr
#   python shared/relerr.py path.exr OUT/cycles.exr
import bpy, sys, os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import (box, constant_sky, export_and_render, exported_materials, grey_floor_and_wall,
                    point_light_and_camera, principled_material, smooth_ball)
out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene

grey_floor_and_wall()

glass = principled_material("coloured glass", {"Transmission Weight": 1.0, "Roughness": 0.0, "IOR": 1.5})
nodes, links = glass.node_tree.nodes, glass.node_tree.links
absorption = nodes.new("ShaderNodeVolumeAbsorption")
absorption.inputs["Color"].default_value = (0.9, 0.5, 0.2, 1)
absorption.inputs["Density"].default_value = 1.5
links.new(absorption.outputs["Volume"], nodes["Material Output"].inputs["Volume"])
# What the exporter reads the thickness from (non-zero: the glass has a volume).
group = bpy.data.node_groups.new("glTF Material Output", "ShaderNodeTree")
group.interface.new_socket("Thickness", in_out="INPUT", socket_type="NodeSocketFloat")
settings = nodes.new("ShaderNodeGroup"); settings.node_tree = group
settings.inputs["Thickness"].default_value = 1.0

box((-1.6, 0.2, 0.6), (1.2, 1.2, 1.2), glass)       # cube
box((0.4, 0.2, 0.8), (1.2, 0.25, 1.6), glass)       # slab, facing the camera
clear = principled_material("clear glass", {"Transmission Weight": 1.0, "Roughness": 0.0, "IOR": 1.5})
smooth_ball((2.2, 0.2, 0.6), 0.6, clear)

point_light_and_camera(scene, (-1.5, -3.0, 3.5), 300.0)
constant_sky(scene, out, (0.3, 0.33, 0.36))
export_and_render(scene, out, "volume_glass")

for m in exported_materials(out, "volume_glass"):
    print(m["name"], m.get("extensions", {}).get("KHR_materials_volume"))
