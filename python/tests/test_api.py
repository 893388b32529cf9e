"""hikari_render's contract (issue #43): loading, rendering to numpy with the
CLI's pixels, passes, errors, the GIL, Ctrl-C and memory."""

import _thread
import os
import pathlib
import subprocess
import threading
import time
import warnings

import numpy as np
import pytest

import hikari_render as hk


def small(**kw):
    """Settings small enough for a software adapter and 2 cores."""
    return dict(resolution=(24, 24), seed=1, **kw)


def test_version_and_builtin_scenes():
    assert hk.__version__.count(".") == 2
    assert "cornell-box" in hk.scenes() and "fog-stage" in hk.scenes()


def test_load_takes_names_and_pathlike(tmp_path):
    scene = hk.load("cornell-box")
    assert scene.resolution[0] > 0
    toml = tmp_path / "box.toml"
    toml.write_text(
        """
[camera]
position = [0.0, 1.0, 4.0]
look_at = [0.0, 1.0, 0.0]
fov_y = 40.0
resolution = [16, 12]

[[material]]
name = "white"
type = "diffuse"
albedo = [0.8, 0.8, 0.8]

[[object]]
shape = "sphere"
center = [0.0, 1.0, 0.0]
radius = 0.5
material = "white"

[[light]]
type = "point"
position = [0.0, 3.0, 2.0]
intensity = [10.0, 10.0, 10.0]
"""
    )
    assert hk.load(toml).resolution == (16, 12)


def test_scene_errors_name_the_file_and_raise_scene_error(tmp_path):
    missing = tmp_path / "missing.glb"
    with pytest.raises(hk.SceneError, match="missing.glb"):
        hk.load(missing)
    truncated = tmp_path / "truncated.glb"
    truncated.write_bytes(b"glTF\x02\x00\x00\x00\x40\x00\x00")
    with pytest.raises(hk.SceneError, match="truncated.glb"):
        hk.load(truncated)
    bad = tmp_path / "bad.toml"
    bad.write_text("[camera]\nposition = [0.0, 1.0]\n")
    with pytest.raises(ValueError, match="bad.toml"):
        hk.load(bad)
    assert issubclass(hk.SceneError, ValueError)


def test_bad_settings_raise_value_error():
    scene = hk.load("cornell-box")
    with pytest.raises(ValueError, match="renderer"):
        scene.render("nope", passes=1)
    with pytest.raises(ValueError, match="radius"):
        scene.render("photon-cpu", passes=1, radius=-1.0)
    with pytest.raises(ValueError, match="target_error"):
        scene.render("path", target_error=2.0)


@pytest.mark.parametrize(
    "renderer, flags, kw",
    [
        ("photon-cpu", ["--passes", "1", "--photons", "3000"], dict(passes=1, photons=3000)),
        ("path", ["--spp", "4"], dict(spp=4)),
        ("vcm", ["--passes", "2"], dict(passes=2)),
    ],
)
def test_the_clis_pixels(tmp_path, hikari_bin, renderer, flags, kw):
    """The same settings as the CLI give the same pixels, to the bit: both
    images written by the same EXR writer compare byte for byte."""
    cli = tmp_path / "cli.exr"
    subprocess.run(
        [hikari_bin, "render", "cornell-box", "--renderer", renderer, "--resolution", "24x24", "--seed", "1",
         "-q", "-o", str(cli), *flags],
        check=True,
        capture_output=True,
    )
    image = hk.load("cornell-box").render(renderer, **small(**kw))
    assert image.dtype == np.float32 and image.shape == (24, 24, 3)
    assert np.isfinite(image).all() and image.mean() > 0
    ours = tmp_path / "ours.exr"
    hk.save(ours, image)
    assert ours.read_bytes() == cli.read_bytes()


def test_same_image_whatever_the_thread_count():
    scene = hk.load("cornell-box")
    one = scene.render("path", **small(spp=2, threads=1))
    two = scene.render("path", **small(spp=2, threads=2))
    assert np.array_equal(one, two)


