"""The scene as Blender evaluates it, in files hikari loads: Blender's own
glTF exporter writes the meshes, materials, cameras and punctual lights at
the current frame; area lights are added to that file as emitting polygons
(the exporter drops them); the world becomes an equirectangular EXR.
Everything this route loses is a warning (docs/blender.md)."""

import math
import os
from dataclasses import dataclass, field

import bpy
import numpy as np

from .glb import Glb, ellipse, png


@dataclass
class Exported:
    """What `export_scene` wrote and what the render should be told."""

    glb: str
    camera: str | None
    environment: str | None
    warnings: list = field(default_factory=list)


def to_gltf(p) -> tuple:
    """A point or direction of Blender's Z-up frame in glTF's Y-up one (the
    exporter's export_yup)."""
    return (p[0], p[2], -p[1])


def area_light_polygon(light, matrix_world) -> list:
    """The area light's shape as polygon corners in glTF's frame, counter-
    clockwise seen from below (its local −Z, the side it lights)."""
    half_x = light.size / 2
    half_y = (light.size_y if light.shape in {"RECTANGLE", "ELLIPSE"} else light.size) / 2
    if light.shape in {"SQUARE", "RECTANGLE"}:
        local = [(-half_x, -half_y, 0.0), (half_x, -half_y, 0.0), (half_x, half_y, 0.0), (-half_x, half_y, 0.0)]
    else:
        local = ellipse(half_x, half_y)
    # Counter-clockwise seen from +Z is clockwise from −Z: reversed.
    local.reverse()
    return [to_gltf(matrix_world @ _vector(c)) for c in local]


def _vector(c):
    from mathutils import Vector

    return Vector(c)


def spot_inner_angle(spot_size: float, spot_blend: float) -> float:
    """The inner cone angle (radians) for hikari's linear-in-angle ramp that
    stands for Blender's spot blend: Blender ramps by a smoothstep in cos θ
    from cos θo + (1 − cos θo)·blend down to cos θo (θo = spot_size / 2);
    a ramp over the same angles holds the same light (a smoothstep and a
    line over one interval have the same integral). The exporter writes
    θo·(1 − blend), a ramp about twice as wide: hikari drew spots narrower
    than Cycles (blocks at the cone's edge 10–17% darker)."""
    cos_outer = math.cos(spot_size / 2)
    return math.acos(min(1.0, cos_outer + (1 - cos_outer) * spot_blend))


def match_spot_blends(glb: Glb, scene) -> int:
    """Sets each exported spot light's inner cone angle from its Blender
    light (spot_inner_angle); returns how many it set."""
    lights = glb.json.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    changed = 0
    for node in glb.json.get("nodes", []):
        index = node.get("extensions", {}).get("KHR_lights_punctual", {}).get("light")
        obj = scene.objects.get(node.get("name", ""))
        if index is None or index >= len(lights) or obj is None or obj.type != "LIGHT" or obj.data.type != "SPOT":
            continue
        spot = lights[index].get("spot")
        if spot is not None:
            spot["innerConeAngle"] = spot_inner_angle(obj.data.spot_size, obj.data.spot_blend)
            changed += 1
    return changed


def srgb_bytes(linear) -> "np.ndarray":
    """Linear values as 8-bit sRGB (clipped to [0, 1])."""
    c = np.clip(linear, 0.0, 1.0)
    encoded = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    return np.round(encoded * 255).astype(np.uint8)


def blender_image(name: str):
    """The Blender image the exporter named `name`: the one of that name,
    else the only one whose name less its extension is `name` (the
    exporter names a file image "checker.png" "checker"); None where none
    or several are."""
    exact = bpy.data.images.get(name)
    if exact is not None:
        return exact
    stems = [i for i in bpy.data.images if os.path.splitext(i.name)[0] == name]
    return stems[0] if len(stems) == 1 else None


