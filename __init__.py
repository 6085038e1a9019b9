# SolidWire extension entry point. The extension root is the repository root;
# all code lives in the solidwire_addon package. Blender always imports this
# file as a package (bl_ext.<repo>.solidwire); the guard lets tools that load
# it as a plain module (pytest collecting a checkout whose folder name is not
# a Python name) do so without failing on the relative import.
if __package__:
    from .solidwire_addon import register, stats, unregister  # noqa: F401  (the extension's entry points, re-exported)