def test_progressive_passes_report_the_mean_and_its_noise():
    scene = hk.load("cornell-box")
    passes = list(scene.progressive("path", **small(spp=1, passes=4)))
    assert [p.index for p in passes] == [1, 2, 3, 4]
    assert passes[0].noise is None or passes[0].noise >= 0
    assert passes[-1].noise is not None and passes[-1].noise > 0
    assert all(p.image.shape == (24, 24, 3) for p in passes)
    assert passes[-1].seconds >= passes[0].seconds
    # The last pass's mean is the whole render's image.
    assert np.array_equal(passes[-1].image, scene.render("path", **small(spp=1, passes=4)))
    # Stopping early stops the passes.
    for p in scene.progressive("path", **small(spp=1, passes=1000)):
        if p.index == 2:
            break


def test_the_gpu_renders_or_says_why_not():
    """On the GPU where an adapter can, else photon-cpu with a warning
    saying why (never silently)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        image = hk.load("cornell-box").render("gpu", **small(passes=2, photons=2000))
    assert image.shape == (24, 24, 3) and np.isfinite(image).all() and image.mean() > 0
    for w in caught:
        assert "instead" in str(w.message)


def test_the_gil_is_released_while_rendering():
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.01)

    thread = threading.Thread(target=tick)
    thread.start()
    start = time.perf_counter()
    # Passes until half a second has passed: at least that long.
    hk.load("cornell-box").render("path", resolution=(32, 32), spp=1, time=0.5, threads=1)
    end = time.perf_counter()
    done.set()
    thread.join()
    during = [t for t in ticks if start < t < end]
    assert len(during) >= 10, f"the other thread ran {len(during)} times in {end - start:.2f} s"


def test_ctrl_c_raises_keyboard_interrupt_within_a_second():
    scene = hk.load("cornell-box")
    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    start = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        scene.render("path", resolution=(64, 64), spp=1, time=60.0)
    assert time.perf_counter() - start < 1.5


def _rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


@pytest.mark.skipif(not pathlib.Path("/proc/self/statm").exists(), reason="needs Linux's /proc")
def test_memory_stays_flat_over_hundreds_of_renders():
    scene = hk.load("cornell-box")
    for _ in range(20):
        scene.render("path", resolution=(16, 16), spp=1)
    before = _rss_bytes()
    for _ in range(200):
        scene.render("path", resolution=(16, 16), spp=1)
    grown = _rss_bytes() - before
    assert grown < 16 << 20, f"grew {grown / 2**20:.1f} MiB over 200 renders"


def test_save_writes_png_and_exr(tmp_path):
    image = np.full((8, 10, 3), 0.5, dtype=np.float32)
    hk.save(tmp_path / "a.png", image)
    hk.save(tmp_path / "a.exr", image, exposure=1.0)
    assert (tmp_path / "a.png").read_bytes()[:4] == b"\x89PNG"
    assert (tmp_path / "a.exr").stat().st_size > 0
    with pytest.raises(ValueError, match="height, width, 3"):
        hk.save(tmp_path / "b.png", np.zeros((4, 4, 4), dtype=np.float32))


def test_unknown_keywords_and_wrong_types_are_refused():
    scene = hk.load("cornell-box")
    with pytest.raises(TypeError, match="spps"):
        scene.render("path", spps=4)
    with pytest.raises(ValueError, match="resolution"):
        scene.render("path", resolution="big")
    with pytest.raises(ValueError, match="passes"):
        scene.render("path", passes=-1)


def test_help_explains_every_argument():
    doc = hk.Scene.render.__doc__
    for name in ["renderer", "spp", "passes", "time", "target_error", "photons", "radius", "resolution", "seed",
                 "threads", "at"]:
        assert name in doc, name


def test_lights_doubled_double_the_image():
    scene = hk.load("cornell-box")
    for renderer, kw in [("photon-cpu", dict(passes=1, photons=3000)), ("path", dict(spp=2))]:
        before = scene.render(renderer, **small(**kw))
        colors = [light.color for light in scene.lights]
        for light, c in zip(scene.lights, colors):
            light.color = tuple(2 * x for x in c)
        doubled = scene.render(renderer, **small(**kw))
        for light, c in zip(scene.lights, colors):
            light.color = c
        assert np.allclose(doubled, 2 * before, rtol=1e-5, atol=1e-7), renderer
        assert np.array_equal(scene.render(renderer, **small(**kw)), before), "put back: the first image"


def test_camera_moved_and_put_back_gives_the_first_image():
    scene = hk.load("cornell-box")
    first = scene.render("path", **small(spp=2))
    camera = scene.camera
    position = camera.position
    camera.position = (position[0] + 0.3, position[1], position[2])
    moved = scene.render("path", **small(spp=2))
    assert not np.array_equal(moved, first)
    camera.position = position
    assert np.array_equal(scene.render("path", **small(spp=2)), first)
    camera.fov_y = camera.fov_y / 2
    assert not np.array_equal(scene.render("path", **small(spp=2)), first)
    with pytest.raises(ValueError, match="camera"):
        camera.look_at = camera.position


def test_a_light_moved_lights_the_scene_from_there():
    scene = hk.load("fog-stage")
    spot = scene.lights[0]
    assert spot.kind == "spot" and spot.position is not None
    before = scene.render("path", **small(spp=2))
    x, y, z = spot.position
    spot.position = (x + 1.5, y, z)
    assert spot.position == (x + 1.5, y, z)
    assert not np.array_equal(scene.render("path", **small(spp=2)), before)
    with pytest.raises(ValueError, match="negative"):
        spot.color = (-1.0, 0.0, 0.0)


def test_an_area_light_moved_carries_its_geometry():
    scene = hk.load("cornell-caustic")
    area = [light for light in scene.lights if light.kind in ("quad", "sphere")]
    assert area, "cornell-caustic has a sphere light"
    before = scene.render("path", **small(spp=2))
    x, y, z = area[0].position
    area[0].position = (x + 0.2, y, z)
    after = scene.render("path", **small(spp=2))
    assert not np.array_equal(after, before) and np.isfinite(after).all()


WALL = """
[camera]
position = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 20.0
resolution = [8, 6]

