"""The 3D view's Rendered shading: hikari's passes through the viewport's
eye, on a thread of their own, started again whenever the eye or the
region's size changes (the engine's view_draw), and drawn as they come."""

import math
import threading
from dataclasses import dataclass

import numpy as np


def blender_to_gltf(v) -> tuple:
    """A point or direction in Blender's Z-up world in glTF's Y-up frame
    (the exporter's export_yup)."""
    x, y, z = (float(c) for c in v)
    return (x, z, -y)


def view_camera(view_matrix, window_matrix):
    """The eye of a 3D view (its region_3d's view and window matrices) as
    hikari's camera settings in the glTF frame: position, look_at, up and
    fov_y (vertical, degrees). None for an orthographic view, which
    hikari's pinhole camera cannot draw."""
    projection = np.array(window_matrix, dtype=np.float64)
    if abs(projection[3, 3]) > 1e-9:  # orthographic: w does not take -z
        return None
    eye = np.linalg.inv(np.array(view_matrix, dtype=np.float64))
    position, up, back = eye[:3, 3], eye[:3, 1], eye[:3, 2]
    return {
        "position": blender_to_gltf(position),
        "look_at": blender_to_gltf(position - back),
        "up": blender_to_gltf(up / np.linalg.norm(up)),
        "fov_y": math.degrees(2 * math.atan(1 / projection[1, 1])),
    }


def render_size(width: int, height: int, pixel_size: int) -> tuple:
    """The passes' resolution for a region of width × height at one
    rendered pixel per pixel_size × pixel_size (Cycles' Pixel Size)."""
    return max(1, width // pixel_size), max(1, height // pixel_size)


def texture_rows(image: np.ndarray) -> np.ndarray:
    """(height, width, 3) radiance, rows top to bottom, as a texture's
    RGBA floats, rows bottom to top; NaN and Inf drawn black."""
    h, w, _ = image.shape
    rgba = np.ones((h, w, 4), dtype=np.float32)
    rgba[:, :, :3] = np.nan_to_num(image, nan=0.0, posinf=0.0, neginf=0.0)
    return np.ascontiguousarray(rgba[::-1])


def image_texture(image: np.ndarray):
    """(height, width, 3) radiance as a half-float GPU texture (made on
    the thread that draws, inside its GPU context)."""
    import gpu

    rows = texture_rows(image)
    h, w, _ = rows.shape
    return gpu.types.GPUTexture((w, h), format="RGBA16F", data=gpu.types.Buffer("FLOAT", w * h * 4, rows.ravel()))


def draw_texture(texture, width: int, height: int):
    """`texture` stretched over the region (0, 0)–(width, height) in the
    current GPU state: view_draw binds Blender's display-space shader
    around it (the view transform and look), tests set up their own
    matrices."""
    from gpu_extras.presets import draw_texture_2d

    draw_texture_2d(texture, (0, 0), width, height)


@dataclass
class Shown:
    """The newest pass of the current view: its number, the mean so far,
    its estimated noise (None until known), and which start of the
    passes it belongs to."""
    index: int
    image: np.ndarray
    noise: float | None
    generation: int


class ProgressiveView:
    """Passes of one loaded scene (hikari_render.Scene) through one view at
    a time. `show(camera, resolution)` starts them again when either
    changed; the previous passes stop after the one under way (they run
    on a snapshot of the scene, so the camera can be set at once)."""

    def __init__(self, scene, renderer: str, arguments: dict, on_pass=None):
        self.scene, self.renderer, self.arguments = scene, renderer, dict(arguments)
        self.on_pass = on_pass or (lambda: None)
        self.key = None
        self.generation = 0
        self.lock = threading.Lock()
        self.shown: Shown | None = None
        self.finished = False
        self.error: str | None = None

    def show(self, camera: dict, resolution: tuple) -> bool:
        """Passes through `camera` at `resolution` (see view_camera):
        whether they started afresh."""
        key = (tuple(sorted(camera.items())), tuple(resolution))
        if key == self.key:
            return False
        self.key = key
        for name, value in camera.items():
            setattr(self.scene.camera, name, value)
        passes = self.scene.progressive(self.renderer, resolution=tuple(resolution), **self.arguments)
        with self.lock:
            self.generation += 1
            self.finished, self.error = False, None
            generation = self.generation
        threading.Thread(target=self._run, args=(generation, passes), daemon=True).start()
        return True

    def _run(self, generation: int, passes):
        try:
            for p in passes:
                with self.lock:
                    if generation != self.generation:
                        return  # dropping `passes` stops them
                    self.shown = Shown(p.index, p.image, p.noise, generation)
                self.on_pass()
        except Exception as error:  # shown by the engine; the thread must not die silently
            with self.lock:
                if generation == self.generation:
                    self.error = str(error)
        with self.lock:
            if generation == self.generation:
                self.finished = True
        self.on_pass()

    def latest(self) -> Shown | None:
        with self.lock:
            return self.shown

    def stop(self):
        """The passes under way stop after their current pass."""
        with self.lock:
            self.generation += 1
            self.finished = True
