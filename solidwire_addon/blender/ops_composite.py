"""The "Render Wire Over" operator: one click renders the scene with another
engine, the SolidWire pass with the same camera, and writes the composite
(composite.py does the work)."""

from __future__ import annotations

from pathlib import Path

import bpy
from bpy.props import BoolProperty, EnumProperty, StringProperty

from . import composite
from .operator_errors import one_line_errors

ENGINE_ITEMS = (
    ("SCENE", "Scene Engine", "The scene's render engine (when that is not SolidWire)"),
    ("CYCLES", "Cycles", "Render the image underneath with Cycles"),
    ("BLENDER_EEVEE", "EEVEE", "Render the image underneath with EEVEE"),
    ("BLENDER_WORKBENCH", "Workbench", "Render the image underneath with Workbench"),
)


def default_output_path(scene) -> Path:
    """The scene's output path for the current frame, with '_wire_over'
    before the extension (the system temp folder when it is relative to an
    unsaved file)."""
    raw = scene.render.frame_path(frame=scene.frame_current)
    path = bpy.path.abspath(raw)
    if path.startswith("//"):
        import tempfile

        path = str(Path(tempfile.gettempdir()) / path[2:])
    path = Path(path)
    if path.name == "" or path.is_dir():
        path = path / f"{scene.frame_current:04d}"
    return path.with_name(path.stem + "_wire_over" + path.suffix)


class SOLIDWIRE_OT_render_wire_over(bpy.types.Operator):
    """Render the scene with Cycles, EEVEE or Workbench, render the SolidWire pass from the same camera, and write the wire composited over the render with the scene's output format"""

    bl_idname = "solidwire.render_wire_over"
    bl_label = "Render Wire Over"
    bl_options = {"REGISTER"}

    engine: EnumProperty(
        name="Engine", description="Engine of the render underneath the wire", items=ENGINE_ITEMS, default="SCENE"
    )
    filepath: StringProperty(
        name="File Path",
        subtype="FILE_PATH",
        description="Image to write (empty: the scene's output path with '_wire_over' added)",
    )
    keep_layers: BoolProperty(
        name="Keep Layers",
        default=False,
        description="Also write the two float layers (NAME.beauty.exr, NAME.wire.exr) beside the image",
    )
    show_result: BoolProperty(
        name="Show Result",
        default=True,
        description="Open the written image in an Image Editor (interactive sessions only)",
    )

    @classmethod
    def poll(cls, context):
        scene = getattr(context, "scene", None)
        return scene is not None and getattr(scene, "solidwire", None) is not None

    @one_line_errors
    def execute(self, context):
        scene = context.scene
        path = Path(bpy.path.abspath(self.filepath)) if self.filepath else default_output_path(scene)
        try:
            layers = composite.render_wire_over(
                scene, path, self.engine, keep_layers=self.keep_layers, view_layer=context.view_layer
            )
        except composite.CompositeError as exc:
            self.report({"ERROR"}, f"SolidWire: {exc}")
            return {"CANCELLED"}
        except OSError as exc:
            self.report({"ERROR"}, f"SolidWire: cannot write '{path}': {exc.strerror or exc}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"SolidWire: wire over {layers.engine} written to {path}")
        if self.show_result and not bpy.app.background:
            self._show(context, path)
        return {"FINISHED"}

    @staticmethod
    def _show(context, path: Path) -> None:
        image = bpy.data.images.load(str(path), check_existing=True)
        image.reload()
        screen = getattr(context, "screen", None)
        for area in getattr(screen, "areas", ()):
            if area.type == "IMAGE_EDITOR":
                area.spaces.active.image = image
                return


class SOLIDWIRE_MT_render_wire_over(bpy.types.Menu):
    """Engines to render under the wire (the sidebar's "Render Wire Over")"""

    bl_idname = "SOLIDWIRE_MT_render_wire_over"
    bl_label = "Render Wire Over"

    def draw(self, context):
        layout = self.layout
        scene_engine = context.scene.render.engine
        for identifier, name, _description in ENGINE_ITEMS:
            if identifier == "SCENE":
                if scene_engine == composite.ENGINE_ID:
                    continue  # nothing to draw under the wire
                name = f"Scene Engine ({scene_engine.replace('BLENDER_', '').title()})"
            op = layout.operator(SOLIDWIRE_OT_render_wire_over.bl_idname, text=name)
            op.engine = identifier


classes = (SOLIDWIRE_OT_render_wire_over, SOLIDWIRE_MT_render_wire_over)
