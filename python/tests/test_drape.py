"""garnet.Draper and garnet.Body against `garnet drape`, and their errors."""

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import garnet
from conftest import REPO, TSHIRT, read_obj, run


@pytest.fixture(scope="module")
def draper():
    return garnet.Draper(TSHIRT)


@pytest.mark.parametrize("flags", [[], ["--raw", "--keep-pose"]], ids=["default", "raw-keep-pose"])
def test_drape_equals_the_cli(garnet_bin, draper, tmp_path, flags):
    out = tmp_path / "draped.obj"
    run(
        garnet_bin, "drape", "--model", str(TSHIRT), "--random-shape", "3",
        "--pose-procedural", "4", "--out", str(out), *flags,
    )
    cli_vertices, cli_faces = read_obj(out)
    body = garnet.Body.random(3, pose=garnet.Pose.procedural(4))
    result = draper.drape(body, raw="--raw" in flags, keep_pose="--keep-pose" in flags)
    assert result.vertices.dtype == np.float32 and result.vertices.shape == cli_vertices.shape
    assert result.faces.dtype == np.uint32
    np.testing.assert_array_equal(result.faces, cli_faces)
    assert np.abs(result.vertices - cli_vertices).max() <= 1e-5
    assert set(result.timings) == {"warp_ms", "network_ms", "push_out_ms", "collider_ms"}
    assert result.kind == "tshirt"
    if "--raw" in flags:
        assert result.pushed_out == 0


def test_body_arrays_and_units():
    body = garnet.Body.random(3, pose=garnet.Pose.procedural(4))
    v, f, j = body.vertices, body.faces, body.joints
    assert v.dtype == np.float32 and v.ndim == 2 and v.shape[1] == 3
    assert f.dtype == np.uint32 and f.shape[1] == 3 and f.max() < len(v)
    assert j.dtype == np.float32 and j.shape == (len(body.bone_names), 3)
    assert 1.4 < body.height < 2.1
    assert body.pose.rotations.shape == (len(body.bone_names), 4)
    assert body.pose.root_translation.shape == (3,)
    # The same body from its concrete pose's arrays.
    again = garnet.Body(body.phenotype, pose=garnet.Pose.from_arrays(
        body.pose.rotations, body.pose.root_translation))
    np.testing.assert_allclose(again.vertices, v, atol=1e-5)


def test_default_body_and_poses():
    rest = garnet.Body()
    assert abs(rest.height - 1.626) < 0.01
    np.testing.assert_allclose(rest.vertices, rest.rest_vertices, atol=1e-6)
    tpose = rest.with_pose(garnet.Pose.tpose())
    assert not np.allclose(tpose.vertices, rest.vertices)
    body = garnet.Body({"gender": 0.0, "weight": 0.8}, pose=garnet.Pose.procedural(2, kind="walk"))
    assert body.phenotype["gender"] == 0.0
    with pytest.raises(ValueError, match="depends on the body"):
        garnet.Pose.procedural(2).rotations


def synthetic_walk(dir: Path, frames: int) -> Path:
    """A CMU-style walk garnet writes itself (ASF and AMC) into `dir`; the AMC's path."""
    subprocess.run(
        ["cargo", "run", "--release", "-q", "-p", "body", "--example", "synthetic_walk", "--",
         str(dir), str(frames)],
        cwd=REPO, check=True, capture_output=True,
    )
    return dir / "cmu" / "02" / "02_01.amc"


def test_clip_poses(tmp_path, garnet_bin):
    amc = synthetic_walk(tmp_path, 40)
    body = garnet.Body.random(1, pose=garnet.Pose.from_amc(amc, frame=30))
    assert body.pose.description == "02_01.amc frame 30"
    bvh = tmp_path / "walk.bvh"
    run(garnet_bin, "pose", "convert", "--asf", str(amc.with_name("02.asf")), "--amc",
        str(amc), "--out", str(bvh))
    from_bvh = garnet.Body.random(1, pose=garnet.Pose.from_bvh(bvh, frame=30))
    assert from_bvh.vertices.shape == body.vertices.shape
    with pytest.raises(ValueError, match="past the clip"):
        garnet.Pose.from_amc(amc, frame=10**7)


