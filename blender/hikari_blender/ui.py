"""The settings in the Render properties when hikari is the engine."""

import bpy


class HIKARI_PT_render(bpy.types.Panel):
    bl_label = "hikari"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {"HIKARI"}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        settings = context.scene.hikari
        layout.prop(settings, "renderer")
        column = layout.column(heading="Stop At")
        column.prop(settings, "time_limit")
        column.prop(settings, "passes")
        column.prop(settings, "target_error")
        layout.prop(settings, "photons")
        layout.prop(settings, "seed")
        row = layout.row()
        row.active = settings.renderer == "gpu"
        row.prop(settings, "gpu")
        layout.prop(settings, "threads")
        layout.prop(settings, "viewport_pixel_size")


# Blender's own panels that edit what hikari reads: output size and
# format, colour management; the material's node tree (Principled BSDF),
# the world's, the lights' (EEVEE's panels show exactly those).
SHARED_PANELS = [
    "RENDER_PT_format", "RENDER_PT_color_management", "RENDER_PT_output", "RENDER_PT_frame_range",
    "EEVEE_MATERIAL_PT_context_material", "EEVEE_MATERIAL_PT_surface", "EEVEE_WORLD_PT_surface",
    "DATA_PT_context_light", "DATA_PT_EEVEE_light", "DATA_PT_light", "DATA_PT_area",
    "DATA_PT_spot", "DATA_PT_camera", "DATA_PT_lens", "DATA_PT_camera_dof",
]


def register():
    bpy.utils.register_class(HIKARI_PT_render)
    for name in SHARED_PANELS:
        panel = getattr(bpy.types, name, None)
        if panel is not None and hasattr(panel, "COMPAT_ENGINES"):
            panel.COMPAT_ENGINES.add("HIKARI")


def unregister():
    for name in SHARED_PANELS:
        panel = getattr(bpy.types, name, None)
        if panel is not None and hasattr(panel, "COMPAT_ENGINES"):
            panel.COMPAT_ENGINES.discard("HIKARI")
    bpy.utils.unregister_class(HIKARI_PT_render)