[[material]]
name = "wall"
type = "diffuse"
albedo = [0.2, 0.4, 0.6]

[[object]]
shape = "quad"
corner = [-5.0, -5.0, 0.0]
edge_u = [10.0, 0.0, 0.0]
edge_v = [0.0, 10.0, 0.0]
material = "wall"

[[light]]
type = "point"
position = [0.0, 0.0, 3.0]
intensity = [5.0, 5.0, 5.0]
"""


def test_aovs_against_hand_computed_values(tmp_path):
    """A wall facing the eye 5 units away fills the view: its albedo, its
    normal toward the eye, and 5 / cos(angle off the axis) as depth; the
    same for every renderer."""
    path = tmp_path / "wall.toml"
    path.write_text(WALL)
    scene = hk.load(path)
    out = scene.render("path", spp=2, aovs=True)
    assert set(out) == {"color", "albedo", "normal", "depth"}
    assert out["color"].shape == (6, 8, 3) and out["depth"].shape == (6, 8)
    assert np.allclose(out["albedo"], [0.2, 0.4, 0.6], atol=1e-6)
    assert np.allclose(out["normal"], [0.0, 0.0, 1.0], atol=1e-6)
    # The centre ray of pixel (x, y) at the camera's 20° vertical field of view.
    tan = np.tan(np.radians(10.0))
    ys, xs = np.mgrid[0:6, 0:8] + 0.5
    u = (2 * xs / 8 - 1) * tan * 8 / 6
    v = (1 - 2 * ys / 6) * tan
    expected = 5.0 * np.sqrt(1 + u * u + v * v)
    assert np.allclose(out["depth"], expected, rtol=1e-4)
    other = scene.render("photon-cpu", passes=1, photons=2000, aovs=True)
    for key in ["albedo", "normal", "depth"]:
        assert np.array_equal(other[key], out[key]), key


def test_aovs_alone_are_those_of_a_render(tmp_path):
    """Scene.aovs gives a render's albedo, normal and depth without one, at
    another resolution too."""
    path = tmp_path / "wall.toml"
    path.write_text(WALL)
    scene = hk.load(path)
    alone = scene.aovs()
    rendered = scene.render("path", spp=1, aovs=True)
    assert set(alone) == {"albedo", "normal", "depth"}
    for key in alone:
        assert np.array_equal(alone[key], rendered[key]), key
    assert scene.aovs(resolution=(4, 3))["depth"].shape == (3, 4)
    with pytest.raises(ValueError, match="resolution"):
        scene.aovs(resolution=(0, 3))


def test_depth_is_infinite_where_nothing_is_hit(tmp_path):
    path = tmp_path / "empty.toml"
    path.write_text(WALL.replace("[-5.0, -5.0, 0.0]", "[20.0, 20.0, 0.0]"))  # the wall out of view
    out = hk.load(path).render("path", spp=1, aovs=True)
    assert np.isinf(out["depth"]).all() and (out["albedo"] == 0).all() and (out["normal"] == 0).all()


def test_materials_edited_by_name():
    scene = hk.load("cornell-box")
    materials = scene.materials
    assert materials, "cornell-box's materials have names"
    name, material = next((n, m) for n, m in materials.items() if m.kind == "diffuse")
    first = scene.render("path", **small(spp=2))
    color = material.base_color
    material.base_color = (0.9, 0.1, 0.1)
    assert scene.materials[name].base_color == pytest.approx((0.9, 0.1, 0.1))
    assert not np.array_equal(scene.render("path", **small(spp=2)), first)
    material.base_color = color
    assert np.array_equal(scene.render("path", **small(spp=2)), first), "put back: the first image"
    assert material.metallic is None and material.roughness is None
    with pytest.raises(ValueError, match="outside"):
        material.base_color = (2.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="metallic"):
        material.metallic = 0.5


def test_glass_tint_and_roughness_edited():
    scene = hk.load("cornell-caustic")
    name, glass = next((n, m) for n, m in scene.materials.items() if m.kind == "glass")
    assert glass.base_color == pytest.approx((1.0, 1.0, 1.0)) and glass.roughness == 0.0
    first = scene.render("path", **small(spp=2))
    glass.base_color = (0.9, 0.5, 0.2)
    glass.roughness = 0.3
    assert scene.materials[name].base_color == pytest.approx((0.9, 0.5, 0.2))
    assert scene.materials[name].roughness == pytest.approx(0.3)
    tinted = scene.render("path", **small(spp=2))
    assert tinted[..., 2].mean() < first[..., 2].mean(), "blue is taken out of what crosses the glass"
    assert glass.metallic is None


def test_every_light_and_emission_doubled_doubles_the_image():
    scene = hk.load(pathlib.Path(__file__).resolve().parents[2] / "scenes" / "showcase.glb")
    emissive = [m for m in scene.materials.values() if max(m.emission) > 0]
    assert emissive, "showcase.glb's glowing strip"
    # The emissive meshes are lights too: doubled through their material.
    lights = [light for light in scene.lights if light.kind != "mesh"]
    assert lights
    for renderer, kw in [("photon-cpu", dict(passes=1, photons=3000)), ("path", dict(spp=2))]:
        before = scene.render(renderer, **small(**kw))
        colors, emissions = [light.color for light in lights], [m.emission for m in emissive]
        for light, c in zip(lights, colors):
            light.color = tuple(2 * x for x in c)
        for material, e in zip(emissive, emissions):
            material.emission = tuple(2 * x for x in e)
        assert [m.emission for m in emissive] == [tuple(2 * x for x in e) for e in emissions]
        doubled = scene.render(renderer, **small(**kw))
        for light, c in zip(lights, colors):
            light.color = c
        for material, e in zip(emissive, emissions):
            material.emission = e
        assert np.allclose(doubled, 2 * before, rtol=1e-4, atol=1e-6), renderer
        assert np.array_equal(scene.render(renderer, **small(**kw)), before), "put back: the first image"
    plain = next(m for m in scene.materials.values() if m.kind == "pbr" and max(m.emission) == 0)
    assert plain.emission == (0.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="emits no light"):
        plain.emission = (1.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="negative"):
        emissive[0].emission = (-1.0, 0.0, 0.0)


def test_gltf_materials_metallic_and_roughness():
    scene = hk.load(pathlib.Path(__file__).resolve().parents[2] / "scenes" / "showcase.glb")
    pbr = [m for m in scene.materials.values() if m.kind == "pbr"]
    assert pbr
    pbr[0].roughness = 0.25
    pbr[0].metallic = 1.0
    assert (pbr[0].roughness, pbr[0].metallic) == (0.25, 1.0)
    with pytest.raises(ValueError, match="roughness"):
        pbr[0].roughness = 1.5


def test_clear_coat_edited_and_rendered():
    scene = hk.load(pathlib.Path(__file__).resolve().parents[2] / "scenes" / "showcase.glb")
    pbr = next(m for m in scene.materials.values() if m.kind == "pbr" and max(m.emission) == 0)
    assert pbr.clearcoat == 0.0
    before = scene.render("path", **small(spp=2))
    pbr.clearcoat = 1.0
    pbr.clearcoat_roughness = 0.1
    assert (pbr.clearcoat, pbr.clearcoat_roughness) == (1.0, pytest.approx(0.1))
    after = scene.render("path", **small(spp=2))
    assert not np.array_equal(after, before), "the coat changed nothing"
    with pytest.raises(ValueError, match="clearcoat"):
        pbr.clearcoat = 2.0
    glass = hk.load("cornell-caustic")
    clear = next(m for m in glass.materials.values() if m.kind == "glass")
    assert clear.clearcoat is None
    with pytest.raises(ValueError, match="has none"):
        clear.clearcoat = 0.5


def test_sheen_edited_and_rendered():
    scene = hk.load(pathlib.Path(__file__).resolve().parents[2] / "scenes" / "showcase.glb")
    pbr = next(m for m in scene.materials.values() if m.kind == "pbr" and max(m.emission) == 0)
    assert pbr.sheen_color == (0.0, 0.0, 0.0)
    before = scene.render("path", **small(spp=2))
    pbr.sheen_color = (1.0, 0.8, 0.6)
    pbr.sheen_roughness = 0.3
    assert pbr.sheen_color == pytest.approx((1.0, 0.8, 0.6)) and pbr.sheen_roughness == pytest.approx(0.3)
    after = scene.render("path", **small(spp=2))
    assert not np.array_equal(after, before), "the sheen changed nothing"
    with pytest.raises(ValueError, match="sheen_color"):
        pbr.sheen_color = (1.5, 0.0, 0.0)
    pbr.specular_color = (1.0, 3.0, 0.5)
    assert pbr.specular_color == pytest.approx((1.0, 3.0, 0.5))
    with pytest.raises(ValueError, match="specular_color"):
        pbr.specular_color = (-1.0, 0.0, 0.0)
    glass = hk.load("cornell-caustic")
    clear = next(m for m in glass.materials.values() if m.kind == "glass")
    assert clear.sheen_color is None
    with pytest.raises(ValueError, match="has none"):
        clear.sheen_roughness = 0.5
