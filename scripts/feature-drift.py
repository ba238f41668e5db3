#!/usr/bin/env python3
"""Which crates the README's set-up builds more than one way.

`cargo run -p topovox-cli` (README's first command), `cargo test
--workspace` and the Python wheel (`-p topovox-python`) each resolve
features for the crates they share; a crate resolved two ways (and every
crate above it) is compiled twice. topovox-job's Cargo.toml names the
features the others turn on so they agree; this lists any that still
differ, from cargo's unit graphs (`-Z unstable-options --unit-graph`,
allowed on stable by RUSTC_BOOTSTRAP=1; nothing is compiled). Exits 1 on
drift. Workspace crates whose own features differ on purpose (topovox-job
without `gpu` in the wheel, the viewer's `window`) are not counted.
"""

import json
import os
import subprocess
import sys

BUILDS = {
    "run": ["build", "--release", "-p", "topovox-cli"],
    "test": ["test", "--workspace", "--release", "--no-run"],
    "wheel": ["build", "--release", "-p", "topovox-python", "--lib"],
}


def features(args):
    env = dict(os.environ, RUSTC_BOOTSTRAP="1")
    out = subprocess.run(["cargo", *args, "--unit-graph", "-Z", "unstable-options"], env=env, check=True, capture_output=True, text=True).stdout
    seen = {}
    for u in json.loads(out)["units"]:
        if u["mode"] == "build" and not u["pkg_id"].startswith("path+"):
            seen.setdefault(u["pkg_id"].split("#")[-1], set()).add(tuple(sorted(u["features"])))
    return seen


def main():
    graphs = {name: features(args) for name, args in BUILDS.items()}
    drift = 0
    for crate in sorted(set().union(*graphs.values())):
        ways = {name: g[crate] for name, g in graphs.items() if crate in g}
        # Host and target builds of one crate may differ within a build; across builds they must agree.
        if len({frozenset(w) for w in ways.values()}) > 1:
            drift += 1
            every = set().union(*(set(f) for w in ways.values() for f in w))
            for name, w in ways.items():
                for f in w:
                    print(f"{crate}: {name} lacks {sorted(every - set(f))}")
    print(f"{drift} shared crates built more than one way")
    return 1 if drift else 0


if __name__ == "__main__":
    sys.exit(main())
