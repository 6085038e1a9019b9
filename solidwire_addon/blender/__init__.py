"""The Blender-facing side: everything that reads scenes, contexts and user
input, on top of ``core``. What each module holds is in the one module map,
docs/dev/architecture.md (tests/test_architecture.py checks that it lists
every module).
"""
