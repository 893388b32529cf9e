"""What the add-on adds to the exporter's file, checked against hikari's
loader: area lights as emitting polygons, spot blends, the world."""

import math

import numpy as np
import pytest


@pytest.fixture(scope="module")
def export(addon):
    return addon.export


@pytest.fixture(scope="module")
def Glb(addon):
    return addon.glb.Glb



def empty_glb(Glb):
    glb = Glb.__new__(Glb)
    glb.json = {"asset": {"version": "2.0"}, "scenes": [{"nodes": []}], "scene": 0}
    glb.bin = bytearray()
    return glb


def test_an_emitter_added_to_a_glb_is_a_one_sided_mesh_light_of_its_radiance(tmp_path, export, Glb):
    import hikari_render as hk

    """A 2 m × 1 m rectangle facing down at height 3: hikari loads one mesh
    light of the radiance written, one-sided (which side it lights is
    test_render's: the stage's area light lights the floor as Cycles')."""
    glb = empty_glb(Glb)
    corners = [(-1.0, 3.0, -0.5), (1.0, 3.0, -0.5), (1.0, 3.0, 0.5), (-1.0, 3.0, 0.5)]
    normal = np.cross(np.subtract(corners[1], corners[0]), np.subtract(corners[2], corners[0]))
    assert normal[1] < 0, "the corners turn counter-clockwise seen from below"
    glb.add_emitter("panel", corners, (4.0, 2.0, 1.0))
    path = tmp_path / "panel.glb"
    path.write_bytes(glb.to_bytes())
    again = Glb(path.read_bytes())
    assert again.json["materials"][0]["doubleSided"] is False
    assert export.polygon_area(corners) == pytest.approx(2.0)
    scene = hk.load(path)
    lights = [light for light in scene.lights if light.kind == "mesh"]
    assert len(lights) == 1
    assert lights[0].color == pytest.approx((4.0, 2.0, 1.0))


def test_ellipse_polygons_keep_the_ellipses_area(addon, export):
    for a, b, n in [(1.0, 1.0, 48), (2.0, 0.5, 48), (1.0, 1.0, 8)]:
        polygon = addon.glb.ellipse(a, b, n)
        assert len(polygon) == n
        assert export.polygon_area(polygon) == pytest.approx(math.pi * a * b, rel=1e-9)


def test_area_light_radiance_holds_the_lights_power(export):
    class Light:
        energy, color = 100.0, (1.0, 0.5, 0.25)

    radiance = export.area_light_radiance(Light(), 2.0)
    # Φ = π A L for a one-sided Lambertian emitter.
    assert [math.pi * 2.0 * c for c in radiance] == pytest.approx([100.0, 50.0, 25.0])


def test_spot_blend_as_an_inner_angle(export):
    """No blend: a hard edge; full blend: the smoothstep spans cos θo to 1."""
    assert export.spot_inner_angle(math.radians(60), 0.0) == pytest.approx(math.radians(30))
    assert export.spot_inner_angle(math.radians(60), 1.0) == pytest.approx(0.0, abs=1e-6)
    inner = export.spot_inner_angle(math.radians(60), 0.2)
    assert math.cos(inner) == pytest.approx(math.cos(math.radians(30)) + 0.2 * (1 - math.cos(math.radians(30))))


def test_a_glb_round_trips_byte_for_byte(Glb):
    glb = empty_glb(Glb)
    glb.add_emitter("tri", [(0, 0, 0), (1, 0, 0), (0, 0, 1)], (1.0, 1.0, 1.0))
    data = glb.to_bytes()
    assert len(data) % 4 == 0
    assert Glb(data).to_bytes() == data
    with pytest.raises(ValueError, match="not a glTF"):
        Glb(b"nonsense" * 4)


def test_which_images_are_read_as_colour(Glb, addon):
    """An image only a base colour reads is colour; one a normal map also
    reads is data somewhere (the add-on leaves it as exported, warned)."""
    glb = empty_glb(Glb)
    glb.json["textures"] = [{"source": 0}, {"source": 1}, {"source": 1}]
    glb.json["images"] = [{"name": "a"}, {"name": "b"}]
    glb.json["materials"] = [
        {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, "normalTexture": {"index": 1}},
        {"emissiveTexture": {"index": 2}},
    ]
    assert glb.color_images() == {0: True, 1: False}
    import struct
    import zlib

    data = addon.glb.png(np.zeros((2, 3, 4), dtype=np.uint8))
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", data[16:24])
    assert (width, height) == (3, 2)
    idat = data.index(b"IDAT")
    (length,) = struct.unpack(">I", data[idat - 4 : idat])
    assert len(zlib.decompress(data[idat + 4 : idat + 4 + length])) == 2 * (1 + 3 * 4)
