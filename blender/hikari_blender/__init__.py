"""hikari inside Blender: a render engine (bl_idname "HIKARI") that renders
the scene with hikari's photon mapping, path tracing or VCM through the
hikari_render module, pass by pass in the render window, with the passes
Blender's denoiser takes (docs/blender.md)."""

from . import engine, properties, ui

_MODULES = [properties, engine, ui]


def register():
    for module in _MODULES:
        module.register()


def unregister():
    for module in reversed(_MODULES):
        module.unregister()
