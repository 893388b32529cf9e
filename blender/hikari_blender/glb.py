"""Reading, extending and writing a binary glTF (.glb) in memory, without
Blender: what the exporter cannot write (area lights as emitting polygons)
is added to its file here."""

import json
import math
import struct
import zlib

MAGIC = 0x46546C67  # "glTF"
JSON_CHUNK = 0x4E4F534A
BIN_CHUNK = 0x004E4942
EMISSIVE_STRENGTH = "KHR_materials_emissive_strength"
# The name Blender's exporter gives a geometry-nodes instance's node.
GN_INSTANCE = "GN Instance"


class Glb:
    """A .glb's JSON (a dict) and binary buffer (a bytearray)."""

    def __init__(self, data: bytes):
        magic, version, length = struct.unpack_from("<III", data, 0)
        if magic != MAGIC or version != 2 or length > len(data):
            raise ValueError("not a glTF 2.0 binary file")
        offset, self.json, self.bin = 12, None, bytearray()
        while offset + 8 <= length:
            size, kind = struct.unpack_from("<II", data, offset)
            chunk = data[offset + 8 : offset + 8 + size]
            if kind == JSON_CHUNK:
                self.json = json.loads(chunk.decode("utf-8"))
            elif kind == BIN_CHUNK:
                self.bin = bytearray(chunk)
            offset += 8 + size
        if self.json is None:
            raise ValueError("a glTF binary file without its JSON chunk")

    def to_bytes(self) -> bytes:
        buffers = self.json.setdefault("buffers", [])
        if self.bin:
            if not buffers:
                buffers.append({})
            buffers[0]["byteLength"] = len(self.bin)
        text = json.dumps(self.json, separators=(",", ":")).encode("utf-8")
        text += b" " * (-len(text) % 4)
        binary = bytes(self.bin) + b"\0" * (-len(self.bin) % 4)
        chunks = struct.pack("<II", len(text), JSON_CHUNK) + text
        if binary:
            chunks += struct.pack("<II", len(binary), BIN_CHUNK) + binary
        return struct.pack("<III", MAGIC, 2, 12 + len(chunks)) + chunks

    def _append(self, data: bytes, target: int | None) -> int:
        """A buffer view of `data` at the end of the binary buffer: its index."""
        self.bin += b"\0" * (-len(self.bin) % 4)
        views = self.json.setdefault("bufferViews", [])
        view = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        views.append(view)
        self.bin += data
        return len(views) - 1

    def replace_image(self, index: int, png: bytes) -> None:
        """Image `index` becomes the PNG `png` (the old bytes stay, unused)."""
        image = self.json["images"][index]
        image.pop("uri", None)
        image["mimeType"] = "image/png"
        image["bufferView"] = self._append(png, None)

    def color_images(self) -> dict:
        """For each image a material reads: whether every use reads it as
        colour (sRGB: base colour, emission, sheen and specular colour) —
        True — or some use reads it as data (normals, roughness…) — False."""
        srgb_slots = {"baseColorTexture", "emissiveTexture", "sheenColorTexture", "specularColorTexture"}
        textures = self.json.get("textures", [])
        uses = {}

        def visit(node):
            if isinstance(node, dict):
                for key, value in node.items():
                    if key.endswith("Texture") and isinstance(value, dict) and "index" in value:
                        texture = textures[value["index"]] if value["index"] < len(textures) else {}
                        source = texture.get("source")
                        if source is None:
                            source = texture.get("extensions", {}).get("EXT_texture_webp", {}).get("source")
                        if source is not None:
                            uses[source] = uses.get(source, True) and key in srgb_slots
                    visit(value)
            elif isinstance(node, list):
                for value in node:
                    visit(value)

        visit(self.json.get("materials", []))
        return uses

    def mesh_shape(self, index: int) -> tuple:
        """What tells exported meshes apart without reading their buffers:
        each primitive's material and its positions' count and bounds."""
        accessors = self.json.get("accessors", [])
        shape = []
        for primitive in self.json["meshes"][index].get("primitives", []):
            position = accessors[primitive.get("attributes", {}).get("POSITION", 0)] if accessors else {}
            shape.append((primitive.get("material"), position.get("count"),
                          tuple(round(v, 6) for v in position.get("min", ())),
                          tuple(round(v, 6) for v in position.get("max", ()))))
        return tuple(shape)

    def drop_doubled_instances(self) -> int:
        """With geometry-nodes instances on, Blender's exporter writes a
        particle system's instances twice: as the instanced objects and as
        "GN Instance" nodes of a copy of their mesh, at the same places.
        Each "GN Instance" node with a sibling of the same transform and
        the same mesh shape loses its mesh (the node stays, so no index
        changes). Returns how many."""
        nodes = self.json.get("nodes", [])
        groups = [n.get("children", []) for n in nodes] + [s.get("nodes", []) for s in self.json.get("scenes", [])]

        def placed(node):
            where = tuple((key, tuple(round(v, 6) for v in node[key]))
                          for key in ("matrix", "translation", "rotation", "scale") if key in node)
            return where, self.mesh_shape(node["mesh"])

        dropped = 0
        for siblings in groups:
            meshed = [nodes[i] for i in siblings if i < len(nodes) and "mesh" in nodes[i]]
            plain = {placed(n) for n in meshed if not n.get("name", "").startswith(GN_INSTANCE)}
            for node in meshed:
                if node.get("name", "").startswith(GN_INSTANCE) and placed(node) in plain:
                    del node["mesh"]
                    dropped += 1
        return dropped

    def add_emitter(self, name: str, polygon: list, radiance: tuple) -> None:
        """A flat, convex `polygon` (corners in glTF's frame, counter-clockwise
        seen from the side it lights) emitting `radiance` (W/(m² sr), RGB)
        from its front face only: a node at the root of the first scene."""
        if len(polygon) < 3:
            raise ValueError(f"{name}: an emitter needs at least three corners")
        positions = b"".join(struct.pack("<3f", *p) for p in polygon)
        indices = b"".join(struct.pack("<3I", 0, i, i + 1) for i in range(1, len(polygon) - 1))
        accessors = self.json.setdefault("accessors", [])
        lo = [min(p[k] for p in polygon) for k in range(3)]
        hi = [max(p[k] for p in polygon) for k in range(3)]
        accessors.append({"bufferView": self._append(positions, 34962), "componentType": 5126,
                          "count": len(polygon), "type": "VEC3", "min": lo, "max": hi})
        position = len(accessors) - 1
        accessors.append({"bufferView": self._append(indices, 34963), "componentType": 5125,
                          "count": 3 * (len(polygon) - 2), "type": "SCALAR"})
        index = len(accessors) - 1
        peak = max(radiance)
        materials = self.json.setdefault("materials", [])
        materials.append({
            "name": name,
            "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0, "roughnessFactor": 1},
            "emissiveFactor": [c / peak for c in radiance],
            "extensions": {EMISSIVE_STRENGTH: {"emissiveStrength": peak}},
            "doubleSided": False,
        })
        used = self.json.setdefault("extensionsUsed", [])
        if EMISSIVE_STRENGTH not in used:
            used.append(EMISSIVE_STRENGTH)
        meshes = self.json.setdefault("meshes", [])
        meshes.append({"name": name, "primitives": [
            {"attributes": {"POSITION": position}, "indices": index, "material": len(materials) - 1}]})
        nodes = self.json.setdefault("nodes", [])
        nodes.append({"name": name, "mesh": len(meshes) - 1})
        scenes = self.json.setdefault("scenes", [{"nodes": []}])
        scenes[self.json.get("scene", 0)].setdefault("nodes", []).append(len(nodes) - 1)


def ellipse(half_x: float, half_y: float, segments: int = 48) -> list:
    """Corners of a polygon of `segments` sides with the area of the ellipse
    of half-axes `half_x`, `half_y` (its corners a little outside it), in
    the plane z = 0, counter-clockwise seen from +z."""
    # A regular n-gon inscribed in a circle of radius r has area
    # n r² sin(2π/n) / 2: scaled to the circle's π r².
    grow = math.sqrt(2 * math.pi / (segments * math.sin(2 * math.pi / segments)))
    return [(half_x * grow * math.cos(2 * math.pi * i / segments),
             half_y * grow * math.sin(2 * math.pi * i / segments), 0.0) for i in range(segments)]


def png(rgba) -> bytes:
    """An 8-bit RGBA PNG of `rgba` (a (height, width, 4) uint8 array, top row
    first)."""
    height, width, _ = rgba.shape
    raw = b"".join(b"\0" + rgba[y].tobytes() for y in range(height))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b"")