def test_bad_phenotypes_raise_value_errors():
    with pytest.raises(ValueError, match="phenotype gender = NaN is outside"):
        garnet.Body({"gender": math.nan})
    with pytest.raises(ValueError, match="unknown phenotype parameter"):
        garnet.Body({"gendre": 0.5})
    with pytest.raises(ValueError, match="outside"):
        garnet.Body({"age": 1.5})
    with pytest.raises(ValueError, match="unknown pose kind"):
        garnet.Pose.procedural(1, kind="sprint")
    with pytest.raises(ValueError, match="unknown skinning"):
        garnet.Body(skinning="spline")


def test_bad_pose_arrays_raise_value_errors():
    with pytest.raises(ValueError, match=r"shape \[N, 4\]"):
        garnet.Pose.from_arrays(np.zeros((5, 3)))
    with pytest.raises(ValueError, match="not finite"):
        garnet.Pose.from_arrays(np.full((5, 4), np.nan))
    wrong = garnet.Pose.from_arrays(np.tile([0.0, 0.0, 0.0, 1.0], (5, 1)))
    with pytest.raises(ValueError, match="bone rotations"):
        garnet.Body(pose=wrong)


def test_missing_and_damaged_models(tmp_path):
    missing = tmp_path / "none.garnet"
    with pytest.raises(FileNotFoundError, match="none.garnet"):
        garnet.Draper(missing)
    garbage = tmp_path / "garbage.garnet"
    garbage.write_bytes(b"not a model at all")
    with pytest.raises(garnet.GarnetError, match="garbage.garnet"):
        garnet.Draper(garbage)
    # A real model with its tensors damaged: the checksum refuses it.
    damaged = tmp_path / "damaged.garnet"
    shutil.copy(TSHIRT, damaged)
    data = bytearray(damaged.read_bytes())
    data[-100] ^= 0xFF
    damaged.write_bytes(bytes(data))
    with pytest.raises(garnet.GarnetError, match="damaged.garnet"):
        garnet.Draper(damaged)


def test_the_error_message_is_the_clis(garnet_bin, tmp_path):
    import subprocess

    missing = tmp_path / "none.garnet"
    done = subprocess.run(
        [str(garnet_bin), "drape", "--model", str(missing), "--out", str(tmp_path / "x.obj")],
        cwd=REPO, capture_output=True, text=True,
    )
    assert done.returncode != 0
    with pytest.raises(FileNotFoundError) as err:
        garnet.Draper(missing)
    assert str(err.value) in done.stderr


def test_metrics():
    rng = np.random.default_rng(0)
    gt = rng.normal(size=(100, 3)).astype(np.float32)
    faces = np.array([[i, i + 1, i + 2] for i in range(98)], dtype=np.uint32)
    assert garnet.metrics.e_dist(gt, gt) == 0.0
    assert garnet.metrics.e_dist(gt, gt + np.array([0.01, 0, 0], np.float32)) == pytest.approx(1.0, rel=1e-3)
    assert garnet.metrics.e_norm(gt, gt, faces) == pytest.approx(0.0, abs=1e-3)
    # Negating every point leaves every face normal as it was; a mirror image does not.
    assert garnet.metrics.e_norm(gt, -gt, faces) == pytest.approx(0.0, abs=1e-2)
    flipped = gt * np.array([1, 1, -1], np.float32)
    assert garnet.metrics.e_norm(gt, flipped, faces) > 10
    with pytest.raises(ValueError, match="ground-truth vertices"):
        garnet.metrics.e_dist(gt, gt[:50])
    with pytest.raises(ValueError, match=r"shape \[N, 3\]"):
        garnet.metrics.e_dist(gt[:, :2], gt[:, :2])
    with pytest.raises(ValueError):
        garnet.metrics.e_norm(gt, gt, faces + 1000)


def test_simulate_a_coarse_tshirt(tmp_path):
    template = garnet.Template.make("tshirt", edge=0.08)
    path = tmp_path / "t.garment"
    template.save(path)
    fast = {"morph_steps": 2, "pose_steps": 3, "iterations": 2, "max_penetration": 0.5}
    body = garnet.Body.random(1)
    for t in (template, path, str(path)):
        result = garnet.simulate(t, body, simulator=fast, max_settle_steps=5)
        assert result.vertices.shape == template.vertices.shape
        assert result.faces.shape == template.faces.shape
        assert result.stats["settle_steps"] <= 5
        assert "converged" in result.stats
    with pytest.raises(ValueError, match="unknown field"):
        garnet.simulate(template, body, simulator={"frictoin": 0.2})
    with pytest.raises(FileNotFoundError):
        garnet.simulate(tmp_path / "none.garment", body)
    with pytest.raises(ValueError, match="edge length"):
        garnet.Template.make("tshirt", edge=1.0)
