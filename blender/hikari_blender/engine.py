"""The render engine "HIKARI": F12 and Ctrl-F12 through hikari_render.

Each render exports the evaluated scene (export.py) to a temporary
directory, on Blender's main thread (main_thread.py), loads it with hikari's glTF loader and renders it pass by pass,
updating the render window after each pass; then the images Blender's
denoiser takes."""

import logging
import os
import tempfile
import warnings

import bpy
import numpy as np

from . import export, viewport
from .main_thread import MainThreadUnavailable, run_on_main_thread

# Blender's pass names, so the compositor's Denoise node and file outputs
# take them: (name, channels, channel ids, socket type).
DENOISING_PASSES = [
    ("Denoising Albedo", 3, "RGB", "COLOR"),
    ("Denoising Normal", 3, "XYZ", "VECTOR"),
]
DEPTH_PASS = ("Depth", 1, "Z", "VALUE")
# Every warning shown in Blender's report area also goes to this logger.
log = logging.getLogger("hikari_blender")

# What Blender writes as the depth where nothing is hit (Cycles' value).
BACKGROUND_DEPTH = 1e10


def bottom_up(image: np.ndarray) -> np.ndarray:
    """hikari's rows run top to bottom, a render result's bottom to top."""
    return image[::-1]


def combined_rect(image: np.ndarray) -> np.ndarray:
    """(height, width, 3) radiance as the Combined pass's RGBA rows."""
    h, w, _ = image.shape
    rgba = np.ones((h, w, 4), dtype=np.float32)
    rgba[:, :, :3] = np.nan_to_num(image, nan=0.0, posinf=0.0, neginf=0.0)
    return bottom_up(rgba).reshape(-1, 4)


def camera_axes(matrix_world) -> np.ndarray:
    """Rows: the camera's right, up and forward directions in Blender's
    world (its local X, Y and −Z)."""
    m = np.array(matrix_world, dtype=np.float64)[:3, :3]
    axes = np.stack([m[:, 0], m[:, 1], -m[:, 2]])
    return axes / np.linalg.norm(axes, axis=1, keepdims=True)