def encode_linear_colour_images(glb: Glb):
    """Blender's exporter writes an image whose colour space is not sRGB (a
    float image, Linear or Non-Color) into its PNG as the values are, and
    glTF readers decode colour textures as sRGB: a 0.1/0.9 checker drew
    with albedo mean 0.40 where Cycles' is 0.50. Such images, where every
    use reads them as colour, are written again from Blender's pixels,
    encoded as sRGB (alpha as it is). Returns how many, and warnings for
    those also read as data (left as exported) and for colour images whose
    Blender image cannot be told (their colour space unknown)."""
    count, notes = 0, []
    uses = glb.color_images()
    for index, image in enumerate(glb.json.get("images", [])):
        if index not in uses:
            continue
        source = blender_image(image.get("name", ""))
        if source is None:
            notes.append(f"image {image.get('name', index)}: no one Blender image of that name; read as sRGB "
                         "colour whatever its colour space")
            continue
        if source.colorspace_settings.name.startswith("sRGB"):
            continue
        if not uses[index]:
            notes.append(f"image {source.name}: in colour space {source.colorspace_settings.name}, read both as "
                         "colour and as data; the exporter writes it unconverted, so as colour it draws darker")
            continue
        width, height = source.size
        if width == 0 or height == 0:
            continue
        pixels = np.empty(width * height * source.channels, dtype=np.float32)
        source.pixels.foreach_get(pixels)
        linear = pixels.reshape(height, width, source.channels)[::-1]
        rgba = np.empty((height, width, 4), dtype=np.uint8)
        rgba[:, :, :3] = srgb_bytes(linear[:, :, :3]) if source.channels >= 3 else srgb_bytes(linear[:, :, :1])
        rgba[:, :, 3] = np.round(np.clip(linear[:, :, 3], 0, 1) * 255) if source.channels == 4 else 255
        glb.replace_image(index, png(rgba))
        count += 1
    return count, notes


def faces_camera_in_view(scene, camera, matrix_world) -> bool:
    """Whether an area light's lit side (local −Z) faces the camera with its
    centre inside the frame."""
    from bpy_extras.object_utils import world_to_camera_view

    centre = matrix_world.to_translation()
    facing = (matrix_world.to_3x3() @ _vector((0.0, 0.0, -1.0))).dot(camera.matrix_world.to_translation() - centre) > 0
    seen = world_to_camera_view(scene, camera, centre)
    return facing and 0 <= seen.x <= 1 and 0 <= seen.y <= 1 and seen.z > 0


def polygon_area(polygon) -> float:
    """The area of a flat, convex polygon."""
    a = np.asarray(polygon, dtype=np.float64)
    cross = np.zeros(3)
    for i in range(1, len(a) - 1):
        cross += np.cross(a[i] - a[0], a[i + 1] - a[0])
    return float(np.linalg.norm(cross) / 2)


def area_light_radiance(light, area: float) -> tuple:
    """A Lambertian one-sided emitter of `area` m² whose power is the
    light's: Φ = π A L, so L = Φ / (π A) per colour channel."""
    scale = light.energy / (math.pi * area)
    return tuple(c * scale for c in light.color)


def light_warnings(name: str, light) -> list:
    """What hikari does not take from one light."""
    notes = []
    if getattr(light, "use_temperature", False):
        notes.append(f"light {name}: its colour temperature is ignored (the Color is used)")
    # Blender 5 always uses a light's nodes where it has any (use_nodes is deprecated).
    uses_nodes = bpy.app.version >= (5, 0, 0) or light.use_nodes
    if uses_nodes and light.node_tree is not None and len(light.node_tree.nodes) > 2:
        notes.append(f"light {name}: its node setup is ignored (its Color and Power are used)")
    if light.type == "AREA" and getattr(light, "spread", math.pi) < math.pi - 1e-4:
        notes.append(f"light {name}: Spread {math.degrees(light.spread):.0f}° is drawn as 180° (a Lambertian emitter)")
    if light.type in {"POINT", "SPOT"} and light.shadow_soft_size > 0:
        notes.append(f"light {name}: Radius {light.shadow_soft_size:g} m is drawn as 0 (hard shadows)")
    # Blender's default sun (0.526°) is drawn sharp enough to pass unnoted.
    if light.type == "SUN" and light.angle > math.radians(1.0):
        notes.append(f"light {name}: Angle {math.degrees(light.angle):.2g}° is drawn as 0 (hard shadows)")
    return notes


