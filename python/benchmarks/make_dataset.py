"""A deterministic dataset of meshes for the dataset benchmarks: the shared
test meshes, each copy randomly rotated, scaled and moved, written as
binary STL (compact, and read by every tool compared).

    python python/benchmarks/make_dataset.py OUT_DIR [--count 1000] [--seed 0]
"""

import argparse
import pathlib
import sys

import numpy as np

import topovox


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def write_stl(path: pathlib.Path, v: np.ndarray, f: np.ndarray) -> None:
    tri = v[f].astype(np.float32)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    rec = np.zeros(len(f), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rec["n"], rec["v"] = n, tri
    with open(path, "wb") as out:
        out.write(b"topovox benchmark dataset".ljust(80, b" "))
        out.write(np.uint32(len(f)).tobytes())
        out.write(rec.tobytes())


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("out", type=pathlib.Path)
    ap.add_argument("--count", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--shared", type=pathlib.Path, default=pathlib.Path(__file__).resolve().parents[3] / "shared" / "meshes")
    a = ap.parse_args()
    sources = sorted(p for p in a.shared.glob("*.obj"))
    meshes = [(p.stem, topovox.load_mesh(p)) for p in sources]
    rng = np.random.default_rng(a.seed)
    a.out.mkdir(parents=True, exist_ok=True)
    for i in range(a.count):
        name, m = meshes[rng.integers(len(meshes))]
        v = m.vertices
        v = (v - v.mean(axis=0)) @ random_rotation(rng).T * rng.uniform(0.5, 2.0) + rng.uniform(-1, 1, 3)
        write_stl(a.out / f"{i:04d}-{name}.stl", v, m.faces)
    print(f"{a.count} meshes in {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
