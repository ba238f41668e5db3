"""Whole datasets: `topovox batch`, `topovox.batch`, and the Dask and Ray
helpers write the same outputs and manifest lines, and resume each other."""

import json
import shutil

import numpy as np
import pytest

import topovox
from conftest import run_cli

MESHES = ["cow.obj", "suzanne.obj", "teapot.obj", "woody.obj", "beetle.obj", "alligator.obj"]


@pytest.fixture()
def dataset(tmp_path, meshes):
    """A small tree of meshes, a broken one among them."""
    root = tmp_path / "in"
    for n, name in enumerate(MESHES):
        d = root / ("a" if n % 2 else "b") / ("deep" if n % 3 == 0 else "")
        d.mkdir(parents=True, exist_ok=True)
        shutil.copy(meshes / name, d / name)
    (root / "b" / "broken.obj").write_text("v 0 0 0\nf 1 2 3\n")
    (root / "notes.txt").write_text("not a mesh")
    return root


def manifest(out):
    """The manifest's records; a torn line (a crash mid-write) is skipped, as topovox does."""
    records = []
    for line in (out / "manifest.jsonl").read_text().splitlines():
        try:
            records.append(json.loads(line))
        except json.JSONDecodeError:
            pass
    return records


def outputs(out):
    return {p.relative_to(out).as_posix(): np.load(p) for p in sorted(out.rglob("*.npy"))}


def test_python_batch_equals_cli_batch_and_resumes(tmp_path, dataset, cli):
    cli_out, py_out = tmp_path / "cli", tmp_path / "py"
    r = run_cli(cli, "batch", dataset, "-o", cli_out, "--resolution", 32, "--mode", "sep6", "--json", check=False)
    assert r.returncode == 1 and "1 of 7 meshes failed" in r.stderr
    summary = json.loads(r.stdout)
    assert (summary["done"], summary["failed"], summary["skipped"]) == (6, 1, 0)
    s = topovox.batch(dataset, py_out, resolution=32, mode="sep6")
    assert (s["done"], s["failed"], s["skipped"]) == (6, 1, 0)
    a, b = outputs(cli_out), outputs(py_out)
    assert a.keys() == b.keys() and len(a) == 6
    assert "b/deep/cow.npy" in a  # the input tree is mirrored
    for k in a:
        assert np.array_equal(a[k], b[k]), k
    # The same voxels as voxelize().
    one = topovox.voxelize(topovox.load_mesh(dataset / "b" / "deep" / "cow.obj"), mode="sep6", resolution=32).occupancy
    assert np.array_equal(b["b/deep/cow.npy"].astype(bool), one)
    lines = manifest(py_out)
    assert {line["status"] for line in lines} == {"done", "failed"}
    failed = [line for line in lines if line["status"] == "failed"]
    assert len(failed) == 1 and "broken.obj" in failed[0]["input"] and failed[0]["error"]
    done = [line for line in lines if line["status"] == "done"][0]
    assert set(done) >= {"input", "output", "grid", "voxels", "times", "options", "error"}
    # Resuming: the done ones are skipped, the failed one is tried again.
    s2 = topovox.batch(dataset, py_out, resolution=32, mode="sep6")
    assert (s2["done"], s2["failed"], s2["skipped"]) == (0, 1, 6)
    # The CLI resumes the Python run (same options, same manifest).
    r2 = json.loads(run_cli(cli, "batch", dataset, "-o", py_out, "--resolution", 32, "--mode", "sep6", "--json", check=False).stdout)
    assert r2["skipped"] == 6
    # Other options never replace the outputs without a word: refused,
    # naming what differs, and nothing is touched (issue 53).
    before = {p: p.stat().st_mtime_ns for p in py_out.rglob("*.npy")}
    with pytest.raises(FileExistsError, match="other options \\(resolution 32 → 16\\)"):
        topovox.batch(dataset, py_out, resolution=16, mode="sep6")
    assert {p: p.stat().st_mtime_ns for p in py_out.rglob("*.npy")} == before
    r3 = run_cli(cli, "batch", dataset, "-o", py_out, "--resolution", 16, "--mode", "sep6", check=False)
    assert r3.returncode == 1 and "other options" in r3.stderr and len(r3.stderr.strip().splitlines()) == 1, r3.stderr
    # Elsewhere they run.
    s3 = topovox.batch(dataset, tmp_path / "other", resolution=16, mode="sep6")
    assert s3["done"] == 6


def test_a_deleted_or_torn_output_is_redone(tmp_path, dataset):
    out = tmp_path / "o"
    topovox.batch(dataset, out, resolution=16, glob="**/*.obj")
    victim = out / "a" / "suzanne.npy"
    victim.unlink()
    # A torn manifest line (a crash mid-write) is ignored.
    with open(out / "manifest.jsonl", "a") as f:
        f.write('{"input": "x", "status": "do')
    s = topovox.batch(dataset, out, resolution=16, glob="**/*.obj")
    assert (s["done"], s["skipped"]) == (1, 5) and victim.exists()
    # The records after the torn line start on lines of their own.
    assert any(r["input"].endswith("suzanne.obj") and r["status"] == "done" for r in manifest(out)[-2:])


