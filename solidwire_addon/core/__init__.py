"""SolidWire's core: plain data and GPU work, no Blender UI or context.

Nothing in this package imports ``bpy``: it takes plain data (numpy arrays,
float64 matrices, a settings snapshot) and draws with Blender's ``gpu``
module. What each module holds is in the one module map,
docs/dev/architecture.md (tests/test_architecture.py checks that it lists
every module).
"""
