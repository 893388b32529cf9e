# A skinned, animated "character" of about 100,000 triangles, exported from
# Blender as a user would: an open tube of a body on a chain of four
# bones that sway through a two-second loop, on a floor under a sun, with a
# camera. For `hikari view`'s per-frame deformation cost (#44):
#
#   /tmp/bpyenv/bin/python scripts/blender-exports/skinned_character.py -- OUT
#   hikari view OUT/skinned_character.glb --frames 60 --step 0.0333
import bpy, math, os, sys

out = sys.argv[sys.argv.index("--") + 1] if "--" in sys.argv else "."
os.makedirs(out, exist_ok=True)
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = 30
scene.frame_start, scene.frame_end = 1, 61

# The body: an open tube 2 m tall, 250 segments × 200 rows of quads,
# 100,000 triangles.
segments, rings = 250, 201
verts = [(0.3 * math.cos(2 * math.pi * i / segments), 0.3 * math.sin(2 * math.pi * i / segments), 2.0 * j / (rings - 1))
         for j in range(rings) for i in range(segments)]
faces = [(j * segments + i, j * segments + (i + 1) % segments, (j + 1) * segments + (i + 1) % segments,
          (j + 1) * segments + i) for j in range(rings - 1) for i in range(segments)]
mesh = bpy.data.meshes.new("body"); mesh.from_pydata(verts, [], faces); mesh.update()
body = bpy.data.objects.new("body", mesh)
scene.collection.objects.link(body)
bpy.context.view_layer.objects.active = body; body.select_set(True)
bpy.ops.object.shade_smooth()
skin = bpy.data.materials.new("skin"); skin.use_nodes = True
skin.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.8, 0.45, 0.3, 1)
skin.node_tree.nodes["Principled BSDF"].inputs["Roughness"].default_value = 0.6
body.data.materials.append(skin)

# Four bones up the body; each vertex weighted on the two nearest by height.
bpy.ops.object.armature_add(location=(0, 0, 0))
rig = bpy.context.object
rig.name = "rig"
bpy.ops.object.mode_set(mode="EDIT")
bones = rig.data.edit_bones
bones.remove(bones[0])
names = []
for k in range(4):
    b = bones.new(f"bone{k}")
    b.head = (0, 0, k * 0.5)
    b.tail = (0, 0, (k + 1) * 0.5)
    if k > 0:
        b.parent = bones[f"bone{k - 1}"]
        b.use_connect = True
    names.append(b.name)
bpy.ops.object.mode_set(mode="OBJECT")
groups = [body.vertex_groups.new(name=n) for n in names]
for v in body.data.vertices:
    z = (body.matrix_world @ v.co).z
    t = min(max(z / 0.5 - 0.5, 0.0), 2.999)   # between bone centres
    k = int(t); f = t - k
    groups[k].add([v.index], 1.0 - f, "REPLACE")
    groups[k + 1].add([v.index], f, "REPLACE")
body.parent = rig
mod = body.modifiers.new("rig", "ARMATURE"); mod.object = rig

# The sway: each bone turns about x through ±15° over two seconds.
for frame, angle in ((1, -15), (31, 15), (61, -15)):
    for n in names[1:]:
        pb = rig.pose.bones[n]
        pb.rotation_mode = "XYZ"
        pb.rotation_euler = (math.radians(angle), 0, 0)
        pb.keyframe_insert("rotation_euler", frame=frame)

# A floor, a sun and a camera.
bpy.ops.mesh.primitive_plane_add(size=8, location=(0, 0, 0))
grey = bpy.data.materials.new("grey"); grey.use_nodes = True
grey.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.6, 0.6, 0.6, 1)
bpy.context.object.data.materials.append(grey)
bpy.ops.object.light_add(type="SUN", rotation=(math.radians(40), 0, math.radians(30)))
bpy.context.object.data.energy = 3.0
bpy.ops.object.camera_add(location=(4.5, -4.5, 2.2), rotation=(math.radians(80), 0, math.radians(45)))
scene.camera = bpy.context.object

triangles = sum(len(p.vertices) - 2 for p in body.data.polygons)
print(f"body: {len(body.data.vertices)} vertices, {triangles} triangles")
bpy.ops.export_scene.gltf(filepath=os.path.join(out, "skinned_character.glb"), export_format="GLB",
                          export_animations=True, export_skins=True, export_lights=True, export_cameras=True)
