"""The Blender-facing side: everything that reads scenes, contexts and user
input, on top of ``core``.

    properties  PropertyGroups made from the schema
    runtime     process state: the mesh cache, depsgraph handlers, stats
    gather      scene/depsgraph -> draw items (extracting through the cache)
    views       cameras and viewports -> core.view.View
    gpu_context the GPU in background mode
    engine      the SOLIDWIRE render engine
    overlay     the viewport overlay (a draw handler)
    color_management  the scene's view transform as the overlay's display LUT
    presets     preset files, validated against the schema
    composite   wire over a Cycles/EEVEE/Workbench render
    cli         the command line (``blender -c solidwire render``)
    ops, ops_composite, ui   operators, keymap and panels
"""
