"""The 3D view's Rendered shading: the viewport's eye as hikari's camera,
passes started afresh when it moves, and the engine's view_update and
view_draw drawing them. Blender's window cannot be opened headless, so
the engine's viewport methods are driven from inside an F12 render (the
one way to get a live engine), with a stand-in context holding the
region and its matrices, drawing into an offscreen buffer."""

import time
import types

import bpy
import numpy as np
import pytest
import stage

W, H = 32, 24


def lit_floor():
    scene = stage.empty_scene(W, H)
    stage.floor_and_balls(scene)
    stage.light("SUN", (0, 0, 5), 3.0, (40, 0, 30))
    return scene


def region_of(camera, depsgraph, width=W, height=H):
    """What view_draw's context holds for a 3D view looking through
    `camera` (its region and region_3d)."""
    return types.SimpleNamespace(
        region=types.SimpleNamespace(width=width, height=height),
        region_data=types.SimpleNamespace(view_matrix=camera.matrix_world.inverted(),
                                          window_matrix=camera.calc_matrix_camera(depsgraph, x=width, y=height)))


def test_the_view_is_the_exporters_camera(addon, tmp_path):
    """A view through the scene's camera gives the camera hikari loads
    from Blender's glTF export of it: same eye, direction, up and fov."""
    import hikari_render as hk

    scene = lit_floor()
    camera = stage.camera(scene, (3, -4, 2), (70, 0, 35), lens=35)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    context = region_of(camera, depsgraph)
    ours = addon.viewport.view_camera(context.region_data.view_matrix, context.region_data.window_matrix)
    exported = addon.export.export_scene(depsgraph, str(tmp_path))
    theirs = hk.load(exported.glb, camera=exported.camera).camera
    assert np.allclose(ours["position"], theirs.position, atol=1e-4)
    direction = lambda c: np.subtract(c[1], c[0]) / np.linalg.norm(np.subtract(c[1], c[0]))
    assert np.allclose(direction((ours["position"], ours["look_at"])), direction((theirs.position, theirs.look_at)),
                       atol=1e-4)
    assert np.allclose(ours["up"], theirs.up, atol=1e-4)
    assert ours["fov_y"] == pytest.approx(theirs.fov_y, abs=1e-3)


def test_an_orthographic_view_is_refused(addon):
    scene = lit_floor()
    camera = stage.camera(scene, (0, -4, 2), (70, 0, 0))
    camera.data.type = "ORTHO"
    context = region_of(camera, bpy.context.evaluated_depsgraph_get())
    assert addon.viewport.view_camera(context.region_data.view_matrix, context.region_data.window_matrix) is None


def test_pixel_size_divides_the_region(addon):
    assert addon.viewport.render_size(1920, 1080, 2) == (960, 540)
    assert addon.viewport.render_size(3, 1, 4) == (1, 1)


def wait_until_finished(view, limit_s=120):
    start = time.time()
    while not view.finished:
        assert time.time() - start < limit_s, "the passes did not finish"
        time.sleep(0.02)


def test_a_moved_eye_starts_the_passes_afresh(addon):
    """The passes through a view are those of a render through the same
    camera; the same view again changes nothing; another view starts
    afresh and ends as a render through that one."""
    import hikari_render as hk

    arguments = {"passes": 2, "time": 600.0, "seed": 3}
    redraws = []
    view = addon.viewport.ProgressiveView(hk.load("cornell-box"), "path", arguments,
                                          on_pass=lambda: redraws.append(1))
    eyes = [{"position": (0.0, 0.0, 3.9), "look_at": (0.0, 0.0, 0.0), "up": (0.0, 1.0, 0.0), "fov_y": 39.3},
            {"position": (0.5, 0.3, 3.5), "look_at": (0.0, -0.2, 0.0), "up": (0.0, 1.0, 0.0), "fov_y": 45.0}]
    for eye in eyes:
        assert view.show(eye, (W, H))
        assert not view.show(dict(eye), (W, H))
        wait_until_finished(view)
        shown = view.latest()
        assert view.error is None and shown.index == 2
        reference = hk.load("cornell-box")
        for name, value in eye.items():
            setattr(reference.camera, name, value)
        assert np.array_equal(shown.image, reference.render("path", resolution=(W, H), **arguments))
    assert len(redraws) >= 4
    assert view.show(eyes[0], (W + 2, H))  # a resized region starts afresh too
    view.stop()


def test_the_engine_draws_the_passes_through_the_view(addon, monkeypatch):
    """view_update exports and loads the scene, view_draw starts the passes
    and draws the newest into the region: the pixels are the mean so far
    (scene-linear: Blender's viewport applies the view transform after)."""
    import gpu
    from mathutils import Matrix

    drawn = {}

    def viewport_instead(self, depsgraph):
        context = region_of(depsgraph.scene.camera, depsgraph)
        self.view_update(context, depsgraph)
        self.view_draw(context, depsgraph)  # starts the passes; nothing to draw yet
        wait_until_finished(self.view)
        gpu.init()
        offscreen = gpu.types.GPUOffScreen(W, H, format="RGBA16F")
        with offscreen.bind():
            framebuffer = gpu.state.active_framebuffer_get()
            framebuffer.clear(color=(0, 0, 0, 0))
            with gpu.matrix.push_pop():  # the region's pixel space, as Blender sets it for view_draw
                gpu.matrix.load_matrix(Matrix.Identity(4))
                gpu.matrix.load_projection_matrix(Matrix(((2 / W, 0, 0, -1), (0, 2 / H, 0, -1), (0, 0, 1, 0),
                                                          (0, 0, 0, 1))))
                self.view_draw(context, depsgraph)
            pixels = framebuffer.read_color(0, 0, W, H, 4, 0, "FLOAT")
        drawn["pixels"] = np.array(pixels.to_list(), dtype=np.float32)[::-1, :, :3]
        drawn["shown"] = self.view.latest()

    monkeypatch.setattr(addon.engine.HikariRenderEngine, "render", viewport_instead)
    scene = lit_floor()
    stage.camera(scene, (0, -6, 3), (65, 0, 0))
    scene.render.engine = "HIKARI"
    settings = scene.hikari
    settings.renderer, settings.passes, settings.time_limit, settings.target_error = "path", 2, 600.0, 0.0
    settings.viewport_pixel_size = 1
    bpy.ops.render.render()
    shown = drawn["shown"]
    assert shown.index == 2 and shown.image.shape == (H, W, 3)
    image = shown.image
    assert image.mean() > 0.05
    # Half floats: 11 bits of mantissa.
    assert np.allclose(drawn["pixels"], image, rtol=2e-3, atol=1e-4)
