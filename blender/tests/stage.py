"""The scenes the add-on's tests render, built in Blender's Python as a
user would build them."""

import math

import bpy


def principled(name, color, roughness=0.5, metallic=0.0, specular=0.5, emission=None, strength=0.0):
    m = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        m.use_nodes = True
    p = m.node_tree.nodes["Principled BSDF"]
    p.distribution = "GGX"
    p.inputs["Base Color"].default_value = (*color, 1.0)
    p.inputs["Roughness"].default_value = roughness
    p.inputs["Metallic"].default_value = metallic
    p.inputs["Specular IOR Level"].default_value = specular
    if emission is not None:
        p.inputs["Emission Color"].default_value = (*emission, 1.0)
        p.inputs["Emission Strength"].default_value = strength
    return m


def box(name, location, size, material):
    bpy.ops.mesh.primitive_cube_add(location=location)
    o = bpy.context.object
    o.name = name
    o.scale = (size[0] / 2, size[1] / 2, size[2] / 2)
    bpy.ops.object.transform_apply(scale=True)
    o.data.materials.append(material)
    return o


def empty_scene(width=64, height=48):
    # The startup file's settings with no data; unlike a factory reset it
    # keeps the preferences, and with them the installed add-on.
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    return scene


def camera(scene, location, rotation_deg, lens=30.0):
    bpy.ops.object.camera_add(location=location)
    cam = bpy.context.object
    cam.rotation_euler = tuple(math.radians(a) for a in rotation_deg)
    cam.data.lens = lens
    scene.camera = cam
    return cam


def world_color(scene, color, strength=1.0):
    world = bpy.data.worlds.new("sky")
    scene.world = world
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    background = world.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (*color, 1.0)
    background.inputs["Strength"].default_value = strength
    return world


def light(kind, location, energy, rotation_deg=(0, 0, 0), **data):
    bpy.ops.object.light_add(type=kind, location=location)
    o = bpy.context.object
    o.rotation_euler = tuple(math.radians(a) for a in rotation_deg)
    o.data.energy = energy
    for key, value in data.items():
        setattr(o.data, key, value)
    return o


def floor_and_balls(scene):
    """A grey floor and back wall, a plastic and a metal ball, a world of
    dim blue, a camera: what the lights of each test fall on."""
    grey = principled("grey", (0.5, 0.5, 0.5), roughness=1.0, specular=0.0)
    box("floor", (0, 0, -0.05), (8, 6, 0.1), grey)
    box("wall", (0, 2.0, 1.5), (8, 0.2, 3), grey)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=0.6, location=(-0.8, 0, 0.6))
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(principled("plastic", (0.7, 0.15, 0.1), roughness=0.4))
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=0.6, location=(0.8, 0, 0.6))
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(principled("metal", (0.9, 0.8, 0.5), roughness=0.3, metallic=1.0))
    world_color(scene, (0.05, 0.06, 0.1))
    camera(scene, (0, -6, 1.6), (84, 0, 0))


def cycles(scene, samples, seed=0):
    """Cycles as the comparisons take it: CPU, no denoising, box filter,
    GGX, bounces as hikari's."""
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.seed = seed
    scene.cycles.pixel_filter_type = "BOX"
    scene.cycles.filter_width = 1.0
    for attr in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces"):
        setattr(scene.cycles, attr, 16)
    scene.cycles.blur_glossy = 0.0
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0


def render_to(scene, path):
    """Renders the current frame to a multilayer EXR at `path`."""
    settings = scene.render.image_settings
    if hasattr(settings, "media_type"):
        settings.media_type = "MULTI_LAYER_IMAGE"
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)


