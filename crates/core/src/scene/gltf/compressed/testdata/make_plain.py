# A small textured scene exported from Blender, uncompressed: what gltfpack
# and gltf-transform compress into hikari's mesh-compression fixtures.
# Run: python make_plain.py -- OUTPUT_FOLDER (with PyPI's bpy).
import bpy, sys, math, os
out = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
img = bpy.data.images.new("checker", 8, 8)
px = []
for y in range(8):
    for x in range(8):
        v = 0.9 if (x // 2 + y // 2) % 2 == 0 else 0.1
        px += [0.9, 0.2, 0.1, 1.0] if (x < 2 and y >= 6) else [v, v, v, 1.0]
img.pixels = px
img.filepath_raw = os.path.join(out, "checker.png"); img.file_format = "PNG"; img.save()
def textured(name):
    mat = bpy.data.materials.new(name); mat.use_nodes = True
    nt = mat.node_tree; bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Roughness"].default_value = 1.0
    tex = nt.nodes.new("ShaderNodeTexImage"); tex.image = img; tex.interpolation = "Closest"
    nt.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    return mat
bpy.ops.mesh.primitive_plane_add(size=4); floor = bpy.context.object
floor.data.materials.append(textured("floor"))
bpy.ops.mesh.primitive_uv_sphere_add(radius=0.8, location=(0, 0, 0.8), segments=24, ring_count=12)
ball = bpy.context.object; bpy.ops.object.shade_smooth()
ball.data.materials.append(textured("ball"))
bpy.ops.object.light_add(type="SUN", location=(0, 0, 5)); sun = bpy.context.object
sun.data.energy = 3.0; sun.rotation_euler = (math.radians(20), 0, 0)
bpy.ops.object.camera_add(location=(0, -5, 3)); cam = bpy.context.object
cam.rotation_euler = (math.radians(60), 0, 0); cam.data.lens = 35
scene.camera = cam
common = dict(export_format="GLB", export_lights=True, export_cameras=True)
bpy.ops.export_scene.gltf(filepath=os.path.join(out, "plain.glb"), **common)