def normal_rect(normal: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """World-space normals (glTF's Y-up frame) as Cycles writes its
    Denoising Normal: in the camera's frame, x right, y up, z forward."""
    blender = np.stack([normal[:, :, 0], -normal[:, :, 2], normal[:, :, 1]], axis=-1)
    return bottom_up(blender @ axes.T).reshape(-1, 3).astype(np.float32)


def planar_depth(depth: np.ndarray, fov_y_degrees: float) -> np.ndarray:
    """Distances along the rays through the pixels' centres as distances
    along the camera's axis (Cycles' Depth pass); Blender's 10¹⁰ where
    nothing is hit."""
    h, w = depth.shape
    tan = np.tan(np.radians(fov_y_degrees) / 2)
    ys, xs = np.mgrid[0:h, 0:w] + 0.5
    u = (2 * xs / w - 1) * tan * w / h
    v = (1 - 2 * ys / h) * tan
    planar = depth / np.sqrt(1 + u * u + v * v)
    return np.where(np.isfinite(planar), planar, BACKGROUND_DEPTH)


def depth_rect(depth: np.ndarray, fov_y_degrees: float) -> np.ndarray:
    return bottom_up(planar_depth(depth, fov_y_degrees)).reshape(-1, 1).astype(np.float32)


def status_line(renderer: str, p) -> str:
    """What the status line says after pass `p`."""
    noise = "noise not yet estimated" if p.noise is None else f"noise {p.noise:.2%}"
    return f"hikari {renderer}: pass {p.index}, {noise}, {p.seconds:.1f} s"


def fraction_done(kwargs, p) -> float:
    """How far the passes are toward the first limit they will meet: the
    time, the pass count, or the noise target (noise falls as 1/√passes)."""
    fractions = [0.0]
    if "time" in kwargs:
        fractions.append(p.seconds / kwargs["time"])
    if "passes" in kwargs:
        fractions.append(p.index / kwargs["passes"])
    if "target_error" in kwargs and p.noise:
        fractions.append(min(1.0, (kwargs["target_error"] / p.noise) ** 2))
    return min(1.0, max(fractions))


def load_exported(exported, warn):
    """hikari's scene from an export (hikari_render.SceneError where it
    cannot load); the export's notes and the loader's warnings go to
    warn(message)."""
    import hikari_render as hk

    for note in exported.warnings:
        warn(note)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            return hk.load(exported.glb, camera=exported.camera, environment=exported.environment)
        finally:
            for w in caught:
                warn(f"hikari: {w.message}")


class adapter_chosen:
    """HIKARI_GPU (crates/gpu's adapter choice) set to the GPU setting for
    one render, and put back by `restore`."""

    VARIABLE = "HIKARI_GPU"

    def __init__(self, wanted: str):
        self.before = os.environ.get(self.VARIABLE)
        if wanted.strip():
            os.environ[self.VARIABLE] = wanted.strip()

    def restore(self):
        if self.before is None:
            os.environ.pop(self.VARIABLE, None)
        else:
            os.environ[self.VARIABLE] = self.before


class HikariRenderEngine(bpy.types.RenderEngine):
    bl_idname = "HIKARI"
    bl_label = "hikari"
    bl_use_preview = False
    bl_use_postprocess = True
    bl_use_eevee_viewport = True

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        for name, channels, ids, kind in DENOISING_PASSES + [DEPTH_PASS]:
            self.register_pass(scene, renderlayer, name, channels, ids, kind)

    def render(self, depsgraph):
        scene = depsgraph.scene
        scale = scene.render.resolution_percentage / 100.0
        width = max(1, int(scene.render.resolution_x * scale))
        height = max(1, int(scene.render.resolution_y * scale))
        layer_name = depsgraph.view_layer.name
        for name, channels, ids, _ in DENOISING_PASSES:
            self.add_pass(name, channels, ids, layer=layer_name)
        if not depsgraph.view_layer.use_pass_z:
            self.add_pass(*DEPTH_PASS[:3], layer=layer_name)
        with tempfile.TemporaryDirectory(prefix="hikari-blender-") as directory:
            self.render_in(depsgraph, directory, width, height, layer_name)

    def render_in(self, depsgraph, directory, width, height, layer_name):
        import hikari_render as hk

        settings = depsgraph.scene.hikari
        self.update_stats("", "hikari: exporting the scene")
        try:
            exported = run_on_main_thread(lambda: self.export(depsgraph, directory))
        except MainThreadUnavailable as e:
            self.fail(f"hikari could not export the scene: {e}")
            return
        try:
            loaded = load_exported(exported, self.warn)
        except hk.SceneError as e:
            self.fail(f"hikari could not load the exported scene: {e}")
            return
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = self.begin_result(0, 0, width, height, layer=layer_name)
            camera = depsgraph.scene.camera
            chosen = adapter_chosen(settings.gpu)
            axes = camera_axes(camera.evaluated_get(depsgraph).matrix_world if camera else np.eye(4))
            try:
                self.render_passes(loaded, settings, (width, height), result, axes)
            finally:
                chosen.restore()
                self.report_caught(caught)
                self.end_result(result)

    # The 3D view's Rendered shading (viewport.py). Blender calls
    # view_update and view_draw on its main thread.

    def view_update(self, context, depsgraph):
        """The scene changed, or the view opened: export and load it again
        and start the passes afresh."""
        previous = getattr(self, "view", None)
        if previous is not None:
            previous.stop()
        self.view = self.load_view(depsgraph)

    def load_view(self, depsgraph):
        import hikari_render as hk

        settings = depsgraph.scene.hikari
        with tempfile.TemporaryDirectory(prefix="hikari-viewport-") as directory:
            try:
                loaded = load_exported(export.export_scene(depsgraph, directory), self.note_once)
            except hk.SceneError as e:
                self.note_once(f"hikari could not load the exported scene: {e}")
                return None

        def redraw():
            try:
                self.tag_redraw()
            except ReferenceError:  # the view was closed meanwhile
                pass

        return viewport.ProgressiveView(loaded, settings.renderer, settings.render_arguments(), on_pass=redraw)

    def view_draw(self, context, depsgraph):
        """The newest pass through the view's eye, started again when the
        eye or the region's size changed."""
        view = getattr(self, "view", None)
        if view is None:
            return
        region, region_3d = context.region, context.region_data
        camera = viewport.view_camera(region_3d.view_matrix, region_3d.window_matrix)
        if camera is None:
            self.update_stats("", "hikari draws perspective views only (numpad 5 switches)")
            return
        settings = depsgraph.scene.hikari
        view.show(camera, viewport.render_size(region.width, region.height, settings.viewport_pixel_size))
        shown = view.latest()
        if view.error:
            self.update_stats("", f"hikari: {view.error}")
        if shown is None:
            return
        if getattr(self, "texture_key", None) != (shown.generation, shown.index):
            self.texture = viewport.image_texture(shown.image)
            self.texture_key = (shown.generation, shown.index)
            noise = "" if shown.noise is None else f", noise {shown.noise:.2%}"
            self.update_stats("", f"hikari {settings.renderer}: pass {shown.index}{noise}")
        import gpu

        gpu.state.blend_set("ALPHA_PREMULT")
        self.bind_display_space_shader(depsgraph.scene)
        viewport.draw_texture(self.texture, region.width, region.height)
        self.unbind_display_space_shader()
        gpu.state.blend_set("NONE")

    def note_once(self, message: str):
        """A warning for the viewport's renders, said once per view (they
        export the scene again at every edit)."""
        said = getattr(self, "said", None)
        if said is None:
            said = self.said = set()
        if message not in said:
            said.add(message)
            log.warning(message)

    def __del__(self):
        """The viewport's passes stop when Blender frees the engine."""
        try:
            view = getattr(self, "view", None)
        except ReferenceError:
            view = None
        if view is not None:
            view.stop()
        parent = getattr(super(), "__del__", None)
        if parent is not None:
            parent()

    def export(self, depsgraph, directory):
        """The evaluated scene as a glTF file (on Blender's main thread)."""
        if self.is_animation:
            # The render moved the scene to its frame, but the exporter reads
            # the view layer's own depsgraph, still at the first frame.
            scene = depsgraph.scene
            scene.frame_set(scene.frame_current, subframe=scene.frame_subframe)
        return export.export_scene(depsgraph, directory)

    def render_passes(self, loaded, settings, resolution, result, axes):
        layer = result.layers[0]
        combined = layer.passes.find_by_name("Combined", "")
        kwargs = settings.render_arguments()
        self.update_stats("", f"hikari {settings.renderer}: first pass")
        for p in loaded.progressive(settings.renderer, resolution=resolution, **kwargs):
            combined.rect = combined_rect(p.image)
            self.show_pass(result, status_line(settings.renderer, p), fraction_done(kwargs, p))
            if self.esc_pressed():
                break
        aovs = loaded.aovs(resolution=resolution)
        layer.passes.find_by_name("Denoising Albedo", "").rect = bottom_up(aovs["albedo"]).reshape(-1, 3)
        layer.passes.find_by_name("Denoising Normal", "").rect = normal_rect(aovs["normal"], axes)
        layer.passes.find_by_name("Depth", "").rect = depth_rect(aovs["depth"], loaded.camera.fov_y)

    def esc_pressed(self) -> bool:
        """Whether the user asked the render to stop (Esc in the render
        window); the passes so far stay as the result."""
        return self.test_break()

    def show_pass(self, result, status: str, progress: float):
        """The render window shows the mean so far, the status line `status`."""
        self.update_result(result)
        self.update_stats("", status)
        self.update_progress(progress)

    def report_caught(self, caught):
        for w in caught:
            self.warn(f"hikari: {w.message}")
        caught.clear()

    def fail(self, message: str):
        log.error(message)
        self.report({"ERROR"}, message)

    def warn(self, message: str):
        log.warning(message)
        self.report({"WARNING"}, message)


def register():
    bpy.utils.register_class(HikariRenderEngine)


def unregister():
    bpy.utils.unregister_class(HikariRenderEngine)
