"""Fetch the benchmark's real meshes into cache/meshes/ (optional step).

Nothing here is installed system-wide and nothing is committed: Debian
packages are downloaded with ``apt-get download`` into cache/debs/, unpacked
with ``dpkg-deb -x`` into cache/pkgroot/, and the meshes are written as plain
OBJ files into cache/meshes/ (cache/ is git-ignored):

- teapot.obj: the Utah teapot from povray-examples' ``teapot.inc`` (32 bicubic
  Bezier patches), each patch tessellated 10 x 10 into 200 triangles; the
  triangles that collapse at the lid's and bottom's poles are dropped, which
  leaves 6320 triangles, the count the papers' benchmark tables use.
- bunny.obj: the Stanford bunny as glmark2-data ships it (``models/bunny.obj``,
  69,666 triangles), copied unchanged.

Suzanne at subdivision level 5 needs no download (scripts/bench/ builds it
in Blender). Without apt (not Debian, no network), this prints a message and
exits 0; the benchmark then skips the scenes whose mesh is missing.

    python scripts/fetch_meshes.py [--force]
"""

from __future__ import annotations

import argparse
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
CACHE = ROOT / "cache"
MESH_DIR = CACHE / "meshes"
PACKAGES = ("povray-examples", "glmark2-data")
TEAPOT_INC = "usr/share/doc/povray/examples/advanced/teapot/teapot.inc"
BUNNY_OBJ = "usr/share/glmark2/models/bunny.obj"
PATCH_STEPS = 10  # per patch direction: 10 x 10 quads = 200 triangles


def download_packages() -> Path | None:
    """Download and unpack the packages; the unpacked root, or None."""
    if shutil.which("apt-get") is None or shutil.which("dpkg-deb") is None:
        print("fetch_meshes: apt-get/dpkg-deb not available; skipping the optional mesh download.")
        print("fetch_meshes: the benchmark will skip the teapot and bunny scenes.")
        return None
    debs = CACHE / "debs"
    root = CACHE / "pkgroot"
    debs.mkdir(parents=True, exist_ok=True)
    root.mkdir(parents=True, exist_ok=True)
    try:
        subprocess.run(["apt-get", "download", *PACKAGES], cwd=debs, check=True)
    except (subprocess.CalledProcessError, OSError) as exc:
        print(f"fetch_meshes: 'apt-get download' failed ({exc}); skipping the optional mesh download.")
        return None
    for deb in sorted(debs.glob("*.deb")):
        subprocess.run(["dpkg-deb", "-x", str(deb), str(root)], check=True)
    return root


# --------------------------------------------------------------- Bezier teapot

_VECTOR = re.compile(r"<\s*([-+0-9.eE]+)\s*,\s*([-+0-9.eE]+)\s*,\s*([-+0-9.eE]+)\s*>")


def parse_bicubic_patches(text: str) -> np.ndarray:
    """(P, 4, 4, 3) control points of every ``bicubic_patch`` in POV-Ray
    source: the 16 vectors after the keyword, row by row."""
    patches = []
    for block in text.split("bicubic_patch")[1:]:
        points = [tuple(float(c) for c in m.groups()) for m in _VECTOR.finditer(block)][:16]
        if len(points) != 16:
            raise ValueError(f"a bicubic_patch with {len(points)} control points (expected 16)")
        patches.append(np.array(points).reshape(4, 4, 3))
    return np.array(patches)


def _bernstein(t: np.ndarray) -> np.ndarray:
    """(len(t), 4) cubic Bernstein weights."""
    s = 1.0 - t
    return np.stack([s**3, 3 * s * s * t, 3 * s * t * t, t**3], axis=1)


def tessellate(patches: np.ndarray, steps: int = PATCH_STEPS, weld: float = 1e-6):
    """Evaluate every patch on a (steps+1)^2 grid, two triangles per grid cell,
    weld coincident vertices across patches, drop triangles with two equal
    corners (the poles). Returns (vertices (V, 3), triangles (T, 3))."""
    basis = _bernstein(np.linspace(0.0, 1.0, steps + 1))
    # S(u, v) = sum_ij B_i(u) B_j(v) P_ij for all patches at once.
    grid = np.einsum("ui,vj,pijc->puvc", basis, basis, patches)  # (P, n, n, 3)
    n = steps + 1
    positions = grid.reshape(-1, 3)
    keys = np.round(positions / weld).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    vertices = positions[first]
    tris = []
    for p in range(len(patches)):
        idx = inverse[p * n * n : (p + 1) * n * n].reshape(n, n)
        a, b, c, d = idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]
        tris.append(np.stack([a, b, c], axis=-1).reshape(-1, 3))
        tris.append(np.stack([a, c, d], axis=-1).reshape(-1, 3))
    tris = np.concatenate(tris)
    keep = (tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) & (tris[:, 2] != tris[:, 0])
    return vertices, tris[keep]


def write_obj(path: Path, vertices: np.ndarray, triangles: np.ndarray, comment: str) -> None:
    with open(path, "w", encoding="ascii") as out:
        out.write(f"# {comment}\n")
        np.savetxt(out, vertices, fmt="v %.7f %.7f %.7f")
        np.savetxt(out, triangles + 1, fmt="f %d %d %d")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--force", action="store_true", help="download and rebuild even if the meshes exist")
    args = parser.parse_args(argv)

    teapot, bunny = MESH_DIR / "teapot.obj", MESH_DIR / "bunny.obj"
    if teapot.exists() and bunny.exists() and not args.force:
        print(f"fetch_meshes: {teapot} and {bunny} already exist (--force to rebuild)")
        return 0
    root = download_packages()
    if root is None:
        return 0
    MESH_DIR.mkdir(parents=True, exist_ok=True)

    patches = parse_bicubic_patches((root / TEAPOT_INC).read_text(encoding="latin-1"))
    vertices, triangles = tessellate(patches)
    write_obj(
        teapot,
        vertices,
        triangles,
        f"Utah teapot from Debian povray-examples teapot.inc: {len(patches)} Bezier patches, "
        f"{PATCH_STEPS}x{PATCH_STEPS} per patch, {len(triangles)} triangles",
    )
    print(f"fetch_meshes: {teapot} ({len(patches)} patches, {len(vertices)} vertices, {len(triangles)} triangles)")

    shutil.copyfile(root / BUNNY_OBJ, bunny)
    with open(bunny, encoding="ascii", errors="replace") as obj_file:
        faces = sum(1 for line in obj_file if line.startswith("f "))
    print(f"fetch_meshes: {bunny} ({faces} triangles, from Debian glmark2-data)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
