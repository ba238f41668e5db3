"""Shared by the interoperability checks: run topovox, count checks."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np


class Oracle:
    def __init__(self, topovox):
        self.topovox = topovox
        self.passed = 0
        self.failed = 0

    def check(self, name, cond, detail=""):
        if cond:
            self.passed += 1
            print(f"ok   {name}")
        else:
            self.failed += 1
            print(f"FAIL {name} {detail}")

    def voxelize(self, mesh, out, *extra):
        r = subprocess.run([self.topovox, "voxelize", str(mesh), "-o", str(out), "--json", *extra], capture_output=True, text=True)
        if r.returncode != 0:
            raise SystemExit(f"topovox failed: {r.stderr}")
        return json.loads(r.stdout)

    def finish(self):
        print(f"{self.passed} passed, {self.failed} failed")
        sys.exit(1 if self.failed else 0)


def text_voxels(path):
    """topovox's text list of voxels as a sorted (n, 3) int64 array."""
    rows = [l.split() for l in Path(path).read_text().splitlines() if l and not l.startswith("#")]
    return np.array(sorted((int(a), int(b), int(c)) for a, b, c in rows), dtype=np.int64).reshape(-1, 3)
