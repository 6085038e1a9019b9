"""The version helpers of core/compat.py on stand-ins for the two shapes
of Blender's scene API (a scene with compositor effects, Blender 5.3 on,
and one with a compositor node group property, 5.0-5.2). The real
compositor path is rendered by tests/test_composite.py on the Blender the
suite runs on."""

from __future__ import annotations

from types import SimpleNamespace

from solidwire_addon.core import compat


class _Effects:
    """A scene's compositor effects: an active one, and new() making one."""

    def __init__(self, active=None):
        self.active, self.made = active, []

    def new(self, name):
        effect = SimpleNamespace(name=name, node_group=None)
        self.made.append(effect)
        self.active = self.active or effect
        return effect


def test_a_scene_with_effects_gets_the_tree_on_a_new_effect_when_it_has_none():
    scene = SimpleNamespace(compositor_effects=_Effects())
    tree = SimpleNamespace(name="Invert")
    assert compat.has_compositor_node_group(scene)
    compat.set_compositor_node_group(scene, tree)
    assert [effect.node_group for effect in scene.compositor_effects.made] == [tree]
    assert scene.compositor_effects.active.name == "Invert"


def test_a_scene_with_an_active_effect_keeps_that_effect():
    active = SimpleNamespace(name="Grade", node_group=None)
    scene = SimpleNamespace(compositor_effects=_Effects(active))
    tree = SimpleNamespace(name="Invert")
    compat.set_compositor_node_group(scene, tree)
    assert active.node_group is tree and not scene.compositor_effects.made


def test_a_scene_without_effects_takes_the_node_group_property():
    scene = SimpleNamespace(compositing_node_group=None)
    tree = SimpleNamespace(name="Invert")
    assert compat.has_compositor_node_group(scene)
    compat.set_compositor_node_group(scene, tree)
    assert scene.compositing_node_group is tree
    assert not compat.has_compositor_node_group(SimpleNamespace())  # Blender 4.x
