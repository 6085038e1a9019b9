"""Names Blender knows SolidWire by, defined once."""

ENGINE_ID = "SOLIDWIRE"  # RenderEngine.bl_idname, scene.render.engine
EXTENSION_ID = "solidwire"  # blender_manifest.toml id, the `blender -c` command
