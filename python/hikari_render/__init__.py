"""hikari from Python: global illumination by photon mapping.

    import hikari_render as hk
    scene = hk.load("cornell-box")
    image = scene.render("path", spp=64)      # numpy float32, (height, width, 3)
    hk.save("out.png", image)

Every render goes through the same engine as the `hikari` command line, so
the same settings give the same pixels. See docs/python.md.
"""

from ._hikari import (
    Camera,
    Light,
    Material,
    Pass,
    Passes,
    Scene,
    SceneError,
    __version__,
    load,
    save,
    scenes,
)

__all__ = ["Camera", "Light", "Material", "Pass", "Passes", "Scene", "SceneError", "__version__", "load", "save", "scenes"]