def world_environment(world, path: str):
    """The world as an equirectangular EXR at `path` (or None where it is
    black), and warnings for what that leaves out."""
    import hikari_render as hk

    if world is None:
        return None, []
    notes = []
    color, strength, image = tuple(world.color), 1.0, None
    # Blender 5 always uses the world's nodes (use_nodes is deprecated).
    uses_nodes = bpy.app.version >= (5, 0, 0) or world.use_nodes
    tree = world.node_tree if uses_nodes else None
    if tree is not None:
        output = next((n for n in tree.nodes if n.type == "OUTPUT_WORLD" and n.is_active_output), None)
        links = output.inputs["Surface"].links if output else []
        background = links[0].from_node if links else None
        if background is None:
            return None, []
        if background.type != "BACKGROUND":
            notes.append(f"world {world.name}: a {background.bl_label} node is drawn black (hikari reads a Background node)")
            return None, notes
        strength_socket = background.inputs["Strength"]
        strength = strength_socket.default_value
        if strength_socket.links:
            notes.append(f"world {world.name}: a linked Strength is read as {strength:g}")
        color_socket = background.inputs["Color"]
        color = tuple(color_socket.default_value)[:3]
        if color_socket.links:
            source = color_socket.links[0].from_node
            if source.type == "TEX_ENVIRONMENT" and source.image is not None:
                image = source.image
                if source.inputs["Vector"].links:
                    notes.append(f"world {world.name}: the environment texture's mapping is ignored")
                if source.projection != "EQUIRECTANGULAR":
                    notes.append(f"world {world.name}: a {source.projection} environment is read as equirectangular")
            else:
                notes.append(f"world {world.name}: a {source.bl_label} node drives the sky's colour; "
                             f"drawn as its unlinked colour {tuple(round(c, 3) for c in color)}")
    if image is not None:
        width, height = image.size
        if width == 0 or height == 0:
            notes.append(f"world {world.name}: image {image.name} could not be read; drawn black")
            return None, notes
        pixels = np.empty(width * height * image.channels, dtype=np.float32)
        image.pixels.foreach_get(pixels)
        # Blender's rows run bottom to top; hikari's maps top to bottom.
        rgb = pixels.reshape(height, width, image.channels)[::-1, :, :3] * strength
        if not image.is_float:
            notes.append(f"world {world.name}: image {image.name} is not a float image; its values are read as linear")
    else:
        rgb = np.empty((4, 8, 3), dtype=np.float32)
        rgb[:] = np.asarray(color[:3], dtype=np.float32) * strength
    rgb = np.ascontiguousarray(np.nan_to_num(rgb, nan=0.0, posinf=0.0).clip(0.0, None), dtype=np.float32)
    if float(rgb.max()) <= 0.0:
        return None, notes
    hk.save(path, rgb)
    return path, notes


# Shader nodes the glTF exporter turns into glTF material properties (a
# Principled BSDF and what feeds it: image textures with their UV maps and
# mapping, channel splits, factors, emission, the unlit and transparent
# mixes, its "glTF Material Output" group). Any other node on the way to
# the Material Output is dropped by the exporter, and so unseen by hikari.
EXPORTED_NODES = {
    "OUTPUT_MATERIAL", "BSDF_PRINCIPLED", "EMISSION", "BSDF_TRANSPARENT", "MIX_SHADER", "ADD_SHADER",
    "LIGHT_PATH", "TEX_IMAGE", "NORMAL_MAP", "MAPPING", "UVMAP", "TEX_COORD", "SEPARATE_COLOR", "SEPARATE_RGB",
    "MIX", "MIX_RGB", "MATH", "RGB", "VALUE", "VERTEX_COLOR", "ATTRIBUTE", "GROUP", "GROUP_INPUT",
    "GROUP_OUTPUT", "REROUTE", "AMBIENT_OCCLUSION",
}


def principled_unread(node) -> list:
    """The Principled BSDF's settings neither glTF nor hikari carry, where
    they change what it looks like (inputs left linked are the node walk's)."""

    def value(name, default):
        socket = node.inputs.get(name)
        return default if socket is None else socket.default_value

    unread = []
    if value("Subsurface Weight", 0.0) > 0:
        unread.append("subsurface scattering")
    if value("Thin Film Thickness", 0.0) > 0:
        unread.append("thin film")
    if value("Diffuse Roughness", 0.0) > 0:
        unread.append("diffuse roughness")
    if value("Coat Weight", 0.0) > 0:
        if tuple(value("Coat Tint", (1, 1, 1, 1)))[:3] != (1.0, 1.0, 1.0):
            unread.append("coat tint")
        if abs(value("Coat IOR", 1.5) - 1.5) > 1e-3:
            unread.append("coat IOR other than 1.5")
    return unread


