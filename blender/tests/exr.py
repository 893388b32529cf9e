"""Reading the multilayer EXR files Blender writes: {"Combined": (h, w, 4),
"Depth": (h, w), "Denoising Normal": (h, w, 3), …}, rows top to bottom."""

import numpy as np
import OpenEXR


def read_passes(path) -> dict:
    channels = {}
    with OpenEXR.File(str(path)) as f:
        for part in f.parts:
            for name, channel in part.channels.items():
                channels[name] = np.asarray(channel.pixels, dtype=np.float32)
    passes = {}
    for name, pixels in channels.items():
        # "ViewLayer.Denoising Normal.X" (split channels) or "ViewLayer.Combined" (an RGBA group).
        parts = name.split(".")
        if parts[-1] in {"X", "Y", "Z", "R", "G", "B", "A", "V"} and len(parts) == 3:
            passes.setdefault(parts[1], {})[parts[2]] = pixels
        else:
            passes[parts[1] if len(parts) > 1 else parts[0]] = pixels
    for key, value in passes.items():
        if isinstance(value, dict):
            order = [c for c in "XYZRGBAV" if c in value]
            passes[key] = value[order[0]] if len(order) == 1 else np.stack([value[c] for c in order], axis=-1)
    return passes


def blocks(image: np.ndarray, side: int = 16) -> np.ndarray:
    """The means of side × side blocks (whole blocks only)."""
    h, w = image.shape[0] // side * side, image.shape[1] // side * side
    rest = image.shape[2:]
    return image[:h, :w].reshape(h // side, side, w // side, side, *rest).mean(axis=(1, 3))
