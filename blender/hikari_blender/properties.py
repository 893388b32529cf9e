"""The render settings, at `scene.hikari`."""

import bpy

RENDERERS = [
    ("gpu", "GPU", "Photon splatting on the GPU (photon-cpu where no adapter can, with a warning)"),
    ("photon-cpu", "Photon CPU", "Photon mapping with a fixed radius on the CPU"),
    ("path", "Path", "The unbiased path tracer"),
    ("vcm", "VCM", "Vertex connection and merging"),
]


class HikariSettings(bpy.types.PropertyGroup):
    renderer: bpy.props.EnumProperty(name="Renderer", items=RENDERERS, default="gpu")
    time_limit: bpy.props.FloatProperty(
        name="Time Limit", description="Stop after the first pass ending past this many seconds (0: none)",
        default=60.0, min=0.0, soft_max=3600.0, unit="TIME_ABSOLUTE")
    passes: bpy.props.IntProperty(
        name="Passes", description="Stop after this many progressive passes (0: none)", default=0, min=0)
    target_error: bpy.props.FloatProperty(
        name="Noise Target", description="Stop once the estimated noise, relative to the image's mean, "
        "is this low (0: none)", default=0.02, min=0.0, max=0.99, precision=3, step=0.1)
    photons: bpy.props.IntProperty(
        name="Photons", description="Photon paths traced per pass", default=200_000, min=1_000, soft_max=10_000_000)
    seed: bpy.props.IntProperty(
        name="Seed", description="The same seed gives the same image whatever the thread count", default=0, min=0)
    gpu: bpy.props.StringProperty(
        name="GPU", description="The GPU renderer's adapter: its number or part of its name, as hikari's "
        "HIKARI_GPU takes it (empty: the first that can)", default="")
    viewport_pixel_size: bpy.props.IntProperty(
        name="Viewport Pixel Size", description="The 3D view's Rendered shading renders one pixel per this many "
        "pixels across (Cycles' Pixel Size)", default=2, min=1, max=16)
    threads: bpy.props.IntProperty(
        name="Threads", description="CPU threads (0: all cores)", default=0, min=0, soft_max=256)

    def render_arguments(self) -> dict:
        """The keyword arguments of hikari_render's Scene.progressive.
        With none of the three limits, hikari's own: 2% noise or 20 s."""
        kwargs = {"photons": self.photons, "seed": self.seed}
        if self.time_limit > 0:
            kwargs["time"] = self.time_limit
        if self.passes > 0:
            kwargs["passes"] = self.passes
        if self.target_error > 0:
            kwargs["target_error"] = self.target_error
        if self.threads > 0:
            kwargs["threads"] = self.threads
        return kwargs


def register():
    bpy.utils.register_class(HikariSettings)
    bpy.types.Scene.hikari = bpy.props.PointerProperty(type=HikariSettings)


def unregister():
    del bpy.types.Scene.hikari
    bpy.utils.unregister_class(HikariSettings)
