"""SolidWire's core: plain data and GPU work, no Blender UI or context.

Nothing in this package imports ``bpy.types`` or reads ``bpy.context``; it
takes plain data (numpy arrays, matrices, a settings snapshot) and draws with
Blender's ``gpu`` module. Modules, in the order data flows through them:

    schema      every setting, defined once
    settings    the settings snapshot and the shader parameter block
    view        View, DrawItem, DrawStats, frustum test
    extract     evaluated mesh -> numpy arrays
    cache       GPU meshes, keyed by the caller
    shaders     the one loader of shaders/*.glsl
    draw        one pass: shader variant + parameter block + batches
    silhouettes the full-width silhouette fin pass
    targets     offscreen float targets and their readback
    colors      per-object colours (colour sources) and their table
    matcaps     matcap images as textures (loaded by the Blender side)
    display_transform  the overlay's colour management as a 3D LUT (made by
                the Blender side)
    passes      the pass plan, run offscreen or over a viewport
    exr         reading back layers other engines rendered
"""