def material_warnings(material) -> list:
    """What of `material`'s node tree the glTF exporter does not write."""
    tree = material.node_tree
    if tree is None:
        return []
    output = next((n for n in tree.nodes if n.type == "OUTPUT_MATERIAL" and n.is_active_output), None)
    if output is None:
        return [f"material {material.name}: no Material Output; drawn as the exporter's default grey"]
    notes = []
    for socket, what in [("Volume", "its volume shader"), ("Displacement", "its displacement")]:
        if socket in output.inputs and output.inputs[socket].links:
            notes.append(f"material {material.name}: {what} is not exported (not drawn)")
    unread, seen, stack = [], set(), [link.from_node for link in output.inputs["Surface"].links]
    while stack:
        node = stack.pop()
        if node.name in seen:
            continue
        seen.add(node.name)
        if node.type not in EXPORTED_NODES:
            unread.append(node.bl_label or node.type)
            continue
        stack.extend(link.from_node for socket in node.inputs for link in socket.links)
    for node in tree.nodes:
        if node.name in seen and node.type == "BSDF_PRINCIPLED":
            notes += [f"material {material.name}: {what} is not drawn" for what in principled_unread(node)]
    if unread:
        names = ", ".join(sorted(set(unread)))
        notes.append(f"material {material.name}: {names} not exported by the glTF exporter (drawn without)")
    return notes


def scene_warnings(scene, camera) -> list:
    notes = []
    render = scene.render
    if render.film_transparent:
        notes.append("Film > Transparent: the world is drawn behind the scene (alpha is 1)")
    if render.use_motion_blur:
        notes.append("motion blur is not drawn")
    if render.use_border:
        notes.append("the render region is ignored: the whole frame is drawn")
    if camera is not None:
        data = camera.data
        if data.type != "PERSP":
            notes.append(f"camera {camera.name}: a {data.type} camera is drawn as a perspective one")
        if abs(data.shift_x) > 1e-6 or abs(data.shift_y) > 1e-6:
            notes.append(f"camera {camera.name}: lens shift is ignored")
        if data.dof.use_dof:
            notes.append(f"camera {camera.name}: depth of field is not drawn")
    return notes


def export_scene(depsgraph, directory: str) -> Exported:
    """Writes DIRECTORY/scene.glb (and DIRECTORY/world.exr) for the frame
    the depsgraph is at."""
    scene = depsgraph.scene
    camera = scene.camera
    glb_path = os.path.join(directory, "scene.glb")
    warnings = scene_warnings(scene, camera)
    # The exporter reads the context's scene and view layer: the ones being rendered.
    window_scene = {"scene": scene, "view_layer": depsgraph.view_layer}
    with bpy.context.temp_override(**window_scene):
        bpy.ops.export_scene.gltf(
            filepath=glb_path,
            export_format="GLB",
            use_active_scene=True,
            use_renderable=True,
            use_visible=False,
            use_selection=False,
            export_apply=True,
            export_cameras=True,
            export_lights=True,
            export_animations=False,
            # Else the exporter moves the scene to frame 0 to export it.
            export_current_frame=True,
            # Geometry-nodes instances (else dropped without a word).
            export_gn_mesh=True,
            export_skins=False,
            export_morph=False,
            export_yup=True,
            export_import_convert_lighting_mode="SPEC",
            will_save_settings=False,
        )
    with open(glb_path, "rb") as f:
        glb = Glb(f.read())
    added = 0
    materials = {}
    for instance in depsgraph.object_instances:
        obj = instance.object
        for slot in getattr(obj, "material_slots", []):
            if slot.material is not None:
                materials[slot.material.name] = slot.material
        if obj.type != "LIGHT":
            continue
        light = obj.data
        warnings += light_warnings(obj.name, light)
        if light.type != "AREA":
            continue
        polygon = area_light_polygon(light, instance.matrix_world)
        area = polygon_area(polygon)
        if area <= 0 or light.energy <= 0:
            continue
        if not obj.visible_camera and camera is not None and faces_camera_in_view(scene, camera, instance.matrix_world):
            warnings.append(f"light {obj.name}: the camera sees this area light's face, which Blender hides "
                            "(Visibility > Ray Visibility > Camera is off); hikari draws it")
        glb.add_emitter(f"area light {obj.name}", polygon, area_light_radiance(light, area))
        added += 1
    for material in materials.values():
        warnings += material_warnings(material)
    reencoded, notes = encode_linear_colour_images(glb)
    warnings += notes
    if added + match_spot_blends(glb, scene) + reencoded + glb.drop_doubled_instances():
        with open(glb_path, "wb") as f:
            f.write(glb.to_bytes())
    environment, notes = world_environment(scene.world, os.path.join(directory, "world.exr"))
    warnings += notes
    return Exported(glb=glb_path, camera=camera.name if camera else None, environment=environment, warnings=warnings)