def checker_floor_material():
    """A Principled BSDF whose Base Color is an 8 × 8 checker image (two
    greys, sRGB-encoded 0.25 and 0.6), as an artist's textured floor. 256
    texels a side: the squares' edges are sharp (a coarse image's bilinear
    ramps, which Cycles and hikari place a fraction of a texel apart, made
    blocks straddling an edge differ by 10%)."""
    import numpy as np

    image = bpy.data.images.new("checker", 256, 256, alpha=False)
    squares = (np.indices((256, 256)) // 32).sum(axis=0) % 2
    value = np.where(squares == 0, 0.25, 0.6).astype(np.float32)
    rgba = np.stack([value, value, value, np.ones_like(value)], axis=-1)
    image.pixels.foreach_set(rgba.ravel())
    image.pack()
    m = principled("checker floor", (1, 1, 1), roughness=1.0, specular=0.0)
    nodes = m.node_tree.nodes
    texture = nodes.new("ShaderNodeTexImage")
    texture.image = image
    m.node_tree.links.new(texture.outputs["Color"], nodes["Principled BSDF"].inputs["Base Color"])
    return m


def lit_stage(scene):
    """floor_and_balls on a checker floor, lit by a sun, a spot, an area
    light (out of view) and an emissive strip on the wall."""
    floor_and_balls(scene)
    bpy.data.objects["floor"].data.materials[0] = checker_floor_material()
    light("SUN", (0, 0, 5), 2.0, (40, 0, 30))
    light("SPOT", (2.5, -2.0, 3.0), 400.0, (45, 0, 50), spot_size=math.radians(60), spot_blend=0.2,
          shadow_soft_size=0.0)
    light("AREA", (0, -2, 3.8), 300.0, size=1.0)
    glow = principled("glow", (0, 0, 0), emission=(1.0, 0.8, 0.5), strength=4.0)
    box("strip", (0, 1.88, 2.4), (3, 0.04, 0.1), glow)


def room(scene):
    """The issue's room: 6 m × 6 m × 3 m inside, lit by a sun through a
    window in its left wall (and the sky's light with it), a spot on the
    ceiling and an emissive strip on the right wall; a checker floor, a
    plastic and a metal ball; the camera in a corner of the room."""
    white = principled("plaster", (0.7, 0.7, 0.7), roughness=1.0, specular=0.0)
    floor = box("floor", (0, 0, -0.1), (6.4, 6.4, 0.2), checker_floor_material())
    floor.data.materials[0] = bpy.data.materials["checker floor"]
    box("ceiling", (0, 0, 3.1), (6.4, 6.4, 0.2), white)
    box("back", (0, 3.1, 1.5), (6.4, 0.2, 3.0), white)
    box("front", (0, -3.1, 1.5), (6.4, 0.2, 3.0), white)
    box("right", (3.1, 0, 1.5), (0.2, 6.0, 3.0), white)
    # The left wall around a window 2 m wide, from 0.9 m to 2.3 m.
    box("left below", (-3.1, 0, 0.45), (0.2, 6.0, 0.9), white)
    box("left above", (-3.1, 0, 2.65), (0.2, 6.0, 0.7), white)
    box("left back", (-3.1, 2.0, 1.6), (0.2, 2.0, 1.4), white)
    box("left front", (-3.1, -2.0, 1.6), (0.2, 2.0, 1.4), white)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=0.5, location=(-0.6, 1.0, 0.5))
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(principled("plastic", (0.7, 0.15, 0.1), roughness=0.4))
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=0.5, location=(0.8, 0.3, 0.5))
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(principled("metal", (0.9, 0.8, 0.5), roughness=0.3, metallic=1.0))
    glow = principled("glow", (0, 0, 0), emission=(1.0, 0.8, 0.5), strength=6.0)
    box("strip", (2.98, 0.5, 2.2), (0.04, 2.0, 0.1), glow)
    world_color(scene, (0.3, 0.4, 0.6))
    light("SUN", (-5, 0, 4), 4.0, (0, -55, 0))
    light("SPOT", (0.8, 0.3, 2.95), 300.0, (0, 0, 0), spot_size=math.radians(50), spot_blend=0.3,
          shadow_soft_size=0.0)
    camera(scene, (1.8, -2.6, 1.6), (82, 0, 28), lens=16.0)


