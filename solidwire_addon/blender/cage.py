"""Cage edges (placeholder until the detection lands)."""


def cage_key(obj, render):
    return None


def cage_edges(obj, mesh, *, render):
    return None