def test_batch_errors(tmp_path, dataset, meshes):
    with pytest.raises(ValueError, match="no input meshes found"):
        topovox.batch(dataset, tmp_path / "o", glob="**/*.stl")
    clash = tmp_path / "clash"
    clash.mkdir()
    shutil.copy(meshes / "cow.obj", clash / "m.obj")
    (clash / "m.stl").write_bytes(b"solid x\nendsolid x\n")
    # Inputs that differ only in their extension get one output each.
    s = topovox.batch(clash, tmp_path / "o2")
    assert (s["done"], s["failed"]) == (1, 1), s
    assert (tmp_path / "o2" / "m.obj.npy").exists() and not (tmp_path / "o2" / "m.npy").exists()
    assert {r["output"].rsplit("/", 1)[-1] for r in manifest(tmp_path / "o2")} == {"m.obj.npy", "m.stl.npy"}
    with pytest.raises(ValueError, match="would both be written to"):
        topovox.batch([clash / "m.obj", clash / "m.obj"], tmp_path / "o5")
    with pytest.raises(ValueError, match="unknown option \"resolutoin\""):
        topovox.batch(dataset, tmp_path / "o3", resolutoin=3)
    with pytest.raises(FileNotFoundError):
        topovox.batch(tmp_path / "missing", tmp_path / "o4")


def test_dask_local_cluster_writes_what_batch_writes(tmp_path, dataset):
    dask = pytest.importorskip("dask")
    distributed = pytest.importorskip("dask.distributed")
    import topovox.dask as vd

    ref = tmp_path / "ref"
    topovox.batch(dataset, ref, resolution=24, glob="**/*.obj")
    out = tmp_path / "dask"
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster):
            bag = vd.voxelize_paths([dataset], out, resolution=24, glob="**/*.obj")
            assert isinstance(bag, dask.bag.Bag) and bag.npartitions >= 2
            records = bag.compute()
    assert sorted(r["status"] for r in records) == ["done"] * 6 + ["failed"]
    a, b = outputs(ref), outputs(out)
    assert a.keys() == b.keys()
    for k in a:
        assert np.array_equal(a[k], b[k]), k
    assert len(manifest(out)) == 7
    # topovox batch resumes the Dask run.
    s = topovox.batch(dataset, out, resolution=24, glob="**/*.obj")
    assert s["skipped"] == 6


def test_ray_tasks_write_what_batch_writes(tmp_path, dataset):
    ray = pytest.importorskip("ray")
    import topovox.ray as vr

    ref = tmp_path / "ref"
    topovox.batch(dataset, ref, resolution=24, glob="**/*.obj")
    out = tmp_path / "ray"
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, ignore_reinit_error=True)
    try:
        records = vr.voxelize_paths([dataset], out, resolution=24, glob="**/*.obj")
    finally:
        ray.shutdown()
    assert sorted(r["status"] for r in records) == ["done"] * 6 + ["failed"]
    a, b = outputs(ref), outputs(out)
    assert a.keys() == b.keys()
    for k in a:
        assert np.array_equal(a[k], b[k]), k
    s = topovox.batch(dataset, out, resolution=24, glob="**/*.obj")
    assert s["skipped"] == 6


def test_batch_attributes_into_vdb(tmp_path, meshes, cli):
    """``attributes=True`` (``--attributes``) writes the attribute grids
    into each .vdb, the same bytes from Python and the CLI, and is part of
    the options a resumed batch compares."""
    src = tmp_path / "in"
    src.mkdir()
    shutil.copy(meshes / "spot-textured.obj", src)
    shutil.copy(meshes / "spot.mtl", src)
    shutil.copy(meshes / "spot_texture.png", src)
    plain, py_out, cli_out = tmp_path / "plain", tmp_path / "py", tmp_path / "cli"
    assert topovox.batch(src, plain, format="vdb", resolution=24)["done"] == 1
    assert topovox.batch(src, py_out, format="vdb", resolution=24, attributes=True)["done"] == 1
    run_cli(cli, "batch", src, "-o", cli_out, "--format", "vdb", "--resolution", 24, "--attributes", "--json")
    a, b = (py_out / "spot-textured.vdb").read_bytes(), (cli_out / "spot-textured.vdb").read_bytes()
    assert a == b
    assert len(a) > len((plain / "spot-textured.vdb").read_bytes())
    for name in (b"Cd", b"normal", b"coverage", b"material"):
        assert name in a
    assert manifest(py_out)[0]["options"]["attributes"] is True
    assert "attributes" not in manifest(plain)[0]["options"]
    # Other options never replace it without a word: attributes asked for
    # after a plain run are refused, naming the option (issue 53).
    with pytest.raises(FileExistsError, match="attributes unset → true"):
        topovox.batch(src, plain, format="vdb", resolution=24, attributes=True)