def hdri_world(scene, strength=1.5):
    """A world lit by an equirectangular float image (a bright warm band
    low in the west, a blue zenith, a dark ground), as an HDRI would."""
    import numpy as np

    width, height = 64, 32
    image = bpy.data.images.new("sky", width, height, alpha=False, float_buffer=True)
    v, u = np.mgrid[0:height, 0:width] + 0.5
    elevation = (0.5 - v / height) * np.pi  # Blender's rows run bottom to top: row 0 is the nadir
    elevation = -elevation
    blue = np.where(elevation > 0, 0.2 + 0.6 * np.sin(elevation), 0.05)
    sun = np.exp(-(((u / width - 0.25) * 8) ** 2 + ((elevation - 0.3) * 6) ** 2)) * 20
    rgba = np.stack([blue * 0.6 + sun, blue * 0.8 + sun * 0.8, blue + sun * 0.5, np.ones_like(blue)], axis=-1)
    image.pixels.foreach_set(rgba.astype(np.float32).ravel())
    image.pack()
    world = world_color(scene, (0, 0, 0), strength)
    tree = world.node_tree
    texture = tree.nodes.new("ShaderNodeTexEnvironment")
    texture.image = image
    tree.links.new(texture.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    return world


def instanced(scene):
    """Things drawn as instances, each kind of Blender's: balls a geometry-
    nodes modifier puts on a grid's points, cubes a hair particle system
    scatters on a plane, and a collection instance; on a grey floor under
    a sun."""
    grey = principled("grey", (0.5, 0.5, 0.5), roughness=1.0, specular=0.0)
    box("floor", (0, 0, -0.05), (8, 8, 0.1), grey)
    bpy.ops.mesh.primitive_ico_sphere_add(radius=0.25, subdivisions=3, location=(0, 0, -20))
    ball = bpy.context.object
    ball.data.materials.append(principled("red", (0.8, 0.1, 0.1), roughness=0.6))
    ball.hide_render = True  # drawn only where the modifier puts it
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=3, y_subdivisions=3, size=2, location=(-1.5, 0, 0.25))
    tree = bpy.data.node_groups.new("balls on points", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    inputs, outputs = tree.nodes.new("NodeGroupInput"), tree.nodes.new("NodeGroupOutput")
    on_points, info = tree.nodes.new("GeometryNodeInstanceOnPoints"), tree.nodes.new("GeometryNodeObjectInfo")
    info.inputs["Object"].default_value = ball
    tree.links.new(inputs.outputs[0], on_points.inputs["Points"])
    tree.links.new(info.outputs["Geometry"], on_points.inputs["Instance"])
    tree.links.new(on_points.outputs["Instances"], outputs.inputs[0])
    bpy.context.object.modifiers.new("balls", "NODES").node_group = tree
    things = bpy.data.collections.new("things")
    cube = box("cube", (0, 0, 0.2), (0.4, 0.4, 0.4), principled("blue", (0.1, 0.2, 0.8), roughness=0.5))
    for owner in cube.users_collection:
        owner.objects.unlink(cube)
    things.objects.link(cube)
    bpy.ops.object.collection_instance_add(collection=things.name, location=(0, 1.5, 0))
    bpy.ops.mesh.primitive_plane_add(size=2, location=(1.5, 0, 0.001))
    bpy.context.object.data.materials.append(grey)
    hair = bpy.context.object.modifiers.new("scatter", "PARTICLE_SYSTEM").particle_system.settings
    hair.type, hair.count, hair.use_advanced_hair = "HAIR", 6, True
    hair.render_type, hair.instance_object, hair.particle_size = "OBJECT", cube, 0.3
    light("SUN", (0, 0, 5), 3.0, (35, 0, 25))
    world_color(scene, (0.05, 0.06, 0.1))
    camera(scene, (0, -5.5, 3.5), (58, 0, 0))
