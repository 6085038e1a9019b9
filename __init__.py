# SolidWire extension entry point. The extension root is the repository root;
# all code lives in the solidwire_addon package.
from .solidwire_addon import register, stats, unregister  # noqa: F401
