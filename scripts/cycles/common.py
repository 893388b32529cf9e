# What the scripts comparing hikari with Cycles share: the sky written as
# an EXR for hikari's --environment, the glTF export and the Cycles render
# (GGX, 64 bounces of every kind, no denoising, linear EXR output).
import bpy, math, os
import numpy as np, OpenEXR, Imath


def principled_material(name, inputs):
    """A material of one Principled BSDF (GGX) with `inputs` (socket name: value)."""
    m = bpy.data.materials.new(name); m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    p.distribution = "GGX"
    for socket, value in inputs.items():
        p.inputs[socket].default_value = value
    return m


def normal_image(out, name, normals):
    """A non-colour PNG OUT/NAME.png of unit tangent-space `normals` (H×W×3,
    row 0 at the bottom as Blender stores pixels), packed into the file."""
    h, w, _ = normals.shape
    img = bpy.data.images.new(name, w, h, alpha=False)
    img.colorspace_settings.name = "Non-Color"
    rgba = np.concatenate([normals * 0.5 + 0.5, np.ones((h, w, 1))], axis=2)
    img.pixels.foreach_set(rgba.astype(np.float32).ravel())
    img.filepath_raw = os.path.join(out, name + ".png"); img.file_format = "PNG"; img.save()
    return img


def bump_normals(n, waves, amplitude):
    """The tangent-space normals (n×n×3, v up) of the height
    h = amplitude·sin(2π·waves·u)·sin(2π·waves·v) over the image."""
    u, v = np.meshgrid((np.arange(n) + 0.5) / n, (np.arange(n) + 0.5) / n)
    k = 2 * math.pi * waves
    dhdu = amplitude * k * np.cos(k * u) * np.sin(k * v)
    dhdv = amplitude * k * np.sin(k * u) * np.cos(k * v)
    bump = np.stack([-dhdu, -dhdv, np.ones_like(u)], axis=2)
    return bump / np.linalg.norm(bump, axis=2, keepdims=True)


def box(loc, size, material):
    bpy.ops.mesh.primitive_cube_add(location=loc)
    o = bpy.context.object
    o.scale = (size[0] / 2, size[1] / 2, size[2] / 2)
    bpy.ops.object.transform_apply(scale=True)
    o.data.materials.append(material)


def balls_before_a_wall(scene, floor_material, balls):
    """A floor and a back wall of `floor_material`, a ball of radius 0.8 at
    each (x, material) of `balls`, an 800 W point light of radius 0 and the
    camera the comparisons share."""
    box((0, 0, -0.05), (10, 6, 0.1), floor_material)      # floor
    box((0, 2.0, 1.5), (10, 0.2, 3), floor_material)      # back wall
    for x, mat in balls:
        bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=64, radius=0.8, location=(x, 0, 0.8))
        o = bpy.context.object; bpy.ops.object.shade_smooth(); o.data.materials.append(mat)
    point_light_and_camera(scene, (1.5, -2.5, 3.5), 800.0)


def grey_floor_and_wall():
    """The comparisons' stage: a matte grey floor and back wall (no
    specular reflection), 10 m wide."""
    grey = principled_material("grey", {"Base Color": (0.6, 0.6, 0.6, 1), "Roughness": 1.0, "Specular IOR Level": 0.0})
    box((0, 0, -0.05), (10, 6, 0.1), grey)
    box((0, 2.0, 1.5), (10, 0.2, 3), grey)


def smooth_ball(location, radius, material):
    """A smooth-shaded UV sphere (96 × 48) of `material`."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=96, ring_count=48, radius=radius, location=location)
    o = bpy.context.object; bpy.ops.object.shade_smooth(); o.data.materials.append(material)


def exported_materials(out, name):
    """The materials Blender's exporter wrote to OUT/NAME.glb (its JSON)."""
    import json, struct
    with open(os.path.join(out, name + ".glb"), "rb") as f:
        f.seek(12); n, _ = struct.unpack("<II", f.read(8)); return json.loads(f.read(n))["materials"]


def point_light_and_camera(scene, location, energy):
    """A point light of radius 0 at `location` and the camera the
    comparisons share (7 m before the origin, 1.8 m up)."""
    bpy.ops.object.light_add(type="POINT", location=location)
    light = bpy.context.object; light.data.energy = energy; light.data.shadow_soft_size = 0.0
    bpy.ops.object.camera_add(location=(0, -7, 1.8)); cam = bpy.context.object
    cam.rotation_euler = (math.radians(83), 0, 0); cam.data.lens = 30
    scene.camera = cam


def constant_sky(scene, out, sky):
    """A constant world of colour `sky`, and OUT/sky.exr (8x4) with the same."""
    world = bpy.data.worlds.new("w"); scene.world = world; world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (*sky, 1)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    # Written directly: a Blender image saved as EXR goes through its colour
    # management (0.8 came out as 0.906).
    header = OpenEXR.Header(8, 4)
    header["channels"] = {c: Imath.Channel(Imath.PixelType(Imath.PixelType.FLOAT)) for c in "RGB"}
    exr = OpenEXR.OutputFile(os.path.join(out, "sky.exr"), header)
    exr.writePixels({c: np.full(32, v, np.float32).tobytes() for c, v in zip("RGB", sky)})
    exr.close()


def export_and_render(scene, out, name, size=(240, 160)):
    """OUT/NAME.glb (Blender's glTF export) and OUT/cycles.exr at `size`."""
    scene.render.resolution_x, scene.render.resolution_y = size
    bpy.ops.export_scene.gltf(filepath=os.path.join(out, name + ".glb"), export_format="GLB",
                              export_lights=True, export_cameras=True)
    scene.render.engine = "CYCLES"; scene.cycles.samples = int(os.environ.get("SPP", "1024"))
    scene.cycles.device = "CPU"; scene.cycles.use_denoising = False
    for attr in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces", "transparent_max_bounces"):
        setattr(scene.cycles, attr, 64)
    scene.cycles.blur_glossy = 0.0
    scene.render.image_settings.file_format = "OPEN_EXR"; scene.render.image_settings.color_depth = "32"
    scene.view_settings.view_transform = "Standard"
    scene.render.filepath = os.path.join(out, "cycles.exr")
    bpy.ops.render.render(write_still=True)
