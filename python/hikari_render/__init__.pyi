"""Types of hikari_render (the module `_hikari` built from crates/python)."""

import os
from collections.abc import Iterator
from typing import Literal, overload

import numpy as np
import numpy.typing as npt

__version__: str

Renderer = Literal["gpu", "photon-cpu", "path", "vcm"]
Image = npt.NDArray[np.float32]

class SceneError(ValueError):
    """A scene that cannot be loaded: the message names the file, the place and the problem."""

def scenes() -> list[str]:
    """The built-in scenes' names."""

def load(
    scene: str | os.PathLike[str],
    *,
    camera: str | None = None,
    environment: str | os.PathLike[str] | None = None,
) -> Scene:
    """A built-in name, a .toml scene, or a glTF 2.0 file (.glb, .gltf); raises SceneError."""

def save(path: str | os.PathLike[str], image: Image, *, exposure: float = 0.0) -> None:
    """A .png tone-mapped as the CLI does, or a linear .exr."""

class Pass:
    """One progressive pass: the mean so far and its estimated noise."""

    index: int
    image: Image
    noise: float | None
    seconds: float

class Passes(Iterator[Pass]):
    def __iter__(self) -> Passes: ...
    def __next__(self) -> Pass: ...

Vec3 = tuple[float, float, float]

class Camera:
    """The scene's camera: setting a field changes what the next render sees."""

    position: Vec3
    look_at: Vec3
    up: Vec3
    fov_y: float

class Light:
    """One of the scene's lights: setting a field changes the next render."""

    @property
    def kind(self) -> Literal["point", "spot", "sphere", "quad", "sun", "sky", "mesh"]: ...
    @property
    def name(self) -> str | None: ...
    color: Vec3
    """W/sr (point, spot), W/m² (sun), W/(m² sr) (area lights, skies, emissive meshes)."""
    @property
    def position(self) -> Vec3 | None: ...
    @position.setter
    def position(self, value: Vec3) -> None: ...

class Material:
    """One of the scene's materials: setting a field changes the next render."""

    @property
    def kind(self) -> Literal["diffuse", "mirror", "glass", "pbr", "emitter"]: ...
    @property
    def base_color(self) -> Vec3 | None: ...
    @base_color.setter
    def base_color(self, value: Vec3) -> None: ...
    @property
    def metallic(self) -> float | None: ...
    @metallic.setter
    def metallic(self, value: float) -> None: ...
    @property
    def roughness(self) -> float | None: ...
    @roughness.setter
    def roughness(self, value: float) -> None: ...
    @property
    def clearcoat(self) -> float | None: ...
    @clearcoat.setter
    def clearcoat(self, value: float) -> None: ...
    @property
    def clearcoat_roughness(self) -> float | None: ...
    @clearcoat_roughness.setter
    def clearcoat_roughness(self, value: float) -> None: ...
    @property
    def specular_color(self) -> Vec3 | None: ...
    @specular_color.setter
    def specular_color(self, value: Vec3) -> None: ...
    @property
    def sheen_color(self) -> Vec3 | None: ...
    @sheen_color.setter
    def sheen_color(self, value: Vec3) -> None: ...
    @property
    def sheen_roughness(self) -> float | None: ...
    @sheen_roughness.setter
    def sheen_roughness(self, value: float) -> None: ...
    emission: Vec3
    """RGB radiance, W/(m² sr); (0, 0, 0) where the material emits nothing (which cannot be changed)."""

class Scene:
    """A loaded scene."""

    @property
    def resolution(self) -> tuple[int, int]: ...
    @property
    def camera(self) -> Camera: ...
    @property
    def lights(self) -> list[Light]: ...
    @property
    def materials(self) -> dict[str, Material]: ...
    @overload
    def render(
        self,
        renderer: Renderer = "gpu",
        *,
        spp: int | None = None,
        passes: int | None = None,
        time: float | None = None,
        target_error: float | None = None,
        photons: int | None = None,
        radius: float | None = None,
        resolution: tuple[int, int] | None = None,
        seed: int = 0,
        threads: int | None = None,
        at: float = 0.0,
        aovs: Literal[False] = False,
    ) -> Image:
        """The image, float32 (height, width, 3), linear radiance."""
    @overload
    def render(
        self,
        renderer: Renderer = "gpu",
        *,
        spp: int | None = None,
        passes: int | None = None,
        time: float | None = None,
        target_error: float | None = None,
        photons: int | None = None,
        radius: float | None = None,
        resolution: tuple[int, int] | None = None,
        seed: int = 0,
        threads: int | None = None,
        at: float = 0.0,
        aovs: Literal[True],
    ) -> dict[str, Image]:
        """"color", "albedo", "normal" (height, width, 3) and "depth" (height, width)."""

    def aovs(
        self, *, resolution: tuple[int, int] | None = None, at: float = 0.0
    ) -> dict[str, Image]:
        """"albedo", "normal" (height, width, 3) and "depth" (height, width), without rendering the colour."""

    def progressive(
        self,
        renderer: Renderer = "gpu",
        *,
        spp: int | None = None,
        passes: int | None = None,
        time: float | None = None,
        target_error: float | None = None,
        photons: int | None = None,
        radius: float | None = None,
        resolution: tuple[int, int] | None = None,
        seed: int = 0,
        threads: int | None = None,
        at: float = 0.0,
    ) -> Passes:
        """The same render pass by pass."""
